// loadRobot on good input: the robots we author (robots/planar_arm, robots/arm6) and the shared Panda
// and UR5 (counts from DATA.md), mesh URIs (relative, file://, package:// through every search path),
// the SRDF pairs, and the warnings a user should see.
#include <clearway/load/robot_loader.h>

#include "load/robot_files.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <string>

using namespace clearway;
using clearway::test::TempDir;

namespace {

std::size_t collisionTriangles(const RobotModel& m) {
  std::size_t n = 0;
  for (const Link& l : m.links())
    for (const CollisionElement& c : l.collisions)
      if (c.mesh >= 0) n += m.meshes()[c.mesh].triangles.size();
  return n;
}

std::map<JointType, int> jointTypes(const RobotModel& m) {
  std::map<JointType, int> count;
  for (const Joint& j : m.joints()) ++count[j.type];
  return count;
}

int linksWithGeometry(const RobotModel& m) {
  return static_cast<int>(std::count_if(m.links().begin(), m.links().end(),
                                        [](const Link& l) { return !l.collisions.empty(); }));
}

std::set<std::pair<std::string, std::string>> namedPairs(const RobotModel& m,
                                                         const std::vector<std::pair<int, int>>& pairs) {
  std::set<std::pair<std::string, std::string>> out;
  for (const auto& [a, b] : pairs) out.emplace(std::min(m.link(a).name, m.link(b).name), std::max(m.link(a).name, m.link(b).name));
  return out;
}

// Pairs of the SRDF with the given reason, by name.
std::set<std::pair<std::string, std::string>> srdfPairs(const RobotModel& m, const std::string& reason) {
  std::vector<std::pair<int, int>> pairs;
  for (const DisabledCollision& d : m.disabledCollisions())
    if (d.reason == reason) pairs.emplace_back(d.link_a, d.link_b);
  return namedPairs(m, pairs);
}

// A one-link robot whose collision is the mesh at uri.
std::string meshRobot(const std::string& uri) {
  return "<robot name=\"m\"><link name=\"a\"><collision><geometry><mesh filename=\"" + uri +
         "\"/></geometry></collision></link></robot>";
}

}  // namespace

TEST(RobotLoader, PlanarArmPrimitives) {
  const RobotModel m = loadRobot(test::sourceRobot("planar_arm/planar_arm.urdf"));
  EXPECT_EQ(m.name(), "planar_arm");
  ASSERT_EQ(m.linkCount(), 4);
  ASSERT_EQ(m.jointCount(), 3);
  EXPECT_EQ(m.variableCount(), 2);
  EXPECT_TRUE(m.meshes().empty());
  EXPECT_TRUE(m.loadWarnings().empty());

  const Link& link1 = m.link(m.linkIndex("link1"));
  ASSERT_EQ(link1.collisions.size(), 1u);
  const Box* box = std::get_if<Box>(&*link1.collisions[0].primitive);
  ASSERT_NE(box, nullptr);
  EXPECT_TRUE(box->half.isApprox(Vec3(0.5, 0.05, 0.05)));
  EXPECT_TRUE(link1.collisions[0].origin.t.isApprox(Vec3(0.5, 0, 0)));

  const Link& link2 = m.link(m.linkIndex("link2"));
  const Cylinder* cylinder = std::get_if<Cylinder>(&*link2.collisions.at(0).primitive);
  ASSERT_NE(cylinder, nullptr);
  EXPECT_DOUBLE_EQ(cylinder->r, 0.05);
  EXPECT_DOUBLE_EQ(cylinder->h, 0.25);  // half the URDF length
  // Pitch π/2 turns the cylinder's z axis onto x.
  EXPECT_LT((link2.collisions[0].origin.R * Vec3::UnitZ() - Vec3::UnitX()).norm(), 1e-12);

  const Joint& elbow = m.joint(m.jointIndex("elbow"));
  EXPECT_EQ(elbow.type, JointType::Revolute);
  EXPECT_EQ(elbow.parent_link, m.linkIndex("link1"));
  EXPECT_EQ(elbow.child_link, m.linkIndex("link2"));
  EXPECT_DOUBLE_EQ(elbow.lower, -2.5);
  EXPECT_DOUBLE_EQ(elbow.upper, 2.5);
  EXPECT_DOUBLE_EQ(elbow.velocity, 1.0);
  EXPECT_EQ(elbow.first_variable, 1);
  EXPECT_EQ(m.joint(m.jointIndex("tool_joint")).first_variable, -1);
  EXPECT_EQ(m.linkIndex("nope"), -1);
  EXPECT_EQ(m.jointIndex("nope"), -1);
  EXPECT_EQ(m.variableIndex("elbow"), 1);
}

TEST(RobotLoader, Arm6MeshesInEveryFormat) {
  const RobotModel m = loadRobot(test::sourceRobot("arm6/arm6.urdf"), test::sourceRobot("arm6/arm6.srdf"));
  EXPECT_EQ(m.linkCount(), 8);
  EXPECT_EQ(m.jointCount(), 7);
  EXPECT_EQ(m.variableCount(), 6);
  EXPECT_EQ(linksWithGeometry(m), 7);
  EXPECT_EQ(m.meshes().size(), 6u);
  EXPECT_EQ(collisionTriangles(m), 3 * 96u + 3 * 12u);
  for (const TriangleMesh& mesh : m.meshes()) EXPECT_TRUE(isClosed(mesh));

  // The only warning: the forearm's COLLADA file declares Y_UP, ignored as ROS ignores it.
  ASSERT_EQ(m.loadWarnings().size(), 1u);
  EXPECT_NE(m.loadWarnings()[0].find("link 'forearm_link' <collision>"), std::string::npos) << m.loadWarnings()[0];
  EXPECT_NE(m.loadWarnings()[0].find("<up_axis> is Y_UP: ignored"), std::string::npos) << m.loadWarnings()[0];
  // The forearm stands along its link's z, as in RViz and MoveIt.
  double forearm_top = 0.0;
  for (const Vec3& v : m.meshes().at(m.link(m.linkIndex("forearm_link")).collisions.at(0).mesh).vertices)
    forearm_top = std::max(forearm_top, v.z());
  EXPECT_NEAR(forearm_top, 0.35, 1e-7);

  // The millimetre mesh is scaled by the URDF: the wrist is 0.1 m tall, radius 0.035.
  const Link& wrist1 = m.link(m.linkIndex("wrist_1_link"));
  const TriangleMesh& w1 = m.meshes().at(wrist1.collisions.at(0).mesh);
  double top = 0.0, radius = 0.0;
  for (const Vec3& v : w1.vertices) {
    top = std::max(top, v.z());
    radius = std::max(radius, v.head<2>().norm());
  }
  EXPECT_NEAR(top, 0.1, 1e-12);
  EXPECT_NEAR(radius, 0.035, 1e-12);

  // Two collision elements on the last link, in document order: a sphere, then a capsule.
  const Link& wrist3 = m.link(m.linkIndex("wrist_3_link"));
  ASSERT_EQ(wrist3.collisions.size(), 2u);
  EXPECT_NE(std::get_if<Sphere>(&*wrist3.collisions[0].primitive), nullptr);
  const Capsule* capsule = std::get_if<Capsule>(&*wrist3.collisions[1].primitive);
  ASSERT_NE(capsule, nullptr);
  EXPECT_DOUBLE_EQ(capsule->r, 0.02);
  EXPECT_DOUBLE_EQ(capsule->h, 0.03);
  EXPECT_TRUE(wrist3.collisions[1].origin.t.isApprox(Vec3(0, 0, 0.05)));

  // SRDF: 7 pairs with their reasons; the adjacent ones are exactly the tree's adjacent pairs.
  EXPECT_EQ(m.disabledCollisions().size(), 7u);
  EXPECT_EQ(srdfPairs(m, "Adjacent"), namedPairs(m, adjacentLinkPairs(m)));
  EXPECT_EQ(srdfPairs(m, "Never"), (std::set<std::pair<std::string, std::string>>{{"base_link", "upper_arm_link"}}));
}

TEST(RobotLoader, PandaCountsMatchDataMd) {
  CLEARWAY_SHARED_ROBOT_OR_SKIP(urdf, "panda/panda.urdf");
  const RobotModel m = loadRobot(urdf, test::sharedRobot("panda/panda.srdf"));
  EXPECT_EQ(m.name(), "panda");
  EXPECT_EQ(m.linkCount(), 12);
  EXPECT_EQ(linksWithGeometry(m), 11);
  EXPECT_EQ(m.jointCount(), 11);
  EXPECT_EQ(jointTypes(m), (std::map<JointType, int>{{JointType::Fixed, 2}, {JointType::Revolute, 7}, {JointType::Prismatic, 2}}));
  EXPECT_EQ(collisionTriangles(m), 2364u);
  EXPECT_EQ(m.meshes().size(), 10u);  // finger.stl serves both fingers
  EXPECT_TRUE(m.loadWarnings().empty()) << m.loadWarnings().front();

  // 7 arm joints and finger 1 are variables; finger 2 mimics finger 1.
  EXPECT_EQ(m.variableCount(), 8);
  for (int i = 0; i < 7; ++i) EXPECT_EQ(m.variables()[i].name, "panda_joint" + std::to_string(i + 1));
  EXPECT_EQ(m.variables()[7].name, "panda_finger_joint1");
  const Joint& finger2 = m.joint(m.jointIndex("panda_finger_joint2"));
  EXPECT_TRUE(finger2.isMimic());
  EXPECT_EQ(finger2.mimic.joint, m.jointIndex("panda_finger_joint1"));
  EXPECT_EQ(finger2.mimic.multiplier, 1.0);
  EXPECT_EQ(finger2.mimic.offset, 0.0);
  EXPECT_EQ(finger2.first_variable, -1);
  EXPECT_DOUBLE_EQ(m.joint(m.jointIndex("panda_joint4")).upper, 0.0873);

  // Links in topological order, root first.
  EXPECT_EQ(m.link(0).name, "panda_link0");
  for (int i = 1; i < m.linkCount(); ++i) EXPECT_LT(m.parentLink(i), i);

  // The SRDF's 34 pairs; its "Adjacent" pairs are what the Setup Assistant computed, which our adjacency
  // reproduces (panda_link7 – panda_hand through panda_link8, which has no geometry).
  EXPECT_EQ(m.disabledCollisions().size(), 34u);
  EXPECT_EQ(srdfPairs(m, "Adjacent"), namedPairs(m, adjacentLinkPairs(m)));
  EXPECT_EQ(srdfPairs(m, "Default"), (std::set<std::pair<std::string, std::string>>{{"panda_leftfinger", "panda_rightfinger"}}));
}

TEST(RobotLoader, Ur5CountsMatchDataMd) {
  CLEARWAY_SHARED_ROBOT_OR_SKIP(urdf, "ur5/ur5.urdf");
  const RobotModel m = loadRobot(urdf, test::sharedRobot("ur5/ur5.srdf"));
  EXPECT_EQ(m.name(), "ur5_robotiq85");
  EXPECT_EQ(m.linkCount(), 23);
  EXPECT_EQ(linksWithGeometry(m), 19);
  EXPECT_EQ(m.jointCount(), 22);
  EXPECT_EQ(jointTypes(m), (std::map<JointType, int>{{JointType::Fixed, 16}, {JointType::Revolute, 6}}));
  EXPECT_EQ(m.variableCount(), 6);
  EXPECT_EQ(collisionTriangles(m), 104185u);
  EXPECT_EQ(m.meshes().size(), 13u);
  int primitives = 0, meshes = 0;
  for (const Link& l : m.links())
    for (const CollisionElement& c : l.collisions) (c.primitive ? primitives : meshes) += 1;
  EXPECT_EQ(primitives, 2);
  EXPECT_EQ(meshes, 17);
  EXPECT_EQ(m.link(0).name, "world");
  const Box* pedestal = std::get_if<Box>(&*m.link(m.linkIndex("box_link")).collisions.at(0).primitive);
  ASSERT_NE(pedestal, nullptr);
  EXPECT_TRUE(pedestal->half.isApprox(Vec3(0.2, 0.2, 0.4572)));
  // Three Robotiq meshes are not closed; the user is told, naming link and file.
  int open = 0;
  for (const std::string& w : m.loadWarnings()) {
    EXPECT_NE(w.find("not closed"), std::string::npos) << w;
    EXPECT_EQ(w.rfind(urdf + ": link '", 0), 0u) << w;
    ++open;
  }
  EXPECT_EQ(open, 3);
  EXPECT_EQ(m.disabledCollisions().size(), 88u);
  // Every adjacent pair is disabled in the SRDF except the pedestal's (DATA.md: box_link was added to the
  // URDF, the SRDF is VAMP's): the collision filter needs the adjacency, not only the SRDF.
  std::set<std::pair<std::string, std::string>> missing;
  for (const auto& [a, b] : adjacentLinkPairs(m)) {
    const bool disabled = std::any_of(m.disabledCollisions().begin(), m.disabledCollisions().end(),
                                      [&, a = a, b = b](const DisabledCollision& d) { return d.link_a == a && d.link_b == b; });
    if (!disabled) missing.emplace(m.link(a).name, m.link(b).name);
  }
  EXPECT_EQ(missing, (std::set<std::pair<std::string, std::string>>{{"box_link", "base_link"}}));
}

TEST(RobotLoader, LinkOrderIsDepthFirstInDocumentOrder) {
  TempDir dir;
  // Joints listed out of tree order, with a branch: the order follows the tree, children by joint order.
  const std::string urdf = dir.write("tree.urdf", R"(<robot name="t">
    <link name="c"/><link name="root"/><link name="b"/><link name="a"/><link name="a2"/>
    <joint name="ja2" type="fixed"><parent link="a"/><child link="a2"/></joint>
    <joint name="jb" type="fixed"><parent link="root"/><child link="b"/></joint>
    <joint name="ja" type="fixed"><parent link="root"/><child link="a"/></joint>
    <joint name="jc" type="continuous"><parent link="b"/><child link="c"/></joint>
  </robot>)");
  const RobotModel m = loadRobot(urdf);
  std::vector<std::string> links, joints;
  for (const Link& l : m.links()) links.push_back(l.name);
  for (const Joint& j : m.joints()) joints.push_back(j.name);
  EXPECT_EQ(links, (std::vector<std::string>{"root", "b", "c", "a", "a2"}));
  EXPECT_EQ(joints, (std::vector<std::string>{"jb", "jc", "ja", "ja2"}));
  for (int i = 1; i < m.linkCount(); ++i) EXPECT_EQ(m.link(i).parent_joint, i - 1);
}

TEST(RobotLoader, VisualWithoutCollisionIsAWarning) {
  TempDir dir;
  const std::string urdf = dir.write("visual.urdf", R"(<robot name="v">
    <link name="a"><collision><geometry><sphere radius="0.1"/></geometry></collision></link>
    <link name="b"><visual><geometry><box size="1 1 1"/></geometry></visual></link>
    <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>
  </robot>)");
  const RobotModel m = loadRobot(urdf);
  ASSERT_EQ(m.loadWarnings().size(), 1u);
  EXPECT_EQ(m.loadWarnings()[0], urdf + ": link 'b' (line 3): has <visual> but no <collision>: it is never checked for collisions");
}

TEST(RobotLoader, VisualAndInertialDoNotMatter) {
  // urdfdom 3 cannot read a capsule or a mass-less inertial; neither concerns collision checking.
  TempDir dir;
  const std::string urdf = dir.write("extras.urdf", R"(<robot name="x">
    <link name="a">
      <inertial><origin xyz="0 0 0.1"/><inertia ixx="1"/></inertial>
      <visual><geometry><capsule radius="0.1" length="0.2"/></geometry><material name="m"/></visual>
      <collision><geometry><capsule radius="0.1" length="0.2"/></geometry></collision>
    </link>
  </robot>)");
  const RobotModel m = loadRobot(urdf);
  ASSERT_EQ(m.link(0).collisions.size(), 1u);
  EXPECT_NE(std::get_if<Capsule>(&*m.link(0).collisions[0].primitive), nullptr);
  EXPECT_TRUE(m.loadWarnings().empty()) << m.loadWarnings().front();
}

TEST(RobotLoader, MeshUris) {
  TempDir dir;
  const std::string tet = test::tetrahedronStl();
  dir.write("robot/meshes/tet.stl", tet);

  // Relative to the URDF, and absolute, and file://.
  EXPECT_EQ(loadRobot(dir.write("robot/rel.urdf", meshRobot("meshes/tet.stl"))).meshes().size(), 1u);
  EXPECT_EQ(loadRobot(dir.write("robot/abs.urdf", meshRobot(dir.path("robot/meshes/tet.stl")))).meshes().size(), 1u);
  EXPECT_EQ(loadRobot(dir.write("robot/file.urdf", meshRobot("file://" + dir.path("robot/meshes/tet.stl")))).meshes().size(), 1u);
  dir.write("with space/tet.stl", tet);
  EXPECT_EQ(loadRobot(dir.write("robot/escaped.urdf", meshRobot("file://" + dir.path("with%20space/tet.stl"))))
                .meshes()
                .size(),
            1u);

  // package:// through the explicit paths: a folder holding the package, or the package folder itself,
  // or a package.xml folder a few levels down.
  dir.write("ws/src/group/my_robot/package.xml", "<package><name>my_robot</name></package>");
  dir.write("ws/src/group/my_robot/meshes/tet.stl", tet);
  const std::string urdf = dir.write("elsewhere/pkg.urdf", meshRobot("package://my_robot/meshes/tet.stl"));
  for (const std::string& path : {dir.path("ws/src/group"), dir.path("ws/src/group/my_robot"), dir.path("ws")}) {
    LoadOptions options;
    options.package_paths = {dir.path("nothing_here"), path};
    EXPECT_EQ(loadRobot(urdf, "", options).meshes().size(), 1u) << path;
  }

  // ROS_PACKAGE_PATH and AMENT_PREFIX_PATH (<prefix>/share/NAME).
  const char* old_ros = std::getenv("ROS_PACKAGE_PATH");
  const char* old_ament = std::getenv("AMENT_PREFIX_PATH");
  const std::string saved_ros = old_ros ? old_ros : "", saved_ament = old_ament ? old_ament : "";
  ::setenv("ROS_PACKAGE_PATH", (dir.path("nothing_here") + ":" + dir.path("ws/src")).c_str(), 1);
  ::unsetenv("AMENT_PREFIX_PATH");
  EXPECT_EQ(loadRobot(urdf).meshes().size(), 1u);
  ::unsetenv("ROS_PACKAGE_PATH");
  dir.write("install/share/my_robot/meshes/tet.stl", tet);
  ::setenv("AMENT_PREFIX_PATH", (dir.path("other") + ":" + dir.path("install")).c_str(), 1);
  EXPECT_EQ(loadRobot(urdf).meshes().size(), 1u);
  ::unsetenv("AMENT_PREFIX_PATH");
  EXPECT_LOAD_ERROR(loadRobot(urdf), urdf, "link 'a' <collision>", "unresolved package://my_robot");
  if (old_ros) ::setenv("ROS_PACKAGE_PATH", saved_ros.c_str(), 1);
  if (old_ament) ::setenv("AMENT_PREFIX_PATH", saved_ament.c_str(), 1);
}

TEST(RobotLoader, OneMeshPerFileAndScale) {
  TempDir dir;
  dir.write("tet.stl", test::tetrahedronStl());
  const std::string urdf = dir.write("shared.urdf", R"(<robot name="s">
    <link name="a"><collision><geometry><mesh filename="tet.stl"/></geometry></collision></link>
    <link name="b"><collision><geometry><mesh filename="./tet.stl"/></geometry></collision>
                   <collision><geometry><mesh filename="tet.stl" scale="2 2 2"/></geometry></collision></link>
    <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>
  </robot>)");
  const RobotModel m = loadRobot(urdf);
  ASSERT_EQ(m.meshes().size(), 2u);
  EXPECT_EQ(m.link(0).collisions[0].mesh, m.link(1).collisions[0].mesh);
  EXPECT_NE(m.link(1).collisions[0].mesh, m.link(1).collisions[1].mesh);
  EXPECT_DOUBLE_EQ(m.meshes()[m.link(1).collisions[1].mesh].vertices[1].norm(), 2.0);
}

TEST(RobotLoader, ColladaUpAxisWarningOncePerFileAndTheOptionReachesTheMeshes) {
  TempDir dir;
  dir.write("tall.dae", test::colladaBox({-0.05, -0.05, 0}, {0.05, 0.05, 1}, "Y_UP"));
  const std::string urdf = dir.write("r.urdf", R"(<robot name="r">
    <link name="a"><collision><geometry><mesh filename="tall.dae"/></geometry></collision></link>
    <link name="b"><collision><geometry><mesh filename="tall.dae" scale="2 2 2"/></geometry></collision>
                   <collision><geometry><mesh filename="./tall.dae"/></geometry></collision></link>
    <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>
  </robot>)");
  const RobotModel plain = loadRobot(urdf);
  EXPECT_EQ(plain.meshes().size(), 2u);
  ASSERT_EQ(plain.loadWarnings().size(), 1u);
  EXPECT_NE(plain.loadWarnings()[0].find("tall.dae: COLLADA <up_axis> is Y_UP: ignored"), std::string::npos)
      << plain.loadWarnings()[0];
  EXPECT_NEAR(plain.meshes()[0].vertices[0].z(), 0.0, 1e-12);  // corner (-0.05, -0.05, 0) as written

  LoadOptions options;
  options.mesh.honour_up_axis = true;
  const RobotModel turned = loadRobot(urdf, "", options);
  ASSERT_EQ(turned.loadWarnings().size(), 1u);
  EXPECT_NE(turned.loadWarnings()[0].find("rotated"), std::string::npos) << turned.loadWarnings()[0];
  double lowest_y = 0.0;
  for (const Vec3& v : turned.meshes()[0].vertices) lowest_y = std::min(lowest_y, v.y());
  EXPECT_NEAR(lowest_y, -1.0, 1e-12);  // the file's y is up: its z (the box's length) lies along -y
}

TEST(RobotLoader, SrdfDetails) {
  TempDir dir;
  const std::string urdf = dir.write("r.urdf", R"(<robot name="r">
    <link name="a"><collision><geometry><sphere radius="0.1"/></geometry></collision></link>
    <link name="b"><collision><geometry><sphere radius="0.1"/></geometry></collision></link>
    <joint name="j" type="continuous"><parent link="a"/><child link="b"/></joint>
  </robot>)");
  const std::string srdf = dir.write("r.srdf", R"(<robot name="other">
    <group name="arm"><chain base_link="a" tip_link="b"/></group>
    <disable_collisions link1="b" link2="a" reason="Adjacent"/>
    <disable_collisions link1="a" link2="b" reason="Never"/>
    <disable_collisions link1="a" link2="a" reason="User"/>
  </robot>)");
  const RobotModel m = loadRobot(urdf, srdf);
  ASSERT_EQ(m.disabledCollisions().size(), 1u);
  EXPECT_EQ(m.disabledCollisions()[0].link_a, 0);
  EXPECT_EQ(m.disabledCollisions()[0].link_b, 1);
  EXPECT_EQ(m.disabledCollisions()[0].reason, "Adjacent");
  // Warnings: the robot name differs, one pair repeats, one names a link twice.
  ASSERT_EQ(m.loadWarnings().size(), 3u);
  EXPECT_NE(m.loadWarnings()[0].find("names robot 'other'"), std::string::npos);
  EXPECT_EQ(m.loadWarnings()[1], srdf + ": <disable_collisions> (line 4): repeats a pair listed before, ignored");
  EXPECT_NE(m.loadWarnings()[2].find("names one link twice"), std::string::npos);
}
