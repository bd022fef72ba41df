#include <clearway/ompl/planning.h>

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

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <mutex>
#include <shared_mutex>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace clearway {

namespace {

namespace ob = ompl::base;
namespace og = ompl::geometric;

using PlannerMaker = std::function<ob::PlannerPtr(const ob::SpaceInformationPtr&)>;

const std::vector<std::pair<std::string, PlannerMaker>>& planners() {
  static const std::vector<std::pair<std::string, PlannerMaker>> list = {
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
  return list;
}

// Every ompl::RNG takes its seed from one process-wide generator when it is made, and the planner, its
// samplers, its nearest-neighbour structure and the simplifier make theirs during the query. A seeded
// query reseeds that generator and holds this lock alone, so no other query's RNGs draw in between;
// unseeded queries share it.
std::shared_mutex& seedLock() {
  static std::shared_mutex m;
  return m;
}

// OMPL logs an error when the generator is reseeded after its first draw, as every seeded query after the
// first in a process does; reseeding is what we mean, so the message is silenced (under seedLock, which
// no other query holds meanwhile).
void reseedOmpl(std::uint64_t seed) {
  const ompl::msg::LogLevel level = ompl::msg::getLogLevel();
  ompl::msg::setLogLevel(ompl::msg::LOG_NONE);
  ompl::RNG::setSeed(static_cast<std::uint_fast32_t>(seed == 0 ? 1 : seed));  // OMPL takes 0 for 1 or ignores it
  ompl::msg::setLogLevel(level);
}

std::string numberText(double x) {
  std::ostringstream s;
  s.precision(17);
  s << x;
  return s.str();
}

// The start or goal as planned: the request's or the scene file's, checked, and clamped onto the limits
// (validState allows a hair past one, a file's rounding, while OMPL's bounds are exact).
std::vector<double> endState(const Scene& scene, const std::vector<double>& given, const std::vector<double>& file,
                             const char* which) {
  std::vector<double> q = given.empty() ? file : given;
  if (q.empty())
    throw std::invalid_argument(std::string(which) + ": none given, and the scene '" + scene.name() + "' has none");
  if (static_cast<int>(q.size()) != scene.dimension())
    throw std::invalid_argument(std::string(which) + ": needs " + std::to_string(scene.dimension()) + " values, got " +
                                std::to_string(q.size()));
  std::string why;
  if (!scene.validState(q.data(), &why)) throw std::invalid_argument(std::string(which) + ": " + why);
  for (int k = 0; k < scene.dimension(); ++k) q[k] = std::min(std::max(q[k], scene.lower(k)), scene.upper(k));
  return q;
}

}  // namespace

const std::vector<std::string>& plannerNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& p : planners()) n.push_back(p.first);
    return n;
  }();
  return names;
}

const char* toString(PlanStatus status) noexcept {
  switch (status) {
    case PlanStatus::Solved: return "solved";
    case PlanStatus::NoPath: return "no path";
    case PlanStatus::NotCertified: return "not certified";
    case PlanStatus::StartColliding: return "start colliding";
    case PlanStatus::GoalColliding: return "goal colliding";
    case PlanStatus::StartStuck: return "start stuck";
    case PlanStatus::GoalStuck: return "goal stuck";
  }
  return "?";
}

PlanResult plan(const std::shared_ptr<const Scene>& scene, const PlanRequest& request) {
  if (!scene) throw std::invalid_argument("scene: none given");
  return plan(std::make_shared<const MotionChecker>(scene), request);
}

PlanResult plan(const std::shared_ptr<const MotionChecker>& checker, const PlanRequest& request) {
  if (!checker) throw std::invalid_argument("checker: none given");
  if (checker->options().mode == MotionMode::Sampled)
    throw std::invalid_argument("checker: a Sampled checker cannot certify a path (Certified or Cast)");
  const Scene& scene = checker->scene();
  const auto maker = std::find_if(planners().begin(), planners().end(),
                                  [&](const auto& p) { return p.first == request.planner; });
  if (maker == planners().end()) {
    std::string known;
    for (const std::string& n : plannerNames()) known += (known.empty() ? "" : " ") + n;
    throw std::invalid_argument("planner: unknown planner '" + request.planner + "' (known: " + known + ")");
  }
  if (!(request.time > 0.0 && request.time <= kMaxPlanTime))
    throw std::invalid_argument("time: needs a number > 0 and <= 1e6 seconds, got " + numberText(request.time));
  const SceneDescription& d = scene.description();
  const std::vector<double> start_q = endState(scene, request.start, d.start, "start");
  const std::vector<double> goal_q = endState(scene, request.goal, d.goal, "goal");

  PlanResult result;
  result.dimension = scene.dimension();
  for (const auto* q : {&start_q, &goal_q}) {
    CollisionReport r;
    if (!scene.isFree(*q, &r)) {
      const bool is_start = q == &start_q;
      result.status = is_start ? PlanStatus::StartColliding : PlanStatus::GoalColliding;
      result.message = std::string(is_start ? "start" : "goal") + " is in collision: " + scene.describe(r);
      return result;
    }
  }

  std::shared_lock<std::shared_mutex> shared(seedLock(), std::defer_lock);
  std::unique_lock<std::shared_mutex> alone(seedLock(), std::defer_lock);
  if (request.seed) {
    alone.lock();
    reseedOmpl(*request.seed);
  } else {
    shared.lock();
  }

  ob::StateSpacePtr space;
  std::unique_ptr<og::SimpleSetup> setup;
  // Segments checked once the planner's time is up end at once, capped (never free): one segment near
  // contact could otherwise run for tens of seconds past the limit. Unset again for the simplification
  // and the final check.
  const auto deadline = std::make_shared<std::atomic<std::chrono::steady_clock::rep>>(
      std::numeric_limits<std::chrono::steady_clock::rep>::max());
  MotionOptions motion_options = checker->options();
  motion_options.stop = [deadline, also = checker->options().stop] {
    return std::chrono::steady_clock::now().time_since_epoch().count() > deadline->load(std::memory_order_relaxed) ||
           (also && also());
  };
  CollisionChecking checking;
  try {
    space = makeStateSpace(scene);
    setup = std::make_unique<og::SimpleSetup>(space);
    checking = setupCollisionChecking(
        setup->getSpaceInformation(),
        std::make_shared<World>(std::make_shared<const MotionChecker>(*checker, motion_options)));
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::exception& e) {  // (ompl::Exception: a scene OMPL cannot plan in)
    throw std::invalid_argument(e.what());
  }
  const StateMap map(scene);
  ob::ScopedState<> start(space), goal(space);
  map.fromVector(start_q.data(), start.get());
  map.fromVector(goal_q.data(), goal.get());
  setup->setStartAndGoalStates(start, goal);
  // A start or goal that no motion can leave would spend the whole time limit: say what holds it instead.
  // (The certified check lowers its contact distance near a free end, so this takes a touch within the
  // narrow phase's band.)
  for (const auto* s : {&start, &goal}) {
    const MotionResult r = checking.motion->check(s->get(), s->get());
    if (!r.free) {
      const bool is_start = s == &start;
      result.status = is_start ? PlanStatus::StartStuck : PlanStatus::GoalStuck;
      result.message = std::string("the ") + (is_start ? "start" : "goal") +
                       " cannot be left (a motion of length zero from it is not certified free): " +
                       scene.describe(r.report);
      return result;
    }
  }
  setup->setPlanner(maker->second(setup->getSpaceInformation()));

  const auto t0 = std::chrono::steady_clock::now();
  // A condition that reads the clock where the planner asks: SimpleSetup::solve(seconds) starts a thread to
  // watch the limit for runs of a second or more, which costs milliseconds, more than many a solve.
  deadline->store((t0 + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                            std::chrono::duration<double>(request.time)))
                      .time_since_epoch()
                      .count());
  const ob::PlannerStatus status = setup->solve(ob::timedPlannerTerminationCondition(request.time));
  deadline->store(std::numeric_limits<std::chrono::steady_clock::rep>::max());
  result.solve_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  result.ompl_status = status.asString();
  const auto counters = [&] {
    const CheckerCounters& vc = checking.validity->counters();
    const CheckerCounters& mc = checking.motion->counters();
    result.state_checks = vc.states.load();
    result.motion_checks = mc.motions.load();
    result.state_check_seconds = static_cast<double>(vc.nanoseconds.load()) / 1e9;
    result.motion_check_seconds = static_cast<double>(mc.nanoseconds.load()) / 1e9;
  };
  if (status != ob::PlannerStatus::EXACT_SOLUTION) {
    counters();
    result.status = PlanStatus::NoPath;
    std::ostringstream m;
    m << request.planner << " found no path in " << numberText(request.time) << " s (" << result.ompl_status << ")";
    result.message = m.str();
    return result;
  }
  const std::uint64_t states_before = checking.validity->counters().states.load();
  const std::uint64_t motions_before = checking.motion->counters().motions.load();
  if (request.simplify) {
    const auto t1 = std::chrono::steady_clock::now();
    setup->simplifySolution();
    result.simplify_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  }
  result.simplify_state_checks = checking.validity->counters().states.load() - states_before;
  result.simplify_motion_checks = checking.motion->counters().motions.load() - motions_before;
  og::PathGeometric& path = setup->getSolutionPath();
  result.length = path.length();

  // The final path, segment by segment, with the certified check: what is returned as certified is.
  for (std::size_t i = 0; i + 1 < path.getStateCount(); ++i)
    if (!checking.motion->check(path.getState(i), path.getState(i + 1)).free) result.uncertified_segments.push_back(i);
  result.path.resize(path.getStateCount() * static_cast<std::size_t>(scene.dimension()));
  // Each angle of a continuous joint (and of a planar joint) shifted by whole turns against the state before,
  // as the motion validator unwraps it: the path's straight segments are then the ones certified, turning
  // the short way, whatever reads the path back (clearway motion, Scene/MotionChecker from C++ or Python).
  for (std::size_t i = 0; i < path.getStateCount(); ++i) {
    double* q = result.path.data() + i * scene.dimension();
    map.toVector(path.getState(i), q);
    if (i > 0) map.unwrap(q - scene.dimension(), q);
  }
  counters();
  if (result.uncertified_segments.empty()) {
    result.status = PlanStatus::Solved;
  } else {
    result.status = PlanStatus::NotCertified;
    result.message = "segment " + std::to_string(result.uncertified_segments.front()) + " of the final path is not certified free";
    if (result.uncertified_segments.size() > 1)
      result.message += " (and " + std::to_string(result.uncertified_segments.size() - 1) + " more)";
  }
  return result;
}

}  // namespace clearway
