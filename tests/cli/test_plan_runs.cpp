// `clearway plan`: times with microseconds, and --runs N, a line per seed and the medians, each run the
// path that `--seed` of its seed plans alone.
#include "cli/tool_run.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace {

using clearway_test::runTool;
using clearway_test::ToolRun;

std::string scene() { return std::string("'") + CLEARWAY_SOURCE_DIR + "/robots/scenes/arm6_wall.yaml'"; }

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

TEST(PlanRuns, TimesHaveMicroseconds) {
  const ToolRun r = runTool("plan " + scene() + " --seed 4 --time 30");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(std::regex_search(r.err, std::regex("solved in [0-9]+\\.[0-9]{6} s, simplified in [0-9]+\\.[0-9]{6} s")))
      << r.err;
}

TEST(PlanRuns, ALinePerSeedAndTheirMedians) {
  const ToolRun r = runTool("plan " + scene() + " --seed 11 --runs 3 --time 30");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<std::string> out = lines(r.out);
  ASSERT_EQ(out.size(), 4u) << r.out;
  EXPECT_EQ(out[0], "# run seed status solve_s simplify_s states length state_checks motion_checks");
  std::vector<double> solve;
  std::vector<std::string> states_and_length;
  for (int i = 1; i <= 3; ++i) {
    std::istringstream row(out[i]);
    int run = 0;
    unsigned long long seed = 0, state_checks = 0, motion_checks = 0;
    std::string status, states, length;
    double solve_s = -1, simplify_s = -1;
    row >> run >> seed >> status >> solve_s >> simplify_s >> states >> length >> state_checks >> motion_checks;
    ASSERT_FALSE(row.fail()) << out[i];
    EXPECT_EQ(run, i);
    EXPECT_EQ(seed, 10u + i);
    EXPECT_EQ(status, "solved");
    EXPECT_GT(solve_s, 0.0);
    EXPECT_GT(simplify_s, 0.0);
    EXPECT_GT(state_checks, 0u);
    EXPECT_GT(motion_checks, 0u);
    solve.push_back(solve_s);
    states_and_length.push_back(states + " states, length " + length);
  }
  std::sort(solve.begin(), solve.end());
  char median[64];
  std::snprintf(median, sizeof median, "median solve %.6f s", solve[1]);
  EXPECT_MENTIONS(r.err, "3 runs (seeds 11 to 13), 3 certified");
  EXPECT_MENTIONS(r.err, median);
  // The second run is the path `--seed 12` plans alone (the same states and length; paths print in full there).
  const ToolRun alone = runTool("plan " + scene() + " --seed 12 --time 30");
  ASSERT_EQ(alone.exit_code, 0) << alone.err;
  EXPECT_MENTIONS(alone.err, states_and_length[1]);
}

TEST(PlanRuns, BadCountsAreUsageErrors) {
  for (const char* bad : {"0", "-2", "x", "1000001"}) {
    const ToolRun r = runTool("plan " + scene() + " --runs " + bad);
    EXPECT_EQ(r.exit_code, 2) << bad;
    EXPECT_MENTIONS(r.err, "--runs: needs a whole number from 1 to 1000000");
  }
}

// A start in collision is the same for every seed: one line, and exit 1.
TEST(PlanRuns, AStartInCollisionEndsTheRuns) {
  const std::string dir = testing::TempDir() + "clearway_runs_" + std::to_string(::getpid());
  const std::string file = dir + ".yaml";
  std::ofstream(file) << "format: 1\nname: floor\nrobot:\n  urdf: " << CLEARWAY_SOURCE_DIR
                      << "/robots/arm6/arm6.urdf\n  srdf: " << CLEARWAY_SOURCE_DIR
                      << "/robots/arm6/arm6.srdf\n  group: [shoulder_pan_joint, shoulder_lift_joint, elbow_joint, "
                         "wrist_1_joint, wrist_2_joint, wrist_3_joint]\nenvironment:\n  obstacles:\n    - name: floor\n"
                         "      box: {size: [1.6, 1.6, 0.03]}\n      pose: {position: [0, 0, -0.025]}\n"
                         "checks: [self, environment, continuous]\nstart: [0, 1.7, 0.5, 0, 0, 0]\ngoal: [0, 0, 0, 0, 0, 0]\n";
  const ToolRun r = runTool("plan '" + file + "' --runs 5 --seed 1");
  std::remove(file.c_str());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(lines(r.out).size(), 2u) << r.out;
  EXPECT_MENTIONS(r.out, "1 1 start_colliding");
  EXPECT_MENTIONS(r.err, "start is in collision");
}

}  // namespace
