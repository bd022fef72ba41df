// loadRobot on bad input: each problem a user can make in a URDF, an SRDF or a mesh is a LoadError that
// names the file, the element (with its line) and the reason.
#include <clearway/body/robot_geometry.h>
#include <clearway/load/robot_loader.h>
#include <clearway/load/input_limits.h>
#include <clearway/load/mesh_loader.h>

#include "load/robot_files.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>

using namespace clearway;
using clearway::test::TempDir;

namespace {

// A two-link robot: link a, then link b on joint j; the pieces in braces are replaced per test.
std::string twoLinks(const std::string& joint_type = "revolute", const std::string& joint_extra = "",
                     const std::string& link_b = "") {
  return "<robot name=\"r\">\n"
         "  <link name=\"a\"><collision><geometry><box size=\"1 1 1\"/></geometry></collision></link>\n"
         "  <link name=\"b\">" + link_b + "</link>\n"
         "  <joint name=\"j\" type=\"" + joint_type + "\">\n"
         "    <parent link=\"a\"/><child link=\"b\"/>\n"
         "    <limit lower=\"-1\" upper=\"1\" velocity=\"1\" effort=\"1\"/>\n" + joint_extra +
         "  </joint>\n"
         "</robot>\n";
}

std::string meshLink(const std::string& file) {
  return "<collision><geometry><mesh filename=\"" + file + "\"/></geometry></collision>";
}

class BadInput : public ::testing::Test {
 protected:
  TempDir dir;
};

}  // namespace

TEST_F(BadInput, MissingUrdf) {
  const std::string urdf = dir.path("nowhere.urdf");
  EXPECT_LOAD_ERROR(loadRobot(urdf), urdf, "", "cannot open");
}

TEST_F(BadInput, MalformedXml) {
  const std::string urdf = dir.write("malformed.urdf", "<robot name=\"r\">\n  <link name=\"a\">\n</robot>\n");
  EXPECT_LOAD_ERROR(loadRobot(urdf), urdf, "line 2", "malformed XML");  // the unclosed element
  const std::string not_robot = dir.write("not_robot.urdf", "<model name=\"r\"/>\n");
  EXPECT_LOAD_ERROR(loadRobot(not_robot), not_robot, "", "not <robot>");
}

// A chain of more links than kMaxLinks: refused naming the file (50,000 links ran out of memory, naming
// nothing); one link fewer loads.
TEST_F(BadInput, MoreLinksThanTheLimit) {
  const auto chain = [](int links) {
    std::string text = "<robot name=\"chain\">\n<link name=\"l0\"/>\n";
    for (int i = 1; i < links; ++i) {
      const std::string l = std::to_string(i), p = std::to_string(i - 1);
      text += "<link name=\"l" + l + "\"/><joint name=\"j" + l + "\" type=\"fixed\"><parent link=\"l" + p +
              "\"/><child link=\"l" + l + "\"/></joint>\n";
    }
    return text + "</robot>\n";
  };
  const std::string too_many = dir.write("too_many.urdf", chain(kMaxLinks + 1));
  EXPECT_LOAD_ERROR(
      loadRobot(too_many), too_many, "<robot>",
      std::to_string(kMaxLinks + 1) + " links, more than the " + std::to_string(kMaxLinks) + " a robot may have");
  EXPECT_EQ(loadRobot(dir.write("many.urdf", chain(kMaxLinks))).linkCount(), kMaxLinks);
}

TEST_F(BadInput, UnknownJointType) {
  const std::string urdf = dir.write("rotary.urdf", twoLinks("rotary"));
  EXPECT_LOAD_ERROR(loadRobot(urdf), urdf, "joint 'j' (line 4)", "unknown joint type 'rotary'");
  const std::string untyped = dir.write("untyped.urdf", twoLinks(""));
  EXPECT_LOAD_ERROR(loadRobot(untyped), untyped, "joint 'j'", "unknown joint type ''");
}

TEST_F(BadInput, NanInAnOrigin) {
  const std::string joint = dir.write("nan_joint.urdf", twoLinks("revolute", "    <origin xyz=\"0 nan 0\"/>\n"));
  EXPECT_LOAD_ERROR(loadRobot(joint), joint, "joint 'j' <origin> (line 7)", "non-finite");
  const std::string collision = dir.write(
      "nan_collision.urdf",
      twoLinks("revolute", "",
               "<collision><origin rpy=\"0 0 inf\"/><geometry><sphere radius=\"1\"/></geometry></collision>"));
  EXPECT_LOAD_ERROR(loadRobot(collision), collision, "link 'b' <collision> <origin> (line 3)", "non-finite");
  const std::string huge = dir.write("huge_origin.urdf", twoLinks("revolute", "    <origin xyz=\"0 1e999 0\"/>\n"));
  EXPECT_LOAD_ERROR(loadRobot(huge), huge, "joint 'j' <origin>", "out of the range of double");
  const std::string malformed = dir.write("short_origin.urdf", twoLinks("revolute", "    <origin xyz=\"0 1\"/>\n"));
  EXPECT_LOAD_ERROR(loadRobot(malformed), malformed, "joint 'j' <origin>", "expected 3 numbers");
  const std::string limit = dir.write(
      "nan_limit.urdf", "<robot name=\"r\"><link name=\"a\"/><link name=\"b\"/><joint name=\"j\" type=\"prismatic\">"
                        "<parent link=\"a\"/><child link=\"b\"/><limit lower=\"nan\" upper=\"1\" velocity=\"1\" "
                        "effort=\"1\"/></joint></robot>");
  EXPECT_LOAD_ERROR(loadRobot(limit), limit, "joint 'j' <limit>", "non-finite");
}

TEST_F(BadInput, LoopInTheKinematicTree) {
  // c is the child of two joints (a closed chain).
  const std::string two_parents = dir.write("two_parents.urdf", R"(<robot name="r">
    <link name="a"/><link name="b"/><link name="c"/>
    <joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>
    <joint name="j2" type="fixed"><parent link="b"/><child link="c"/></joint>
    <joint name="j3" type="fixed"><parent link="a"/><child link="c"/></joint>
  </robot>)");
  EXPECT_LOAD_ERROR(loadRobot(two_parents), two_parents, "joint 'j3' (line 5)",
                    "loop in the kinematic tree: link 'c' is already the child of joint 'j2'");
  // b and c form a cycle of their own, out of reach of the root (urdfdom accepts this file).
  const std::string cycle = dir.write("cycle.urdf", R"(<robot name="r">
    <link name="root"/><link name="b"/><link name="c"/>
    <joint name="j2" type="fixed"><parent link="b"/><child link="c"/></joint>
    <joint name="j3" type="fixed"><parent link="c"/><child link="b"/></joint>
  </robot>)");
  EXPECT_LOAD_ERROR(loadRobot(cycle), cycle, "link 'b' (line 2)", "loop in the kinematic tree");
  // Every link has a parent.
  const std::string ring = dir.write("ring.urdf", R"(<robot name="r">
    <link name="b"/><link name="c"/>
    <joint name="j2" type="fixed"><parent link="b"/><child link="c"/></joint>
    <joint name="j3" type="fixed"><parent link="c"/><child link="b"/></joint>
  </robot>)");
  EXPECT_LOAD_ERROR(loadRobot(ring), ring, "", "loop in the kinematic tree");
  const std::string self = dir.write("self.urdf", R"(<robot name="r">
    <link name="a"/><joint name="j" type="fixed"><parent link="a"/><child link="a"/></joint>
  </robot>)");
  EXPECT_LOAD_ERROR(loadRobot(self), self, "joint 'j'", "loop in the kinematic tree");
}

TEST_F(BadInput, SeveralRootsAndUnknownLinks) {
  const std::string forest = dir.write("forest.urdf", "<robot name=\"r\"><link name=\"a\"/>\n<link name=\"b\"/></robot>");
  EXPECT_LOAD_ERROR(loadRobot(forest), forest, "link 'b' (line 2)", "a second root link");
  const std::string unknown = dir.write("unknown_link.urdf", R"(<robot name="r"><link name="a"/>
    <joint name="j" type="fixed"><parent link="a"/><child link="ghost"/></joint></robot>)");
  EXPECT_LOAD_ERROR(loadRobot(unknown), unknown, "joint 'j' <child> (line 2)", "no link named 'ghost'");
  const std::string empty = dir.write("empty.urdf", "<robot name=\"r\"/>");
  EXPECT_LOAD_ERROR(loadRobot(empty), empty, "", "no <link>");
}

TEST_F(BadInput, InvertedLimits) {
  const std::string urdf = dir.write(
      "inverted.urdf", "<robot name=\"r\"><link name=\"a\"/><link name=\"b\"/>\n<joint name=\"j\" type=\"revolute\">"
                       "<parent link=\"a\"/><child link=\"b\"/>\n<limit lower=\"1\" upper=\"-1\" velocity=\"1\" "
                       "effort=\"1\"/></joint></robot>");
  EXPECT_LOAD_ERROR(loadRobot(urdf), urdf, "joint 'j' <limit> (line 3)", "inverted limits: lower 1 > upper -1");
  const std::string no_limit = dir.write(
      "no_limit.urdf", "<robot name=\"r\"><link name=\"a\"/><link name=\"b\"/><joint name=\"j\" type=\"prismatic\">"
                       "<parent link=\"a\"/><child link=\"b\"/></joint></robot>");
  EXPECT_LOAD_ERROR(loadRobot(no_limit), no_limit, "joint 'j'", "needs <limit");
}

TEST_F(BadInput, Mimics) {
  const std::string ghost = dir.write("mimic_ghost.urdf", twoLinks("revolute", "    <mimic joint=\"ghost\"/>\n"));
  EXPECT_LOAD_ERROR(loadRobot(ghost), ghost, "joint 'j' <mimic>", "mimics 'ghost', which is not a joint");
  const std::string cycle = dir.write("mimic_cycle.urdf", R"(<robot name="r">
    <link name="a"/><link name="b"/><link name="c"/>
    <joint name="j1" type="continuous"><parent link="a"/><child link="b"/><mimic joint="j2"/></joint>
    <joint name="j2" type="continuous"><parent link="b"/><child link="c"/><mimic joint="j1"/></joint>
  </robot>)");
  EXPECT_LOAD_ERROR(loadRobot(cycle), cycle, "joint 'j", "mimic cycle");
  const std::string fixed_leader = dir.write("mimic_fixed.urdf", R"(<robot name="r">
    <link name="a"/><link name="b"/><link name="c"/>
    <joint name="j1" type="fixed"><parent link="a"/><child link="b"/></joint>
    <joint name="j2" type="continuous"><parent link="b"/><child link="c"/><mimic joint="j1"/></joint>
  </robot>)");
  EXPECT_LOAD_ERROR(loadRobot(fixed_leader), fixed_leader, "joint 'j2'", "a fixed joint (not one variable)");
  const std::string planar = dir.write("mimic_planar.urdf", R"(<robot name="r">
    <link name="a"/><link name="b"/><link name="c"/>
    <joint name="j1" type="continuous"><parent link="a"/><child link="b"/></joint>
    <joint name="j2" type="planar"><parent link="b"/><child link="c"/><mimic joint="j1"/></joint>
  </robot>)");
  EXPECT_LOAD_ERROR(loadRobot(planar), planar, "joint 'j2'", "a planar joint cannot mimic");
  // Multipliers and offsets are bounded as joint values are (a link 1e300 m away was placed), also once
  // composed along a chain of mimics (1e4 · 1e4 = 1e8); within the bound, as any real gear is, they load.
  const auto chain = [&](const std::string& m2, const std::string& o2, const std::string& m3) {
    return dir.write("mimic_far.urdf", R"(<robot name="r">
    <link name="a"/><link name="b"/><link name="c"/><link name="d"/>
    <joint name="j1" type="continuous"><parent link="a"/><child link="b"/></joint>
    <joint name="j2" type="prismatic"><parent link="b"/><child link="c"/><limit lower="0" upper="1" effort="1" velocity="1"/>
      <mimic joint="j1" multiplier=")" + m2 +
                                           R"(" offset=")" + o2 + R"("/></joint>
    <joint name="j3" type="prismatic"><parent link="c"/><child link="d"/><limit lower="0" upper="1" effort="1" velocity="1"/>
      <mimic joint="j2" multiplier=")" + m3 +
                                           R"("/></joint>
  </robot>)");
  };
  const std::string far = chain("1e300", "0", "1");
  EXPECT_LOAD_ERROR(loadRobot(far), far, "joint 'j2'", "mimic multiplier 1.0000000000000001e+300 (composed");
  const std::string offset = chain("1", "-2e6", "1");
  EXPECT_LOAD_ERROR(loadRobot(offset), offset, "joint 'j2'",
                    "mimic offset -2000000 (composed along its chain of mimics) "
                    "is beyond ±1e6");
  const std::string composed = chain("1e4", "0", "1e4");
  EXPECT_LOAD_ERROR(loadRobot(composed), composed, "joint 'j3'", "mimic multiplier 100000000 (composed");
  const std::string geared = chain("-2.5", "0.1", "1e4");
  const RobotModel m = loadRobot(geared);
  EXPECT_EQ(m.joint(m.jointIndex("j3")).mimic.multiplier, -2.5e4);
}

TEST_F(BadInput, AMimicOnAFixedJointIsIgnoredWithAWarning) {
  // urdfdom accepts it and it does nothing (MoveIt too), whether the joint it names exists or not.
  for (const std::string leader : {"j1", "ghost"}) {
    const std::string urdf = dir.write("fixed_mimic_" + leader + ".urdf", R"(<robot name="r">
    <link name="a"/><link name="b"/><link name="c"/>
    <joint name="j1" type="continuous"><parent link="a"/><child link="b"/></joint>
    <joint name="j2" type="fixed"><parent link="b"/><child link="c"/><mimic joint=")" + leader + R"(" multiplier="2"/></joint>
  </robot>)");
    const RobotModel m = loadRobot(urdf);
    EXPECT_EQ(m.variableCount(), 1);
    const Joint& j2 = m.joint(m.jointIndex("j2"));
    EXPECT_EQ(j2.type, JointType::Fixed);
    EXPECT_FALSE(j2.isMimic());
    ASSERT_EQ(m.loadWarnings().size(), 1u);
    EXPECT_EQ(m.loadWarnings()[0], urdf + ": joint 'j2' (line 4): a fixed joint cannot mimic: <mimic joint=\"" + leader +
                                       "\"> ignored");
  }
}

TEST_F(BadInput, UnsupportedGeometry) {
  const std::string urdf = dir.write("cone.urdf", twoLinks("revolute", "", "<collision><geometry><cone radius=\"1\" length=\"1\"/></geometry></collision>"));
  EXPECT_LOAD_ERROR(loadRobot(urdf), urdf, "link 'b' <collision> <geometry> <cone> (line 3)", "unsupported geometry <cone>");
  const std::string zero = dir.write("zero_radius.urdf", twoLinks("revolute", "", "<collision><geometry><sphere radius=\"0\"/></geometry></collision>"));
  EXPECT_LOAD_ERROR(loadRobot(zero), zero, "<sphere>", "radius > 0");
  const std::string none = dir.write("no_geometry.urdf", twoLinks("revolute", "", "<collision></collision>"));
  EXPECT_LOAD_ERROR(loadRobot(none), none, "link 'b' <collision> (line 3)", "no <geometry>");
}

TEST_F(BadInput, MissingMeshFile) {
  const std::string urdf = dir.write("missing_mesh.urdf", twoLinks("revolute", "", meshLink("meshes/missing.stl")));
  EXPECT_LOAD_ERROR(loadRobot(urdf), urdf, "link 'b' <collision> (line 3)", "mesh file not found");
  try {
    loadRobot(urdf);
  } catch (const LoadError& e) {
    EXPECT_NE(e.reason().find(dir.path("meshes/missing.stl")), std::string::npos) << "names the resolved path: " << e.what();
  }
}

TEST_F(BadInput, UnsupportedMeshFormat) {
  dir.write("part.SLDPRT", "a SolidWorks part");
  const std::string urdf = dir.write("cad.urdf", twoLinks("revolute", "", meshLink("part.SLDPRT")));
  EXPECT_LOAD_ERROR(loadRobot(urdf), urdf, "link 'b' <collision>", "unsupported mesh format 'sldprt'");
}

TEST_F(BadInput, EmptyMesh) {
  dir.write("empty.stl", "solid empty\nendsolid empty\n");
  const std::string urdf = dir.write("empty_mesh.urdf", twoLinks("revolute", "", meshLink("empty.stl")));
  EXPECT_LOAD_ERROR(loadRobot(urdf), urdf, "link 'b' <collision>", "empty mesh");
}

TEST_F(BadInput, BadMeshUris) {
  const std::string package = dir.write("package.urdf", twoLinks("revolute", "", meshLink("package://no_such_package/m.stl")));
  EXPECT_LOAD_ERROR(loadRobot(package), package, "link 'b' <collision>", "unresolved package://no_such_package");
  const std::string http = dir.write("http.urdf", twoLinks("revolute", "", meshLink("http://example.com/m.stl")));
  EXPECT_LOAD_ERROR(loadRobot(http), http, "link 'b' <collision>", "unsupported URI scheme 'http://'");
  const std::string file = dir.write("file.urdf", twoLinks("revolute", "", meshLink("file://relative/m.stl")));
  EXPECT_LOAD_ERROR(loadRobot(file), file, "link 'b' <collision>", "without an absolute path");
}

TEST_F(BadInput, SrdfPairsNamingMissingLinksAreSkippedWithOneWarning) {
  // MoveIt skips such pairs; shipped SRDFs often name links of another variant of the robot.
  const std::string urdf = dir.write("r.urdf", twoLinks());
  std::string text = "<robot name=\"r\">\n  <disable_collisions link1=\"a\" link2=\"b\" reason=\"Adjacent\"/>\n";
  for (int i = 0; i < 8; ++i)  // 8 pairs, 7 distinct missing names (ghost0 twice)
    text += "  <disable_collisions link1=\"a\" link2=\"ghost" + std::to_string(i % 7) + "\" reason=\"Never\"/>\n";
  text += "  <disable_collisions link1=\"ghost0\" link2=\"gone\" reason=\"Never\"/>\n</robot>\n";
  const std::string srdf = dir.write("r.srdf", text);
  const RobotModel m = loadRobot(urdf, srdf);
  ASSERT_EQ(m.disabledCollisions().size(), 1u);
  EXPECT_EQ(m.disabledCollisions()[0].reason, "Adjacent");
  ASSERT_EQ(m.loadWarnings().size(), 1u) << m.loadWarnings()[0];
  const std::string& w = m.loadWarnings()[0];
  EXPECT_EQ(w.rfind(srdf + ": 9 <disable_collisions> pairs skipped (as MoveIt does): 8 link names not in " + urdf +
                        ": 'ghost0', 'ghost1', 'ghost2', 'ghost3', 'ghost4', ...", 0),
            0u)
      << w;
  EXPECT_EQ(w.find("ghost5"), std::string::npos) << "only the first few names: " << w;

  const std::string one = dir.write("one.srdf", "<robot name=\"r\"><disable_collisions link1=\"ghost\" link2=\"b\"/></robot>");
  const RobotModel m1 = loadRobot(urdf, one);
  EXPECT_TRUE(m1.disabledCollisions().empty());
  ASSERT_EQ(m1.loadWarnings().size(), 1u);
  EXPECT_EQ(m1.loadWarnings()[0], one + ": 1 <disable_collisions> pair skipped (as MoveIt does): 1 link name not in " +
                                      urdf + ": 'ghost'");
}

TEST_F(BadInput, BadSrdfFile) {
  const std::string urdf = dir.write("r.urdf", twoLinks());
  const std::string missing = dir.path("missing.srdf");
  EXPECT_LOAD_ERROR(loadRobot(urdf, missing), missing, "", "cannot open");
  const std::string malformed = dir.write("malformed.srdf", "<robot name=\"r\">\n<disable_collisions link1=\"a\"\n");
  EXPECT_LOAD_ERROR(loadRobot(urdf, malformed), malformed, "line", "malformed XML");
  const std::string half = dir.write("half.srdf", "<robot name=\"r\"><disable_collisions link1=\"a\"/></robot>");
  EXPECT_LOAD_ERROR(loadRobot(urdf, half), half, "<disable_collisions> (line 1)", "no link2 attribute");
}

TEST_F(BadInput, SuspiciousMeshesAreWarnings) {
  // The arm6 wrist is modelled in millimetres; without its scale it is 100 m tall. An open mesh is
  // reported too. Both load (a warning is not an error), naming the link and the mesh.
  dir.write("open.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const std::string urdf = dir.write(
      "suspicious.urdf",
      twoLinks("revolute", "",
               meshLink(test::sourceRobot("arm6/meshes/wrist1_mm.stl")) + meshLink("open.obj")));
  const RobotModel m = loadRobot(urdf);
  ASSERT_EQ(m.loadWarnings().size(), 2u);
  EXPECT_EQ(m.loadWarnings()[0].rfind(urdf + ": link 'b' <collision> (line 3): mesh '", 0), 0u) << m.loadWarnings()[0];
  EXPECT_NE(m.loadWarnings()[0].find("probably millimetres"), std::string::npos) << m.loadWarnings()[0];
  EXPECT_NE(m.loadWarnings()[1].find("open.obj: not closed (3 edges with one triangle"), std::string::npos)
      << m.loadWarnings()[1];
}

// ---- Inputs that once crashed, hung or exhausted memory (../shared/bad-inputs), written out here.

TEST_F(BadInput, SizesAndCoordinatesBeyondTheInputLimits) {
  // A sphere of radius 1e-310 crashed the hull builder; a coordinate of 1e308 the tree builder. Sizes
  // below 1e-9 m are grown to it (Scene.TinySolidsAreGrownNeverSkipped), lengths beyond 1e6 m refused.
  const std::string tiny = dir.write("tiny.urdf", twoLinks("revolute", "", "<collision><geometry><sphere radius=\"1e-310\"/></geometry></collision>"));
  const RobotModel tiny_model = loadRobot(tiny);
  ASSERT_EQ(tiny_model.loadWarnings().size(), 1u);
  EXPECT_EQ(tiny_model.loadWarnings()[0], tiny + ": link 'b' <collision> <geometry> <sphere> (line 3): radius=\"1e-310\" is "
                                           "below the smallest size Clearway computes with (1e-9 m): checked as radius=\"1e-09\"");
  const std::string thin = dir.write("thin.urdf", twoLinks("revolute", "", "<collision><geometry><cylinder radius=\"0.1\" length=\"1e-320\"/></geometry></collision>"));
  EXPECT_EQ(RobotGeometry(std::make_shared<const RobotModel>(loadRobot(thin))).link(1)->primitives().size(), 1u);
  const std::string flat = dir.write("flat.urdf", twoLinks("revolute", "", "<collision><geometry><box size=\"0.1 0 1e-12\"/></geometry></collision>"));
  EXPECT_EQ(loadRobot(flat).loadWarnings().size(), 1u);
  const std::string far = dir.write("far.urdf", twoLinks("revolute", "", "<collision><origin xyz=\"0 1e308 0\"/><geometry><sphere radius=\"1\"/></geometry></collision>"));
  EXPECT_LOAD_ERROR(loadRobot(far), far, "<origin>", "beyond the largest length an input may give (1e6 m)");
  const std::string slide = dir.write("slide.urdf", R"(<robot name="r"><link name="a"/><link name="b"/>
    <joint name="j" type="prismatic"><parent link="a"/><child link="b"/><limit lower="0" upper="1e300" velocity="1" effort="1"/></joint></robot>)");
  EXPECT_LOAD_ERROR(loadRobot(slide), slide, "joint 'j' <limit>", "within ±1e6 m");
  // At the limits, and a flat box, still load.
  const std::string edge = dir.write("edge.urdf", twoLinks("revolute", "<origin xyz=\"1e6 0 0\"/>\n", "<collision><geometry><sphere radius=\"1e-9\"/></geometry></collision><collision><geometry><box size=\"1 0 1\"/></geometry></collision>"));
  EXPECT_EQ(loadRobot(edge).link(1).collisions.size(), 2u);
  // Found by fuzz_urdf: the geometry of a flat box (size 0 on an axis) cast an infinite ball count to int
  // (UBSan), and so did a box 5e14 times longer than thick; both build (the plate without a core, the
  // needle with at most 4).
  const std::string plate = dir.write("plate.urdf", "<?xml version=\"1.0\"?>\n<robot name=\"r\"><link name=\"a\"><collision><geometry>"
                                                    "<box size=\"0.1 0.0 0.1\"/></geometry></collision></link></robot>\n");
  const RobotGeometry plate_geometry(std::make_shared<const RobotModel>(loadRobot(plate)));
  ASSERT_NE(plate_geometry.link(0), nullptr);
  EXPECT_EQ(plate_geometry.link(0)->primitives().size(), 1u);
  EXPECT_TRUE(plate_geometry.link(0)->cores().empty());
  const std::string needle = dir.write("needle.urdf", twoLinks("revolute", "", "<collision><geometry><box size=\"2e-9 2e-9 1e6\"/></geometry></collision>"));
  const RobotGeometry needle_geometry(std::make_shared<const RobotModel>(loadRobot(needle)));
  ASSERT_NE(needle_geometry.link(1), nullptr);
  EXPECT_LE(needle_geometry.link(1)->cores().size(), 4u);

  // A mesh scaled to 1e270 (finite, far beyond any robot), or to nothing.
  dir.write("tet.stl", test::tetrahedronStl());
  const std::string huge = dir.write("huge.urdf", twoLinks("revolute", "", "<collision><geometry><mesh filename=\"tet.stl\" scale=\"1e270 1 1\"/></geometry></collision>"));
  EXPECT_LOAD_ERROR(loadRobot(huge), huge, "link 'b' <collision>", "1e+270 m from the origin after scale, beyond the largest length");
  // A mesh scaled below 1e-9 m becomes the closed box 2e-9 m wide around it, with a warning.
  const std::string speck = dir.write("speck.urdf", twoLinks("revolute", "", "<collision><origin xyz=\"1e-16 0 0\"/><geometry><mesh filename=\"tet.stl\" scale=\"1e-12 1e-12 1e-12\"/></geometry></collision>"));
  const RobotModel speck_model = loadRobot(speck);
  ASSERT_EQ(speck_model.loadWarnings().size(), 1u);
  EXPECT_NE(speck_model.loadWarnings()[0].find("the mesh spans 1e-12 m after scale, below the smallest size Clearway "
                                               "computes with (1e-9 m): checked as a closed box 2e-9 m wide around it"),
            std::string::npos) << speck_model.loadWarnings()[0];
  const TriangleMesh box = loadMesh(dir.path("tet.stl"), Vec3::Constant(1e-12));
  EXPECT_EQ(box.triangles.size(), 12u);
  EXPECT_TRUE(isClosed(box));
}

TEST_F(BadInput, MeshFormatsAndPlyIndices) {
  // A PLY face index past the vertex count was used unchecked (SIGSEGV).
  const std::string header = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                             "element face 4\nproperty list uchar int vertex_indices\nend_header\n"
                             "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
  const std::string ok = dir.write("tet.ply", header + "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  EXPECT_EQ(loadMesh(ok, Vec3::Ones()).triangles.size(), 4u);
  const std::string bad = dir.write("bad.ply", header + "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 1000000000\n");
  EXPECT_LOAD_ERROR(loadMesh(bad, Vec3::Ones()), bad, "", "uses vertex 1000000000, but the mesh has 4 vertices");
  // Found by fuzz_mesh_ply: one vertex fewer than the faces use aborted inside assimp's post-processing,
  // before the check above ran.
  std::string three = header;
  three.replace(three.find("element vertex 4"), 16, "element vertex 3");
  three.replace(three.find("0 0 1\n"), 6, "");
  const std::string short_list = dir.write("short.ply", three + "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  EXPECT_LOAD_ERROR(loadMesh(short_list, Vec3::Ones()), short_list, "", "uses vertex 3, but the mesh has 3 vertices");
  // Found by fuzz_mesh_ply: a face of length 0 aborted assimp's triangulation.
  const std::string empty_face = dir.write("empty_face.ply", header + "0\n3 0 2 1\n3 0 1 3\n3 0 3 2\n");
  EXPECT_LOAD_ERROR(loadMesh(empty_face, Vec3::Ones()), empty_face, "", "face 0 has no vertices");
  // Formats other than these four are refused, by the name the error gives them.
  for (const std::string name : {"garbage.x", "model.3ds", "archive.zae", "scene.fbx"}) {
    const std::string path = dir.write(name, "xof 0302txt 0064\ngarbage");
    EXPECT_LOAD_ERROR(loadMesh(path, Vec3::Ones()), path, "", "(Clearway reads STL, OBJ, COLLADA (.dae) or PLY)");
  }
  // Assimp leaks on a facet with two vertices (suppressed for libassimp in sanitizer builds); a clear error.
  const std::string two = dir.write("two_verts.stl", "solid x\n facet normal 0 0 1\n outer loop\n vertex 0 0 0\n vertex 1 0 0\n"
                                                     " endloop\n endfacet\nendsolid x\n");
  EXPECT_LOAD_ERROR(loadMesh(two, Vec3::Ones()), two, "", "assimp cannot read it");
}

TEST_F(BadInput, PlyHeaderWithoutEndHeader) {
  // Found by fuzz_mesh_ply: assimp read header lines forever, looking for end_header past the end of file.
  const std::string header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                             "property float z\nelement face 1\nproperty list uchar int vertex_indices\n";
  const std::string body = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const std::string none = dir.write("no_end.ply", header + body);
  EXPECT_LOAD_ERROR(loadMesh(none, Vec3::Ones()), none, "", "the PLY header has no 'end_header' line");
  // The same header closed loads, also with a CR LF line end.
  EXPECT_EQ(loadMesh(dir.write("end.ply", header + "end_header\r\n" + body), Vec3::Ones()).triangles.size(), 1u);
  // Found by fuzz_mesh_ply: end_header as the file's last bytes, without a line end, after a line longer
  // than it; assimp's line reader never reached the end of the file (a hang, seeking forever).
  const std::string unended = dir.write("unended.ply", "ply\nformat ascii 1.0\nunknown_keyword\nend_header");
  EXPECT_LOAD_ERROR(loadMesh(unended, Vec3::Ones()), unended, "line 4", "'end_header' line has no line end");
  const std::string unended_header = dir.write("unended_header.ply", header + "end_header");
  EXPECT_LOAD_ERROR(loadMesh(unended_header, Vec3::Ones()), unended_header, "line 9", "'end_header' line has no line end");

  // Found by fuzz_mesh_ply (heap corruption reported by ASan's allocator, then valgrind): a second vertex
  // or face element, which assimp wrote past the arrays it sized by the first.
  const std::string vertex = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
  const std::string face = "element face 1\nproperty list uchar int vertex_indices\n";
  const std::string two_vertex = dir.write("two_vertex.ply", "ply\nformat ascii 1.0\n" + vertex + vertex + face + "end_header\n" + body);
  EXPECT_LOAD_ERROR(loadMesh(two_vertex, Vec3::Ones()), two_vertex, "line 7", "a second 'element vertex' (the first is on line 3)");
  const std::string two_faces = dir.write("two_faces.ply", header + "element tristrips 2\nproperty list uchar int vertex_indices\nend_header\n" + body);
  EXPECT_LOAD_ERROR(loadMesh(two_faces, Vec3::Ones()), two_faces, "line 9",
                    "a second face list 'element tristrips' (the first, 'element face', is on line 7)");
  // Found by fuzz_mesh_ply (out of memory): counts that assimp allocates before reading what they count.
  const std::string huge = dir.write("huge.ply", "ply\nformat ascii 1.0\n" + vertex +
                                                   "element face 8888888888888888888888\nproperty list uchar int vertex_indices\nend_header\n" + body);
  EXPECT_LOAD_ERROR(loadMesh(huge, Vec3::Ones()), huge, "line 7", "element 'face' has 8888888888888888888888 instances, more than the file has bytes");
  const std::string long_list = dir.write("long_list.ply", header + "end_header\n0 0 0\n1 0 0\n0 1 0\n555555555555 0 1 2\n");
  EXPECT_LOAD_ERROR(loadMesh(long_list, Vec3::Ones()), long_list, "line 13",
                    "list 'vertex_indices' of face 0 claims 555555555555 values, but the line holds 3 more");
  const std::string negative = dir.write("negative.ply", header + "end_header\n0 0 0\n1 0 0\n0 1 0\n-1 0 1 2\n");
  EXPECT_LOAD_ERROR(loadMesh(negative, Vec3::Ones()), negative, "line 13", "claims -1 values");
  // The same in binary: a count of 2^32 - 1 (uint), and of -1 (int), in a file of a few bytes.
  const std::string binary_header = "ply\nformat binary_little_endian 1.0\n" + vertex + "element face 1\nproperty list TYPE int vertex_indices\nend_header\n";
  const std::string vertices(36, '\0');
  for (const char* type : {"uint", "int"}) {
    std::string text = binary_header;
    text.replace(text.find("TYPE"), 4, type);
    text += vertices + std::string(4, '\xff') + std::string(12, '\0');
    const std::string path = dir.write(std::string("count_") + type + ".ply", text);
    EXPECT_LOAD_ERROR(loadMesh(path, Vec3::Ones()), path, "byte", std::string(type) == "uint" ? "claims 4294967295 values, but the file holds 3 more" : "claims a negative number of values");
  }
  // A sound binary file still loads (little-endian values, as on the machines we build for).
  std::string good_binary = binary_header;
  good_binary.replace(good_binary.find("TYPE"), 4, "uchar");
  const auto bytes = [](auto v) { return std::string(reinterpret_cast<const char*>(&v), sizeof v); };
  for (const float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) good_binary += bytes(v);
  good_binary += bytes(std::uint8_t{3});
  for (const std::int32_t i : {0, 1, 2}) good_binary += bytes(i);
  EXPECT_EQ(loadMesh(dir.write("good_binary.ply", good_binary), Vec3::Ones()).triangles.size(), 1u);
}

namespace {

// A COLLADA file around a library of nodes and a visual scene's content.
std::string collada(const std::string& geometry_p, const std::string& nodes, const std::string& scene_nodes,
                    const std::string& positions = "0 0 0 1 0 0 0 1 0 0 0 1", int vertices = 4,
                    const std::string& accessor = "count=\"4\" stride=\"3\"") {
  return "<?xml version=\"1.0\"?>\n<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">\n"
         "<asset><unit meter=\"1\"/><up_axis>Z_UP</up_axis></asset>\n"
         "<library_geometries><geometry id=\"g\"><mesh>\n"
         "<source id=\"p\"><float_array id=\"pa\" count=\"" + std::to_string(3 * vertices) + "\">" + positions + "</float_array>\n"
         "<technique_common><accessor source=\"#pa\" " + accessor + "><param name=\"X\" type=\"float\"/>"
         "<param name=\"Y\" type=\"float\"/><param name=\"Z\" type=\"float\"/></accessor></technique_common></source>\n"
         "<vertices id=\"v\"><input semantic=\"POSITION\" source=\"#p\"/></vertices>\n"
         "<triangles count=\"4\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/>\n<p>" + geometry_p +
         "</p></triangles>\n</mesh></geometry></library_geometries>\n"
         "<library_nodes>" + nodes + "</library_nodes>\n"
         "<library_visual_scenes><visual_scene id=\"s\">" + scene_nodes + "</visual_scene></library_visual_scenes>\n"
         "<scene><instance_visual_scene url=\"#s\"/></scene>\n</COLLADA>\n";
}

const char* const kTetP = "0 2 1 0 1 3 0 3 2 1 2 3";

// The tetrahedron with a <float_array> that does not say its count.
std::string uncounted() {
  std::string text = collada(kTetP, "", "<node id=\"n\"><instance_geometry url=\"#g\"/></node>");
  const std::string counted = "<float_array id=\"pa\" count=\"12\">";
  text.replace(text.find(counted), counted.size(), "<float_array id=\"pa\">");
  return text;
}

// The tetrahedron as a <polylist> of four triangles, with the given <vcount> element.
std::string polylist(const std::string& vcount) {
  std::string text = collada(kTetP, "", "<node id=\"n\"><instance_geometry url=\"#g\"/></node>");
  const std::string triangles = "<triangles count=\"4\">";
  text.replace(text.find(triangles), triangles.size(), "<polylist count=\"4\">" + vcount);
  text.replace(text.find("</triangles>"), std::string("</triangles>").size(), "</polylist>");
  return text;
}
const char* const kTetNode = "<node id=\"tet\"><instance_geometry url=\"#g\"/></node>";

// text with its first `from` replaced by `to`.
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  return text.replace(text.find(from), from.size(), to);
}

}  // namespace

TEST_F(BadInput, ColladaThatAssimpCannotSurvive) {
  // The reference: a tetrahedron through a library node loads.
  const std::string good = dir.write("good.dae", collada(kTetP, kTetNode, "<node id=\"n\"><instance_node url=\"#tet\"/></node>"));
  EXPECT_EQ(loadMesh(good, Vec3::Ones()).triangles.size(), 4u);
  EXPECT_EQ(loadMesh(dir.write("polylist_ok.dae", polylist("<vcount>3 3 3 3</vcount>")), Vec3::Ones()).triangles.size(), 4u);

  struct Case {
    std::string name, text, element, reason;
  };
  std::string deep_chain;  // 300 library nodes, each instancing the next
  for (int i = 0; i < 300; ++i)
    deep_chain += "<node id=\"c" + std::to_string(i) + "\"><instance_node url=\"#c" + std::to_string(i + 1) + "\"/></node>";
  deep_chain += "<node id=\"c300\"><instance_geometry url=\"#g\"/></node>";
  std::string doubling;  // 2^30 nodes once expanded
  for (int i = 0; i < 30; ++i)
    doubling += "<node id=\"d" + std::to_string(i) + "\"><instance_node url=\"#d" + std::to_string(i + 1) +
                "\"/><instance_node url=\"#d" + std::to_string(i + 1) + "\"/></node>";
  doubling += "<node id=\"d30\"><instance_geometry url=\"#g\"/></node>";
  std::string nested;  // 20,000 nested nodes: tinyxml2 stops at its depth limit
  for (int i = 0; i < 20000; ++i) nested += "<node>";
  for (int i = 0; i < 20000; ++i) nested += "</node>";
  const Case cases[] = {
      // A letter in an index list: assimp looped forever, allocating.
      {"letter.dae", collada("0 2 1 0 1 3 0 3 2 1 2 3x", kTetNode, "<node id=\"n\"><instance_node url=\"#tet\"/></node>"),
       "<p> (line 9)", "'3x' is not an integer"},
      {"decimal.dae", collada("0 2 1 0 1 3 0 3 2 1 2 3.0", kTetNode, "<node id=\"n\"/>"), "<p>", "'3.0' is not an integer"},
      {"float.dae", collada(kTetP, kTetNode, "<node id=\"n\"/>", "0 0 0 1 0 0 0 1 0 0 0 one"), "<float_array> (line 5)",
       "'one' is not a number"},
      // A node that instantiates itself: assimp recursed until the stack overflowed.
      {"self.dae", collada(kTetP, "", "<node id=\"n\"><instance_geometry url=\"#g\"/><instance_node url=\"#n\"/></node>"),
       "<node> (line 12)", "contains itself through <instance_node>"},
      {"cycle.dae", collada(kTetP, "<node id=\"a\"><instance_node url=\"#b\"/></node><node id=\"b\"><node><instance_node url=\"#a\"/></node></node>",
                            "<node id=\"n\"><instance_node url=\"#a\"/></node>"),
       "<node>", "contains itself"},
      {"deep.dae", collada(kTetP, deep_chain, "<node id=\"n\"><instance_node url=\"#c0\"/></node>"), "<node>",
       "nested deeper than 256 levels"},
      {"doubling.dae", collada(kTetP, doubling, "<node id=\"n\"><instance_node url=\"#d0\"/></node>"), "<node>",
       "more than 100000 nodes"},
      {"nested.dae", collada(kTetP, "", nested), "line", "malformed XML"},
      // Counts and accessors beyond what the file holds: assimp reserved or read past the array.
      {"count.dae", collada(kTetP, kTetNode, "<node id=\"n\"/>", "0 0 0 1 0 0 0 1 0 0 0 1", 4,
                            "count=\"99999999999\" stride=\"3\""),
       "<accessor> (line 6)", "count=\"99999999999\" exceeds the size of the file"},
      {"accessor.dae", collada(kTetP, kTetNode, "<node id=\"n\"/>", "0 0 0 1 0 0 0 1 0 0 0 1", 4, "count=\"5\" stride=\"3\""),
       "<accessor> (line 6)", "reaches value 15 of 'pa', which holds 12"},
      // Found by fuzz_mesh_dae: a <polylist> without <vcount>, which assimp read through a null pointer.
      {"polylist.dae", polylist(""), "<polylist> (line 8)", "count=\"4\" polygons, but <vcount> gives 0 corner counts"},
      {"short_vcount.dae", polylist("<vcount>3 3 3</vcount>"), "<polylist>", "<vcount> gives 3 corner counts"},
      // Found by fuzz_mesh_dae: a <float_array> without count="N", of which assimp reads no value.
      {"uncounted.dae", uncounted(), "<accessor> (line 6)", "reaches value 12 of 'pa', which holds 0"},
      {"stride.dae", collada(kTetP, kTetNode, "<node id=\"n\"/>", "0 0 0 1 0 0 0 1 0 0 0 1", 4, "count=\"4\" stride=\"-3\""),
       "<accessor>", "stride=\"-3\" is not a whole number"},
      // Found by fuzz_mesh_dae: a form feed (or vertical tab) between indices, which assimp's list reader
      // does not skip: it read a 0 index at the same place forever, until memory ran out (2.4 GB).
      {"form_feed.dae", collada("0 2 1 0 1 3\f0 3 2 1 2 3", kTetNode, "<node id=\"n\"/>"), "<p> (line 9)",
       "'3\\x0C0' is not an integer"},
      {"vertical_tab.dae", collada("0 2 1 0 1 3 0 3 2 1 2 3\v", kTetNode, "<node id=\"n\"/>"), "<p>",
       "'3\\x0B' is not an integer"},
      // Found by fuzz_mesh_dae (then valgrind, as assimp is not instrumented): <triangles> without an
      // <input semantic="VERTEX">, where assimp read before the start of a heap block.
      {"no_vertex_input.dae", replaced(collada(kTetP, kTetNode, "<node id=\"n\"/>"), "<input semantic=\"VERTEX\"", "<input"),
       "<triangles> (line 8)", "no <input semantic=\"VERTEX\">"},
      {"texcoord_input.dae", replaced(collada(kTetP, kTetNode, "<node id=\"n\"/>"), "semantic=\"VERTEX\"", "semantic=\"TEXCOORD\""),
       "<triangles>", "no <input semantic=\"VERTEX\">"},
      // Found by fuzz_mesh_dae (out of memory, 19 GB): a <vcount> entry of 2222222222222222222222222222222
      // corners, room for which assimp reserved before reading <p>; likewise a triangle count beyond <p>.
      {"huge_vcount.dae", polylist("<vcount>3 3 2222222222222222222222222222222 3</vcount>"), "<vcount> (line 8)",
       "the corner counts add up to more than 12, the corners <p> holds (1 indices each)"},
      {"negative_vcount.dae", polylist("<vcount>3 3 -3 3</vcount>"), "<vcount>", "a negative corner count"},
      {"short_p.dae", replaced(collada(kTetP, kTetNode, "<node id=\"n\"/>"), "<triangles count=\"4\">", "<triangles count=\"5\">"),
       "<triangles> (line 8)", "count=\"5\" triangles, but <p> holds 12 corners (1 indices each)"},
      {"float_form_feed.dae", collada(kTetP, kTetNode, "<node id=\"n\"/>", "0 0 0 1 0 0\f0 1 0 0 0 1"),
       "<float_array> (line 5)", "'0\\x0C0' is not a number"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = dir.write(c.name, c.text);
    EXPECT_LOAD_ERROR(loadMesh(path, Vec3::Ones()), path, c.element, c.reason);
  }
  // Found by fuzz_mesh_dae: primitives whose count="N" their <p> elements do not hold; assimp asserted
  // (abort) after reading them.
  const auto without_p = [](std::string text) {
    const std::size_t a = text.find("<p>"), b = text.find("</p>");
    return text.erase(a, b + 4 - a);
  };
  const auto twice_p = [](std::string text) {
    const std::size_t a = text.find("<p>"), b = text.find("</p>");
    return text.insert(b + 4, text.substr(a, b + 4 - a));
  };
  const std::string no_p = dir.write("no_p.dae", without_p(polylist("<vcount>3 3 3 3</vcount>")));
  EXPECT_LOAD_ERROR(loadMesh(no_p, Vec3::Ones()), no_p, "<polylist>", "count=\"4\" primitives, but it has 0 <p> elements");
  const std::string two_p = dir.write("two_p.dae", twice_p(collada(kTetP, kTetNode, "<node id=\"n\"/>")));
  EXPECT_LOAD_ERROR(loadMesh(two_p, Vec3::Ones()), two_p, "<triangles>", "count=\"4\" primitives, but it has 2 <p> elements");
  std::string polygons = collada(kTetP, kTetNode, "<node id=\"n\"/>");
  polygons.replace(polygons.find("<triangles count=\"4\">"), 21, "<polygons count=\"2\">");
  polygons.replace(polygons.find("</triangles>"), 12, "</polygons>");
  const std::string one_polygon = dir.write("polygons.dae", polygons);
  EXPECT_LOAD_ERROR(loadMesh(one_polygon, Vec3::Ones()), one_polygon, "<polygons>", "count=\"2\" primitives, but it has 1 <p> elements (one per polygon)");
}
