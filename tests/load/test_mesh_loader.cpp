// loadMesh: every format robots use (STL ASCII and binary, OBJ, COLLADA with unit and up axis), the
// node hierarchy, scale, welding, the warnings (zero-area, not closed, millimetres, up axis) and the
// errors (missing, unsupported, empty, non-finite).
#include <clearway/load/mesh_loader.h>

#include "load/robot_files.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

using namespace clearway;
using clearway::test::TempDir;

namespace {

struct Bounds {
  Vec3 lo, hi;
};

Bounds bounds(const TriangleMesh& m) {
  Bounds b{m.vertices.at(0), m.vertices.at(0)};
  for (const Vec3& v : m.vertices) {
    b.lo = b.lo.cwiseMin(v);
    b.hi = b.hi.cwiseMax(v);
  }
  return b;
}

void expectBounds(const TriangleMesh& m, const Vec3& lo, const Vec3& hi, double tol) {
  const Bounds b = bounds(m);
  EXPECT_LT((b.lo - lo).cwiseAbs().maxCoeff(), tol) << "lo " << b.lo.transpose() << " expected " << lo.transpose();
  EXPECT_LT((b.hi - hi).cwiseAbs().maxCoeff(), tol) << "hi " << b.hi.transpose() << " expected " << hi.transpose();
}

// The enclosed volume by the divergence theorem: positive for a closed mesh with outward triangles.
double signedVolume(const TriangleMesh& m) {
  double six_v = 0.0;
  for (const auto& t : m.triangles) six_v += m.vertices[t[0]].dot(m.vertices[t[1]].cross(m.vertices[t[2]]));
  return six_v / 6.0;
}

bool anyContains(const std::vector<std::string>& warnings, const std::string& text) {
  return std::any_of(warnings.begin(), warnings.end(),
                     [&](const std::string& w) { return w.find(text) != std::string::npos; });
}

std::string arm6Mesh(const std::string& name) { return test::sourceRobot("arm6/meshes/" + name); }

// A regular 24-gon prism (as written by robots/gen/gen_arm6_meshes.py): 50 vertices, 96 triangles.
constexpr std::size_t kPrismVertices = 50, kPrismTriangles = 96;

}  // namespace

TEST(MeshLoader, AsciiStlIsWeldedClosedAndOutward) {
  std::vector<std::string> warnings;
  const TriangleMesh m = loadMesh(arm6Mesh("base.stl"), Vec3::Ones(), &warnings);
  EXPECT_TRUE(warnings.empty()) << warnings.front();
  EXPECT_EQ(m.vertices.size(), kPrismVertices);  // the STL repeats each corner once per facet
  EXPECT_EQ(m.triangles.size(), kPrismTriangles);
  EXPECT_TRUE(isClosed(m));
  expectBounds(m, Vec3(-0.08, -0.08, 0.0), Vec3(0.08, 0.08, 0.1), 1e-7);  // corners every 15°
  // A 24-gon of circumradius r has area 12 r² sin(2π/24).
  EXPECT_NEAR(signedVolume(m), 12 * 0.08 * 0.08 * std::sin(2 * M_PI / 24) * 0.1, 1e-8);
}

TEST(MeshLoader, BinaryStl) {
  const TriangleMesh m = loadMesh(arm6Mesh("shoulder.stl"), Vec3::Ones());
  EXPECT_EQ(m.vertices.size(), kPrismVertices);
  EXPECT_EQ(m.triangles.size(), kPrismTriangles);
  EXPECT_TRUE(isClosed(m));
  EXPECT_NEAR(bounds(m).hi.z(), 0.15, 1e-7);  // stored as float
}

TEST(MeshLoader, ObjQuadsAreTriangulated) {
  std::vector<std::string> warnings;
  const TriangleMesh m = loadMesh(arm6Mesh("upper_arm.obj"), Vec3::Ones(), &warnings);
  EXPECT_TRUE(warnings.empty());
  EXPECT_EQ(m.vertices.size(), 8u);
  EXPECT_EQ(m.triangles.size(), 12u);
  EXPECT_TRUE(isClosed(m));
  expectBounds(m, Vec3(-0.04, -0.04, 0.0), Vec3(0.04, 0.04, 0.4), 1e-7);
  EXPECT_NEAR(signedVolume(m), 0.08 * 0.08 * 0.4, 1e-9);
}

TEST(MeshLoader, ColladaUpAxisIsIgnoredAsRosDoesAndTheUnitKept) {
  // The forearm is written in centimetres with the link's coordinates (z up) in a file declaring Y_UP:
  // ROS ignores <up_axis> (geometric_shapes drops assimp's root transform), and so does the loader.
  std::vector<std::string> warnings;
  const TriangleMesh m = loadMesh(arm6Mesh("forearm.dae"), Vec3::Ones(), &warnings);
  EXPECT_EQ(m.triangles.size(), 12u);
  expectBounds(m, Vec3(-0.03, -0.03, 0.0), Vec3(0.03, 0.03, 0.35), 1e-7);
  EXPECT_GT(signedVolume(m), 0.0);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("COLLADA <up_axis> is Y_UP: ignored as ROS"), std::string::npos) << warnings[0];

  // Honoured on request: the file's y becomes z, so the forearm lies along -y.
  warnings.clear();
  MeshOptions honour;
  honour.honour_up_axis = true;
  const TriangleMesh r = loadMesh(arm6Mesh("forearm.dae"), Vec3::Ones(), &warnings, honour);
  expectBounds(r, Vec3(-0.03, -0.35, -0.03), Vec3(0.03, 0.0, 0.03), 1e-7);
  EXPECT_GT(signedVolume(r), 0.0);  // a rotation keeps the triangles outward
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("COLLADA <up_axis> is Y_UP: rotated"), std::string::npos) << warnings[0];
}

TEST(MeshLoader, ColladaEveryUpAxisWithUnitAndNodeTransform) {
  // A box x in [1, 2], y in [0, 0.5], z in [0, 3] (file units: cm), under a node translated by (0, 0, 1).
  TempDir dir;
  const Vec3 lo(0.01, 0.0, 0.01), hi(0.02, 0.005, 0.04);  // in metres, the translation included
  struct Case {
    std::string up_axis;
    Vec3 honoured_lo, honoured_hi;  // the file's up axis turned to z
    bool warned;
  };
  const Case cases[] = {
      {"Z_UP", lo, hi, false},
      {"Y_UP", Vec3(lo.x(), -hi.z(), lo.y()), Vec3(hi.x(), -lo.z(), hi.y()), true},  // (x, y, z) -> (x, -z, y)
      {"", Vec3(lo.x(), -hi.z(), lo.y()), Vec3(hi.x(), -lo.z(), hi.y()), true},      // COLLADA's default is Y_UP
      {"X_UP", Vec3(-hi.y(), -hi.z(), lo.x()), Vec3(-lo.y(), -lo.z(), hi.x()), true},  // (x, y, z) -> (-y, -z, x)
  };
  for (const Case& c : cases) {
    SCOPED_TRACE("up axis '" + c.up_axis + "'");
    const std::string path = dir.write("box_" + c.up_axis + ".dae",
                                       test::colladaBox({1, 0, 0}, {2, 0.5, 3}, c.up_axis, 0.01, "<translate>0 0 1</translate>"));
    std::vector<std::string> warnings;
    const TriangleMesh plain = loadMesh(path, Vec3::Ones(), &warnings);
    expectBounds(plain, lo, hi, 1e-9);  // as written, in metres (assimp keeps floats), whatever the up axis
    EXPECT_NEAR(signedVolume(plain), 0.01 * 0.005 * 0.03, 1e-12);
    EXPECT_EQ(warnings.size(), c.warned ? 1u : 0u);
    warnings.clear();
    MeshOptions honour;
    honour.honour_up_axis = true;
    const TriangleMesh turned = loadMesh(path, Vec3::Ones(), &warnings, honour);
    expectBounds(turned, c.honoured_lo, c.honoured_hi, 1e-9);
    EXPECT_NEAR(signedVolume(turned), 0.01 * 0.005 * 0.03, 1e-12);
    EXPECT_EQ(warnings.size(), c.warned ? 1u : 0u);
  }
}

TEST(MeshLoader, ColladaZUpWithNodeTransform) {
  std::vector<std::string> warnings;
  const TriangleMesh m = loadMesh(arm6Mesh("wrist2.dae"), Vec3::Ones(), &warnings);
  EXPECT_TRUE(warnings.empty()) << warnings.front();  // Z_UP: nothing to say
  expectBounds(m, Vec3(-0.03, -0.03, 0.02), Vec3(0.03, 0.03, 0.08), 1e-7);  // node translated by 0.02
}

TEST(MeshLoader, ScaleAndMillimetreWarning) {
  std::vector<std::string> warnings;
  const TriangleMesh mm = loadMesh(arm6Mesh("wrist1_mm.stl"), Vec3::Ones(), &warnings);
  EXPECT_TRUE(anyContains(warnings, "probably millimetres")) << (warnings.empty() ? "" : warnings[0]);
  EXPECT_NEAR(bounds(mm).hi.z(), 100.0, 1e-9);

  warnings.clear();
  const TriangleMesh m = loadMesh(arm6Mesh("wrist1_mm.stl"), Vec3::Constant(0.001), &warnings);
  EXPECT_TRUE(warnings.empty()) << warnings.front();
  EXPECT_NEAR(bounds(m).hi.z(), 0.1, 1e-12);
  EXPECT_NEAR(bounds(m).hi.x(), 0.035, 1e-12);

  const TriangleMesh stretched = loadMesh(arm6Mesh("upper_arm.obj"), Vec3(2.0, 1.0, 0.5));
  expectBounds(stretched, Vec3(-0.08, -0.04, 0.0), Vec3(0.08, 0.04, 0.2), 1e-7);
}

TEST(MeshLoader, MirroringScaleKeepsTrianglesOutward) {
  const TriangleMesh m = loadMesh(arm6Mesh("upper_arm.obj"), Vec3(-1.0, 1.0, 1.0));
  EXPECT_NEAR(signedVolume(m), 0.08 * 0.08 * 0.4, 1e-9);
}

TEST(MeshLoader, MeshesOfAFileAreMergedAndWeldedAcrossNodes) {
  // Two instances of a unit cube, the second translated by x = 1: they share the face x = 1.
  TempDir dir;
  const std::string cube =
      "<?xml version=\"1.0\"?>\n"
      "<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">\n"
      "<asset><unit meter=\"1\"/><up_axis>Z_UP</up_axis></asset>\n"
      "<library_geometries><geometry id=\"g\"><mesh>\n"
      "<source id=\"p\"><float_array id=\"pa\" count=\"24\">0 0 0 1 0 0 1 1 0 0 1 0 0 0 1 1 0 1 1 1 1 0 1 1</float_array>\n"
      "<technique_common><accessor source=\"#pa\" count=\"8\" stride=\"3\"><param name=\"X\" type=\"float\"/>"
      "<param name=\"Y\" type=\"float\"/><param name=\"Z\" type=\"float\"/></accessor></technique_common></source>\n"
      "<vertices id=\"v\"><input semantic=\"POSITION\" source=\"#p\"/></vertices>\n"
      "<triangles count=\"12\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/>\n"
      "<p>0 3 2 0 2 1 4 5 6 4 6 7 0 1 5 0 5 4 2 3 7 2 7 6 1 2 6 1 6 5 3 0 4 3 4 7</p></triangles>\n"
      "</mesh></geometry></library_geometries>\n"
      "<library_visual_scenes><visual_scene id=\"s\">\n"
      "<node id=\"a\"><instance_geometry url=\"#g\"/></node>\n"
      "<node id=\"b\"><translate>1 0 0</translate><instance_geometry url=\"#g\"/></node>\n"
      "</visual_scene></library_visual_scenes><scene><instance_visual_scene url=\"#s\"/></scene>\n"
      "</COLLADA>\n";
  const TriangleMesh m = loadMesh(dir.write("two_cubes.dae", cube), Vec3::Ones());
  EXPECT_EQ(m.triangles.size(), 24u);
  EXPECT_EQ(m.vertices.size(), 12u);  // 16 corners, 4 of them shared
  expectBounds(m, Vec3(0, 0, 0), Vec3(2, 1, 1), 1e-12);
  EXPECT_NEAR(signedVolume(m), 2.0, 1e-12);
}

TEST(MeshLoader, ZeroAreaTrianglesAreDroppedWithAWarning) {
  TempDir dir;
  // A closed tetrahedron plus a needle with two equal corners and a flat one with collinear corners.
  const std::string extra = test::stlFacet("0 0 0", "0 0 0", "1 0 0") + test::stlFacet("0 0 0", "0.5 0 0", "1 0 0");
  std::vector<std::string> warnings;
  const TriangleMesh m = loadMesh(dir.write("tet.stl", test::tetrahedronStl(extra)), Vec3::Ones(), &warnings);
  EXPECT_EQ(m.triangles.size(), 4u);
  EXPECT_EQ(m.vertices.size(), 4u);  // the collinear triangle's midpoint is used by no triangle left
  EXPECT_TRUE(isClosed(m));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("2 zero-area triangles dropped"), std::string::npos) << warnings[0];
}

TEST(MeshLoader, RepeatedTrianglesAreDroppedWithAWarning) {
  TempDir dir;
  // The tetrahedron with one face written again as it is and once turned round: the same three vertices.
  const std::string extra = test::stlFacet("0 0 0", "0 1 0", "1 0 0") + test::stlFacet("1 0 0", "0 0 1", "0 1 0");
  std::vector<std::string> warnings;
  const TriangleMesh m = loadMesh(dir.write("tet.stl", test::tetrahedronStl(extra)), Vec3::Ones(), &warnings);
  EXPECT_EQ(m.triangles.size(), 4u);
  EXPECT_TRUE(isClosed(m));
  EXPECT_NEAR(signedVolume(m), 1.0 / 6.0, 1e-15);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("2 repeated triangles dropped"), std::string::npos) << warnings[0];

  // A box instanced 2^12 times at one place (a few hundred bytes of nodes instancing each other twice)
  // is one box.
  std::string doubling = test::colladaBox({0, 0, 0}, {1, 1, 1}, "Z_UP");
  std::string nodes = "<library_nodes>";
  for (int k = 0; k < 12; ++k)
    nodes += "<node id=\"d" + std::to_string(k) + "\"><instance_node url=\"#d" + std::to_string(k + 1) +
             "\"/><instance_node url=\"#d" + std::to_string(k + 1) + "\"/></node>";
  nodes += "<node id=\"d12\"><instance_geometry url=\"#g\"/></node></library_nodes>\n";
  const std::string leaf = "<node id=\"n\"><instance_geometry url=\"#g\"/></node>";
  const std::size_t at = doubling.find(leaf);
  ASSERT_NE(at, std::string::npos);
  doubling.replace(at, leaf.size(), "<node id=\"n\"><instance_node url=\"#d0\"/></node>");
  doubling.insert(doubling.find("<library_visual_scenes>"), nodes);
  warnings.clear();
  const TriangleMesh stacked = loadMesh(dir.write("stacked.dae", doubling), Vec3::Ones(), &warnings);
  EXPECT_EQ(stacked.triangles.size(), 12u);
  EXPECT_NEAR(signedVolume(stacked), 1.0, 1e-12);
  ASSERT_EQ(warnings.size(), 1u) << (warnings.empty() ? "" : warnings[0]);
  EXPECT_NE(warnings[0].find(std::to_string(12 * 4095) + " repeated triangles dropped"), std::string::npos)
      << warnings[0];
}

TEST(MeshLoader, OpenMeshIsReported) {
  TempDir dir;
  const std::string path = dir.write("open.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n");
  std::vector<std::string> warnings;
  const TriangleMesh m = loadMesh(path, Vec3::Ones(), &warnings);
  EXPECT_FALSE(isClosed(m));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("not closed (3 edges with one triangle"), std::string::npos) << warnings[0];
  EXPECT_EQ(warnings[0].rfind(path + ": ", 0), 0u) << "warnings start with the file: " << warnings[0];
}

TEST(MeshLoader, PointsAndLinesAreIgnoredWithAWarning) {
  TempDir dir;
  std::vector<std::string> warnings;
  const TriangleMesh m = loadMesh(dir.write("with_line.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                                               "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nl 1 2\n"),
                                  Vec3::Ones(), &warnings);
  EXPECT_EQ(m.triangles.size(), 4u);
  EXPECT_TRUE(anyContains(warnings, "1 point and line primitives ignored"));
}

TEST(MeshLoader, Errors) {
  TempDir dir;
  const std::string missing = dir.path("missing.stl");
  EXPECT_LOAD_ERROR(loadMesh(missing, Vec3::Ones()), missing, "", "not found");

  const std::string part = dir.write("part.SLDPRT", "a SolidWorks part");
  EXPECT_LOAD_ERROR(loadMesh(part, Vec3::Ones()), part, "", "unsupported mesh format 'sldprt'");

  const std::string empty_file = dir.write("empty.stl", "");
  EXPECT_LOAD_ERROR(loadMesh(empty_file, Vec3::Ones()), empty_file, "", "empty mesh");
  const std::string no_facets = dir.write("no_facets.stl", "solid x\nendsolid x\n");
  EXPECT_LOAD_ERROR(loadMesh(no_facets, Vec3::Ones()), no_facets, "", "empty mesh");
  const std::string only_points = dir.write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  EXPECT_LOAD_ERROR(loadMesh(only_points, Vec3::Ones()), only_points, "", "empty mesh");
  const std::string only_degenerate = dir.write("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
  EXPECT_LOAD_ERROR(loadMesh(only_degenerate, Vec3::Ones()), only_degenerate, "", "empty mesh");

  const std::string garbage = dir.write("garbage.stl", "hello");
  EXPECT_LOAD_ERROR(loadMesh(garbage, Vec3::Ones()), garbage, "", "assimp cannot read it");

  const std::string nan_stl = dir.write("nan.stl", test::tetrahedronStl(
      "facet normal 0 0 0\nouter loop\nvertex nan 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n"));
  EXPECT_LOAD_ERROR(loadMesh(nan_stl, Vec3::Ones()), nan_stl, "", "non-finite coordinate");
  const std::string nan_obj = dir.write("nan.obj", "v 0 0 0\nv 1 0 inf\nv 0 1 0\nf 1 2 3\n");
  EXPECT_LOAD_ERROR(loadMesh(nan_obj, Vec3::Ones()), nan_obj, "", "non-finite coordinate");

  const std::string tet = dir.write("tet.stl", test::tetrahedronStl());
  EXPECT_LOAD_ERROR(loadMesh(tet, Vec3(1, NAN, 1)), tet, "", "scale");
  EXPECT_LOAD_ERROR(loadMesh(tet, Vec3(1, 0, 1)), tet, "", "scale");
}

TEST(MeshLoader, SharedRobotMeshCounts) {
  // Triangle counts from DATA.md (assimp info); vertices are fewer here because corners are welded.
  CLEARWAY_SHARED_ROBOT_OR_SKIP(panda, "panda/panda.urdf");
  const std::string dir = test::sharedRobot("panda/meshes/collision/");
  EXPECT_EQ(loadMesh(dir + "link0.stl", Vec3::Ones()).triangles.size(), 200u);
  EXPECT_EQ(loadMesh(dir + "link3.stl", Vec3::Ones()).triangles.size(), 300u);
  EXPECT_EQ(loadMesh(dir + "finger.stl", Vec3::Ones()).triangles.size(), 32u);
  const TriangleMesh link1 = loadMesh(dir + "link1.stl", Vec3::Ones());
  EXPECT_LT(link1.vertices.size(), 300u * 3 / 4);  // welded: about half as many vertices as triangles
}
