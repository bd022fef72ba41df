// The tool's one argument parser (CLI11), case by case: --opt=value and --opt value, the deprecated
// spellings (one warning each, --quiet silences them), - for stdin and stdout, --help and --version for
// every command, the exit codes of exit_codes.h, and bad arguments named with their reason.
#include "cli/tool_run.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

using clearway_test::runTool;
using clearway_test::ToolRun;

namespace {


std::string source(const std::string& rel) { return "'" + std::string(CLEARWAY_SOURCE_DIR) + "/" + rel + "'"; }
const std::string kScene = source("robots/scenes/arm6_wall.yaml");
const std::string kUrdf = source("robots/arm6/arm6.urdf");
const std::string kSrdf = source("robots/arm6/arm6.srdf");

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (auto p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

// A file in the test's temporary folder, named after this process (CTest runs tests in parallel).
std::string writeTemp(const std::string& name, const std::string& text) {
  const std::string path = testing::TempDir() + "clearway_args_" + std::to_string(::getpid()) + "_" + name;
  std::ofstream(path) << text;
  return path;
}

const char* const kStates = "0 -0.6 -1.2 -1.34 0 0\n0 1.7 0.5 0 0 0\n";            // free, into the floor
const char* const kMotions = "0 -0.6 -1.2 -1.34 0 0   0 0.6 1.2 1.34 0 0\n";  // through the wall

}  // namespace

TEST(Arguments, OptionEqualsValueIsTheSameAsTwoWords) {
  const std::string states = writeTemp("states.txt", kStates);
  const ToolRun spaced = runTool("check " + kScene + " --states '" + states + "' --geometry hull");
  const ToolRun joined = runTool("check " + kScene + " --states='" + states + "' --geometry=hull");
  ASSERT_EQ(spaced.exit_code, 0) << spaced.err;
  EXPECT_EQ(joined.exit_code, 0) << joined.err;
  EXPECT_EQ(joined.out, spaced.out);
  // Given twice, the last value counts (scripts append "$@" after their defaults).
  const ToolRun twice = runTool("check " + kScene + " --states '" + states + "' --geometry mesh --geometry hull");
  EXPECT_EQ(twice.exit_code, 0) << twice.err;
  EXPECT_EQ(twice.out, spaced.out);
  const std::string motions = writeTemp("motions.txt", kMotions);
  const ToolRun m = runTool("motion " + kScene + " --motions='" + motions + "' --motion=sampled:0.01 --geometry=mesh");
  EXPECT_EQ(m.exit_code, 0) << m.err;
  EXPECT_EQ(m.out.rfind("collision ", 0), 0u) << m.out;
  const ToolRun a = runTool("audit " + kUrdf + " --samples=10 --threads=1 --seed=4 --quiet");
  EXPECT_EQ(a.exit_code, 0) << a.err;
  EXPECT_MENTIONS(a.out, "pairs");
}

TEST(Arguments, OldSpellingsWorkWithOneWarning) {
  // check and plan: --mode was the geometry; motion: --mode was the motion mode.
  const ToolRun now = runTool("check " + kScene + " --geometry hull --quiet");
  ToolRun old = runTool("check " + kScene + " --mode hull --mode hull");
  EXPECT_EQ(old.exit_code, 0) << old.err;
  EXPECT_EQ(old.out, now.out);
  EXPECT_EQ(count(old.err, "--mode is deprecated; use --geometry"), 1) << old.err;
  old = runTool("check " + kScene + " --mode hull --quiet");
  EXPECT_EQ(old.err, "");
  const ToolRun cast = runTool("motion " + kScene + " --motion cast");
  old = runTool("motion " + kScene + " --mode cast");
  EXPECT_EQ(old.exit_code, 0) << old.err;
  EXPECT_EQ(old.out, cast.out);
  EXPECT_EQ(count(old.err, "--mode is deprecated; use --motion"), 1) << old.err;
  EXPECT_EQ(count(cast.err, "deprecated"), 0) << cast.err;
  old = runTool("motion " + kScene + " --mode warp");
  EXPECT_EQ(old.exit_code, 2);
  EXPECT_MENTIONS(old.err, "unknown motion mode 'warp'");
  old = runTool("plan " + kScene + " --mode fuzzy");
  EXPECT_EQ(old.exit_code, 2);
  EXPECT_MENTIONS(old.err, "--mode: unknown geometry 'fuzzy' (mesh or hull)");
}

TEST(Arguments, DashIsStdinAndStdout) {
  const std::string states = writeTemp("stdin_states.txt", kStates);
  ToolRun r = runTool("check " + kScene + " --states - <'" + states + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("free\ncollision ", 0), 0u) << r.out;
  const std::string motions = writeTemp("stdin_motions.txt", kMotions);
  r = runTool("motion " + kScene + " --motions=- <'" + motions + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("collision ", 0), 0u) << r.out;
  r = runTool("query - <" + source("robots/demo/queries.jsonl"));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(count(r.out, "\n"), 5);
  r = runTool("audit " + kUrdf + " --srdf " + kSrdf + " --samples 10 --srdf-out -");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("<?xml", 0), 0u) << r.out.substr(0, 200);
  EXPECT_MENTIONS(r.err, "pairs differ");  // the report goes to stderr beside it
  // A scene from stdin: its relative paths start at the working directory (absolute here).
  std::ifstream in(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/arm6_wall.yaml");
  std::string yaml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (std::size_t p; (p = yaml.find(": ../arm6/")) != std::string::npos;)
    yaml.replace(p, 10, std::string(": ") + CLEARWAY_SOURCE_DIR + "/robots/arm6/");
  const std::string scene = writeTemp("stdin_scene.yaml", yaml);
  r = runTool("check - <'" + scene + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, runTool("check " + kScene).out);
  r = runTool("motion - --motion sampled:0.01 <'" + scene + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("start -> goal: collision", 0), 0u) << r.out;
  r = runTool("plan - --seed 3 --time 30 <'" + scene + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("path ", 0), 0u) << r.out;
  r = runTool("check - --states - <'" + scene + "'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "cannot both be -");
  // A folder is not an input file, - or not.
  r = runTool("check " + kScene + " --states '" + testing::TempDir() + "'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "is a directory");
}

TEST(Arguments, HelpAndVersionForEveryCommand) {
  for (const char* command : {"plan", "check", "motion", "audit", "query", "bench"}) {
    ToolRun r = runTool(std::string(command) + " --help");
    EXPECT_EQ(r.exit_code, 0) << command << ": " << r.err;
    EXPECT_MENTIONS(r.out, "Exit status");
    EXPECT_MENTIONS(r.out, std::string("clearway ") + command);
    if (std::string(command) != "bench") EXPECT_MENTIONS(r.out, "docs/");
    r = runTool(std::string(command) + " --version");
    EXPECT_EQ(r.exit_code, 0) << command << ": " << r.err;
    EXPECT_EQ(r.out, "clearway " CLEARWAY_VERSION "\n") << command;
  }
  ToolRun r = runTool("bench merge --help");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_MENTIONS(r.out, "SHARD_DIR");
  r = runTool("--help");
  EXPECT_MENTIONS(r.out, "docs/query-format.md");
  EXPECT_MENTIONS(r.out, "docs/scene-format.md");
  EXPECT_MENTIONS(r.out, "Exit status: 0 success; 1");
  // The formats --help points to are in the repository.
  for (const char* doc : {"docs/query-format.md", "docs/scene-format.md"})
    EXPECT_TRUE(std::ifstream(std::string(CLEARWAY_SOURCE_DIR) + "/" + doc).good()) << doc;
}

TEST(Arguments, ExitCodes) {
  const std::string states = writeTemp("exit_states.txt", std::string(kStates) + "0 1 x\n");
  EXPECT_EQ(runTool("check " + kScene + " --states '" + states + "'").exit_code, 1);  // a bad line
  EXPECT_EQ(runTool("check " + kScene).exit_code, 0);
  EXPECT_EQ(runTool("check").exit_code, 2);  // usage
  EXPECT_EQ(runTool("check /nonexistent/scene.yaml").exit_code, 2);
  const ToolRun none = runTool("");
  EXPECT_EQ(none.exit_code, 2);
  EXPECT_MENTIONS(none.err, "plan");  // the usage, on stderr
}

TEST(Arguments, BadArgumentsNameTheOptionAndTheReason) {
  struct Case {
    std::string args, says;
  };
  const Case cases[] = {
      {"plan " + kScene + " --time=abc", "--time: needs a number > 0 and <= 1e+06, got 'abc'"},
      // OMPL's deadline overflowed: no path at once.
      {"plan " + kScene + " --time 7.5e9", "--time: needs a number > 0 and <= 1e+06, got '7.5e9'"},
      {"plan " + kScene + " --time -1", "--time"},
      {"plan " + kScene + " --planner Teleport", "--planner: unknown planner 'Teleport'"},
      {"check " + kScene + " --geometry fuzzy", "--geometry: unknown geometry 'fuzzy' (mesh or hull)"},
      {"motion " + kScene + " --motion sampled:0", "--motion: sampled:RES needs a resolution > 0, got '0'"},
      {"check " + kScene + " --frobnicate", "--frobnicate"},
      {"check " + kScene + " --states", "--states"},
      {"check " + kScene + " --package-path /nonexistent/folder", "/nonexistent/folder: folder not found"},
      {"audit " + kUrdf + " --samples 0", "--samples: needs a whole number from 1 to 100000000, got '0'"},
      // An empty report name wrote nothing and exited 0.
      {"audit " + kUrdf + " --samples 10 --report ''", "--report: needs a file name, got ''"},
      {"audit " + kUrdf + " --samples 10 --srdf-out ''", "--srdf-out: needs a file name, got ''"},
      {"bench --count=x", "--count: needs a whole number"},
      {"bench --shard 2/2", "--shard: '2/2'"},
      {"query a b", "b"},
      {"frobnicate", "frobnicate"},
  };
  for (const Case& c : cases) {
    const ToolRun r = runTool(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args;
    EXPECT_MENTIONS(r.err, c.says);
    EXPECT_MENTIONS(r.err, "--help");  // where the usage is
  }
}

TEST(Arguments, OneSeedParserForEveryCommand) {
  for (const std::string& args : {"plan " + kScene, "audit " + kUrdf, std::string("bench narrowphase")})
    for (const char* seed : {"-1", "1.5", "x", "18446744073709551616"}) {
      const ToolRun r = runTool(args + " --seed " + seed);
      EXPECT_EQ(r.exit_code, 2) << args << " --seed " << seed;
      EXPECT_MENTIONS(r.err, std::string("--seed: needs a whole number from 0 to 2^64 - 1, got '") + seed + "'");
    }
  // The largest seed is a seed.
  const ToolRun r = runTool("audit " + kUrdf + " --samples 10 --quiet --seed 18446744073709551615");
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

// A path reads back as printed (17 digits): a goal on a joint limit is printed on it, not past it, and a
// start a hair past a limit (within the tolerance check accepts) is planned from the limit, not refused.
TEST(Arguments, PlannedPathsReadBackExactly) {
  const std::string scene = writeTemp("limit.yaml",
      "format: 1\nname: limit\nrobot:\n  urdf: " + std::string(CLEARWAY_SOURCE_DIR) +
      "/robots/planar_arm/planar_arm.urdf\n  group: [shoulder, elbow]\nenvironment:\n  obstacles: []\n"
      "checks: [self, environment]\nstart: [0.3, -2.5000000000001]\ngoal: [1.9, 2.5]\n");
  const ToolRun r = runTool("plan '" + scene + "' --seed 1 --time 5 --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::istringstream out(r.out);
  std::string word;
  std::size_t n = 0;
  out >> word >> n;
  ASSERT_EQ(word, "path");
  ASSERT_GE(n, 2u);
  std::vector<std::string> lines;
  std::string line;
  std::getline(out, line);
  while (std::getline(out, line)) lines.push_back(line);
  ASSERT_EQ(lines.size(), n);
  EXPECT_EQ(lines.front(), "0.29999999999999999 -2.5");
  EXPECT_EQ(lines.back(), "1.8999999999999999 2.5");
  const std::string path = writeTemp("limit_path.txt", lines.front() + "\n" + lines.back() + "\n" + lines[1] + "\n");
  const ToolRun check = runTool("check '" + scene + "' --states '" + path + "'");
  EXPECT_EQ(check.exit_code, 0) << check.err;
  EXPECT_EQ(count(check.out, "free"), 3) << check.out;
  // check names a state past the tolerance with every digit.
  const std::string past = writeTemp("past.txt", "0 2.5000001\n");
  const ToolRun refused = runTool("check '" + scene + "' --states '" + past + "'");
  EXPECT_MENTIONS(refused.out + refused.err, "= 2.5000001 is outside [-2.5, 2.5]");
}

// The scene's own start and goal, when no valid state: check and motion say "error" and exit 1, as for a
// line of --states or --motions (they exited 0).
TEST(Arguments, AStartOrGoalOutOfBoundsExitsOne) {
  const std::string scene =
      writeTemp("bounds.yaml",
                "format: 1\nname: bounds\nrobot:\n  urdf: " + std::string(CLEARWAY_SOURCE_DIR) +
                    "/robots/planar_arm/planar_arm.urdf\n  group: [shoulder, elbow]\nenvironment:\n  obstacles: []\n"
                    "checks: [self, environment]\nstart: [0.3, 0]\ngoal: [1.9, 3]\n");
  const ToolRun check = runTool("check '" + scene + "'");
  EXPECT_EQ(check.exit_code, 1) << check.out << check.err;
  EXPECT_MENTIONS(check.out, "start: free");
  EXPECT_MENTIONS(check.out, "goal: error state[1] (elbow) = 3 is outside [-2.5, 2.5]");
  const ToolRun motion = runTool("motion '" + scene + "'");
  EXPECT_EQ(motion.exit_code, 1) << motion.out << motion.err;
  EXPECT_MENTIONS(motion.out, "start -> goal: error state[1] (elbow) = 3 is outside [-2.5, 2.5]");
}

// Input that cannot be read to its end (/dev/zero: no end of line, ever) stops check and motion with an
// error naming the file, exit 2: they stopped early and exited 0, as if every line had run.
TEST(Arguments, UnreadableStatesAndMotionsFail) {
  for (const char* command : {"check", "motion"}) {
    const std::string option = std::string(command) == "check" ? " --states " : " --motions ";
    const ToolRun r = runTool(std::string(command) + " " + kScene + option + "/dev/zero");
    EXPECT_EQ(r.exit_code, 2) << command;
    EXPECT_MENTIONS(r.err, "/dev/zero: a line longer than 16777216 bytes");
  }
  // A last line without a newline still runs.
  const std::string states = writeTemp("no_newline.txt", "0 -0.6 -1.2 -1.34 0 0");
  const ToolRun r = runTool("check " + kScene + " --states '" + states + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "free\n");
}
