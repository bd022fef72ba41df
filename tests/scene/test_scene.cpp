// Scenes: the file format (every error names the file and the key), the effects a scene declares
// (and the work it does not do), and the shared MotionBenchMaker problems.
#include <clearway/motion/motion.h>
#include <clearway/scene/scene.h>
#include <clearway/kinematics/kinematic_lanes.h>

#include "forced_target.h"
#include "load/robot_files.h"
#include "scene_cache.h"

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <random>
#include <regex>
#include <sstream>
#include <set>
#include <thread>

namespace clearway {
namespace {

using test::TempDir;

std::string sharedScenes() { return test::sharedDir() + "/scenes"; }

#define CLEARWAY_SHARED_SCENES_OR_SKIP()           \
  CLEARWAY_REQUIRE_SHARED("scenes");                 \
  CLEARWAY_REQUIRE_SHARED("robots/panda/panda.urdf")

// A scene of the planar arm (robots/planar_arm) with a box obstacle; `extra` replaces parts.
std::string planarScene(const std::string& checks = "[self, environment]", const std::string& obstacles =
                            "    - {name: wall, box: {size: [0.1, 2, 1]}, pose: {position: [1.2, 0, 0]}}\n",
                        const std::string& robot_extra = "", const std::string& tail = "") {
  return "format: 1\nname: planar\nrobot:\n  urdf: " + test::sourceRobot("planar_arm/planar_arm.urdf") +
         "\n  group: [shoulder, elbow]\n" + robot_extra + "environment:\n  obstacles:\n" + obstacles +
         "checks: " + checks + "\nstart: [1.5, 0]\ngoal: [-1.5, 0]\n" + tail;
}

TEST(SceneFile, TextFromElsewhereTakesItsPathsFromTheGivenFolder) {
  // As `clearway check -` reads stdin: the same description as the file, errors named as asked.
  TempDir dir;
  const std::string text = planarScene();
  const SceneDescription from_file = parseSceneFile(dir.write("s.yaml", text));
  const SceneDescription from_text = parseSceneText(text, "<stdin>", dir.path(""));
  EXPECT_EQ(from_text.urdf, from_file.urdf);
  EXPECT_EQ(from_text.group, from_file.group);
  EXPECT_EQ(from_text.file, "<stdin>");
  const std::string relative = "format: 1\nrobot:\n  urdf: nowhere.urdf\n  group: [a]\n";
  EXPECT_LOAD_ERROR(parseSceneText(relative, "<stdin>", dir.path("")), "<stdin>", "key 'robot.urdf'",
                    dir.path("nowhere.urdf"));
}

// Obstacles declared but never checked (no 'environment' among the checks): accepted, as a self-only audit
// may mean it, but said, since a state inside them is free.
TEST(SceneFile, ObstaclesTheChecksOmitAreSaid) {
  TempDir dir;
  const SceneDescription self_only = parseSceneFile(dir.write("self.yaml", planarScene("[self]")));
  ASSERT_EQ(self_only.warnings.size(), 1u);
  EXPECT_NE(self_only.warnings[0].find(
                "key 'checks': 'environment' is not among the checks: the scene's 1 obstacle is never checked"),
            std::string::npos)
      << self_only.warnings[0];
  EXPECT_TRUE(parseSceneFile(dir.write("both.yaml", planarScene())).warnings.empty());
  EXPECT_TRUE(parseSceneFile(dir.write("none.yaml", planarScene("[self]", ""))).warnings.empty());
}

// Two obstacles of one name: both kept and checked (MoveIt keeps shapes under one id), but said, since a
// report naming it cannot tell them apart (nor can an edit by name, which refuses it).
TEST(SceneFile, ObstaclesOfOneNameAreSaid) {
  TempDir dir;
  const std::string two =
      dir.write("two.yaml", planarScene("[self, environment]",
                                        "    - {name: wall, box: {size: [0.1, 2, 1]}, pose: {position: [1.2, 0, 0]}}\n"
                                        "    - {name: post, sphere: {radius: 0.1}, pose: {position: [0, 3, 0]}}\n"
                                        "    - {name: wall, sphere: {radius: 0.1}, pose: {position: [0, -3, 0]}}\n"));
  const SceneDescription d = parseSceneFile(two);
  EXPECT_EQ(d.obstacles.size(), 3u);
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_NE(d.warnings[0].find(two + ": key 'environment.obstacles[2].name': 'wall' also names obstacles[0]: both are "
                                     "checked"),
            std::string::npos)
      << d.warnings[0];
  // Unnamed obstacles take their keys as names: never the same.
  EXPECT_TRUE(parseSceneFile(dir.write("unnamed.yaml", planarScene("[self, environment]",
                                                                   "    - {sphere: {radius: 0.1}}\n"
                                                                   "    - {sphere: {radius: 0.2}}\n")))
                  .warnings.empty());
}

// A mesh obstacle's errors and warnings name the scene file and the obstacle's key, then the mesh file and
// the reason; an open mesh (a surface: a body wholly inside it does not collide) is said as for a robot's
// link. (The errors named the mesh alone, and the warnings were dropped.)
TEST(Scene, MeshObstaclesAndMapsSayTheirKey) {
  TempDir dir;
  dir.write("tet.stl", test::tetrahedronStl());
  // Two of its faces: not closed.
  dir.write("open.stl", "solid tet\n" + test::stlFacet("0 0 0", "0 1 0", "1 0 0") +
                            test::stlFacet("0 0 0", "1 0 0", "0 0 1") + "endsolid tet\n");
  const auto scene = [&](const std::string& mesh) {
    return dir.write("mesh.yaml", planarScene("[self, environment]",
                                              "    - {name: m, mesh: " + mesh + ", pose: {position: [3, 0, 0]}}\n"));
  };
  const std::string closed = scene("{file: tet.stl}");
  EXPECT_TRUE(Scene(parseSceneFile(closed)).description().warnings.empty());
  const std::string opened = scene("{file: open.stl}");
  const std::vector<std::string> said = Scene(parseSceneFile(opened)).description().warnings;
  ASSERT_EQ(said.size(), 1u);
  EXPECT_NE(said[0].find(opened + ": key 'environment.obstacles[0].mesh': "), std::string::npos) << said[0];
  EXPECT_NE(said[0].find("open.stl: not closed"), std::string::npos) << said[0];
  const std::string flat = scene("{file: tet.stl, scale: [0, 1, 1]}");
  EXPECT_LOAD_ERROR(Scene(parseSceneFile(flat)), flat, "key 'environment.obstacles[0].mesh'",
                    "tet.stl: scale must be finite and non-zero in every component");
  // The same for the OctoMap.
  dir.write("junk.bt", "not an octree\n");
  std::string text = planarScene();
  text.replace(text.find("environment:\n"), 13, "environment:\n  octomap: junk.bt\n");
  const std::string junk = dir.write("junk.yaml", text);
  EXPECT_LOAD_ERROR(Scene(parseSceneFile(junk)), junk, "key 'environment.octomap'", "junk.bt: not an OctoMap file");
}

TEST(SceneFile, ParsesEveryKey) {
  TempDir dir;
  const std::string path = dir.write("s.yaml", planarScene("[self, environment]",
      "    - {name: ball, sphere: {radius: 0.1}, pose: {position: [0, 1, 0]}, velocity: [0, -1, 0]}\n"));
  // A moving obstacle needs `moving` among the checks.
  EXPECT_LOAD_ERROR(parseSceneFile(path), path, "key 'checks'", "velocity");
  const std::string ok = dir.write("ok.yaml", planarScene("[self, environment, clearance, moving, continuous]",
      "    - {name: wall, box: {size: [0.1, 2, 1]}, pose: {position: [1.2, 0, 0], orientation: [0, 0, 0, 1]}}\n"
      "    - {name: ball, sphere: {radius: 0.1}, pose: {position: [0, 1, 0]}, velocity: [0, -1, 0]}\n"
      "    - {name: can, cylinder: {radius: 0.1, length: 0.4}}\n"
      "    - {name: pill, capsule: {radius: 0.1, length: 0.4}}\n",
      "  padding: 0.01\n  allow: [[base_link, link2]]\n"));
  const SceneDescription d = parseSceneFile(ok);
  EXPECT_EQ(d.name, "planar");
  EXPECT_EQ(d.group, (std::vector<std::string>{"shoulder", "elbow"}));
  EXPECT_EQ(d.padding, 0.01);
  ASSERT_EQ(d.allow.size(), 1u);
  EXPECT_EQ(d.allow[0].second, "link2");
  ASSERT_EQ(d.obstacles.size(), 4u);
  EXPECT_EQ(std::get<Box>(d.obstacles[0].shape).half, Vec3(0.05, 1, 0.5));
  EXPECT_EQ(d.obstacles[0].pose.t, Vec3(1.2, 0, 0));
  EXPECT_EQ(d.obstacles[1].velocity, Vec3(0, -1, 0));
  EXPECT_EQ(std::get<Cylinder>(d.obstacles[2].shape).h, 0.2);
  EXPECT_EQ(std::get<Capsule>(d.obstacles[3].shape).r, 0.1);
  EXPECT_TRUE(d.effects.self && d.effects.environment && d.effects.clearance && d.effects.moving && d.effects.continuous);
  EXPECT_EQ(d.start, (std::vector<double>{1.5, 0}));
}

TEST(SceneFile, BadInputNamesFileAndKey) {
  TempDir dir;
  struct Case {
    std::string text, key, reason;
  };
  const std::string good = planarScene();
  auto replaced = [&](const std::string& from, const std::string& to) {
    std::string s = good;
    const auto at = s.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return s.replace(at, from.size(), to);
  };
  const Case cases[] = {
      {replaced("checks:", "colour: red\nchecks:"), "key 'colour'", "unknown key"},
      {replaced("  group:", "  paddin: 0.1\n  group:"), "key 'robot.paddin'", "unknown key"},
      {replaced("planar_arm.urdf", "nowhere.urdf"), "key 'robot.urdf'", "file not found"},
      {replaced("goal: [-1.5, 0]", "goal: [-1.5, .nan]"), "key 'goal[1]'", "not a finite number"},
      {replaced("goal: [-1.5, 0]", "goal: [-1.5, zero]"), "key 'goal[1]'", "not a number"},
      {replaced("[self, environment]", "[self, gravity]"), "key 'checks'", "unknown check 'gravity'"},
      {replaced("size: [0.1, 2, 1]", "size: [0.1, 2]"), "key 'environment.obstacles[0].box.size'",
       "expected 3 numbers"},
      {replaced("size: [0.1, 2, 1]", "size: [0.1, -2, 1]"), "key 'environment.obstacles[0].box.size[1]'",
       "'-2' m: a size must be >= 0"},
      {replaced("box: {size: [0.1, 2, 1]}", "cone: {radius: 1}"), "key 'environment.obstacles[0].cone'", "unknown key"},
      {replaced("position: [1.2, 0, 0]}", "position: [1.2, 0, 0], orientation: [0, 0, 0, 2]}"),
       "key 'environment.obstacles[0].pose.orientation'", "norm"},
      {replaced("format: 1", "format: 2"), "key 'format'", "unsupported format"},
      {replaced("  group:", "  bounds: {elbow: [0]}\n  group:"), "key 'robot.bounds.elbow'", "expected [lower, upper]"},
      {replaced("  group:", "  bounds: {elbow: [0, .nan]}\n  group:"), "key 'robot.bounds.elbow'",
       "not a finite number"},
      {replaced("  group:", "  bounds: [elbow]\n  group:"), "key 'robot.bounds'", "expected a mapping"},
      {"format: 1\nrobot: [\n", "", "not valid YAML"},
      {replaced("environment:\n  obstacles:", "environment:\n  octomap: missing.bt\n  obstacles:"),
       "key 'environment.octomap'", "file not found"},
      // A repeated key silently lost to the first (a colliding state was called free).
      {replaced("checks:", "checks: [self]\nchecks:"), "key 'checks'",
       "given twice with different values (lines 9 and 10)"},
      {replaced("  group:", "  padding: 0\n  padding: 0.1\n  group:"), "key 'robot.padding'", "given twice"},
      {replaced("  group:", "  hold: {elbow: 0, elbow: 1}\n  group:"), "key 'robot.hold.elbow'", "given twice"},
      {replaced("  group:", "  bounds: {elbow: [0, 1], elbow: [0, 2]}\n  group:"), "key 'robot.bounds.elbow'",
       "given twice"},
      {replaced("{name: wall, box:", "{name: wall, name: post, box:"), "key 'environment.obstacles[0].name'",
       "given twice"},
      // Complex keys: yaml-cpp's "bad conversion" named neither the file nor the key.
      {replaced("  group:", "  hold: {? [a, b] : 1}\n  group:"), "key 'robot.hold'",
       "a key must be a plain name, not a list"},
      {"? {a: 1}\n: 2\n" + good, "", "a key must be a plain name, not a mapping"},
      // Checks that check nothing: every state was free without a word.
      {replaced("[self, environment]", "[]"), "key 'checks'", "is empty: every state would be free"},
      {replaced("[self, environment]", "[continuous, clearance]"), "key 'checks'", "names no collision check"},
      // Lengths beyond the input limits: an infinite box centre crashed the tree builder, a subnormal
      // radius the hull builder.
      {replaced("position: [1.2, 0, 0]", "position: [1e308, 0, 0]"), "key 'environment.obstacles[0].pose.position[0]'",
       "'1e308' m is beyond the largest length an input may give"},
      {replaced("size: [0.1, 2, 1]", "size: [0.1, 2, -1e-310]"), "key 'environment.obstacles[0].box.size[2]'",
       "'-1e-310' m: a size must be >= 0"},
      {replaced("box: {size: [0.1, 2, 1]}", "sphere: {radius: 0}"), "key 'environment.obstacles[0].sphere.radius'",
       "'0' m: a size must be > 0"},
      {replaced("box: {size: [0.1, 2, 1]}", "capsule: {radius: 0.1, length: 2e6}"),
       "key 'environment.obstacles[0].capsule.length'", "beyond the largest length"},
      // A second document was dropped unread: its obstacles never checked.
      {good + "---\nenvironment:\n  obstacles: []\n", "",
       "holds more than one YAML document, where a scene is one: document 2 is not empty (line 13)"},
      // Stray closing brackets after the scene: yaml-cpp's own reading of every document looped for ever
      // (a fuzzer's find), and its reading of the first dropped the text after them unread.
      {"{format: 1, robot: {urdf: a.urdf, group: [drive], drive/y: [-3, 2]}},\n envnvironment], start: [0]}\n", "",
       "not valid YAML: the text after line 1 cannot be read"},
      {"\n{format: 1, name: x},\n{checks: []}\n", "", "not valid YAML: the text after line 2 cannot be read"},
  };
  for (const Case& c : cases) {
    const std::string path = dir.write("bad.yaml", c.text);
    EXPECT_LOAD_ERROR(parseSceneFile(path), path, c.key, c.reason);
  }
  const std::string missing = dir.path("absent.yaml");
  EXPECT_LOAD_ERROR(parseSceneFile(missing), missing, "", "not found");
  // A key repeated with the same value says nothing new: read once.
  const std::string same = dir.write("same.yaml", replaced("checks:", "checks: [self, environment]\nchecks:"));
  EXPECT_TRUE(parseSceneFile(same).effects.environment);
  // Nor does a stray `---` with nothing after it.
  const std::string stray = dir.write("stray.yaml", good + "---\n");
  EXPECT_EQ(parseSceneFile(stray).obstacles.size(), parseSceneFile(dir.write("good.yaml", good)).obstacles.size());
}

// Text quoted from a scene file is cut to a few dozen characters: a 100 KB "number" or joint name made
// each error a 100 KB line (twice, with the key).
TEST(SceneFile, ErrorsQuoteAFewDozenCharactersOfTheInput) {
  TempDir dir;
  const std::string long_text(100000, '7');
  const std::string name(100000, 'j');
  for (const std::string& text : {planarScene("[self]", "    - {name: w, box: {size: [0.1, 2, " + long_text + "x]}}\n"),
                                  // (Explicit keys: YAML limits implicit ones to 1024 characters.)
                                  planarScene("[self]", "", "  hold:\n    ? " + name + "\n    : 0\n"),
                                  planarScene("[self]", "", "  bounds:\n    ? " + name + "\n    : [0, 1]\n")}) {
    const std::string path = dir.write("long.yaml", text);
    try {
      Scene::load(path);
      ADD_FAILURE() << "loaded";
    } catch (const LoadError& e) {
      EXPECT_LT(std::string(e.what()).size(), 400u) << std::string(e.what()).substr(0, 400);
      EXPECT_NE(std::string(e.what()).find("..."), std::string::npos) << std::string(e.what()).substr(0, 400);
    }
  }
}

TEST(SceneFile, PackagePathsAreFoldersRelativeToTheSceneFile) {
  TempDir dir;
  // Two packages named my_robot: a tetrahedron of size 1 in ws/, of size 2 in other/.
  dir.write("ws/src/my_robot/package.xml", "<package><name>my_robot</name></package>");
  dir.write("ws/src/my_robot/meshes/tet.stl", test::tetrahedronStl());
  std::string big = test::tetrahedronStl();
  for (std::size_t at = 0; (at = big.find("1", at)) != std::string::npos; ++at) big[at] = '2';
  dir.write("other/my_robot/meshes/tet.stl", big);
  const std::string urdf = dir.write("robot/r.urdf", R"(<robot name="r">
    <link name="a"><collision><geometry><sphere radius="0.1"/></geometry></collision></link>
    <link name="b"><collision><origin xyz="3 0 0"/><geometry><mesh filename="package://my_robot/meshes/tet.stl"/></geometry></collision></link>
    <joint name="j" type="continuous"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/></joint>
  </robot>)");
  const std::string scene_text = "format: 1\npackage_paths: [../ws]\nrobot:\n  urdf: ../robot/r.urdf\n  group: [j]\n"
                                 "checks: [self]\n";
  const std::string path = dir.write("scenes/s.yaml", scene_text);

  // Only the paths given here: ROS_PACKAGE_PATH and AMENT_PREFIX_PATH are out of the way.
  const char* old_ros = std::getenv("ROS_PACKAGE_PATH");
  const char* old_ament = std::getenv("AMENT_PREFIX_PATH");
  const std::string saved_ros = old_ros ? old_ros : "", saved_ament = old_ament ? old_ament : "";
  ::unsetenv("ROS_PACKAGE_PATH");
  ::unsetenv("AMENT_PREFIX_PATH");

  const SceneDescription d = parseSceneFile(path);
  EXPECT_EQ(d.package_paths, std::vector<std::string>{dir.path("ws")});
  auto meshSize = [](const Scene& scene) {
    double size = 0.0;
    for (const Vec3& v : scene.robot().meshes().at(0).vertices) size = std::max(size, v.maxCoeff());
    return size;
  };
  EXPECT_DOUBLE_EQ(meshSize(*Scene::load(path)), 1.0);
  // The caller's folders come first.
  SceneOptions options;
  options.load.package_paths = {dir.path("other")};
  EXPECT_DOUBLE_EQ(meshSize(*Scene::load(path, options)), 2.0);

  // Without the key the package is not found.
  std::string without = scene_text;
  without.erase(without.find("package_paths: [../ws]\n"), std::string("package_paths: [../ws]\n").size());
  const std::string bare = dir.write("scenes/bare.yaml", without);
  EXPECT_LOAD_ERROR(Scene::load(bare), urdf, "link 'b' <collision>", "unresolved package://my_robot");

  std::string missing = scene_text;
  missing.replace(missing.find("[../ws]"), 7, "[../ws, ../nowhere]");
  const std::string bad = dir.write("scenes/bad.yaml", missing);
  EXPECT_LOAD_ERROR(parseSceneFile(bad), bad, "key 'package_paths[1]'", "folder not found");
  std::string scalar = scene_text;
  scalar.replace(scalar.find("[../ws]"), 7, "../ws");
  const std::string not_list = dir.write("scenes/scalar.yaml", scalar);
  EXPECT_LOAD_ERROR(parseSceneFile(not_list), not_list, "key 'package_paths'", "expected a list of folders");

  if (old_ros) ::setenv("ROS_PACKAGE_PATH", saved_ros.c_str(), 1);
  if (old_ament) ::setenv("AMENT_PREFIX_PATH", saved_ament.c_str(), 1);
}

TEST(Scene, BadRobotReferencesNameTheKey) {
  TempDir dir;
  struct Case {
    std::string robot_extra, group, key, reason;
  };
  const Case cases[] = {
      {"", "[shoulder, wrist]", "key 'robot.group[1]'", "joint 'wrist' is not in robot"},
      {"", "[shoulder, tool_joint]", "key 'robot.group[1]'", "fixed"},
      {"  hold: {shoulder: 0.3}\n", "[shoulder, elbow]", "key 'robot.hold.shoulder'", "in the group"},
      {"  allow: [[base_link, hand]]\n", "[shoulder, elbow]", "key 'robot.allow[0]'", "link 'hand' is not in robot"},
      {"  bounds: {wrist: [0, 1]}\n", "[shoulder, elbow]", "key 'robot.bounds.wrist'", "not a variable of the group"},
      {"", "[shoulder]", "key 'start'", "has 2 values for 1 group variables"},
      {"  bounds: {elbow: [1, 0]}\n", "[shoulder, elbow]", "key 'robot.bounds.elbow'", "lower < upper"},
      {"  bounds: {elbow: [-9, 0]}\n", "[shoulder, elbow]", "key 'robot.bounds.elbow'", "outside the joint's limits"},
      // A held value no state may hold (the link was placed 1e300 m away).
      {"  hold: {elbow: 1e300}\n", "[shoulder]", "key 'robot.hold.elbow'",
       "'1e+300' is beyond ±1e6, the largest joint value a state may hold"},
  };
  for (const Case& c : cases) {
    std::string text = planarScene("[self]", "", c.robot_extra);
    text.replace(text.find("[shoulder, elbow]"), 17, c.group);
    const std::string path = dir.write("bad.yaml", text);
    EXPECT_LOAD_ERROR(Scene(parseSceneFile(path)), path, c.key, c.reason);
  }
}

TEST(Scene, BoundsNarrowTheStateSpace) {
  TempDir dir;
  const auto scene = Scene::load(dir.write("b.yaml", planarScene("[self]", "", "  bounds: {elbow: [-1, 0.5]}\n")));
  EXPECT_EQ(scene->lower(1), -1.0);
  EXPECT_EQ(scene->upper(1), 0.5);
  EXPECT_TRUE(scene->validState(std::vector<double>{0.0, 0.5}.data()));
  EXPECT_FALSE(scene->validState(std::vector<double>{0.0, 0.6}.data()));
  EXPECT_FALSE(scene->isFree(std::vector<double>{0.0, -1.2}));
}

TEST(Scene, PlanarArmAgainstAWall) {
  TempDir dir;
  // The wall's near face is at x = 1.15; link2 (a cylinder from the elbow at x = 1 to x = 1.5) reaches
  // into it at q = 0. Pointing along y (q = (π/2, 0)), the robot is 1.05 from the wall (the base box's
  // face at x = 0.1), and link2 (y from 1.0 to 1.5) is 0.9 from the base box (y ≤ 0.1): self counts too.
  const auto scene = Scene::load(dir.write("s.yaml", planarScene("[self, environment, clearance]")));
  EXPECT_EQ(scene->dimension(), 2);
  CollisionReport r;
  EXPECT_FALSE(scene->isFree({0.0, 0.0}, &r));
  EXPECT_EQ(r.kind, CollisionReport::Kind::Environment);
  EXPECT_EQ(scene->describe(r), "link2 wall");
  EXPECT_TRUE(scene->isFree({M_PI / 2, 0.0}, &r));
  EXPECT_EQ(r.kind, CollisionReport::Kind::None);
  SceneContext ctx = scene->makeContext();
  const double up[2] = {M_PI / 2, 0.0};
  double lower = -1;
  EXPECT_NEAR(scene->clearance(up, ctx, &lower), 0.9, 1e-6);
  EXPECT_LE(lower, 0.9 + 1e-12);
  EXPECT_GE(lower, 0.9 * (1 - 1e-5));
  // Through the wall (x from 1.15 to 1.25): link2 spans x from 1.0 to 1.5, so it leaves the wall
  // by moving 0.25 along +x (0.35 along −x, 0.45 up, 1.05 sideways): the signed clearance is −0.25,
  // and EPA ran for it.
  const double into[2] = {0.0, 0.0};
  const long long epa_before = ctx.counters().environment.penetration_tests;
  EXPECT_NEAR(scene->clearance(into, ctx, &lower), -0.25, 1e-5);
  EXPECT_LE(lower, -0.25 + 1e-5);
  EXPECT_GT(ctx.counters().environment.penetration_tests, epa_before);
  // Free states run no EPA.
  const long long epa_free = ctx.counters().environment.penetration_tests;
  scene->clearance(up, ctx);
  EXPECT_EQ(ctx.counters().environment.penetration_tests, epa_free);
}

TEST(Scene, SignedClearanceOfSelfPenetration) {
  // Two unit cubes, the second on a prismatic joint: they overlap by 0.2 at q = 0.8 (the planar arm
  // cannot reach itself).
  TempDir dir;
  const std::string urdf = dir.write("cubes.urdf", R"(<?xml version="1.0"?>
<robot name="cubes">
  <link name="a"><collision><geometry><box size="1 1 1"/></geometry></collision></link>
  <link name="mid"><collision><origin xyz="0 0 5"/><geometry><sphere radius="0.1"/></geometry></collision></link>
  <link name="b"><collision><geometry><box size="1 1 1"/></geometry></collision></link>
  <joint name="slide" type="prismatic"><parent link="a"/><child link="mid"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="3" velocity="1" effort="1"/></joint>
  <joint name="fix" type="fixed"><parent link="mid"/><child link="b"/><origin xyz="0 0 0"/></joint>
</robot>
)");
  const std::string scene_file = dir.write("s.yaml", "format: 1\nname: cubes\nrobot:\n  urdf: " + urdf +
                                                         "\n  group: [slide]\nchecks: [self, clearance]\n");
  // 'mid' has geometry (a ball far above), so a and b are not adjacent: their pair is checked.
  const auto scene = Scene::load(scene_file);
  ASSERT_EQ(scene->selfCollision().pairs().size(), 1u);
  SceneContext ctx = scene->makeContext();
  const double q[1] = {0.8};
  EXPECT_NEAR(scene->clearance(q, ctx), -0.2, 1e-6);
  const double apart[1] = {1.5};
  EXPECT_NEAR(scene->clearance(apart, ctx), 0.5, 1e-6);
}

TEST(Scene, InvalidStatesAreNeverFree) {
  TempDir dir;
  const auto scene = Scene::load(dir.write("s.yaml", planarScene("[self]", "")));
  CollisionReport r;
  EXPECT_TRUE(scene->isFree({0.5, 2.5}, &r));  // on the limit
  EXPECT_FALSE(scene->isFree({0.5, 2.6}, &r));
  EXPECT_EQ(r.kind, CollisionReport::Kind::Invalid);
  EXPECT_FALSE(scene->isFree({std::nan(""), 0.0}, &r));
  EXPECT_EQ(r.kind, CollisionReport::Kind::Invalid);
  EXPECT_FALSE(scene->isFree({0.5}, &r));
  EXPECT_EQ(r.kind, CollisionReport::Kind::Invalid);
  std::string why;
  const double bad[2] = {0.5, 2.6};
  EXPECT_FALSE(scene->validState(bad, &why));
  EXPECT_NE(why.find("elbow"), std::string::npos) << why;
}

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The URDF text with each zero in an origin's xyz and rpy replaced by a residue of the kind CAD exporters
// write (the stock Fetch's bellows_link has -1.67219873481315E-16), relative mesh paths made absolute (from
// `folder`), and an <inertial> and a <visual> with such origins added to each link.
std::string withResidues(const std::string& urdf, const std::string& folder) {
  static const char* const kResidues[] = {"1e-16", "-1.67219873481315E-16", "1e-300", "-1e-310", "1e-330", "1e-17"};
  std::size_t k = 0;
  std::string out;
  std::string rest = urdf;
  for (const char* attribute : {"xyz", "rpy"}) {
    const std::regex origin(std::string(R"((<origin[^>]*?\b)") + attribute + R"(=")([^"]*)("))");
    out.clear();
    std::size_t last = 0;
    for (auto it = std::sregex_iterator(rest.begin(), rest.end(), origin); it != std::sregex_iterator(); ++it) {
      const std::smatch& m = *it;
      out += rest.substr(last, m.position(0) - last) + m[1].str();
      std::istringstream values(m[2].str());
      std::string v, replaced;
      while (values >> v)
        replaced += (replaced.empty() ? "" : " ") + (std::strtod(v.c_str(), nullptr) == 0.0 ? kResidues[k++ % 6] : v);
      out += replaced + m[3].str();
      last = m.position(0) + m.length(0);
    }
    out += rest.substr(last);
    rest = out;
  }
  out = std::regex_replace(out, std::regex(R"(filename="(?!package:|/))"), "filename=\"" + folder + "/");
  return std::regex_replace(
      out, std::regex(R"((<link name="[^"]*">))"),
      "$1<inertial><origin xyz=\"0.0191 -1.67219873481315E-16 -0.1348\" rpy=\"1e-300 0 -1e-16\"/><mass value=\"1\"/>"
      "<inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/></inertial>"
      "<visual><origin xyz=\"1e-17 0 -1e-310\"/><geometry><sphere radius=\"1e-310\"/></geometry></visual>");
}

// The scene's robot with residues in every origin kind loads, with no more warnings, and gives the
// verdicts of the robot with zeros on `count` states uniform in the limits.
void expectResiduesChangeNoVerdict(const std::string& scene_file, int count) {
  TempDir dir;
  const auto plain = Scene::load(scene_file);
  SceneDescription d = plain->description();
  const std::string text = withResidues(readText(d.urdf), std::filesystem::path(d.urdf).parent_path().string());
  ASSERT_NE(text.find("-1.67219873481315E-16"), std::string::npos);
  d.urdf = dir.write("residues.urdf", text);
  const Scene residues(d);
  EXPECT_EQ(residues.robot().loadWarnings().size(), plain->robot().loadWarnings().size());
  std::mt19937 rng(7);
  std::vector<double> q(plain->dimension());
  int colliding = 0;
  for (int i = 0; i < count; ++i) {
    for (int j = 0; j < plain->dimension(); ++j)
      q[j] = std::uniform_real_distribution<double>(plain->lower(j), plain->upper(j))(rng);
    const bool free = plain->isFree(q);
    ASSERT_EQ(residues.isFree(q), free) << "state " << i;
    colliding += free ? 0 : 1;
  }
  EXPECT_GT(colliding, 0);
  EXPECT_LT(colliding, count);
}

TEST(Scene, ResiduesInOriginsChangeNoVerdict) {
  expectResiduesChangeNoVerdict(test::sourceRobot("scenes/dual_arm_shelf.yaml"), 2000);
}

TEST(Scene, ResiduesInTheSharedPandasOriginsChangeNoVerdict) {
  CLEARWAY_SHARED_OR_SKIP(scene, "scenes/box_panda/box_panda_0001.yaml");
  expectResiduesChangeNoVerdict(scene, 2000);
}

// A body below the smallest size computed with is grown to it, with a warning naming the element:
// loaded, never skipped (a speck inside an obstacle collides), in a URDF and in a scene file alike.
TEST(Scene, TinySolidsAreGrownNeverSkipped) {
  TempDir dir;
  const std::string urdf = dir.write("speck.urdf", R"(<robot name="speck">
  <link name="a"/>
  <link name="b"><collision><origin xyz="0.5 0 0"/><geometry><sphere radius="1e-310"/></geometry></collision>
    <collision><origin xyz="0.5 0.2 0"/><geometry><box size="1e-12 0 3e-300"/></geometry></collision>
    <collision><origin xyz="0.5 -0.2 0"/><geometry><capsule radius="1e-320" length="1e-12"/></geometry></collision></link>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
    <limit lower="-3.2" upper="3.2" velocity="1" effort="1"/></joint>
</robot>)");
  const auto scene = Scene::load(dir.write("speck.yaml", "format: 1\nname: speck\nrobot:\n  urdf: " + urdf +
      "\n  group: [j]\nenvironment:\n  obstacles:\n"
      "    - {name: grain, box: {size: [1e-12, 1e-300, 0]}, pose: {position: [0, 0.5, 0]}}\n"
      "    - {name: dust, sphere: {radius: 1e-310}, pose: {position: [0, -0.5, 0]}}\n"
      "    - {name: block, box: {size: [0.1, 0.1, 0.1]}, pose: {position: [-0.5, 0, 0]}}\n"
      "checks: [environment]\n"));
  const std::vector<std::string>& robot = scene->robot().loadWarnings();
  ASSERT_EQ(robot.size(), 4u);
  EXPECT_NE(robot[0].find("link 'b' <collision> <geometry> <sphere> (line 3): radius=\"1e-310\" is below the "
                          "smallest size Clearway computes with (1e-9 m): checked as radius=\"1e-09\""),
            std::string::npos) << robot[0];
  EXPECT_NE(robot[1].find("checked as size=\"1e-09 0 1e-09\""), std::string::npos) << robot[1];
  EXPECT_NE(robot[2].find("<capsule> (line 5): radius=\"1e-320\""), std::string::npos) << robot[2];
  EXPECT_NE(robot[3].find("<capsule> (line 5): length=\"1e-12\""), std::string::npos) << robot[3];
  const std::vector<std::string>& file = scene->description().warnings;
  ASSERT_EQ(file.size(), 3u);
  EXPECT_NE(file[0].find("key 'environment.obstacles[0].box.size[0]': '1e-12' m is below the smallest size"),
            std::string::npos) << file[0];
  EXPECT_NE(file[2].find("key 'environment.obstacles[1].sphere.radius'"), std::string::npos) << file[2];
  // The speck at (0.5, 0) meets the block at q = pi; each grown obstacle meets the speck at its angle.
  EXPECT_FALSE(scene->isFree({M_PI}));
  EXPECT_FALSE(scene->isFree({M_PI / 2}));
  EXPECT_FALSE(scene->isFree({-M_PI / 2}));
  EXPECT_TRUE(scene->isFree({M_PI / 4}));
  EXPECT_TRUE(scene->isFree({M_PI / 2 + 0.01}));
}

// What a scene does not declare, it does not compute: counted, per effect.
TEST(Scene, UndeclaredEffectsCostNothing) {
  TempDir dir;
  std::mt19937_64 rng(5);
  std::vector<std::array<double, 2>> states(200);
  for (auto& s : states)
    s = {std::uniform_real_distribution<double>(-3.1, 3.1)(rng), std::uniform_real_distribution<double>(-2.5, 2.5)(rng)};
  const std::string wall =
      "    - {name: wall, box: {size: [0.1, 2, 1]}, pose: {position: [1.2, 0, 0]}}\n"
      "    - {name: post, cylinder: {radius: 0.1, length: 1}, pose: {position: [-1.2, 0, 0]}}\n";
  for (const std::string checks : {"[self]", "[environment]", "[self, environment]", "[self, environment, clearance]"}) {
    const auto scene = Scene::load(dir.write("s.yaml", planarScene(checks, wall)));
    SceneContext ctx = scene->makeContext();
    int colliding = 0;
    for (const auto& s : states) colliding += !scene->isFree(s.data(), ctx);
    const double c = scene->clearance(states[0].data(), ctx);
    const SceneCounters& n = ctx.counters();
    SCOPED_TRACE(checks);
    EXPECT_EQ(n.states, 200);
    const bool env = scene->effects().environment, self = scene->effects().self;
    EXPECT_EQ(n.environment.obstacle_tests > 0, env);
    EXPECT_EQ(n.environment.voxel_tests, 0);  // no map
    EXPECT_EQ(colliding > 0, env) << "the planar arm cannot collide with itself";
    // The planar arm's only non-adjacent pair (base, link2) never moves close: its tests stop at the
    // bounding spheres, so self shows as checked pairs only when declared.
    if (!self) EXPECT_EQ(n.self_pair_tests, 0);
    if (scene->effects().clearance) {
      EXPECT_FALSE(std::isnan(c));
      EXPECT_GT(n.environment.distance_tests, 0);
    } else {
      EXPECT_TRUE(std::isnan(c));
      EXPECT_EQ(n.environment.distance_tests, 0);
      EXPECT_EQ(n.clearance_queries, 0);
      EXPECT_EQ(n.environment.penetration_tests, 0);  // no EPA without clearance
    }
  }
}

TEST(Scene, ContextsOfDroppedScenesAreReleased) {
  // A thread that loads, queries and drops one scene after another keeps contexts for the live ones
  // only (a planner service must not grow without bound).
  TempDir dir;
  const std::string file = dir.write("s.yaml", planarScene("[self, environment]"));
  const auto live = Scene::load(file);
  live->isFree({M_PI / 2, 0.0});
  for (int i = 0; i < 1000; ++i) {
    const auto scene = Scene::load(file);
    scene->isFree({M_PI / 2, 0.0});
  }
  live->isFree({M_PI / 2, 0.0});
  EXPECT_LE(PerThread<SceneContext>::heldByThisThread(), 2u);
  EXPECT_GE(PerThread<SceneContext>::heldByThisThread(), 1u);
}

TEST(Scene, ThreadsShareOneScene) {
  TempDir dir;
  const auto scene = Scene::load(dir.write("s.yaml", planarScene()));
  std::mt19937_64 rng(9);
  std::vector<std::vector<double>> states(500);
  for (auto& s : states)
    s = {std::uniform_real_distribution<double>(-3.1, 3.1)(rng), std::uniform_real_distribution<double>(-2.5, 2.5)(rng)};
  std::vector<char> serial(states.size()), parallel(states.size());
  for (std::size_t i = 0; i < states.size(); ++i) serial[i] = scene->isFree(states[i]);
  auto run = [&](std::size_t begin) {
    for (std::size_t i = begin; i < states.size(); i += 2) parallel[i] = scene->isFree(states[i]);
  };
  std::thread a(run, 0), b(run, 1);
  a.join();
  b.join();
  EXPECT_EQ(serial, parallel);
}

// Every start and goal of the shared problems is classified, and the primitive and OctoMap forms
// agree except where a link is within the map's voxel margin of an obstacle.
TEST(Scene, SharedProblemsStartAndGoal) {
  CLEARWAY_SHARED_SCENES_OR_SKIP();
  int problems = 0, free_states = 0, agree = 0, margin = 0;
  for (const auto& family : std::filesystem::directory_iterator(sharedScenes())) {
    if (!family.is_directory()) continue;
    for (const auto& f : std::filesystem::directory_iterator(family.path())) {
      const std::string p = f.path().string();
      if (f.path().extension() != ".yaml" || p.find(".octomap.") != std::string::npos) continue;
      std::string mp = p;
      mp.replace(mp.size() - 5, 5, ".octomap.yaml");
      const auto prim = test::loadScene(p);
      const auto map = test::loadScene(mp);
      ++problems;
      SceneDescription padded_d = parseSceneFile(p);
      padded_d.padding = 0.035;  // a voxel diagonal (0.0346 m) and rounding
      const Scene padded(padded_d, prim->geometryPtr(), std::make_shared<Environment>(prim->environment()));
      for (const auto* q : {&prim->description().start, &prim->description().goal}) {
        const bool a = prim->isFree(*q), b = map->isFree(*q);
        free_states += a;
        if (a == b) {
          ++agree;
        } else {
          ++margin;
          // Disagreement is allowed only within the margin: then the padded primitive scene collides.
          EXPECT_FALSE(padded.isFree(*q)) << p << ": primitive " << a << ", octomap " << b;
        }
      }
    }
  }
  EXPECT_EQ(problems, 60);
  EXPECT_GT(free_states, 60) << "most starts and goals of MotionBenchMaker problems are valid";
  std::printf("%d problems: %d of %d start/goal states free; primitive and OctoMap forms agree on %d, "
              "differ within the voxel margin on %d\n", problems, free_states, 2 * problems, agree, margin);
}

// The self pairs a scene checks, as sorted name pairs.
std::set<std::pair<std::string, std::string>> checkedPairs(const Scene& scene) {
  std::set<std::pair<std::string, std::string>> out;
  for (const LinkPair& p : scene.selfCollision().pairs()) {
    const std::string a = scene.robot().link(p.a).name, b = scene.robot().link(p.b).name;
    out.insert(a < b ? std::make_pair(a, b) : std::make_pair(b, a));
  }
  return out;
}

TEST(Scene, CheckedSelfPairsOfOurArm) {
  // arm6: 7 links with geometry (tool0 has none) make 21 pairs; the SRDF disables the 6 adjacent ones and
  // base/upper arm (Never): 14 are checked. A scene's `allow` takes away one more.
  const auto scene = Scene::load(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/arm6_wall.yaml");
  const std::set<std::pair<std::string, std::string>> expected = {
      {"base_link", "forearm_link"},      {"base_link", "wrist_1_link"},      {"base_link", "wrist_2_link"},
      {"base_link", "wrist_3_link"},      {"forearm_link", "shoulder_link"},  {"shoulder_link", "wrist_1_link"},
      {"shoulder_link", "wrist_2_link"},  {"shoulder_link", "wrist_3_link"},  {"upper_arm_link", "wrist_1_link"},
      {"upper_arm_link", "wrist_2_link"}, {"upper_arm_link", "wrist_3_link"}, {"forearm_link", "wrist_2_link"},
      {"forearm_link", "wrist_3_link"},   {"wrist_1_link", "wrist_3_link"}};
  EXPECT_EQ(checkedPairs(*scene), expected);
  SceneDescription d = scene->description();
  d.allow.push_back({"wrist_3_link", "base_link"});
  auto fewer = expected;
  fewer.erase({"base_link", "wrist_3_link"});
  EXPECT_EQ(checkedPairs(Scene(d, scene->geometryPtr(), scene->environmentPtr())), fewer);
}

TEST(Scene, CheckedSelfPairsOfTheSharedPanda) {
  // box_panda_0001: 11 links with geometry, 55 pairs; 10 adjacent, 34 disabled by the SRDF and 34 by the
  // scene's `allow` (overlapping) leave these 21, worked out from the files by hand (a script), not by
  // the loader.
  CLEARWAY_SHARED_OR_SKIP(file, "scenes/box_panda/box_panda_0001.yaml");
  const auto scene = Scene::load(file);
  const std::set<std::pair<std::string, std::string>> expected = {
      {"panda_hand", "panda_link0"},        {"panda_hand", "panda_link1"},        {"panda_hand", "panda_link2"},
      {"panda_hand", "panda_link5"},        {"panda_leftfinger", "panda_link0"},  {"panda_leftfinger", "panda_link1"},
      {"panda_leftfinger", "panda_link2"},  {"panda_leftfinger", "panda_link5"},  {"panda_link0", "panda_link5"},
      {"panda_link0", "panda_link6"},       {"panda_link0", "panda_link7"},       {"panda_link0", "panda_rightfinger"},
      {"panda_link1", "panda_link5"},       {"panda_link1", "panda_link6"},       {"panda_link1", "panda_link7"},
      {"panda_link1", "panda_rightfinger"}, {"panda_link2", "panda_link5"},       {"panda_link2", "panda_link7"},
      {"panda_link2", "panda_rightfinger"}, {"panda_link5", "panda_link7"},       {"panda_link5", "panda_rightfinger"}};
  EXPECT_EQ(checkedPairs(*scene), expected);
}

TEST(Scene, OctomapAndPrimitiveFormsDifferByAVoxelAtMost) {
  // Random states of the first problem of each shared family, in both forms. A voxel is occupied when its
  // centre lies in an obstacle (scenes/README.md), so an obstacle's surface may stand up to a voxel
  // diagonal beyond the map, and the map's voxels up to one beyond the obstacle. Both directions: where
  // only the primitive form collides, the map form padded by a voxel diagonal must collide (the map is
  // never freer beyond that); where only the map collides, the padded primitive form must. Self-collision
  // is the same in both and left out.
  CLEARWAY_SHARED_SCENES_OR_SKIP();
  std::mt19937 rng(19);
  int states = 0, both = 0, only_map = 0, only_primitive = 0, families = 0;
  constexpr double kVoxelDiagonal = 0.035;  // 0.02·√3 = 0.0346 m, and rounding
  for (const auto& family : std::filesystem::directory_iterator(sharedScenes())) {
    if (!family.is_directory()) continue;
    const std::string stem = family.path().string() + "/" + family.path().filename().string() + "_0001";
    if (!std::filesystem::exists(stem + ".yaml") || !std::filesystem::exists(stem + ".octomap.yaml")) continue;
    ++families;
    SceneDescription pd = parseSceneFile(stem + ".yaml"), md = parseSceneFile(stem + ".octomap.yaml");
    for (SceneDescription* d : {&pd, &md}) d->effects.self = false;
    const auto geometry = loadRobotGeometry(pd);
    const Scene prim(pd, geometry, loadEnvironment(pd));
    const Scene map(md, geometry, loadEnvironment(md));
    SceneDescription padded_pd = pd, padded_md = md;
    padded_pd.padding += kVoxelDiagonal;
    padded_md.padding += kVoxelDiagonal;
    const Scene padded_prim(padded_pd, geometry, prim.environmentPtr());
    const Scene padded_map(padded_md, geometry, map.environmentPtr());
    std::vector<double> q(prim.dimension());
    for (int trial = 0; trial < 300; ++trial) {
      for (int i = 0; i < prim.dimension(); ++i)
        q[i] = std::uniform_real_distribution<double>(std::max(prim.lower(i), -M_PI), std::min(prim.upper(i), M_PI))(rng);
      ++states;
      CollisionReport why;
      const bool prim_free = prim.isFree(q, &why), map_free = map.isFree(q);
      if (!prim_free && !map_free) {
        ++both;
      } else if (!prim_free) {
        ++only_primitive;
        EXPECT_FALSE(padded_map.isFree(q)) << stem << " trial " << trial << ": the map misses " << prim.describe(why);
      } else if (!map_free) {
        ++only_map;
        EXPECT_FALSE(padded_prim.isFree(q)) << stem << " trial " << trial << ": the map collides beyond a voxel";
      }
    }
  }
  EXPECT_EQ(families, 6);
  EXPECT_GT(both, states / 20) << "too few colliding states to say anything";
  std::printf("%d states: %d collide in both forms, %d in the primitive form only, %d in the OctoMap form only "
              "(each within a voxel)\n", states, both, only_primitive, only_map);
}

// isFree tries first the environment link that met an obstacle last in its context: the verdict must not
// depend on it. Random walks (each state near the last, as a planner's), checked with one context kept
// along the walk and with a new context per state: the verdicts agree, a report names a link that does
// meet an obstacle, and the lead changes which link is reported often enough to show it is taken.
void expectLeadKeepsVerdicts(const Scene& scene, const std::string& what, std::mt19937& rng, int& changed) {
  SceneContext kept = scene.makeContext();
  std::vector<double> q(scene.dimension());
  const auto fresh = [&](CollisionReport& why) {
    SceneContext once = scene.makeContext();
    return scene.isFree(q.data(), once, &why);
  };
  int env_hits = 0;
  for (int walk = 0; walk < 30; ++walk) {
    for (int i = 0; i < scene.dimension(); ++i)
      q[i] = std::uniform_real_distribution<double>(std::max(scene.lower(i), -M_PI), std::min(scene.upper(i), M_PI))(rng);
    for (int step = 0; step < 20; ++step) {
      for (int i = 0; i < scene.dimension(); ++i)
        q[i] = std::clamp(q[i] + std::normal_distribution<double>(0.0, 0.15)(rng), scene.lower(i), scene.upper(i));
      CollisionReport a, b;
      const bool led = scene.isFree(q.data(), kept, &a);
      ASSERT_EQ(led, fresh(b)) << what << " walk " << walk << " step " << step;
      if (led || a.kind != CollisionReport::Kind::Environment) continue;
      ++env_hits;
      const int link = a.link;
      EXPECT_TRUE(scene.environment().linkIntersects(*scene.geometry().link(link), kept.poses()[link],
                                                     scene.options().tolerances,
                                                     {scene.linkPadding(link), scene.options().mode}))
          << what << ": reported " << scene.describe(a) << ", which does not collide";
      changed += b.kind != CollisionReport::Kind::Environment || b.link != link;
    }
  }
  EXPECT_GT(env_hits, 0) << what << ": no state met an obstacle";
}

// A context made by another scene of the same robot is accepted (the same links), but that scene holds
// other joints and checks other pairs and environment links: its held values, warm starts and leads must
// never stand for this scene's (they did: a joint the other scene plans kept its value where this one holds it).
// arm6_wall, and the same robot with its first self pairs allowed and its first joint held (so that the
// pairs and the environment links shift by index): each scene's verdicts with the other's context, kept
// along random walks, equal those of fresh contexts.
TEST(Scene, AContextOfAnotherSceneOfTheSameRobotChangesNoVerdict) {
  const auto a = Scene::load(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/arm6_wall.yaml");
  SceneDescription d = a->description();
  for (int k = 0; k < 3 && k < static_cast<int>(a->selfCollision().pairs().size()); ++k) {
    const LinkPair& p = a->selfCollision().pairs()[k];
    d.allow.emplace_back(a->robot().link(p.a).name, a->robot().link(p.b).name);
  }
  d.hold.emplace_back(d.group.front(), 0.0);
  d.group.erase(d.group.begin());
  d.start.clear();
  d.goal.clear();
  const auto b = std::make_shared<const Scene>(d, a->geometryPtr(), a->environmentPtr(), a->options());
  ASSERT_LT(b->selfCollision().pairs().size(), a->selfCollision().pairs().size());
  ASSERT_LT(b->environmentLinks().size(), a->environmentLinks().size());
  std::mt19937 rng(41);
  int colliding = 0;
  for (const auto& [one, other] : {std::make_pair(a, b), std::make_pair(b, a)}) {
    SceneContext borrowed = other->makeContext();
    std::vector<double> q(one->dimension());
    for (int walk = 0; walk < 40; ++walk) {
      // Each walk starts where the other scene last met something, so that its leads point past this one's.
      std::vector<double> r(other->dimension());
      for (int i = 0; i < other->dimension(); ++i)
        r[i] = std::uniform_real_distribution<double>(std::max(other->lower(i), -M_PI),
                                                      std::min(other->upper(i), M_PI))(rng);
      other->isFree(r.data(), borrowed);
      for (int i = 0; i < one->dimension(); ++i)
        q[i] =
            std::uniform_real_distribution<double>(std::max(one->lower(i), -M_PI), std::min(one->upper(i), M_PI))(rng);
      for (int step = 0; step < 10; ++step) {
        for (int i = 0; i < one->dimension(); ++i)
          q[i] = std::clamp(q[i] + std::normal_distribution<double>(0.0, 0.2)(rng), one->lower(i), one->upper(i));
        SceneContext fresh = one->makeContext();
        CollisionReport want, got;
        const bool expected = one->isFree(q.data(), fresh, &want);
        ASSERT_EQ(one->isFree(q.data(), borrowed, &got), expected)
            << one->name() << " walk " << walk << " step " << step << ": " << one->describe(got) << " / "
            << one->describe(want);
        colliding += !expected;
      }
    }
  }
  EXPECT_GT(colliding, 50);
}

TEST(Scene, TheLinkThatHitLastGoesFirstAndNoVerdictChanges) {
  std::mt19937 rng(23);
  int changed = 0;
  expectLeadKeepsVerdicts(*Scene::load(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/arm6_wall.yaml"), "arm6_wall",
                          rng, changed);
  CLEARWAY_SHARED_SCENES_OR_SKIP();
  for (const auto& family : std::filesystem::directory_iterator(sharedScenes())) {
    if (!family.is_directory()) continue;
    const std::string stem = family.path().string() + "/" + family.path().filename().string() + "_0001";
    for (const std::string form : {".yaml", ".octomap.yaml"})
      if (std::filesystem::exists(stem + form))
        expectLeadKeepsVerdicts(*test::loadScene(stem + form), stem + form, rng, changed);
  }
  EXPECT_GT(changed, 0) << "the lead never changed which link is reported: is it taken at all?";
  std::printf("the lead changed the reported link on %d colliding states\n", changed);
}

// The link that hit last is asked first, and its own bounding ball is asked of the obstacles' boxes first as
// every other link's is: a free state after a collision clears as many links by the boxes as a fresh
// context's check of it, the lead included (before, the lead always took its exact test).
TEST(Scene, TheLeadIsClearedByTheBoxesLikeEveryOtherLink) {
  const auto scene = Scene::load(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/arm6_wall.yaml");
  ASSERT_NE(scene->environment().obstacleBoxes(), nullptr);
  std::mt19937 rng(41);
  const int d = scene->dimension();
  std::vector<double> hit(d), q(d);
  const auto draw = [&](std::vector<double>& x) {
    for (int i = 0; i < d; ++i)
      x[i] = std::uniform_real_distribution<double>(std::max(scene->lower(i), -M_PI),
                                                    std::min(scene->upper(i), M_PI))(rng);
  };
  int pairs = 0, lead_cleared = 0;
  for (int attempt = 0; attempt < 4000 && pairs < 200; ++attempt) {
    draw(hit);
    SceneContext led = scene->makeContext();
    CollisionReport why;
    if (scene->isFree(hit.data(), led, &why) || why.kind != CollisionReport::Kind::Environment) continue;
    draw(q);
    SceneContext fresh = scene->makeContext();
    CollisionReport fresh_why;
    const bool free = scene->isFree(q.data(), fresh, &fresh_why);
    if (!free) continue;
    const long long clears = led.counters().environment.box_clears;
    const long long exact = led.counters().environment.obstacle_tests;
    ASSERT_TRUE(scene->isFree(q.data(), led)) << "state " << attempt;
    EXPECT_EQ(led.counters().environment.box_clears - clears, fresh.counters().environment.box_clears)
        << "state " << attempt << ": after " << scene->describe(why);
    EXPECT_EQ(led.counters().environment.obstacle_tests - exact, fresh.counters().environment.obstacle_tests)
        << "state " << attempt << ": after " << scene->describe(why);
    ++pairs;
    lead_cleared += fresh.counters().environment.box_clears > 0;
  }
  EXPECT_GE(pairs, 100) << "too few free states after a collision with an obstacle";
  EXPECT_GT(lead_cleared, pairs / 2) << "the boxes cleared too few links to tell";
}

// Which shortcut of the environment a verdict test compares: the clearance grid, the obstacles' boxes, or
// the map's voxels merged into blocks.
enum class Shortcut { Grid, Boxes, Blocks };

// The same states with one shortcut of the environment and without it: every verdict, and what each report
// names, equal; one at a time and batched. Half the states are random, half walk near obstacles. The grid
// is compared on a world without boxes (which would clear first), the boxes beside the grid, on each of
// `targets` in turn (none: the CPU's own).
void expectShortcutKeepsVerdicts(Shortcut shortcut, const std::shared_ptr<const Scene>& loaded, const std::string& what,
                                 std::mt19937& rng, long long& clears, const std::vector<std::int64_t>& targets) {
  const Environment& env = loaded->environment();
  const auto with = shortcut == Shortcut::Grid
                        ? loaded->withEnvironment(std::make_shared<Environment>(env.withoutObstacleBoxes()))
                        : loaded;
  const auto without = with->withEnvironment(
      std::make_shared<Environment>(shortcut == Shortcut::Grid    ? with->environment().withoutClearanceGrid()
                                    : shortcut == Shortcut::Boxes ? env.withoutObstacleBoxes()
                                                                  : env.withoutVoxelBlocks()));
  with->environment().prepareClearanceGrid();
  without->environment().prepareClearanceGrid();
  if (shortcut == Shortcut::Grid) ASSERT_NE(with->environment().clearanceGrid(), nullptr) << what;
  const bool has_boxes = with->environment().obstacleBoxes() != nullptr;
  for (std::size_t t = 0; t < std::max<std::size_t>(targets.size(), 1); ++t) {
    std::optional<test::ForcedTarget> forced;
    if (!targets.empty()) forced.emplace(targets[t]);
    const std::string where = what + (targets.empty() ? "" : std::string(", ") + hwy::TargetName(targets[t]));
    SceneContext a = with->makeContext(), b = without->makeContext(), batched = with->makeContext();
    const int d = with->dimension();
    std::vector<double> q(d), states;
    std::vector<char> verdicts;
    for (int k = 0; k < 600; ++k) {
      const bool jump = k % 2 == 0 || k % 20 == 1;
      for (int i = 0; i < d; ++i) {
        const double lo = std::max(with->lower(i), -M_PI), hi = std::min(with->upper(i), M_PI);
        q[i] = jump
                   ? std::uniform_real_distribution<double>(lo, hi)(rng)
                   : std::clamp(q[i] + std::normal_distribution<double>(0.0, 0.1)(rng), with->lower(i), with->upper(i));
      }
      CollisionReport ra, rb;
      const bool fa = with->isFree(q.data(), a, &ra), fb = without->isFree(q.data(), b, &rb);
      ASSERT_EQ(fa, fb) << where << " state " << k;
      EXPECT_EQ(ra.kind, rb.kind) << where << " state " << k;
      EXPECT_EQ(ra.link, rb.link) << where << " state " << k;
      EXPECT_EQ(ra.other_link, rb.other_link) << where << " state " << k;
      states.insert(states.end(), q.begin(), q.end());
      verdicts.push_back(fa);
    }
    std::unique_ptr<bool[]> free(new bool[verdicts.size()]);
    with->areFree(states.data(), static_cast<int>(verdicts.size()), batched, free.get());
    for (std::size_t k = 0; k < verdicts.size(); ++k)
      ASSERT_EQ(free[k], verdicts[k] != 0) << where << " batched state " << k;
    if (shortcut == Shortcut::Grid) {
      EXPECT_EQ(b.counters().environment.grid_clears, 0) << where;
      EXPECT_GT(a.counters().environment.grid_clears, 0) << where << ": the grid cleared no link";
      clears += a.counters().environment.grid_clears;
    } else if (shortcut == Shortcut::Boxes) {
      EXPECT_EQ(b.counters().environment.box_clears, 0) << where;
      if (has_boxes) EXPECT_GT(a.counters().environment.box_clears, 0) << where << ": the boxes cleared no link";
      clears += a.counters().environment.box_clears;
    } else {  // (the tests the blocks saved: never more than the voxels need)
      EXPECT_LE(a.counters().environment.voxel_tests, b.counters().environment.voxel_tests) << where;
      clears += b.counters().environment.voxel_tests - a.counters().environment.voxel_tests;
    }
  }
}

// Two open plates (0.2 m squares at z = ±0.5) as dir/plates.stl: one link of two parts whose hull is a
// box their parts' balls do not fill.
void writePlates(const test::TempDir& dir) {
  const auto facet = [](const std::string& a, const std::string& b, const std::string& c) {
    return "facet normal 0 0 0\nouter loop\nvertex " + a + "\nvertex " + b + "\nvertex " + c + "\nendloop\nendfacet\n";
  };
  std::string stl = "solid plates\n";
  for (const std::string z : {"-0.5", "0.5"})
    stl += facet("-0.1 -0.1 " + z, "0.1 -0.1 " + z, "0.1 0.1 " + z) + facet("-0.1 -0.1 " + z, "0.1 0.1 " + z, "-0.1 0.1 " + z);
  dir.write("plates.stl", stl + "endsolid plates\n");
}

// A link of two open plates, 1 m apart, around a small box: the meshes are clear of it, the hull (Hull
// mode's geometry) holds it, and so the parts' balls, which hold each plate, must not clear the link there.
TEST(Scene, TheClearanceGridKeepsHullModeVerdicts) {
  const test::TempDir dir;
  writePlates(dir);
  dir.write("plates.urdf", R"(<robot name="plates">
  <link name="base"/>
  <link name="plates"><collision><geometry><mesh filename="plates.stl"/></geometry></collision></link>
  <joint name="slide" type="prismatic"><parent link="base"/><child link="plates"/><axis xyz="1 0 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
</robot>)");
  const std::string path = dir.write("plates.yaml", "format: 1\nname: plates\nrobot:\n  urdf: " + dir.path("plates.urdf") +
                                                        "\n  group: [slide]\nenvironment:\n  obstacles:\n"
                                                        "    - {name: block, box: {size: [0.1, 0.1, 0.1]}}\n"
                                                        "checks: [environment]\n");
  for (const GeometryMode mode : {GeometryMode::Mesh, GeometryMode::Hull}) {
    SceneOptions options;
    options.mode = mode;
    const auto scene = Scene::load(path, options);
    ASSERT_GT(scene->geometry().link(1)->parts().size(), 1u) << "the test needs a link of several parts";
    ASSERT_EQ(scene->geometry().link(1)->solidCount(), 0);
    scene->environment().prepareClearanceGrid();
    ASSERT_NE(scene->environment().clearanceGrid(), nullptr);
    SceneContext ctx = scene->makeContext();
    const std::vector<double> q = {0.0};
    EXPECT_EQ(scene->isFree(q.data(), ctx), mode == GeometryMode::Mesh) << (mode == GeometryMode::Mesh ? "mesh" : "hull");
    if (mode == GeometryMode::Mesh)  // (the parts' balls cleared it: the path the hull must not take)
      EXPECT_EQ(ctx.counters().environment.grid_clears, 1);
  }
}

// The same plates around a block of the robot itself: in Hull mode the plates' hull holds the block, so
// the pair collides, though every ball of the plates' parts is clear of the block's.
TEST(Scene, HullModeSelfPairsAreDecidedByTheHulls) {
  const test::TempDir dir;
  writePlates(dir);
  // (The base has geometry of its own, far off: through a link without any, plates and block would be
  // adjacent, as MoveIt counts, and never checked.)
  dir.write("plates.urdf", R"(<robot name="plates">
  <link name="base"><collision><origin xyz="0 0 -3"/><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <link name="plates"><collision><geometry><mesh filename="plates.stl"/></geometry></collision></link>
  <link name="block"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <joint name="slide" type="prismatic"><parent link="base"/><child link="plates"/><axis xyz="1 0 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="hold" type="fixed"><parent link="base"/><child link="block"/></joint>
</robot>)");
  const std::string path = dir.write("plates.yaml", "format: 1\nname: plates\nrobot:\n  urdf: " + dir.path("plates.urdf") +
                                                        "\n  group: [slide]\nchecks: [self]\n");
  for (const GeometryMode mode : {GeometryMode::Mesh, GeometryMode::Hull}) {
    SceneOptions options;
    options.mode = mode;
    const auto scene = Scene::load(path, options);
    const int plates = scene->robot().linkIndex("plates");
    ASSERT_GE(plates, 0);
    ASSERT_GT(scene->geometry().link(plates)->parts().size(), 1u) << "the test needs a link of several parts";
    ASSERT_EQ(scene->selfCollision().pairs().size(), 1u) << "plates and block must be a checked pair";
    SceneContext ctx = scene->makeContext();
    for (const double x : {0.0, 0.05, -0.12}) {
      const std::vector<double> q = {x};
      EXPECT_EQ(scene->isFree(q.data(), ctx), mode == GeometryMode::Mesh) << (mode == GeometryMode::Mesh ? "mesh" : "hull") << " at x = " << x;
    }
    const std::vector<double> away = {1.0};
    EXPECT_TRUE(scene->isFree(away.data(), ctx));
  }
}

// A shortcut on arm6_wall and every shared family, in Mesh and Hull mode (where a link's hull, which its
// parts' balls need not hold, decides). The grid in both forms; the boxes in the primitive form (a map's
// voxels have none), on every SIMD target of the lanes in Mesh mode; the blocks in the map's form (the
// primitive one has no map), both modes. Returns the links it cleared (the blocks: the voxel tests saved).
long long expectShortcutKeepsVerdicts(Shortcut shortcut, unsigned seed) {
  std::mt19937 rng(seed);
  long long clears = 0;
  const std::vector<std::int64_t> targets =
      shortcut == Shortcut::Boxes ? KinematicLanes::targets() : std::vector<std::int64_t>{};
  const std::string arm6 = std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/arm6_wall.yaml";
  SceneOptions hull;
  hull.mode = GeometryMode::Hull;
  expectShortcutKeepsVerdicts(shortcut, Scene::load(arm6), "arm6_wall", rng, clears, targets);
  expectShortcutKeepsVerdicts(shortcut, Scene::load(arm6, hull), "arm6_wall (hull)", rng, clears, {});
  if (!std::filesystem::is_directory(sharedScenes())) return clears;
  for (const auto& family : std::filesystem::directory_iterator(sharedScenes())) {
    if (!family.is_directory()) continue;
    const std::string stem = family.path().string() + "/" + family.path().filename().string() + "_0001";
    for (const std::string form : {".yaml", ".octomap.yaml"}) {
      if (!std::filesystem::exists(stem + form)) continue;
      if (shortcut == Shortcut::Boxes && form != ".yaml") {
        EXPECT_EQ(test::loadScene(stem + form)->environment().obstacleBoxes(), nullptr) << stem + form;
        continue;
      }
      if (shortcut == Shortcut::Blocks && form == ".yaml") {
        EXPECT_EQ(test::loadScene(stem + form)->environment().voxelBlocks(), nullptr) << stem + form;
        continue;
      }
      expectShortcutKeepsVerdicts(shortcut, test::loadScene(stem + form), stem + form, rng, clears, targets);
      if (form == ".yaml" || shortcut == Shortcut::Blocks)
        expectShortcutKeepsVerdicts(shortcut, test::loadScene(stem + form, hull), stem + form + " (hull)", rng, clears,
                                    {});
    }
  }
  return clears;
}

TEST(Scene, TheClearanceGridChangesNoVerdict) {
  const long long clears = expectShortcutKeepsVerdicts(Shortcut::Grid, 29);
  CLEARWAY_SHARED_SCENES_OR_SKIP();
  std::printf("the grid cleared %lld links\n", clears);
}

TEST(Scene, TheObstacleBoxesChangeNoVerdict) {
  const long long clears = expectShortcutKeepsVerdicts(Shortcut::Boxes, 31);
  CLEARWAY_SHARED_SCENES_OR_SKIP();
  std::printf("the obstacles' boxes cleared %lld links\n", clears);
}

// (Our own maps are compared with their voxels in tests/environment/test_voxel_blocks.cpp.)
TEST(Scene, TheVoxelBlocksChangeNoVerdict) {
  CLEARWAY_SHARED_SCENES_OR_SKIP();
  const long long saved = expectShortcutKeepsVerdicts(Shortcut::Blocks, 37);
  EXPECT_GT(saved, 0) << "the blocks saved no voxel test: are they walked at all?";
  std::printf("the voxel blocks saved %lld voxel tests\n", saved);
}

// Found by fuzz_scene_edits: a floating joint's quaternion of zeros passed validState (the tool's check
// and motion, Python, OMPL's bounds), while its poses are NaN: check called the state a collision with
// "environment", and the certified and cast motions called a segment ending there free. The flyer by its
// post (the plate taken away): [1, 1, 1, 0, 0, 0, 0] is now invalid, naming the quaternion, everywhere.
TEST(Scene, AZeroQuaternionIsAnInvalidState) {
  TempDir dir;
  std::ifstream in(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/flyer_post.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = std::regex_replace(text.str(), std::regex("    - name: plate\n.*\n.*\n"), "");
  yaml = std::regex_replace(yaml, std::regex("\\.\\./flyer/"), test::sourceRobot("flyer/"));
  ASSERT_EQ(yaml.find("name: plate"), std::string::npos);
  const auto scene = Scene::load(dir.write("post.yaml", yaml));
  const std::vector<double> zero{1, 1, 1, 0, 0, 0, 0}, upright{1, 1, 1, 0, 0, 0, 1}, tiny{1, 1, 1, 0, 0, 0, 1e-170};
  std::string why;
  EXPECT_FALSE(scene->validState(zero.data(), &why));
  EXPECT_NE(why.find("state[3..6] (fly/qx ...) is a zero quaternion"), std::string::npos) << why;
  EXPECT_FALSE(scene->validState(tiny.data()));  // its square is 0 in doubles: no rotation either
  EXPECT_TRUE(scene->validState(upright.data()));
  EXPECT_TRUE(scene->validState(std::vector<double>{1, 1, 1, 0, 0, 0, 1e-150}.data()));  // normalises
  CollisionReport report;
  EXPECT_FALSE(scene->isFree(zero, &report));
  EXPECT_EQ(report.kind, CollisionReport::Kind::Invalid);
  EXPECT_TRUE(scene->isFree(upright));
  for (const MotionMode mode : {MotionMode::Certified, MotionMode::Cast}) {
    MotionOptions options;
    options.mode = mode;
    const MotionChecker checker(scene, options);
    MotionContext ctx = checker.makeContext();
    EXPECT_FALSE(checker.check(upright.data(), zero.data(), ctx).free) << static_cast<int>(mode);
    EXPECT_FALSE(checker.check(zero.data(), upright.data(), ctx).free) << static_cast<int>(mode);
  }
}

// rigidAnchors: each link moves rigidly with its anchor at every state (the UR5's gripper and wrist sensor
// with wrist_3_link), an anchor's own joint is one the group moves (or it is the root), and the scene's
// environment check, which clears such a body with one ball, answers as before (the shortcut tests above).
TEST(Scene, LinksMoveRigidlyWithTheirAnchors) {
  CLEARWAY_SHARED_OR_SKIP(file, "scenes/box_ur5/box_ur5_0001.yaml");
  const auto scene = Scene::load(file);
  const RobotModel& model = scene->robot();
  const std::vector<int>& anchor = scene->rigidAnchors();
  ASSERT_EQ(anchor.size(), static_cast<std::size_t>(model.linkCount()));
  const int wrist = model.linkIndex("wrist_3_link");
  for (const char* name : {"fts_robotside", "robotiq_85_base_link", "robotiq_85_left_finger_tip_link"})
    EXPECT_EQ(anchor[model.linkIndex(name)], wrist) << name;
  EXPECT_EQ(anchor[wrist], wrist);
  SceneContext ctx = scene->makeContext();
  std::mt19937 rng(37);
  std::vector<std::vector<Pose>> seen;
  for (int s = 0; s < 20; ++s) {
    std::vector<double> q(scene->dimension());
    for (int i = 0; i < scene->dimension(); ++i)
      q[i] = std::uniform_real_distribution<double>(std::max(scene->lower(i), -M_PI),
                                                    std::min(scene->upper(i), M_PI))(rng);
    scene->computePoses(q.data(), ctx);
    std::vector<Pose> relative;
    for (int l = 0; l < model.linkCount(); ++l)
      relative.push_back(relativePose(ctx.poses()[anchor[l]], ctx.poses()[l]));
    seen.push_back(relative);
  }
  for (int l = 0; l < model.linkCount(); ++l) {
    for (std::size_t s = 1; s < seen.size(); ++s) {
      EXPECT_LT((seen[s][l].t - seen[0][l].t).norm(), 1e-12) << model.link(l).name;
      EXPECT_LT((seen[s][l].R - seen[0][l].R).norm(), 1e-12) << model.link(l).name;
    }
    const int a = anchor[l];
    if (a != 0) {
      const std::vector<int>& group = scene->groupVariables();
      const Joint& j = model.joint(model.link(a).parent_joint);
      EXPECT_NE(std::find(group.begin(), group.end(), j.first_variable), group.end()) << model.link(l).name;
    }
  }
}

TEST(Scene, PairsWithinOneRigidBodyAreCheckedOnce) {
  // Two links joined by fixed joints never move relative to each other: the scene decides their pair once,
  // at load. Where they overlap, every state collides and names them (the motion checker's segments too);
  // where they do not, the pair is not among those checked per state.
  const auto urdf = [](double finger_x) {
    const auto box = [](const char* size) {
      return std::string("<collision><geometry><box size=\"") + size + "\"/></geometry></collision>";
    };
    return std::string("<robot name=\"rigid\">") + "<link name=\"base\">" + box("0.2 0.2 0.2") + "</link>" +
           "<link name=\"arm\">" + box("0.6 0.1 0.1") + "</link>" + "<link name=\"mount\">" + box("0.02 0.02 0.02") +
           "</link>" + "<link name=\"finger\">" + box("0.1 0.1 0.1") + "</link>" +
           "<joint name=\"turn\" type=\"revolute\"><parent link=\"base\"/><child link=\"arm\"/>"
           "<origin xyz=\"0 0 0.5\"/><axis xyz=\"0 0 1\"/><limit lower=\"-3\" upper=\"3\" effort=\"1\" "
           "velocity=\"1\"/></joint>"
           "<joint name=\"to_mount\" type=\"fixed\"><parent link=\"arm\"/><child link=\"mount\"/>"
           "<origin xyz=\"0.5 0 0.3\"/></joint>"
           "<joint name=\"to_finger\" type=\"fixed\"><parent link=\"mount\"/><child link=\"finger\"/>"
           "<origin xyz=\"" +
           std::to_string(finger_x - 0.5) + " 0 -0.3\"/></joint></robot>";
  };
  TempDir dir;
  for (const double finger_x : {0.2, 0.5 + 0.3}) {  // overlapping the arm (x in [-0.3, 0.3]), and clear of it
    const bool overlap = finger_x < 0.3;
    const std::string robot = dir.write(overlap ? "over.urdf" : "clear.urdf", urdf(finger_x));
    const std::shared_ptr<const Scene> loaded =
        Scene::load(dir.write(overlap ? "over.yaml" : "clear.yaml", "format: 1\nname: rigid\nrobot:\n  urdf: " + robot +
                                                                        "\n  group: [turn]\nchecks: [self]\n"));
    const Scene& scene = *loaded;
    const RobotModel& model = scene.robot();
    const int arm = model.linkIndex("arm"), finger = model.linkIndex("finger");
    ASSERT_EQ(scene.rigidAnchors()[finger], arm);
    for (const LinkPair& p : scene.selfCollision().pairs())
      EXPECT_NE(scene.rigidAnchors()[p.a], scene.rigidAnchors()[p.b])
          << model.link(p.a).name << ", " << model.link(p.b).name << " are one rigid body";
    SceneContext ctx = scene.makeContext();
    MotionChecker motion(loaded);
    MotionContext mctx = motion.makeContext();
    for (const double turn : {-2.0, 0.0, 1.0}) {
      CollisionReport report;
      EXPECT_EQ(scene.isFree(&turn, ctx, &report), !overlap) << turn;
      const double next = turn + 0.5;
      const MotionResult m = motion.check(&turn, &next, mctx, false);
      EXPECT_EQ(m.free, !overlap) << turn;
      if (!overlap) continue;
      EXPECT_EQ(report.kind, CollisionReport::Kind::Self);
      EXPECT_EQ(std::minmax(report.link, report.other_link), std::minmax(arm, finger));
      EXPECT_EQ(m.report.kind, CollisionReport::Kind::Self);
    }
  }
}

TEST(Scene, ARigidPairsAnswerIsRememberedPerPaddingAndRobot) {
  // Scenes over one loaded robot share the answers of its rigid pairs (searched once, not per scene), yet
  // what each scene is told depends on its own padding and its own robot. The finger is fixed 0.45 m clear
  // of the arm, past a mount that keeps the two from being adjacent.
  const auto urdf = [](double finger_x) {
    const auto box = [](const char* size) {
      return std::string("<collision><geometry><box size=\"") + size + "\"/></geometry></collision>";
    };
    return std::string("<robot name=\"rigid\"><link name=\"base\"/><link name=\"arm\">") + box("0.6 0.1 0.1") +
           "</link><link name=\"mount\">" + box("0.02 0.02 0.02") + "</link><link name=\"finger\">" +
           box("0.1 0.1 0.1") +
           "</link><joint name=\"turn\" type=\"revolute\"><parent link=\"base\"/><child link=\"arm\"/>"
           "<axis xyz=\"0 0 1\"/><limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/></joint>"
           "<joint name=\"to_mount\" type=\"fixed\"><parent link=\"arm\"/><child link=\"mount\"/>"
           "<origin xyz=\"0.5 0 0.3\"/></joint><joint name=\"to_finger\" type=\"fixed\"><parent link=\"mount\"/>"
           "<child link=\"finger\"/><origin xyz=\"" +
           std::to_string(finger_x - 0.5) + " 0 -0.3\"/></joint></robot>";
  };
  TempDir dir;
  const auto scene = [&](const std::string& robot_file, const std::shared_ptr<const RobotGeometry>& robot,
                         double padding) {
    SceneDescription d = parseSceneFile(dir.write(
        "rigid.yaml", "format: 1\nname: rigid\nrobot:\n  urdf: " + robot_file + "\n  group: [turn]\nchecks: [self]\n"));
    d.padding = padding;
    const auto r = robot ? robot : loadRobotGeometry(d);
    return std::make_shared<const Scene>(d, r, std::make_shared<const Environment>());
  };
  const std::string clear_file = dir.write("clear.urdf", urdf(0.8));
  const std::shared_ptr<const RobotGeometry> clear = scene(clear_file, nullptr, 0.0)->geometryPtr();
  // A padding of p per link meets across the gap when 2p >= 0.45.
  for (const double padding : {0.2, 0.25, 0.0, 0.2, 0.25}) {
    const bool meet = padding > 0.225;
    EXPECT_EQ(scene(clear_file, clear, padding)->staticCollision().kind,
              meet ? CollisionReport::Kind::Self : CollisionReport::Kind::None)
        << "padding " << padding;
  }
  // Another robot, loaded from other bytes, is asked afresh (whatever addresses its links happen to get).
  for (int k = 0; k < 3; ++k) {
    const std::string over_file = dir.write("over.urdf", urdf(k % 2 == 0 ? 0.2 : 0.8));
    EXPECT_EQ(scene(over_file, nullptr, 0.0)->staticCollision().kind,
              k % 2 == 0 ? CollisionReport::Kind::Self : CollisionReport::Kind::None)
        << "load " << k;
  }
}

TEST(Scene, NoPairTablesForASceneThatLeavesOutSelf) {
  // Simulate only the effects a scene calls for: tables are a self check's, and take most of a load.
  SceneDescription d = parseSceneFile(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/arm6_wall.yaml");
  ASSERT_TRUE(d.effects.self && d.effects.environment);
  const auto tabled = [](const Scene& scene) {
    int n = 0;
    for (std::size_t k = 0; k < scene.selfCollision().pairs().size(); ++k)
      n += scene.selfCollision().pairTable(k) != nullptr;
    return n;
  };
  EXPECT_GT(tabled(Scene(d)), 0);
  d.effects.self = false;
  const long long built = PairTable::cacheStats().built;
  const Scene environment_only(d);
  EXPECT_EQ(tabled(environment_only), 0);
  EXPECT_EQ(PairTable::cacheStats().built, built) << "no table was built";
}

}  // namespace
}  // namespace clearway
