// `clearway plan [SCENE] [--planner NAME] [--time S] [--seed N] [--no-simplify] [--runs N]`: plans start →
// goal with OMPL on a scene through the plugin's plan() (clearway/ompl/planning.h, which Python's
// clearway.plan calls too), and prints the certified path (one state per line) and the checker's
// statistics; with --runs N, one line of statistics per seed and their medians.
#include "commands.h"
#include "data_paths.h"
#include "exit_codes.h"
#include "scene_commands.h"

#include <clearway/ompl/planning.h>

#include <ompl/util/Console.h>

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <random>
#include <stdexcept>

// The bundled scene, relative to the tool's data folder (data_paths.h).
#define CLEARWAY_DEFAULT_SCENE "robots/scenes/arm6_wall.yaml"

namespace clearway::cli {

namespace {

const char* const kPlanHelp =
    "Plans from the scene's start to its goal with an OMPL geometric planner (RRTConnect by default)\n"
    "using Clearway's validity checker and certified motion validator; simplifies the path and checks\n"
    "it again, segment by segment, with the certified check. Prints the path, one state per line, on\n"
    "stdout ('path N' then N lines) and the statistics on stderr. Without SCENE it plans on the bundled\n"
    "scene " CLEARWAY_DEFAULT_SCENE " of the tool's prefix (BIN/../share/clearway/).\n"
    "With --runs N it plans N times, with seeds S, S+1, ..., S+N-1 (S: --seed, or drawn from the clock),\n"
    "and prints on stdout a line per run instead of a path ('# run seed status solve_s simplify_s states\n"
    "length state_checks motion_checks'), and on stderr the medians: solve and simplification time over\n"
    "every run (a run without a path counts the time it planned), states and length over the certified.\n"
    "Python's clearway.plan(scene, planner, time, seed) plans the same path for the same seed.\n"
    "Planners: RRTConnect RRT RRTstar LazyRRT BiTRRT pRRT PRM PRMstar LazyPRM KPIECE1 BKPIECE1 LBKPIECE1\n"
    "EST BiEST SBL pSBL (with a seed, the same path every time for all but pRRT, pSBL and PRM, which plan\n"
    "in several threads).\n"
    "--mode is the old spelling of --geometry (deprecated).\n"
    "Exit status: 0 with a certified path (every run's, with --runs), 1 when no certified path was found\n"
    "in time (or the start or goal is in collision), 2 on bad input.\n";

// The bundled scene beside the tool (data_paths.h), or "" when this tool has no bundled data.
std::string defaultScene() {
  const std::string dir = bundledDataDir();
  return dir.empty() ? "" : dir + "/" CLEARWAY_DEFAULT_SCENE;
}

struct PlanSettings {
  std::string scene;
  PlanRequest request;
  std::uint64_t seed = 0;
  bool seeded = false;
  int runs = 1;
  SceneOptions options;
};

// The median of xs (the mean of the middle two for an even count); 0 for none.
double median(std::vector<double> xs) {
  if (xs.empty()) return 0.0;
  std::sort(xs.begin(), xs.end());
  const std::size_t n = xs.size();
  return n % 2 ? xs[n / 2] : 0.5 * (xs[n / 2 - 1] + xs[n / 2]);
}

// Why a query found no certified path, as one line on stderr.
void printFailure(const std::string& scene_path, const PlanRequest& request, const PlanResult& r) {
  if (r.status == PlanStatus::NoPath)
    std::fprintf(stderr, "clearway plan: %s found no path in %g s (%s; planned for %.6f s)\n", request.planner.c_str(),
                 request.time, r.ompl_status.c_str(), r.solve_seconds);
  else if (r.status == PlanStatus::NotCertified)
    for (std::size_t i : r.uncertified_segments)
      std::fprintf(stderr, "clearway plan: segment %zu of the final path is not certified free\n", i);
  else
    std::cerr << "clearway plan: " << scene_path << ": " << r.message << "\n";
}

// One query: the path on stdout, the statistics on stderr.
int planOnce(const std::shared_ptr<const MotionChecker>& checker, const std::string& scene_path,
             const PlanRequest& request) {
  const PlanResult r = plan(checker, request);
  if (r.status != PlanStatus::Solved && r.status != PlanStatus::NotCertified) {
    printFailure(scene_path, request, r);
    return kExitNo;
  }
  if (!r.solved()) printFailure(scene_path, request, r);
  std::printf("path %zu\n", r.stateCount());
  for (std::size_t i = 0; i < r.stateCount(); ++i) {
    // 17 significant digits read back as the same double: a path fed to check or motion is this path.
    for (int k = 0; k < r.dimension; ++k) std::printf(k ? " %.17g" : "%.17g", r.path[i * r.dimension + k]);
    std::printf("\n");
  }
  std::fprintf(stderr,
               "planner %s: solved in %.6f s, simplified in %.6f s; %zu states, length %.4f; certified: %s\n"
               "checker: %llu states (%.2f us each), %llu motions (%.2f us each); during simplification: %llu "
               "states, %llu motions\n",
               request.planner.c_str(), r.solve_seconds, r.simplify_seconds, r.stateCount(), r.length,
               r.solved() ? "yes" : "NO", static_cast<unsigned long long>(r.state_checks),
               r.state_checks ? 1e6 * r.state_check_seconds / r.state_checks : 0.0,
               static_cast<unsigned long long>(r.motion_checks),
               r.motion_checks ? 1e6 * r.motion_check_seconds / r.motion_checks : 0.0,
               static_cast<unsigned long long>(r.simplify_state_checks),
               static_cast<unsigned long long>(r.simplify_motion_checks));
  std::fflush(stdout);
  return r.solved() ? kExitOk : kExitNo;
}

// --runs N: a line per seeded run on stdout, the medians on stderr (as OMPL's benchmark: a run that found
// no path counts the time it planned).
int planRuns(const std::shared_ptr<const MotionChecker>& checker, const std::string& scene_path, PlanRequest request,
             std::uint64_t first_seed, int runs) {
  std::vector<double> solve, simplify, states, length;
  int certified = 0;
  std::printf("# run seed status solve_s simplify_s states length state_checks motion_checks\n");
  for (int i = 0; i < runs; ++i) {
    request.seed = first_seed + static_cast<std::uint64_t>(i);  // (wraps past 2^64 - 1, as unsigned numbers do)
    const PlanResult r = plan(checker, request);
    if (!r.solved()) printFailure(scene_path, request, r);
    std::string status = toString(r.status);
    std::replace(status.begin(), status.end(), ' ', '_');  // one word per column
    std::printf("%d %llu %s %.6f %.6f %zu %.4f %llu %llu\n", i + 1, static_cast<unsigned long long>(*request.seed),
                status.c_str(), r.solve_seconds, r.simplify_seconds, r.stateCount(), r.length,
                static_cast<unsigned long long>(r.state_checks), static_cast<unsigned long long>(r.motion_checks));
    std::fflush(stdout);
    if (r.status == PlanStatus::StartColliding || r.status == PlanStatus::GoalColliding ||
        r.status == PlanStatus::StartStuck || r.status == PlanStatus::GoalStuck)
      return kExitNo;  // the same for every seed
    solve.push_back(r.solve_seconds);
    simplify.push_back(r.simplify_seconds);
    if (r.solved()) {
      ++certified;
      states.push_back(static_cast<double>(r.stateCount()));
      length.push_back(r.length);
    }
  }
  std::fprintf(stderr,
               "planner %s: %d runs (seeds %llu to %llu), %d certified; median solve %.6f s (fastest %.6f, slowest "
               "%.6f), median simplification %.6f s",
               request.planner.c_str(), runs, static_cast<unsigned long long>(first_seed),
               static_cast<unsigned long long>(first_seed + static_cast<std::uint64_t>(runs - 1)), certified,
               median(solve), *std::min_element(solve.begin(), solve.end()),
               *std::max_element(solve.begin(), solve.end()), median(simplify));
  if (certified > 0) std::fprintf(stderr, "; certified paths: median %g states, length %.4f", median(states), median(length));
  std::fprintf(stderr, "\n");
  return certified == runs ? kExitOk : kExitNo;
}

int runPlan(const PlanSettings& s) {
  std::string scene_path = s.scene;
  PlanRequest request = s.request;
  const std::vector<std::string>& known = plannerNames();
  if (std::find(known.begin(), known.end(), request.planner) == known.end()) {
    std::cerr << "clearway plan: --planner: unknown planner '" << request.planner << "' (clearway plan --help lists them)\n";
    return kExitUsage;
  }
  if (scene_path.empty()) scene_path = defaultScene();
  if (scene_path.empty()) {
    std::cerr << "clearway plan: no SCENE given, and the bundled scene is not installed: "
              << installedDataDir() << "/" CLEARWAY_DEFAULT_SCENE " does not exist (install with cmake --install, "
                 "or give a SCENE)\n";
    return kExitUsage;
  }

  std::shared_ptr<const Scene> scene;
  try {
    scene = openScene(scene_path, s.options);
  } catch (const std::exception& e) {
    std::cerr << "clearway plan: " << e.what() << "\n";
    return kExitUsage;
  }
  const SceneDescription& d = scene->description();
  if (d.start.empty() || d.goal.empty()) {
    std::cerr << "clearway plan: " << scene_path << ": the scene needs a start and a goal\n";
    return kExitUsage;
  }
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  std::cerr << "scene " << scene->name() << " (" << scene_path << "): robot " << scene->robot().name() << ", "
            << scene->dimension() << " joints, " << scene->selfCollision().pairs().size() << " self pairs, "
            << scene->environment().obstacleCount() << " obstacles"
            << (scene->environment().map() ? ", an OctoMap" : "") << "; checks: " << scene->effects().toString()
            << "\n";
  try {
    // Built once: every run plans with it (a new one per run cost a UR5 a third of a second each).
    const auto checker = std::make_shared<const MotionChecker>(scene);
    if (s.runs > 1) return planRuns(checker, scene_path, request, s.seeded ? s.seed : std::random_device()(), s.runs);
    if (s.seeded) request.seed = s.seed;
    return planOnce(checker, scene_path, request);
  } catch (const std::invalid_argument& e) {  // a start or goal out of bounds, a scene OMPL cannot plan in
    std::cerr << "clearway plan: " << scene_path << ": " << e.what() << "\n";
    return kExitUsage;
  }
}

}  // namespace

Subcommand addPlanCommand(CLI::App& root) {
  auto s = std::make_shared<PlanSettings>();
  CLI::App* app = root.add_subcommand("plan", "plan start -> goal on a scene with OMPL (a bundled scene when none is given)");
  app->add_option("SCENE", s->scene,
                  "the scene file (YAML; - for stdin, its paths then from the working directory); default: the "
                  "bundled " CLEARWAY_DEFAULT_SCENE);
  app->add_option("--planner", s->request.planner, "an OMPL geometric planner (listed below)")->capture_default_str();
  // OMPL's deadline is a clock time point: beyond about 7.5e9 s it overflows and the planner stops at once.
  app->add_option("--time", s->request.time, "seconds the planner may take (at most 1e6)")
      ->check(numberAbove(0, kMaxPlanTime))
      ->type_name("SECONDS")
      ->capture_default_str();
  CLI::Option* seed = addSeedOption(*app, s->seed, "OMPL's random seed (default: from the clock); with --runs, the first run's");
  app->add_flag_callback("--no-simplify", [s] { s->request.simplify = false; }, "print the path as the planner found it");
  app->add_option("--runs", s->runs, "plan N times, seeds S to S+N-1, and print each run's statistics and their medians")
      ->check(wholeNumber(1, 1000000))
      ->type_name("N");
  addGeometryOption(*app, s->options.mode, /*mode_alias=*/true);
  addLoadOptions(*app, s->options.load);
  app->footer(std::string(kPlanHelp) + kFormatsHelp);
  return {app, [s, seed] {
            s->seeded = seed->count() > 0;
            return runPlan(*s);
          }};
}

}  // namespace clearway::cli
