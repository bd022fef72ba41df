// The robot-loading options of the commands that load robots (check, motion, plan, audit):
// --package-path DIR finds package:// meshes that no environment variable points at; the audit prints
// the warnings of the SRDF it compares with.
#include "cli/tool_run.h"
#include "load/robot_files.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

using clearway::test::TempDir;
using clearway_test::runTool;
using clearway_test::ToolRun;

namespace {

bool mentions(const std::string& text, const std::string& what) { return text.find(what) != std::string::npos; }

// A one-joint robot whose moving link is a mesh in package my_robot (under ws/src), and a scene for it.
class PackagePath : public ::testing::Test {
 protected:
  void SetUp() override {
    // The tool inherits the environment: keep ROS's search paths out of it.
    for (const char* name : {"ROS_PACKAGE_PATH", "AMENT_PREFIX_PATH"}) {
      if (const char* v = std::getenv(name)) saved_.emplace_back(name, v);
      ::unsetenv(name);
    }
    dir.write("ws/src/my_robot/package.xml", "<package><name>my_robot</name></package>");
    dir.write("ws/src/my_robot/meshes/tet.stl", clearway::test::tetrahedronStl());
    urdf = dir.write("robot/r.urdf", R"(<robot name="r">
      <link name="a"><collision><geometry><sphere radius="0.1"/></geometry></collision></link>
      <link name="b"><collision><origin xyz="0.5 0 0"/><geometry><mesh filename="package://my_robot/meshes/tet.stl" scale="0.1 0.1 0.1"/></geometry></collision></link>
      <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
        <limit lower="-2" upper="2" velocity="1" effort="1"/></joint>
    </robot>)");
    scene = dir.write("scene.yaml", "format: 1\nrobot:\n  urdf: robot/r.urdf\n  group: [j]\n"
                                    "checks: [self, environment, continuous]\nstart: [0]\ngoal: [1]\n");
    states = dir.write("states.txt", "0\n1\n");
    motions = dir.write("motions.txt", "0 1\n");
  }
  void TearDown() override {
    for (const auto& [name, value] : saved_) ::setenv(name.c_str(), value.c_str(), 1);
  }
  std::string q(const std::string& path) const { return "'" + path + "'"; }

  TempDir dir;
  std::string urdf, scene, states, motions;

 private:
  std::vector<std::pair<std::string, std::string>> saved_;
};

}  // namespace

TEST_F(PackagePath, EveryCommandThatLoadsARobotTakesIt) {
  const std::string path = " --package-path " + q(dir.path("nothing")) + " --package-path " + q(dir.path("ws"));
  // A missing folder is a usage error, named.
  ToolRun r = runTool("check " + q(scene) + path);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(mentions(r.err, dir.path("nothing") + ": folder not found")) << r.err;

  const std::string good = " --package-path " + q(dir.path("ws"));
  r = runTool("check " + q(scene) + " --states " + q(states) + good);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "free\nfree\n");
  r = runTool("motion " + q(scene) + " --motions " + q(motions) + good);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "free\n");
  r = runTool("plan " + q(scene) + " --seed 1 --time 5" + good);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(mentions(r.out, "path ")) << r.out;
  r = runTool("audit " + q(urdf) + " --samples 10" + good);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(mentions(r.out, "r: 1 pairs")) << r.out;

  // Without it the package is not found, and the error says which.
  for (const std::string& command : {"check " + q(scene), "motion " + q(scene), "plan " + q(scene),
                                     "audit " + q(urdf) + " --samples 10"}) {
    r = runTool(command);
    EXPECT_EQ(r.exit_code, 2) << command;
    EXPECT_TRUE(mentions(r.err, "unresolved package://my_robot")) << command << ": " << r.err;
  }
  r = runTool("check " + q(scene) + " --package-path");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(mentions(r.err, "--package-path")) << r.err;  // (and that it needs a DIR)
  EXPECT_TRUE(mentions(runTool("check --help").out, "--package-path DIR"));
}

TEST_F(PackagePath, AuditPrintsTheWarningsOfTheSrdfItComparesWith) {
  const std::string srdf = dir.write("robot/r.srdf", R"(<robot name="r">
    <disable_collisions link1="a" link2="b" reason="Adjacent"/>
    <disable_collisions link1="a" link2="gripper" reason="Never"/>
  </robot>)");
  const ToolRun r = runTool("audit " + q(urdf) + " --srdf " + q(srdf) + " --samples 10 --package-path " + q(dir.path("ws")));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(mentions(r.err, "warning: " + srdf + ": 1 <disable_collisions> pair skipped")) << r.err;
  EXPECT_TRUE(mentions(r.err, "'gripper'")) << r.err;
}

TEST(HonourUpAxis, TheOptionTurnsYUpMeshesAndIsOffByDefault) {
  // Link b is a Y_UP COLLADA box 1 m long along the file's z: as ROS reads it, it stands up and misses
  // the block at y = -0.5; with the up axis honoured it lies along -y, through the block (wider than
  // the box, so that their surfaces cross).
  TempDir dir;
  dir.write("tall.dae", clearway::test::colladaBox({-0.05, -0.05, 0}, {0.05, 0.05, 1}, "Y_UP"));
  dir.write("r.urdf", R"(<robot name="r">
    <link name="a"><collision><geometry><sphere radius="0.01"/></geometry></collision></link>
    <link name="b"><collision><geometry><mesh filename="tall.dae"/></geometry></collision></link>
    <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
      <limit lower="-2" upper="2" velocity="1" effort="1"/></joint>
  </robot>)");
  const std::string scene = dir.write("s.yaml", "format: 1\nrobot:\n  urdf: r.urdf\n  group: [j]\nenvironment:\n"
                                                "  obstacles:\n    - {name: block, box: {size: [0.3, 0.1, 0.3]}, "
                                                "pose: {position: [0, -0.5, 0]}}\nchecks: [environment]\nstart: [0]\n");
  ToolRun r = runTool("check '" + scene + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "start: free\n");
  EXPECT_TRUE(mentions(r.err, "<up_axis> is Y_UP: ignored")) << r.err;
  r = runTool("check '" + scene + "' --honour-up-axis");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "start: collision b block\n");
  EXPECT_TRUE(mentions(r.err, "<up_axis> is Y_UP: rotated")) << r.err;
}
