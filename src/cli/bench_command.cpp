// `clearway bench`: runs the suites of benchmarks/suites.h, case by case, and writes what accuracy costs
// in time: results.csv (one row per case and configuration), summary.csv and a table (one row per
// configuration over all cases), gnuplot plots (PNG) and OMPL benchmark logs for planning.
//
// Sharding: `--shard I/N` runs the cases whose index is I modulo N and writes results.csv only;
// `clearway bench merge` checks that shards 0 … N−1 of one configuration are all there, each once, and
// writes the same files an unsharded run writes. Rows are copied verbatim and ordered by case, so a
// merged results.csv equals an unsharded one except for the measured times.
#include "bench_results.h"
#include "commands.h"
#include "data_paths.h"
#include "exit_codes.h"
#include "gnuplot_text.h"
#include "scene_commands.h"

#include "suites.h"  // (the clearway_bench_suites library)

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace clearway::cli {
namespace {

namespace fs = std::filesystem;

const char* const kBenchHelp =
    "SUITE: narrowphase (GJK distance by tolerance, Clearway and FCL's two solvers), states (one state:\n"
    "exact meshes, convex hulls, FCL OBBRSS; mesh-batch: 64 states per call), verdicts (the same states through\n"
    "every path to a verdict: one per call with and without the clearance grid,\n"
    "64 per call with the lanes forced to each SIMD target, judged against FCL; a state where they differ fails\n"
    "the case), motions (certified by contact distance, OMPL's sampling by\n"
    "resolution over Clearway and over FCL, against a dense reference), plan (RRTConnect with each\n"
    "checker: one OMPL benchmark log per problem in DIR/plan, the checkers as planners side by side for\n"
    "Planner Arena), or all. Default: narrowphase states motions. The scene suites take both forms of each\n"
    "problem: its primitives (NAME_0001) and its OctoMap (NAME_0001.octomap, a family of its own: NAME.octomap).\n"
    "Writes DIR/results.csv; unsharded runs and merges also DIR/summary.csv, DIR/table.txt (printed; it\n"
    "ends with each problem family's state, motion and planning figures beside issue 20's targets),\n"
    "DIR/plots.gp and its PNG plots (when gnuplot is installed). --shard I/N runs the cases with index I\n"
    "modulo N; `clearway bench merge --out DIR SHARD_DIR...` combines shards 0..N-1.\n"
    "Exit status: 0 when every case ran, 1 when a case failed, 2 on a usage error, missing shared data or\n"
    "an output that cannot be written.\n";

// ---- Summary, table and plots ---------------------------------------------------------------------------

struct Summary {
  std::string suite, engine, mode;
  double tolerance = 0, items = 0, ns_total = 0, work_total = 0, positives = 0, misses = 0, false_alarms = 0,
         error_weighted = 0, error_weight = 0, max_error = 0;
  double ns() const { return items > 0 ? ns_total / items : 0.0; }
  double work() const { return items > 0 ? work_total / items : 0.0; }
  double error() const { return error_weight > 0 ? error_weighted / error_weight : 0.0; }
  std::string key() const { return engine + " " + mode; }
};

std::vector<Summary> summarize(const std::vector<BenchRow>& rows) {
  std::vector<Summary> out;
  for (const BenchRow& r : rows) {
    auto it = std::find_if(out.begin(), out.end(), [&](const Summary& s) {
      return s.suite == r.suite && s.engine == r.engine && s.mode == r.mode && s.tolerance == r.tolerance;
    });
    if (it == out.end()) {
      out.push_back({r.suite, r.engine, r.mode, r.tolerance});
      it = out.end() - 1;
    }
    it->items += r.items;
    it->ns_total += r.ns * r.items;
    it->work_total += r.work * r.items;
    it->positives += r.positives;
    it->misses += r.misses;
    it->false_alarms += r.false_alarms;
    // Distance errors average over the pairs that gave one; planning rates over the solved runs.
    const double weight = r.suite == "narrowphase" ? r.items - r.misses : r.suite == "plan" ? r.positives : r.items;
    it->error_weighted += r.error * weight;
    it->error_weight += weight;
    it->max_error = std::max(it->max_error, r.max_error);
  }
  return out;
}

// FCL's time for the same job, to divide by: the same mode and tolerance (the faster FCL solver), else
// what OMPL users run by default (FCL sampled at 1%), else FCL's only mode in the suite.
double fclPeerNs(const Summary& s, const std::vector<Summary>& all) {
  double same = 0, fallback = 0;
  for (const Summary& f : all) {
    if (f.suite != s.suite || f.engine.rfind("fcl", 0) != 0 || f.ns() <= 0) continue;
    if (f.mode == s.mode && f.tolerance == s.tolerance && (same == 0 || f.ns() < same)) same = f.ns();
    if ((f.tolerance == 0.01 || f.tolerance == 0) && fallback == 0) fallback = f.ns();
  }
  return same > 0 ? same : fallback;
}

std::string fmt(const char* f, double x) {
  char b[64];
  std::snprintf(b, sizeof b, f, x);
  return b;
}

std::string table(const std::vector<Summary>& all) {
  std::ostringstream t;
  char line[256];
  std::snprintf(line, sizeof line, "%-12s %-11s %-12s %9s %7s %12s %9s %6s %6s %6s %11s %11s %8s\n", "suite", "engine",
                "mode", "tolerance", "items", "ns/item", "work", "refpos", "missed", "extra", "error", "max_error",
                "FCL/x");
  t << line;
  for (const Summary& s : all) {
    const double peer = s.engine.rfind("fcl", 0) == 0 ? 0.0 : fclPeerNs(s, all);
    std::snprintf(line, sizeof line, "%-12s %-11s %-12s %9.3g %7.0f %12.1f %9.2f %6.0f %6.0f %6.0f %11.3g %11.3g %8s\n",
                  s.suite.c_str(), s.engine.c_str(), s.mode.c_str(), s.tolerance, s.items, s.ns(), s.work(), s.positives,
                  s.misses, s.false_alarms, s.error(), s.max_error, peer > 0 && s.ns() > 0 ? fmt("%.2f", peer / s.ns()).c_str() : "-");
    t << line;
  }
  t << "work: GJK iterations per query (Clearway; FCL does not report them), states or advancement steps per motion, solved fraction of planning runs.\n"
       "refpos: items the reference calls colliding (planning: solved runs); missed: said free where the\n"
       "reference collides (planning: solved paths a 1e-3 rad sampling finds colliding); extra: said colliding\n"
       "where the reference is free (planning: paths the certified check does not pass). error: mean |distance\n"
       "error| in m (narrowphase), wrong-verdict rate (states), missed-collision rate (motions, planning).\n"
       "FCL/x: FCL's time for the same job divided by this row's (above 1: this row is faster).\n";
  return t.str();
}

// Issue 20's figures per problem family (a problem's name without its number), beside its targets: the
// exact state check one per call and batched, a certified motion at a 1 mm contact distance, and RRTConnect
// with the certified validator, each against FCL in the same run (states: OBBRSS; motions and planning:
// OMPL's 1% sampling over FCL). A family's ratio is FCL's total time over ours on the same items.
std::string targets(const std::vector<BenchRow>& rows) {
  struct Family {
    double one = 0, one_n = 0, batch = 0, batch_n = 0, fcl_state = 0, fcl_state_n = 0, motion = 0, motion_n = 0,
           fcl_motion = 0, fcl_motion_n = 0, plan = 0, fcl_plan = 0, e2e = 0, fcl_e2e = 0;
  };
  std::vector<std::pair<std::string, Family>> families;
  for (const BenchRow& r : rows) {
    if (r.suite != "states" && r.suite != "motions" && r.suite != "plan") continue;
    // (bookshelf_small_panda_0001 and bookshelf_small_panda_0001.octomap: two families, by form.)
    const std::size_t cut = r.subject.find_last_of('_');
    const bool map = r.subject.size() > 8 && r.subject.compare(r.subject.size() - 8, 8, ".octomap") == 0;
    const std::string name =
        (cut == std::string::npos ? r.subject : r.subject.substr(0, cut)) + (map ? ".octomap" : "");
    auto it = std::find_if(families.begin(), families.end(), [&](const auto& f) { return f.first == name; });
    if (it == families.end()) it = families.insert(families.end(), {name, Family{}});
    Family& f = it->second;
    const bool fcl = r.engine.rfind("fcl", 0) == 0;
    const auto add = [&](double& total, double& items) { total += r.ns * r.items, items += r.items; };
    if (r.suite == "states" && r.engine == "clearway" && r.mode == "mesh") add(f.one, f.one_n);
    if (r.suite == "states" && r.engine == "clearway" && r.mode == "mesh-batch") add(f.batch, f.batch_n);
    if (r.suite == "states" && fcl) add(f.fcl_state, f.fcl_state_n);
    if (r.suite == "motions" && r.engine == "clearway" && r.mode == "certified" && r.tolerance == 1e-3) add(f.motion, f.motion_n);
    if (r.suite == "motions" && fcl && r.mode == "sampled" && r.tolerance == 0.01) add(f.fcl_motion, f.fcl_motion_n);
    // (Planning: the medians of each problem's runs, summed over the family's problems.)
    if (r.suite == "plan" && r.engine == "clearway" && r.mode == "certified") f.plan += r.ns;
    if (r.suite == "plan" && fcl && r.mode == "sampled") f.fcl_plan += r.ns;
    if (r.suite == "plan" && r.engine == "clearway" && r.mode == "certified+simplify") f.e2e += r.ns;
    if (r.suite == "plan" && fcl && r.mode == "sampled+simplify") f.fcl_e2e += r.ns;
  }
  if (families.empty()) return "";
  const auto per = [](double total, double n, double unit) { return n > 0 ? fmt("%.0f", total / n / unit) : "-"; };
  const auto ratio = [](double theirs, double ours) { return theirs > 0 && ours > 0 ? fmt("%.1f", theirs / ours) : "-"; };
  std::ostringstream t;
  char line[256];
  std::snprintf(line, sizeof line, "%-28s %10s %10s %8s %10s %10s %8s %8s\n", "family", "state ns", "batch ns", "FCL/x",
                "motion us", "OMPL-FCL/x", "plan/x", "e2e/x");
  t << line;
  for (const auto& [name, f] : families) {
    std::snprintf(
        line, sizeof line, "%-28s %10s %10s %8s %10s %10s %8s %8s\n", name.c_str(), per(f.one, f.one_n, 1).c_str(),
        per(f.batch, f.batch_n, 1).c_str(),
        ratio(f.fcl_state_n > 0 ? f.fcl_state / f.fcl_state_n : 0, f.one_n > 0 ? f.one / f.one_n : 0).c_str(),
        per(f.motion, f.motion_n, 1e3).c_str(),
        ratio(f.fcl_motion_n > 0 ? f.fcl_motion / f.fcl_motion_n : 0, f.motion_n > 0 ? f.motion / f.motion_n : 0)
            .c_str(),
        ratio(f.fcl_plan, f.plan).c_str(), ratio(f.fcl_e2e, f.e2e).c_str());
    t << line;
  }
  std::snprintf(line, sizeof line, "%-28s %10s %10s %8s %10s %10s %8s %8s\n", "target (issue 20)", "500", "100", "30",
                "4", "80", "10", "10");
  t << line;
  t << "state ns: the exact check, one state per call; batch ns: 64 per call; FCL/x: FCL OBBRSS's time per state over\n"
       "the one-per-call check's. motion us: certified at a 1 mm contact distance; OMPL-FCL/x: OMPL's 1% sampling\n"
       "over FCL against it. plan/x: RRTConnect's median solve time with OMPL's 1% sampling over FCL divided by\n"
       "the certified validator's; e2e/x: the same for the solve and simplifySolution together, end to end (issue\n"
       "41's target). The time targets are the Panda's; the UR5's are the same factors over its figures when the\n"
       "issue was filed.\n";
  return t.str();
}

void writeSummaryCsv(const std::string& file, const std::vector<Summary>& all) {
  std::ofstream out(file);
  out << "suite,engine,mode,tolerance,items,ns_per_item,work_per_item,positives,misses,false_alarms,error,max_error,"
         "fcl_ratio\n";
  for (const Summary& s : all) {
    const double peer = fclPeerNs(s, all);
    out << s.suite << "," << s.engine << "," << s.mode << "," << fmt("%.10g", s.tolerance) << "," << s.items << ","
        << fmt("%.6g", s.ns()) << "," << fmt("%.6g", s.work()) << "," << s.positives << "," << s.misses << ","
        << s.false_alarms << "," << fmt("%.6g", s.error()) << "," << fmt("%.6g", s.max_error) << ","
        << (peer > 0 && s.ns() > 0 ? fmt("%.4g", peer / s.ns()) : "") << "\n";
  }
  if (!out) throw std::runtime_error("cannot write " + file);
}

// One gnuplot datablock per curve (engine + mode) of a suite: x = time per item, y = the chosen error.
std::string datablocks(const std::vector<Summary>& all, const std::string& suite, const char* prefix, double unit,
                       double (*y)(const Summary&), std::vector<std::string>& names) {
  std::ostringstream gp;
  std::map<std::string, std::vector<const Summary*>> curves;
  std::vector<std::string> order;
  for (const Summary& s : all)
    if (s.suite == suite) {
      if (!curves.count(s.key())) order.push_back(s.key());
      curves[s.key()].push_back(&s);
    }
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::string name = "$" + std::string(prefix) + std::to_string(k);
    gp << name << " << EOD\n";
    for (const Summary* s : curves[order[k]]) gp << fmt("%.6g", s->ns() / unit) << " " << fmt("%.6g", y(*s)) << " " << fmt("%g", s->tolerance) << "\n";
    gp << "EOD\n";
    names.push_back(name + "|" + order[k]);
  }
  return gp.str();
}

std::string plotCommand(const std::vector<std::string>& names) {
  std::string cmd = "plot ";
  for (std::size_t k = 0; k < names.size(); ++k) {
    const auto bar = names[k].find('|');
    cmd += (k ? ", " : "") + names[k].substr(0, bar) + " using 1:2 with linespoints pt 7 title '" + gnuplotSafeText(names[k].substr(bar + 1)) +
           "', " + names[k].substr(0, bar) + " using 1:2:3 with labels offset 0.6,0.6 font ',7' notitle";
  }
  return cmd + "\n";
}

// Writes plots.gp (self-contained: the data is inside) and runs gnuplot on it when it is installed.
void writePlots(const std::string& dir, const std::vector<Summary>& all) {
  std::ostringstream gp;
  gp << "# Written by clearway bench: what accuracy costs in time. Run: gnuplot plots.gp\n"
        "set terminal pngcairo noenhanced size 1000,650 font ',10'\nset grid\nset key outside right top\n"
        "set logscale x\n";
  auto has = [&](const char* suite) {
    return std::any_of(all.begin(), all.end(), [&](const Summary& s) { return s.suite == suite; });
  };
  if (has("narrowphase")) {
    std::vector<std::string> names;
    gp << datablocks(all, "narrowphase", "np", 1.0, [](const Summary& s) { return std::max(s.max_error, 1e-17); }, names);
    gp << "set output 'narrowphase.png'\nset title 'GJK distance: worst error against time per query (labels: tolerance; "
          "1e-17 means exact)'\nset xlabel 'ns per query'\nset ylabel 'max |distance error| (m)'\nset logscale y\n"
          "set format y '1e%T'\n"
       << plotCommand(names) << "unset logscale y\nset format y '%g'\n";
  }
  if (has("states")) {
    std::vector<std::string> names;
    gp << datablocks(all, "states", "st", 1.0, [](const Summary& s) { return s.error(); }, names);
    gp << "set output 'states.png'\nset title 'One state: wrong verdicts against time per state'\n"
          "set xlabel 'ns per state'\nset ylabel 'wrong-verdict rate (against exact meshes)'\nset yrange [-0.01:*]\n"
       << plotCommand(names) << "set yrange [*:*]\n";
  }
  if (has("motions")) {
    std::vector<std::string> missed, extra;
    gp << datablocks(all, "motions", "mm", 1e3, [](const Summary& s) { return s.items ? s.misses / s.items : 0.0; }, missed);
    gp << datablocks(all, "motions", "mf", 1e3, [](const Summary& s) { return s.items ? s.false_alarms / s.items : 0.0; }, extra);
    gp << "set terminal pngcairo noenhanced size 1400,600 font ',10'\nset output 'motions.png'\nset multiplot layout 1,2 "
          "title 'Motion checks: what each mode misses and adds, against time per motion (labels: contact distance in m, "
          "or resolution as a fraction of the extent)'\nset xlabel 'us per motion'\nset yrange [-0.002:*]\n"
          "set key inside right top\nset title 'missed collisions (dense reference collides, mode says free)'\n"
          "set ylabel 'missed-collision rate'\n"
       << plotCommand(missed) << "set title 'false alarms (reference free, mode says collision)'\n"
       << "set ylabel 'false-alarm rate'\n" << plotCommand(extra) << "unset multiplot\n";
  }
  const std::string file = dir + "/plots.gp";
  std::ofstream(file) << gp.str();
  std::string why;
  if (!runGnuplot(file, why)) std::cerr << "clearway bench: plots not drawn: " << why << "\n";
}

void finish(const std::string& dir, const BenchResults& res) {
  writeResults(dir + "/results.csv", res);
  const std::vector<Summary> all = summarize(res.rows);
  writeSummaryCsv(dir + "/summary.csv", all);
  const std::string t = table(all) + targets(res.rows);
  std::ofstream(dir + "/table.txt") << "# " << res.config << "\n" << t;
  std::cout << t;
  writePlots(dir, all);
}

int usageError(const std::string& why) {
  std::cerr << "clearway bench: " << why << " (clearway bench --help shows the usage)\n";
  return kExitUsage;
}

int runMerge(const std::string& out, const std::vector<std::string>& dirs) {
  try {
    std::vector<BenchResults> shards;
    std::vector<std::string> files;
    for (const std::string& d : dirs) {
      files.push_back(d + "/results.csv");
      shards.push_back(readResults(files.back()));
    }
    const BenchResults merged = mergeShards(shards, files);
    for (const std::string& d : dirs)
      if (fs::is_directory(d + "/plan")) {
        fs::create_directories(out + "/plan");
        for (const auto& log : fs::directory_iterator(d + "/plan"))
          fs::copy_file(log.path(), out + "/plan/" + log.path().filename().string(), fs::copy_options::overwrite_existing);
      }
    fs::create_directories(out);
    finish(out, merged);
  } catch (const std::exception& e) {
    std::cerr << "clearway bench merge: " << e.what() << "\n";
    return kExitUsage;
  }
  return kExitOk;
}

struct BenchSettings {
  bench::SuiteConfig config;
  std::string shard;  // "I/N", checked by the parser
  std::vector<std::string> subjects;
  std::string merge_out;
  std::vector<std::string> merge_dirs;
};

int runBench(BenchSettings& settings) {
  bench::SuiteConfig& config = settings.config;
  long shard = -1, shards = 0;
  std::string why;
  if (!settings.shard.empty()) parseShard(settings.shard, shard, shards, why);
  for (const std::string& list : settings.subjects)
    for (const std::string& s : splitFields(list, ','))
      if (!s.empty()) config.subjects.push_back(s);
  if (std::find(config.suites.begin(), config.suites.end(), "all") != config.suites.end()) config.suites = bench::suiteNames();
  if (config.suites.empty()) config.suites = {"narrowphase", "states", "motions"};
  std::vector<bench::SuiteCase> cases;
  try {
    cases = bench::enumerateCases(config);
  } catch (const std::exception& e) {
    return usageError(e.what());
  }
  // Built without FCL: say which comparisons are not made, rather than leave rows silently out.
  for (const std::string& m : bench::missingComparisons())
    std::cerr << "clearway bench: built without FCL (libfcl-dev), not measured: " << m << "\n";
  BenchResults res;
  std::string suites;
  for (const std::string& s : bench::suiteNames())
    if (std::find(config.suites.begin(), config.suites.end(), s) != config.suites.end()) suites += (suites.empty() ? "" : ",") + s;
  std::string subjects;
  for (const std::string& s : config.subjects) subjects += (subjects.empty() ? "" : ",") + s;
  res.config = "suites=" + suites + (subjects.empty() ? "" : " subjects=" + subjects) + " count=" + std::to_string(config.count) + " problems=" + std::to_string(config.problems) +
               " plan_runs=" + std::to_string(config.plan_runs) + " plan_time=" + fmt("%g", config.plan_time) +
               " seed=" + std::to_string(config.seed);
  res.shard = shard, res.shards = shards, res.cases = static_cast<long>(cases.size());
  std::error_code ec;
  fs::create_directories(config.out, ec);
  if (ec) return usageError("cannot create " + config.out + ": " + ec.message());
  int done = 0, mine = 0;
  for (std::size_t k = 0; k < cases.size(); ++k) mine += shard < 0 || static_cast<long>(k) % shards == shard;
  for (std::size_t k = 0; k < cases.size(); ++k) {
    if (shard >= 0 && static_cast<long>(k) % shards != shard) continue;
    const bench::SuiteCase& c = cases[k];
    ++done;
    if (!quiet()) std::cerr << "[" << done << "/" << mine << "] " << c.suite << " " << c.subject << "\n";
    std::vector<bench::SuiteRow> rows;
    try {
      bench::runCase(c, config, rows);
    } catch (const std::exception& e) {
      std::cerr << "clearway bench: " << c.suite << " " << c.subject << ": " << e.what() << "\n";
      return kExitNo;
    }
    for (const bench::SuiteRow& r : rows) {
      std::ostringstream line;
      line << r.suite << "," << k << "," << r.subject << "," << r.engine << "," << r.mode << "," << fmt("%.10g", r.tolerance)
           << "," << r.items << "," << fmt("%.6g", r.ns_per_item) << "," << fmt("%.10g", r.work_per_item) << ","
           << r.positives << "," << r.misses << "," << r.false_alarms << "," << fmt("%.10g", r.error) << ","
           << fmt("%.10g", r.max_error);
      res.rows.push_back(parseRow(line.str(), "row"));
    }
  }
  try {
    if (shard >= 0) writeResults(config.out + "/results.csv", res);
    else finish(config.out, res);
  } catch (const std::exception& e) {
    std::cerr << "clearway bench: " << e.what() << "\n";
    return kExitUsage;
  }
  return kExitOk;
}

}  // namespace

Subcommand addBenchCommand(CLI::App& root) {
  auto s = std::make_shared<BenchSettings>();
  s->config.shared = sharedDataDir();
  s->config.out = "bench-results";
  CLI::App* app = root.add_subcommand(
      "bench", "accuracy against time per suite, mode and tolerance, FCL side by side: CSV, table, plots; shards");
  app->add_option("SUITE", s->config.suites, "narrowphase, states, verdicts, motions, plan or all")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  app->add_option("--out", s->config.out, "the output folder")->type_name("DIR")->capture_default_str();
  app->add_option("--shard", s->shard, "run the cases whose index is I modulo N (results.csv only)")
      ->type_name("I/N")
      ->check(CLI::Validator(
          [](std::string& v) {
            long i = 0, n = 0;
            std::string why;
            return parseShard(v, i, n, why) ? std::string() : "'" + v + "': " + why;
          },
          ""));
  const CLI::Validator count = wholeNumber(1, 1000000000);
  app->add_option("--count", s->config.count, "pairs per shape family, states or motions per problem")
      ->check(count)->capture_default_str();
  app->add_option("--problems", s->config.problems, "problems per scene family")->check(count)->capture_default_str();
  app->add_option("--plan-runs", s->config.plan_runs, "planning runs per problem and checker")->check(count)
      ->capture_default_str();
  app->add_option("--plan-time", s->config.plan_time, "seconds per planning run")->check(numberAbove(0))
      ->type_name("SECONDS")->capture_default_str();
  addSeedOption(*app, s->config.seed, "inputs depend only on the seed and the case")->capture_default_str();
  app->add_option("--subjects", s->subjects, "only the shape families or problems whose name contains one of these")
      ->type_name("S1,S2")->allow_extra_args(false)->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  app->add_option("--shared", s->config.shared,
                  "the shared development data, the folder holding scenes/ (states, motions and plan need it); "
                  "default $CLEARWAY_SHARED, and for the binary in its build tree ../shared beside the source")
      ->type_name("DIR");
  app->footer(kBenchHelp);
  CLI::App* merge = app->add_subcommand("merge", "combine the results of shards 0..N-1 into one run's files");
  merge->add_option("--out", s->merge_out, "the output folder")->type_name("DIR")->required();
  merge->add_option("SHARD_DIR", s->merge_dirs, "the shards' output folders")->required()
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  merge->footer(kExitCodesHelp);
  return {app, [s, merge] { return merge->parsed() ? runMerge(s->merge_out, s->merge_dirs) : runBench(*s); }};
}

}  // namespace clearway::cli
