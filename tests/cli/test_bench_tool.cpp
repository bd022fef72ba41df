// `clearway bench`: shards merge into exactly the unsharded result (every field but the measured time),
// its CSV and OMPL logs parse back, accuracy moves the right way with the tolerance, and bad input
// (a shard out of range, a missing or repeated shard, a truncated file, mixed configurations) is a
// clear error.
#include "cli/tool_run.h"
#include "shared_data.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace clearway_test;

namespace {

#define EXPECT_MENTIONS(text, key) EXPECT_NE((text).find(key), std::string::npos) << "\"" << (text) << "\" should name " << (key)

// The shared scenes when present; when CI=true they must be (the tests that use them fail otherwise).
bool haveSharedScenes() { return fs::is_directory(clearway::test::sharedDir() + "/scenes") || clearway::test::sharedDataRequired(); }
std::string sharedArg() { return " --shared '" + clearway::test::sharedDir() + "'"; }

std::string tempDir(const std::string& name) {
  const std::string dir = testing::TempDir() + "clearway_bench_" + name + "_" + std::to_string(::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::vector<std::string> fields(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream in(line);
  for (std::string f; std::getline(in, f, ',');) out.push_back(f);
  return out;
}

// The data rows of a results.csv, the measured time (field 8) blanked.
std::vector<std::string> rowsWithoutTime(const std::string& file) {
  std::ifstream in(file);
  std::vector<std::string> rows;
  bool header = false;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    if (!header) {
      header = true;
      continue;
    }
    std::vector<std::string> f = fields(line);
    EXPECT_EQ(f.size(), 14u) << line;
    if (f.size() > 7) f[7] = "";
    std::string joined;
    for (const std::string& x : f) joined += x + ",";
    rows.push_back(joined);
  }
  return rows;
}

// The bench arguments of the shard tests: the shape families always, two shared problems when present.
std::string shardArgs() {
  return haveSharedScenes() ? "narrowphase states --count 12 --subjects hull16,box-capsule,box_panda,cage_ur5 --seed 7" + sharedArg()
                            : "narrowphase --count 12 --seed 7";
}

}  // namespace

TEST(BenchTool, ShardsMergeIntoTheUnshardedRun) {
  if (!haveSharedScenes()) std::cerr << "[ note ] " << clearway::test::sharedMissing("scenes") << ": narrowphase only\n";
  const std::string dir = tempDir("shards");
  ToolRun r = runTool("bench " + shardArgs() + " --out '" + dir + "/all'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_MENTIONS(r.out, "FCL/x");
  for (int i = 0; i < 3; ++i) {
    r = runTool("bench " + shardArgs() + " --shard " + std::to_string(i) + "/3 --out '" + dir + "/s" + std::to_string(i) + "'");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_FALSE(fs::exists(dir + "/s" + std::to_string(i) + "/summary.csv")) << "a shard writes results.csv only";
  }
  // The shards in any order.
  r = runTool("bench merge --out '" + dir + "/merged' '" + dir + "/s2' '" + dir + "/s0' '" + dir + "/s1'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<std::string> all = rowsWithoutTime(dir + "/all/results.csv");
  const std::vector<std::string> merged = rowsWithoutTime(dir + "/merged/results.csv");
  EXPECT_GE(all.size(), haveSharedScenes() ? 39u : 36u);  // 18 distance rows per family, 3 per problem
  EXPECT_EQ(all, merged);
  // The same derived files as an unsharded run.
  for (const char* f : {"summary.csv", "table.txt", "plots.gp"}) {
    EXPECT_TRUE(fs::exists(dir + "/merged/" + f)) << f;
    EXPECT_TRUE(fs::exists(dir + "/all/" + f)) << f;
  }
  if (std::system("command -v gnuplot >/dev/null 2>&1") == 0) {
    EXPECT_GT(fs::file_size(dir + "/merged/narrowphase.png"), 1000u);
    if (haveSharedScenes()) EXPECT_GT(fs::file_size(dir + "/merged/states.png"), 1000u);
  }
  fs::remove_all(dir);
}

TEST(BenchTool, ResultsParseBackAndAccuracyFollowsTheTolerance) {
  const std::string dir = tempDir("parse");
  const ToolRun r = runTool("bench narrowphase --count 30 --subjects hull16 --out '" + dir + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(dir + "/summary.csv");
  std::string line;
  std::getline(in, line);
  ASSERT_EQ(fields(line).size(), 13u) << line;
  std::map<std::string, std::map<double, double>> worst;  // engine → tolerance → max error
  int rows = 0;
  while (std::getline(in, line)) {
    const std::vector<std::string> f = fields(line);
    ASSERT_GE(f.size(), 12u) << line;
    ++rows;
    EXPECT_EQ(f[0], "narrowphase");
    EXPECT_EQ(std::stod(f[4]), 30.0) << line;
    EXPECT_GT(std::stod(f[5]), 0.0) << line;
    worst[f[1]][std::stod(f[3])] = std::stod(f[11]);
  }
  EXPECT_EQ(rows, 18);  // 6 tolerances × (Clearway, FCL indep, FCL libccd)
  // Clearway's tolerance is a relative bound on the distance error: the worst error stays under it
  // (distances here are at most a few metres) and shrinks as the tolerance does.
  ASSERT_EQ(worst["clearway"].size(), 6u);
  for (const auto& [tol, err] : worst["clearway"]) EXPECT_LE(err, tol * 10.0) << "tolerance " << tol;
  EXPECT_LT(worst["clearway"].begin()->second, std::prev(worst["clearway"].end())->second);
  fs::remove_all(dir);
}

TEST(BenchTool, PlanningWritesOmplBenchmarkLogs) {
  CLEARWAY_REQUIRE_SHARED("scenes");
  const std::string dir = tempDir("plan");
  const ToolRun r = runTool("bench plan --subjects box_panda --plan-runs 2 --plan-time 20" + sharedArg() + " --out '" + dir + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  int logs = 0;
  for (const auto& entry : fs::directory_iterator(dir + "/plan")) {
    ++logs;
    // OMPL's benchmark log, as ompl_benchmark_statistics.py reads it: the planner block ends with the
    // run-property names, "N runs", N lines of as many "; "-separated values, and ".".
    std::ifstream in(entry.path());
    std::vector<std::string> lines;
    for (std::string l; std::getline(in, l);) lines.push_back(l);
    ASSERT_GT(lines.size(), 10u);
    EXPECT_EQ(lines[1].rfind("Experiment ", 0), 0u) << entry.path();
    std::size_t k = 0;
    while (k < lines.size() && lines[k].find(" properties for each run") == std::string::npos) ++k;
    ASSERT_LT(k, lines.size()) << entry.path();
    const int properties = std::stoi(lines[k]);
    std::vector<std::string> names(lines.begin() + k + 1, lines.begin() + k + 1 + properties);
    EXPECT_NE(std::find(names.begin(), names.end(), "collides_dense BOOLEAN"), names.end());
    EXPECT_NE(std::find(names.begin(), names.end(), "certified BOOLEAN"), names.end());
    k += 1 + properties;
    ASSERT_EQ(lines[k], "2 runs") << entry.path();
    for (int run = 0; run < 2; ++run) {
      const std::string& values = lines[k + 1 + run];
      EXPECT_EQ(static_cast<int>(std::count(values.begin(), values.end(), ';')), properties) << values;
    }
    EXPECT_EQ(lines[k + 3], ".");
  }
  EXPECT_EQ(logs, 3);  // certified, sampled over Clearway, sampled over FCL
  // The certified checker's paths re-check as free under the dense reference.
  std::ifstream in(dir + "/results.csv");
  int plan_rows = 0;
  for (std::string line; std::getline(in, line);) {
    const std::vector<std::string> f = fields(line);
    if (f.size() != 14 || f[0] != "plan") continue;
    ++plan_rows;
    if (f[4] == "certified") {
      EXPECT_EQ(f[9], "2") << "both runs solve box_panda within 20 s";
      EXPECT_EQ(f[10], "0") << "a certified path collides";
    }
  }
  EXPECT_EQ(plan_rows, 3);
  fs::remove_all(dir);
}

TEST(BenchTool, BadInputIsAClearError) {
  const std::string dir = tempDir("bad");
  ToolRun r = runTool("bench narrowphase --shard 3/3 --out '" + dir + "/x'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "--shard: '3/3'");
  EXPECT_EQ(runTool("bench narrowphase --shard 1 --out '" + dir + "/x'").exit_code, 2);
  EXPECT_EQ(runTool("bench narrowphase --shard -1/2 --out '" + dir + "/x'").exit_code, 2);
  EXPECT_EQ(runTool("bench narrowphase --count 0").exit_code, 2);
  r = runTool("bench teleport");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "teleport");
  EXPECT_EQ(runTool("bench --frobnicate").exit_code, 2);
  EXPECT_EQ(runTool("bench --help").exit_code, 0);

  // Two shards of one configuration, one of another.
  const std::string args = "narrowphase --subjects box-capsule,cylinder-cone --count 5";
  ASSERT_EQ(runTool("bench " + args + " --shard 0/2 --out '" + dir + "/a0'").exit_code, 0);
  ASSERT_EQ(runTool("bench " + args + " --shard 1/2 --out '" + dir + "/a1'").exit_code, 0);
  ASSERT_EQ(runTool("bench " + args + " --seed 9 --shard 1/2 --out '" + dir + "/b1'").exit_code, 0);
  r = runTool("bench merge --out '" + dir + "/m' '" + dir + "/a0'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "shard 1/2 is missing");
  r = runTool("bench merge --out '" + dir + "/m' '" + dir + "/a0' '" + dir + "/a0'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "given twice");
  r = runTool("bench merge --out '" + dir + "/m' '" + dir + "/a0' '" + dir + "/b1'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "another configuration");
  r = runTool("bench merge --out '" + dir + "/m' '" + dir + "/nowhere'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "nowhere/results.csv");
  EXPECT_EQ(runTool("bench merge --out '" + dir + "/m'").exit_code, 2);
  // A truncated shard: its last row cut short, then its header lines gone.
  std::string text = slurp(dir + "/a1/results.csv");
  std::ofstream(dir + "/a1/results.csv") << text.substr(0, text.size() - 12);
  r = runTool("bench merge --out '" + dir + "/m' '" + dir + "/a0' '" + dir + "/a1'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "a1/results.csv:");
  std::ofstream(dir + "/a1/results.csv") << text.substr(0, 40);
  r = runTool("bench merge --out '" + dir + "/m' '" + dir + "/a0' '" + dir + "/a1'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "truncated");
  // A merge refuses an unsharded result.
  ASSERT_EQ(runTool("bench " + args + " --out '" + dir + "/whole'").exit_code, 0);
  r = runTool("bench merge --out '" + dir + "/m' '" + dir + "/whole'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "not a shard");
  fs::remove_all(dir);
}
