// Warnings: each distinct one printed once, none with --quiet (wherever it stands). The bundled arm6's
// forearm mesh declares a COLLADA up axis, which is ignored with a warning.
#include "cli/tool_run.h"
#include "load/robot_files.h"

#include <gtest/gtest.h>

#include <string>

using clearway_test::runTool;
using clearway_test::ToolRun;

namespace {

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

const std::string kUpAxis = "COLLADA <up_axis> is Y_UP";
std::string source(const std::string& rel) { return "'" + std::string(CLEARWAY_SOURCE_DIR) + "/" + rel + "'"; }

}  // namespace

TEST(Warnings, OnceEachAndNoneWhenQuiet) {
  const std::string scene = source("robots/scenes/arm6_wall.yaml");
  ToolRun r = runTool("check " + scene);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(count(r.err, kUpAxis), 1) << r.err;
  const std::string verdicts = r.out;
  for (const std::string& args : {"check " + scene + " --quiet", "--quiet check " + scene}) {
    r = runTool(args);
    EXPECT_EQ(r.exit_code, 0) << args << ": " << r.err;
    EXPECT_EQ(r.err, "") << args;
    EXPECT_EQ(r.out, verdicts) << args;  // results stay
  }
  // The audit loads the robot twice (alone, then with the SRDF): each warning still comes once.
  const std::string audit = "audit " + source("robots/arm6/arm6.urdf") + " --srdf " + source("robots/arm6/arm6.srdf") +
                            " --samples 10";
  r = runTool(audit);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(count(r.err, kUpAxis), 1) << r.err;
  r = runTool(audit + " --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_NE(r.out.find("pairs differ from"), std::string::npos) << r.out;
  // Progress lines go too (bench prints one per case).
  const clearway::test::TempDir dir;
  const std::string bench = "bench narrowphase --count 2 --subjects hull16 --out '" + dir.path("bench") + "'";
  r = runTool(bench);
  if (r.err.find("no benchmark suites") == std::string::npos) {  // (a build without FCL has none)
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.err.find("[1/1] narrowphase hull16"), std::string::npos) << r.err;
    r = runTool(bench + " --quiet");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err.find("[1/1]"), std::string::npos) << r.err;
  }
  // Errors are not warnings: --quiet keeps them.
  r = runTool("check /nonexistent/scene.yaml --quiet");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("/nonexistent/scene.yaml"), std::string::npos) << r.err;
}
