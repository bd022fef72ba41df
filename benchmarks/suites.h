#pragma once
// The measurements behind `clearway bench`: what accuracy costs in time, Clearway and FCL side by side
// in one process on the same geometry. Work is cut into cases (a suite on one subject: a shape family or
// a shared problem); a case is measured whole, so every ratio inside it compares like with like, and
// its inputs depend only on the seed and the case, so any shard of the cases measures the same things.
#include <cstdint>
#include <string>
#include <vector>

namespace clearway::bench {

/// What a bench run covers; every field is written into the results so that shards can be matched.
struct SuiteConfig {
  std::vector<std::string> suites;  ///< narrowphase, states, motions, plan (in this order)
  std::string shared;               ///< the folder holding scenes/ (../shared)
  int count = 200;                  ///< pairs per shape family, states or motions per problem
  int problems = 1;                 ///< problems per scene family
  int plan_runs = 5;                ///< planning runs per problem and checker
  double plan_time = 10.0;          ///< seconds per planning run
  std::uint64_t seed = 1;
  std::vector<std::string> subjects;  ///< when not empty: only subjects containing one of these strings
  std::string out;                  ///< the output folder (planning logs go to out/plan/)
};

/// One unit of work: a suite on one subject.
struct SuiteCase {
  std::string suite;
  std::string subject;  ///< a shape family or a problem name
  std::string file;     ///< the problem's scene file ("" for shape families)
};

/// One measured configuration of a case. Every field but ns_per_item is a function of the config and
/// the case alone (planning aside, whose outcomes depend on time).
struct SuiteRow {
  std::string suite, subject, engine, mode;
  double tolerance = 0;     ///< the swept parameter: GJK tolerance, contact distance, resolution (0: none)
  long items = 0;           ///< queries, states, motions or planning runs
  double ns_per_item = 0;   ///< thread CPU time per item (planning: median solve time)
  double work_per_item = 0; ///< GJK iterations, states or steps per motion, solved fraction
  long positives = 0;       ///< items the reference calls colliding (planning: solved runs)
  long misses = 0;          ///< said free where the reference collides (planning: paths that collide)
  long false_alarms = 0;    ///< said colliding where the reference is free (planning: uncertified paths)
  double error = 0;         ///< the plotted error: mean |distance error| (m) or a rate of wrong verdicts
  double max_error = 0;     ///< the worst single error (m for distances; 0/1 for verdicts)
};

/// The known suites, in run order.
const std::vector<std::string>& suiteNames();

/// The comparisons this build cannot make, one line each (FCL was not found when it was built: its rows,
/// and the narrowphase suite, which compares with FCL alone); empty when it makes them all.
const std::vector<std::string>& missingComparisons();

/// Every case of the config, in a fixed order (the case index is the position). Throws
/// std::runtime_error when a suite is unknown or the shared scenes are missing for one that needs them.
std::vector<SuiteCase> enumerateCases(const SuiteConfig& config);

/// Measures one case and appends its rows. Throws std::runtime_error on a scene that does not load.
void runCase(const SuiteCase& c, const SuiteConfig& config, std::vector<SuiteRow>& rows);

}  // namespace clearway::bench
