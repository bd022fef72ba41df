// The bench suites built without FCL (benchmarks/suites.cpp compiled again here, CLEARWAY_HAVE_FCL unset):
// they measure Clearway alone, name every comparison they cannot make, and never pass off a missing row.
#include "suites.h"

#include "shared_data.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace clearway {
namespace {

TEST(BenchWithoutFcl, NamesTheComparisonsItCannotMake) {
  const std::vector<std::string>& missing = bench::missingComparisons();
  ASSERT_EQ(missing.size(), 5u);
  for (const char* suite : {"narrowphase", "states: fcl", "verdicts: FCL", "motions: fcl", "plan: fcl"})
    EXPECT_TRUE(std::any_of(missing.begin(), missing.end(), [&](const std::string& m) { return m.find(suite) == 0; }))
        << suite;
  bench::SuiteConfig config;
  config.suites = {"narrowphase"};
  EXPECT_TRUE(bench::enumerateCases(config).empty()) << "the narrowphase suite compares with FCL alone";
  std::vector<bench::SuiteRow> rows;
  try {
    bench::runCase({"narrowphase", "hull16", ""}, config, rows);
    FAIL() << "a narrowphase case without FCL must not run";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("FCL"), std::string::npos) << e.what();
  }
}

TEST(BenchWithoutFcl, StatesVerdictsAndMotionsMeasureClearwayAlone) {
  CLEARWAY_SHARED_OR_SKIP(scenes, "scenes");
  bench::SuiteConfig config;
  config.suites = {"states", "verdicts", "motions"};
  config.shared = test::sharedDir();
  config.subjects = {"box_panda"};
  config.count = 10;
  const std::vector<bench::SuiteCase> cases = bench::enumerateCases(config);
  ASSERT_EQ(cases.size(), 6u);  // (each suite: both forms of the problem)
  for (const bench::SuiteCase& c : cases) {
    std::vector<bench::SuiteRow> rows;
    bench::runCase(c, config, rows);
    EXPECT_FALSE(rows.empty()) << c.suite;
    for (const bench::SuiteRow& r : rows) {
      EXPECT_EQ(r.engine, "clearway") << c.suite << " " << r.mode;
      if (r.mode != "sampled")  // (sampling may tunnel; the exact and certified checks never miss)
        EXPECT_EQ(r.misses, 0) << c.suite << " " << r.mode << " " << r.tolerance;
    }
  }
}

}  // namespace
}  // namespace clearway
