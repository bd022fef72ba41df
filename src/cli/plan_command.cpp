// `clearway plan [SCENE] [--planner NAME] [--time S] [--seed N] [--no-simplify]`: plans start → goal
// with OMPL on a scene, simplifies, re-validates the final path with the certified motion check, and
// prints the path (one state per line) and the checker's statistics.
#include "commands.h"
#include "data_paths.h"
#include "exit_codes.h"
#include "scene_commands.h"

#include <clearway/ompl/collision_checking.h>

#include <ompl/base/goals/GoalState.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/est/BiEST.h>
#include <ompl/geometric/planners/est/EST.h>
#include <ompl/geometric/planners/kpiece/BKPIECE1.h>
#include <ompl/geometric/planners/kpiece/KPIECE1.h>
#include <ompl/geometric/planners/kpiece/LBKPIECE1.h>
#include <ompl/geometric/planners/prm/LazyPRM.h>
#include <ompl/geometric/planners/prm/PRM.h>
#include <ompl/geometric/planners/prm/PRMstar.h>
#include <ompl/geometric/planners/rrt/BiTRRT.h>
#include <ompl/geometric/planners/rrt/LazyRRT.h>
#include <ompl/geometric/planners/rrt/RRT.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/geometric/planners/rrt/RRTstar.h>
#include <ompl/geometric/planners/rrt/pRRT.h>
#include <ompl/geometric/planners/sbl/SBL.h>
#include <ompl/geometric/planners/sbl/pSBL.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <functional>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>

// The bundled scene, relative to the tool's data folder (data_paths.h).
#define CLEARWAY_DEFAULT_SCENE "robots/scenes/arm6_wall.yaml"

namespace clearway::cli {

namespace {

namespace ob = ompl::base;
namespace og = ompl::geometric;

const char* const kPlanHelp =
    "Plans from the scene's start to its goal with an OMPL geometric planner (RRTConnect by default)\n"
    "using Clearway's validity checker and certified motion validator; simplifies the path and checks\n"
    "it again, segment by segment, with the certified check. Prints the path, one state per line, on\n"
    "stdout ('path N' then N lines) and the statistics on stderr. Without SCENE it plans on the bundled\n"
    "scene " CLEARWAY_DEFAULT_SCENE " of the tool's prefix (BIN/../share/clearway/).\n"
    "Planners: RRTConnect RRT RRTstar LazyRRT BiTRRT pRRT PRM PRMstar LazyPRM KPIECE1 BKPIECE1 LBKPIECE1\n"
    "EST BiEST SBL pSBL.\n"
    "--mode is the old spelling of --geometry (deprecated).\n"
    "Exit status: 0 with a certified path, 1 when no certified path was found in time (or the start or\n"
    "goal is in collision), 2 on bad input.\n";

using PlannerMaker = std::function<ob::PlannerPtr(const ob::SpaceInformationPtr&)>;

const std::map<std::string, PlannerMaker>& planners() {
  static const std::map<std::string, PlannerMaker> m = {
      {"RRTConnect", [](auto si) { return std::make_shared<og::RRTConnect>(si); }},
      {"RRT", [](auto si) { return std::make_shared<og::RRT>(si); }},
      {"RRTstar", [](auto si) { return std::make_shared<og::RRTstar>(si); }},
      {"LazyRRT", [](auto si) { return std::make_shared<og::LazyRRT>(si); }},
      {"BiTRRT", [](auto si) { return std::make_shared<og::BiTRRT>(si); }},
      {"pRRT", [](auto si) { return std::make_shared<og::pRRT>(si); }},
      {"PRM", [](auto si) { return std::make_shared<og::PRM>(si); }},
      {"PRMstar", [](auto si) { return std::make_shared<og::PRMstar>(si); }},
      {"LazyPRM", [](auto si) { return std::make_shared<og::LazyPRM>(si); }},
      {"KPIECE1", [](auto si) { return std::make_shared<og::KPIECE1>(si); }},
      {"BKPIECE1", [](auto si) { return std::make_shared<og::BKPIECE1>(si); }},
      {"LBKPIECE1", [](auto si) { return std::make_shared<og::LBKPIECE1>(si); }},
      {"EST", [](auto si) { return std::make_shared<og::EST>(si); }},
      {"BiEST", [](auto si) { return std::make_shared<og::BiEST>(si); }},
      {"SBL", [](auto si) { return std::make_shared<og::SBL>(si); }},
      {"pSBL", [](auto si) { return std::make_shared<og::pSBL>(si); }},
  };
  return m;
}

// The bundled scene beside the tool (data_paths.h), or "" when this tool has no bundled data.
std::string defaultScene() {
  const std::string dir = bundledDataDir();
  return dir.empty() ? "" : dir + "/" CLEARWAY_DEFAULT_SCENE;
}

struct PlanSettings {
  std::string scene, planner = "RRTConnect";
  double time = 10.0;
  std::uint64_t seed = 0;
  bool seeded = false, simplify = true;
  SceneOptions options;
};

int runPlan(const PlanSettings& s) {
  std::string scene_path = s.scene;
  const std::string& planner_name = s.planner;
  const double time_limit = s.time;
  const SceneOptions& options = s.options;
  const auto maker = planners().find(planner_name);
  if (maker == planners().end()) {
    std::cerr << "clearway plan: --planner: unknown planner '" << planner_name << "' (clearway plan --help lists them)\n";
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
    scene = openScene(scene_path, options);
  } catch (const std::exception& e) {
    std::cerr << "clearway plan: " << e.what() << "\n";
    return kExitUsage;
  }
  const SceneDescription& d = scene->description();
  if (d.start.empty() || d.goal.empty()) {
    std::cerr << "clearway plan: " << scene_path << ": the scene needs a start and a goal\n";
    return kExitUsage;
  }
  std::vector<double> start_q = d.start, goal_q = d.goal;
  for (auto* q : {&start_q, &goal_q}) {
    std::string why;
    CollisionReport r;
    const char* which = q == &start_q ? "start" : "goal";
    if (!scene->validState(q->data(), &why)) {
      std::cerr << "clearway plan: " << scene_path << ": " << which << ": " << why << "\n";
      return kExitUsage;
    }
    // validState allows a hair past a limit (a file's rounding); OMPL's bounds are exact and would call
    // such a start invalid, so it is moved onto the limit and checked there.
    for (int k = 0; k < scene->dimension() && k < static_cast<int>(q->size()); ++k)
      (*q)[k] = std::min(std::max((*q)[k], scene->lower(k)), scene->upper(k));
    if (!scene->isFree(*q, &r)) {
      std::cerr << "clearway plan: " << scene_path << ": " << which << " is in collision: " << scene->describe(r) << "\n";
      return kExitNo;
    }
  }

  if (s.seeded) ompl::RNG::setSeed(static_cast<std::uint_fast32_t>(s.seed));
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  const ob::StateSpacePtr space = makeStateSpace(*scene);
  og::SimpleSetup setup(space);
  // Segments checked once the planner's time is up end at once, capped (never free): one segment near
  // contact could otherwise run for tens of seconds past the limit. Unset again for the simplification
  // and the final check.
  const auto deadline = std::make_shared<std::atomic<std::chrono::steady_clock::rep>>(
      std::numeric_limits<std::chrono::steady_clock::rep>::max());
  MotionOptions motion_options;
  motion_options.stop = [deadline] {
    return std::chrono::steady_clock::now().time_since_epoch().count() > deadline->load(std::memory_order_relaxed);
  };
  CollisionChecking checking;
  try {
    checking = setupCollisionChecking(setup.getSpaceInformation(), scene, motion_options);
  } catch (const std::exception& e) {
    std::cerr << "clearway plan: " << scene_path << ": " << e.what() << "\n";
    return kExitUsage;
  }
  const StateMap map(*scene);
  ob::ScopedState<> start(space), goal(space);
  map.fromVector(start_q.data(), start.get());
  map.fromVector(goal_q.data(), goal.get());
  setup.setStartAndGoalStates(start, goal);
  // A start or goal that no motion can leave would spend the whole time limit: say what holds it instead.
  // (The certified check lowers its contact distance near a free end, so this takes a touch within the
  // narrow phase's band.)
  for (const auto* s : {&start, &goal}) {
    const MotionResult r = checking.motion->check(s->get(), s->get());
    if (!r.free) {
      std::cerr << "clearway plan: " << scene_path << ": the " << (s == &start ? "start" : "goal")
                << " cannot be left (a motion of length zero from it is not certified free): "
                << scene->describe(r.report) << "\n";
      return kExitNo;
    }
  }
  setup.setPlanner(maker->second(setup.getSpaceInformation()));

  std::cerr << "scene " << scene->name() << " (" << scene_path << "): robot " << scene->robot().name() << ", "
            << scene->dimension() << " joints, " << scene->selfCollision().pairs().size() << " self pairs, "
            << scene->environment().obstacleCount() << " obstacles"
            << (scene->environment().map() ? ", an OctoMap" : "") << "; checks: " << scene->effects().toString()
            << "\n";
  const auto t0 = std::chrono::steady_clock::now();
  // A condition that reads the clock where the planner asks: SimpleSetup::solve(seconds) starts a thread to
  // watch the limit for runs of a second or more, which costs milliseconds, more than many a solve.
  deadline->store((t0 + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                 std::chrono::duration<double>(time_limit)))
                      .time_since_epoch()
                      .count());
  const ob::PlannerStatus status = setup.solve(ob::timedPlannerTerminationCondition(time_limit));
  deadline->store(std::numeric_limits<std::chrono::steady_clock::rep>::max());
  const double solve_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (status != ob::PlannerStatus::EXACT_SOLUTION) {
    std::cerr << "clearway plan: " << planner_name << " found no path in " << time_limit << " s (" << status.asString()
              << "; planned for " << std::fixed << std::setprecision(6) << solve_s << " s)\n";
    return kExitNo;
  }
  const auto states_before = checking.validity->counters().states.load();
  const auto motions_before = checking.motion->counters().motions.load();
  double simplify_s = 0.0;
  if (s.simplify) {
    const auto t1 = std::chrono::steady_clock::now();
    setup.simplifySolution();
    simplify_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  }
  og::PathGeometric& path = setup.getSolutionPath();

  // The final path, segment by segment, with the certified check: what we print is what we certify.
  bool certified = true;
  for (std::size_t i = 0; i + 1 < path.getStateCount(); ++i)
    if (!checking.motion->check(path.getState(i), path.getState(i + 1)).free) {
      std::cerr << "clearway plan: segment " << i << " of the final path is not certified free\n";
      certified = false;
    }

  std::vector<double> q(scene->dimension());
  std::printf("path %zu\n", path.getStateCount());
  for (std::size_t i = 0; i < path.getStateCount(); ++i) {
    map.toVector(path.getState(i), q.data());
    // 17 significant digits read back as the same double: a path fed to check or motion is this path.
    for (int k = 0; k < scene->dimension(); ++k) std::printf(k ? " %.17g" : "%.17g", q[k]);
    std::printf("\n");
  }
  const auto& vc = checking.validity->counters();
  const auto& mc = checking.motion->counters();
  std::fprintf(stderr,
               "planner %s: solved in %.6f s, simplified in %.6f s; %zu states, length %.4f; certified: %s\n"
               "checker: %llu states (%.2f us each), %llu motions (%.2f us each); during simplification: %llu "
               "states, %llu motions\n",
               planner_name.c_str(), solve_s, simplify_s, path.getStateCount(), path.length(),
               certified ? "yes" : "NO", static_cast<unsigned long long>(vc.states.load()),
               vc.states ? 1e-3 * vc.nanoseconds.load() / vc.states.load() : 0.0,
               static_cast<unsigned long long>(mc.motions.load()),
               mc.motions ? 1e-3 * mc.nanoseconds.load() / mc.motions.load() : 0.0,
               static_cast<unsigned long long>(vc.states.load() - states_before),
               static_cast<unsigned long long>(mc.motions.load() - motions_before));
  std::fflush(stdout);
  return certified ? kExitOk : kExitNo;
}

}  // namespace

Subcommand addPlanCommand(CLI::App& root) {
  auto s = std::make_shared<PlanSettings>();
  CLI::App* app = root.add_subcommand("plan", "plan start -> goal on a scene with OMPL (a bundled scene when none is given)");
  app->add_option("SCENE", s->scene,
                  "the scene file (YAML; - for stdin, its paths then from the working directory); default: the "
                  "bundled " CLEARWAY_DEFAULT_SCENE);
  app->add_option("--planner", s->planner, "an OMPL geometric planner (listed below)")->capture_default_str();
  // OMPL's deadline is a clock time point: beyond about 7.5e9 s it overflows and the planner stops at once.
  app->add_option("--time", s->time, "seconds the planner may take (at most 1e6)")->check(numberAbove(0, 1e6))->type_name("SECONDS")
      ->capture_default_str();
  CLI::Option* seed = addSeedOption(*app, s->seed, "OMPL's random seed (default: from the clock)");
  app->add_flag_callback("--no-simplify", [s] { s->simplify = false; }, "print the path as the planner found it");
  addGeometryOption(*app, s->options.mode, /*mode_alias=*/true);
  addLoadOptions(*app, s->options.load);
  app->footer(std::string(kPlanHelp) + kFormatsHelp);
  return {app, [s, seed] {
            s->seeded = seed->count() > 0;
            return runPlan(*s);
          }};
}

}  // namespace clearway::cli
