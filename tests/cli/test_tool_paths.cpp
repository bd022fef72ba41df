// Where the tool finds its data, and --version. The binary in its build tree falls back to the source
// tree (and ../shared); a copy of it elsewhere (as an installed tool is) finds the bundled scene only
// at BIN/../share/clearway and shared data only through --shared or $CLEARWAY_SHARED, and says so.
// scripts/install-check.sh checks the real install.
#include "cli/tool_run.h"
#include "load/robot_files.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace fs = std::filesystem;
using clearway_test::runTool;
using clearway_test::ToolRun;

namespace {


// Runs `tool args` (the tool at any path) as runTool runs the built one.
ToolRun runAt(const std::string& tool, const std::string& args) {
  const std::string stem = testing::TempDir() + "clearway_paths_" + std::to_string(::getpid());
  const int raw = std::system(("'" + tool + "' " + args + " >'" + stem + ".out' 2>'" + stem + ".err'").c_str());
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, clearway_test::slurp(stem + ".out"), clearway_test::slurp(stem + ".err")};
}

// Sets an environment variable for one test (unset when value is null) and restores it after.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old, had_ = true;
    value ? ::setenv(name, value, 1) : ::unsetenv(name);
  }
  ~ScopedEnv() { had_ ? ::setenv(name_.c_str(), old_.c_str(), 1) : ::unsetenv(name_.c_str()); }

 private:
  std::string name_, old_;
  bool had_ = false;
};

// A prefix P with a copy of the built tool in P/bin (it still finds its libraries: the build tree's RPATH).
std::string copyToolTo(const std::string& prefix) {
  fs::create_directories(prefix + "/bin");
  fs::copy_file(CLEARWAY_TOOL_PATH, prefix + "/bin/clearway");
  fs::permissions(prefix + "/bin/clearway", fs::perms::owner_exec, fs::perm_options::add);
  return prefix + "/bin/clearway";
}

}  // namespace

TEST(ToolPaths, Version) {
  const ToolRun r = runTool("--version");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "clearway " CLEARWAY_VERSION "\n");
  EXPECT_MENTIONS(runTool("--help").out, "--version");
}

TEST(ToolPaths, ACopyOutsideTheBuildTreeUsesOnlyItsPrefix) {
  const ScopedEnv no_shared("CLEARWAY_SHARED", nullptr);
  const clearway::test::TempDir dir;
  const std::string prefix = dir.path("prefix");
  const std::string tool = copyToolTo(prefix);
  // No share/clearway beside it: no default scene, named with where it was looked for. The source tree
  // (compiled in for the build-tree binary) is not used.
  ToolRun r = runAt(tool, "plan --time 1");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "clearway plan: no SCENE given");
  EXPECT_MENTIONS(r.err, prefix + "/share/clearway/robots/scenes/arm6_wall.yaml does not exist");
  EXPECT_EQ(r.err.find(CLEARWAY_SOURCE_DIR), std::string::npos) << r.err;
  // No shared data: not ../shared beside the source, but a message saying how to give it.
  r = runAt(tool, "bench states --count 1 --out '" + prefix + "/bench'");
  EXPECT_EQ(r.exit_code, 2);
  if (r.err.find("no benchmark suites") == std::string::npos) {  // (a build without FCL has no suites)
    EXPECT_MENTIONS(r.err, "needs the shared scenes (clearway bench --shared DIR or $CLEARWAY_SHARED)");
    EXPECT_MENTIONS(r.err, "no shared data folder was given");
  }
  // With the bundled robots in P/share/clearway, as cmake --install puts them, it plans on that scene.
  fs::create_directories(prefix + "/share/clearway");
  fs::copy(std::string(CLEARWAY_SOURCE_DIR) + "/robots", prefix + "/share/clearway/robots", fs::copy_options::recursive);
  r = runAt(tool, "plan --seed 1 --time 30");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("path ", 0), 0u) << r.out;
  EXPECT_MENTIONS(r.err, prefix + "/share/clearway/robots/scenes/arm6_wall.yaml");
}

TEST(ToolPaths, BenchSharedDataFromTheEnvironment) {
  // $CLEARWAY_SHARED is where bench looks; a folder without scenes/ is named.
  const ScopedEnv shared("CLEARWAY_SHARED", "/nonexistent-clearway-shared");
  const clearway::test::TempDir dir;
  const ToolRun r = runTool("bench states --count 1 --out '" + dir.path("bench") + "'");
  EXPECT_EQ(r.exit_code, 2);
  if (r.err.find("no benchmark suites") == std::string::npos)
    EXPECT_MENTIONS(r.err, "/nonexistent-clearway-shared/scenes is not a folder");
}
