// Mesh input made to crash, hang or exhaust Clearway, each generated here as it was found: a NUL or
// other control byte in a mesh path (the format picked from the text after it, the file opened before
// it), COLLADA that assimp aborts or crashes on or that expands through instancing into millions of
// triangles, FIFOs where a mesh or an OBJ's material library should be, and a reader's error quoting
// the rest of a file. Each ends in a LoadError naming the file, element and reason, or in a mesh; and
// runs under a timeout, so that a hang fails the test instead of blocking the suite.
#include <clearway/load/mesh_loader.h>
#include <clearway/load/robot_loader.h>
#include <clearway/scene/scene.h>

#include "load/robot_files.h"
#include "timeout_guard.h"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <string>

using namespace clearway;
using clearway::test::endsWithin;
using clearway::test::TempDir;

namespace {

// Long enough for any of these inputs under the sanitizers, short next to a hang.
constexpr double kSeconds = 60.0;

const char* const kTetP = "0 2 1 0 1 3 0 3 2 1 2 3";

// A COLLADA tetrahedron: `array` is the positions' array element, p the triangles' indices (count of
// them given), `nodes` the library nodes and `scene` the visual scene's nodes.
std::string collada(const std::string& scene, const std::string& nodes = "",
                    const std::string& array = "<float_array id=\"pa\" count=\"12\">0 0 0 1 0 0 0 1 0 0 0 1</float_array>",
                    const std::string& p = kTetP, int triangles = 4) {
  return "<?xml version=\"1.0\"?>\n<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">\n"
         "<asset><unit meter=\"1\"/><up_axis>Z_UP</up_axis></asset>\n"
         "<library_geometries><geometry id=\"g\"><mesh>\n"
         "<source id=\"p\">" + array + "\n"
         "<technique_common><accessor source=\"#pa\" count=\"4\" stride=\"3\"><param name=\"X\" type=\"float\"/>"
         "<param name=\"Y\" type=\"float\"/><param name=\"Z\" type=\"float\"/></accessor></technique_common></source>\n"
         "<vertices id=\"v\"><input semantic=\"POSITION\" source=\"#p\"/></vertices>\n"
         "<triangles count=\"" + std::to_string(triangles) + "\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/>\n<p>" +
         p + "</p></triangles>\n</mesh></geometry></library_geometries>\n"
         "<library_nodes>" + nodes + "</library_nodes>\n"
         "<library_visual_scenes><visual_scene id=\"s\">" + scene + "</visual_scene></library_visual_scenes>\n"
         "<scene><instance_visual_scene url=\"#s\"/></scene>\n</COLLADA>\n";
}

const char* const kTetScene = "<node id=\"n\"><instance_geometry url=\"#g\"/></node>";

// Runs statement within kSeconds; it must throw a LoadError as EXPECT_LOAD_ERROR says.
#define EXPECT_LOAD_ERROR_IN_TIME(statement, file, element, reason) \
  EXPECT_LOAD_ERROR(endsWithin(kSeconds, [&] { statement; }), file, element, reason)

// what() of the LoadError that statement throws ("" when none).
template <class F>
std::string errorOf(F&& statement) {
  try {
    statement();
  } catch (const LoadError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// A NUL in a mesh path: Clearway took the format from ".stl" after the NUL, the OS opened x.dae before
// it, and assimp read that by its own extension, past the COLLADA pre-check.
TEST(HostileMesh, ControlBytesInAMeshPathAreRefused) {
  TempDir dir;
  const std::string dae = dir.write("x.dae", collada(kTetScene));
  ASSERT_EQ(loadMesh(dae, Vec3::Ones()).triangles.size(), 4u);  // the file itself loads
  for (const char byte : {'\0', '\x01', '\n', '\x7f'}) {
    const std::string path = dae + std::string(1, byte) + ".stl";
    const std::string shown = dae + (byte == '\0' ? "\\x00" : byte == '\x01' ? "\\x01" : byte == '\n' ? "\\x0A" : "\\x7F") + ".stl";
    SCOPED_TRACE(shown);
    EXPECT_LOAD_ERROR_IN_TIME(loadMesh(path, Vec3::Ones()), shown, "", "control character");
  }

  // The same through a URDF's file:// URI (percent-decoded) and a package path.
  const std::string urdf = dir.write(
      "nul.urdf", "<robot name=\"r\"><link name=\"a\"><collision><geometry><mesh filename=\"file://" + dae +
                      "%00.stl\"/></geometry></collision></link></robot>\n");
  EXPECT_LOAD_ERROR_IN_TIME(loadRobot(urdf), urdf, "link 'a' <collision> (line 1)", "control character");
  const std::string message = errorOf([&] { loadRobot(urdf); });
  EXPECT_EQ(message.find('\0'), std::string::npos);
  EXPECT_NE(message.find("x.dae%00.stl"), std::string::npos) << message;  // the URI as written
  const std::string tab = dir.write(
      "tab.urdf", "<robot name=\"r\"><link name=\"a\"><collision><geometry><mesh filename=\"x.dae&#9;.stl\"/>"
                  "</geometry></collision></link></robot>\n");
  EXPECT_LOAD_ERROR_IN_TIME(loadRobot(tab), tab, "link 'a' <collision>", "control character");
  EXPECT_EQ(errorOf([&] { loadRobot(tab); }).find('\t'), std::string::npos);

  // And through a scene file: "\0" in a double-quoted YAML string is a NUL.
  const std::string scene = dir.write(
      "nul.yaml", "format: 1\nname: nul\nrobot:\n  urdf: " + test::sourceRobot("planar_arm/planar_arm.urdf") +
                      "\n  group: [shoulder, elbow]\nenvironment:\n  obstacles:\n"
                      "    - {name: part, mesh: {file: \"x.dae\\0.stl\"}}\nchecks: [environment]\n");
  EXPECT_LOAD_ERROR_IN_TIME(parseSceneFile(scene), scene, "key 'environment.obstacles[0].mesh.file'",
                            "control character");
  EXPECT_EQ(errorOf([&] { parseSceneFile(scene); }).find('\0'), std::string::npos);
}

// COLLADA that assimp 5.2 aborts on (<skew>) or crashes on (names where vertex positions should be).
TEST(HostileMesh, ColladaSkewAndNameArraysAsPositionsAreRefused) {
  TempDir dir;
  const std::string skew = dir.write(
      "skew.dae", collada("<node id=\"n\">\n<skew>45 0 1 0 1 0 0</skew><instance_geometry url=\"#g\"/></node>"));
  EXPECT_LOAD_ERROR_IN_TIME(loadMesh(skew, Vec3::Ones()), skew, "<skew> (line 13)", "not supported");
  const std::string names = dir.write(
      "names.dae", collada(kTetScene, "", "<Name_array id=\"pa\" count=\"12\">a b c d e f g h i j k l</Name_array>"));
  EXPECT_LOAD_ERROR_IN_TIME(loadMesh(names, Vec3::Ones()), names, "<input> (line 7)", "<Name_array> 'pa' (line 5)");
  const std::string idrefs = dir.write(
      "idrefs.dae", collada(kTetScene, "", "<IDREF_array id=\"pa\" count=\"12\">g g g g g g g g g g g g</IDREF_array>"));
  EXPECT_LOAD_ERROR_IN_TIME(loadMesh(idrefs, Vec3::Ones()), idrefs, "<input> (line 7)", "<IDREF_array> 'pa' (line 5)");
}

// A 9 KB file whose nodes instance each other two by two: 14 levels are 16,383 nodes (within the node
// limit) but 8,192 copies of a 1,200-triangle geometry, 9.8 million triangles. The limit is on what the
// instances expand to, counted before assimp reads the file.
TEST(HostileMesh, ColladaInstancesExpandingToMillionsOfTrianglesAreRefused) {
  TempDir dir;
  std::string p;
  for (int i = 0; i < 300; ++i) p += std::string(kTetP) + " ";
  std::string nodes;
  for (int i = 0; i < 13; ++i)
    nodes += "<node id=\"d" + std::to_string(i) + "\"><instance_node url=\"#d" + std::to_string(i + 1) +
             "\"/><instance_node url=\"#d" + std::to_string(i + 1) + "\"/></node>\n";
  nodes += "<node id=\"d13\"><instance_geometry url=\"#g\"/></node>\n";
  const std::string array = "<float_array id=\"pa\" count=\"12\">0 0 0 1 0 0 0 1 0 0 0 1</float_array>";
  const std::string bomb =
      dir.write("bomb.dae", collada("<node id=\"n\"><instance_node url=\"#d0\"/></node>", nodes, array, p, 1200));
  EXPECT_LT(std::filesystem::file_size(bomb), 40000u);
  // d3, the first node past the limit: 1,024 copies.
  EXPECT_LOAD_ERROR_IN_TIME(loadMesh(bomb, Vec3::Ones()), bomb, "<node> (line 14)", "1228800 triangles");

  // Found by fuzz_mesh_dae (FUZZ_SEED=1): the same file with one instance of d1 naming no node and one of
  // d8's a mangled tag expands to 2,457,600 triangles, under 2^22, and took over 10 s in the fuzzer's build.
  std::string mangled = nodes;
  mangled.replace(mangled.find("url=\"#d2\""), 9, "url=\"#e2\"");
  const std::size_t d8 = mangled.find("<instance_node", mangled.find("id=\"d8\""));
  mangled.replace(mangled.find("<instance_node", d8 + 1), 14, "<insta\x92\x9c\x9a\xaanode");
  const std::string fuzzed =
      dir.write("fuzzed.dae", collada("<node id=\"n\"><instance_node url=\"#d0\"/></node>", mangled, array, p, 1200));
  EXPECT_LOAD_ERROR_IN_TIME(loadMesh(fuzzed, Vec3::Ones()), fuzzed, "<node>", "triangles");
  // Then, with d9 renamed a second d8: the count followed the first d8 (its d9 gone, nothing), assimp the
  // second (2,457,600 triangles). Ids of what instances name must be unique, and names they fall back to.
  std::string twin = mangled;
  twin.replace(twin.find("<node id=\"d9\">"), 15, "<node id=\"d8\">");
  const std::string twins =
      dir.write("twins.dae", collada("<node id=\"n\"><instance_node url=\"#d0\"/></node>", twin, array, p, 1200));
  EXPECT_LOAD_ERROR_IN_TIME(loadMesh(twins, Vec3::Ones()), twins, "<node>", "a second element with id 'd8'");
  const std::string named = dir.write(
      "named.dae", collada("<node id=\"n\"><instance_node url=\"#x\"/></node>",
                           "<node id=\"a\" name=\"x\"/><node id=\"b\" name=\"x\"><instance_geometry url=\"#g\"/></node>"));
  EXPECT_LOAD_ERROR_IN_TIME(loadMesh(named, Vec3::Ones()), named, "<instance_node>", "several nodes' name");

  // Within the limit the same instancing loads: 8 copies at one place, welded into one tetrahedron (the
  // repeated triangles dropped).
  std::string few;
  for (int i = 0; i < 3; ++i)
    few += "<node id=\"d" + std::to_string(i) + "\"><instance_node url=\"#d" + std::to_string(i + 1) +
           "\"/><instance_node url=\"#d" + std::to_string(i + 1) + "\"/></node>\n";
  few += "<node id=\"d3\"><instance_geometry url=\"#g\"/></node>\n";
  const std::string fine = dir.write("few.dae", collada("<node id=\"n\"><instance_node url=\"#d0\"/></node>", few));
  EXPECT_EQ(loadMesh(fine, Vec3::Ones()).triangles.size(), 4u);
  // A caller may ask for a lower limit (the fuzzer does): the same 32 triangles are then refused.
  MeshOptions low;
  low.max_expanded_triangles = 16;
  EXPECT_LOAD_ERROR_IN_TIME(loadMesh(fine, Vec3::Ones(), nullptr, low), fine, "<node>", "32 triangles");
}

// Found by fuzz_mesh_dae: a node of the visual scene instancing the visual scene itself. Assimp keeps a
// visual scene as a node, found by its id, by its name, or by "Scene" when it has none, and recursed
// until the stack overflowed (SIGSEGV); the pre-check looked for nodes only. Another visual scene may be
// instanced, as assimp does.
TEST(HostileMesh, ColladaVisualScenesInstancedByTheirOwnNodesAreRefused) {
  TempDir dir;
  const std::string scene = "<node id=\"n\"><instance_geometry url=\"#g\"/><node id=\"again\"><instance_node url=\"#";
  const std::string by_id = dir.write("by_id.dae", collada(scene + "s\"/></node></node>"));
  EXPECT_LOAD_ERROR_IN_TIME(loadMesh(by_id, Vec3::Ones()), by_id, "<node> (line 12)",
                            "contains itself through <instance_node>");
  const std::string unnamed = dir.write("unnamed.dae", collada(scene + "Scene\"/></node></node>"));
  EXPECT_LOAD_ERROR_IN_TIME(loadMesh(unnamed, Vec3::Ones()), unnamed, "<node>", "contains itself");
  std::string text = collada(scene + "world\"/></node></node>");
  text.replace(text.find("<visual_scene id=\"s\">"), 21, "<visual_scene id=\"s\" name=\"world\">");
  const std::string by_name = dir.write("by_name.dae", text);
  EXPECT_LOAD_ERROR_IN_TIME(loadMesh(by_name, Vec3::Ones()), by_name, "<node>", "contains itself");

  // A second visual scene, instanced by a node of the first: its tetrahedron joins the first one's.
  text = collada(scene + "s2\"/></node></node>");
  text.replace(text.find("</library_visual_scenes>"), 0,
               "<visual_scene id=\"s2\"><node id=\"k\"><translate>5 0 0</translate><instance_geometry url=\"#g\"/></node></visual_scene>");
  EXPECT_EQ(loadMesh(dir.write("other.dae", text), Vec3::Ones()).triangles.size(), 8u);
}

// Found by fuzz_mesh_dae: an <accessor> without <param> elements over a <float_array> without count="N"
// (of which assimp reads no value). Assimp still reads one value per item, at sub-offset 0: a null read
// (SIGSEGV). The pre-check skipped accessors without parameters.
TEST(HostileMesh, ColladaAccessorsWithoutParamsStayWithinTheirArrays) {
  TempDir dir;
  const auto without_params = [](std::string text) {
    const std::string params =
        "<param name=\"X\" type=\"float\"/><param name=\"Y\" type=\"float\"/><param name=\"Z\" type=\"float\"/>";
    return text.replace(text.find(params), params.size(), "");
  };
  const std::string uncounted = dir.write(
      "uncounted.dae", without_params(collada(kTetScene, "", "<float_array id=\"pa\">0 0 0 1 0 0 0 1 0 0 0 1</float_array>")));
  EXPECT_LOAD_ERROR_IN_TIME(loadMesh(uncounted, Vec3::Ones()), uncounted, "<accessor> (line 6)",
                            "reaches value 10 of 'pa', which holds 0");
  std::string text = without_params(collada(kTetScene));
  text.replace(text.find("count=\"4\" stride=\"3\""), 20, "count=\"5\" stride=\"3\"");
  const std::string beyond = dir.write("beyond.dae", text);
  EXPECT_LOAD_ERROR_IN_TIME(loadMesh(beyond, Vec3::Ones()), beyond, "<accessor>", "reaches value 13 of 'pa', which holds 12");
}

// An OBJ whose material library is a FIFO: assimp opened it and waited for a writer forever. A FIFO
// given as the mesh itself is refused as not a regular file.
TEST(HostileMesh, FifosAreNeverOpened) {
  TempDir dir;
  const std::string fifo = dir.path("materials.mtl");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string obj = dir.write("tet.obj", "mtllib materials.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                               "usemtl steel\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  // Should the load block, opening the FIFO's other end lets it go on.
  const auto unblock = [&] {
    const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    if (fd >= 0) ::close(fd);
  };
  std::size_t triangles = 0;
  endsWithin(kSeconds, [&] { triangles = loadMesh(obj, Vec3::Ones()).triangles.size(); }, unblock);
  EXPECT_EQ(triangles, 4u);

  const std::string fifo_mesh = dir.path("part.stl");
  ASSERT_EQ(::mkfifo(fifo_mesh.c_str(), 0600), 0);
  EXPECT_LOAD_ERROR_IN_TIME(loadMesh(fifo_mesh, Vec3::Ones()), fifo_mesh, "", "not a regular file");
  const std::string device = dir.path("zero.stl");
  ASSERT_EQ(::symlink("/dev/zero", device.c_str()), 0);
  EXPECT_LOAD_ERROR_IN_TIME(loadMesh(device, Vec3::Ones()), device, "", "not a regular file");
}

// An ASCII STL with one bad number among 20,000 facets: assimp's message quoted the rest of the file.
TEST(HostileMesh, ErrorsQuoteAFewDozenCharactersOfTheInput) {
  TempDir dir;
  std::string facets;
  for (int i = 0; i < 20000; ++i)
    facets += "facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n";
  const std::string stl = dir.write(
      "bad_number.stl", "solid s\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 x\nendloop\n"
                        "endfacet\n" + facets + "endsolid s\n");
  ASSERT_GT(std::filesystem::file_size(stl), 1000000u);
  std::string message;
  endsWithin(kSeconds, [&] { message = errorOf([&] { loadMesh(stl, Vec3::Ones()); }); });
  ASSERT_NE(message, "");
  EXPECT_LT(message.size(), 400u) << message.substr(0, 1000);
  EXPECT_NE(message.find(stl), std::string::npos) << message.substr(0, 1000);
}
