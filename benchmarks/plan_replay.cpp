// bench_plan_replay: where a planner's time goes, and what each checker costs on the very motions a planner
// asks for. RRTConnect plans each problem with Clearway's validity checker and certified motion validator
// (seeds 1..N); its solve time is split into motion checks, state checks and the rest (OMPL's own work, the
// same for every checker). Every motion it asked for is then replayed, free and colliding ones apart:
// certified (the verdict only, as planners ask), and OMPL's DiscreteMotionValidator at its default 1%
// resolution over Clearway's state check and over FCL's (FclValidity). Ratios of one process's times;
// the state and query counts do not depend on the machine.
//
//   bench_plan_replay SEEDS SCENE.yaml...
#include "fcl_ompl.h"

#include <clearway/ompl/collision_checking.h>
#include <clearway/scene/scene.h>

#include <ompl/base/DiscreteMotionValidator.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

namespace ob = ompl::base;
namespace og = ompl::geometric;
using clearway::Scene;
using clearway::SceneDescription;
using clearway::StateMap;
using Clock = std::chrono::steady_clock;

double microseconds(Clock::time_point since) {
  return std::chrono::duration<double, std::micro>(Clock::now() - since).count();
}

struct Segment {
  std::vector<double> from, to;
};

// Times the inner motion validator and keeps every segment it is asked about.
class Recorder : public ob::MotionValidator {
 public:
  Recorder(const ob::SpaceInformationPtr& si, ob::MotionValidatorPtr inner, const StateMap& map,
           std::vector<Segment>& out, double& us)
      : ob::MotionValidator(si), inner_(std::move(inner)), map_(map), out_(out), us_(us) {}
  bool checkMotion(const ob::State* a, const ob::State* b) const override {
    Segment s{std::vector<double>(map_.dimension()), std::vector<double>(map_.dimension())};
    map_.toVector(a, s.from.data());
    map_.toVector(b, s.to.data());
    map_.unwrap(s.from.data(), s.to.data());
    out_.push_back(std::move(s));
    const Clock::time_point t = Clock::now();
    const bool free = inner_->checkMotion(a, b);
    us_ += microseconds(t);
    return free;
  }
  bool checkMotion(const ob::State* a, const ob::State* b, std::pair<ob::State*, double>& last) const override {
    return inner_->checkMotion(a, b, last);
  }

 private:
  ob::MotionValidatorPtr inner_;
  const StateMap& map_;
  std::vector<Segment>& out_;
  double& us_;
};

// Times and counts the inner validity checker's calls.
class Counter : public ob::StateValidityChecker {
 public:
  Counter(const ob::SpaceInformationPtr& si, ob::StateValidityCheckerPtr inner)
      : ob::StateValidityChecker(si), inner_(std::move(inner)) {}
  bool isValid(const ob::State* s) const override {
    ++calls;
    const Clock::time_point t = Clock::now();
    const bool valid = inner_->isValid(s);
    us += microseconds(t);
    return valid;
  }
  mutable long calls = 0;
  mutable double us = 0.0;

 private:
  ob::StateValidityCheckerPtr inner_;
};

// One OMPL setup over the scene with a 1%-resolution DiscreteMotionValidator over `validity`.
struct Sampled {
  og::SimpleSetup setup;
  std::shared_ptr<Counter> counter;
  std::shared_ptr<ob::DiscreteMotionValidator> motion;
  Sampled(const Scene& scene, const std::function<ob::StateValidityCheckerPtr(const ob::SpaceInformationPtr&)>& make)
      : setup(clearway::makeStateSpace(scene)) {
    const ob::SpaceInformationPtr si = setup.getSpaceInformation();
    counter = std::make_shared<Counter>(si, make(si));
    si->setStateValidityChecker(counter);
    si->setStateValidityCheckingResolution(0.01);
    si->setup();
    motion = std::make_shared<ob::DiscreteMotionValidator>(si);
  }
};

void replay(const std::string& file, int seeds) {
  const auto scene = Scene::load(file);
  const SceneDescription& d = scene->description();
  const std::size_t dimension = static_cast<std::size_t>(scene->dimension());
  if (d.start.size() != dimension || d.goal.size() != dimension)
    throw std::invalid_argument(file + ": the scene needs a start and a goal of " + std::to_string(dimension) + " values");
  const StateMap map(*scene);
  std::vector<Segment> segments;
  double solve_us = 0.0, motion_us = 0.0, state_us = 0.0;
  int solved = 0;
  for (int seed = 1; seed <= seeds; ++seed) {
    ompl::RNG::setSeed(seed);
    og::SimpleSetup setup(clearway::makeStateSpace(*scene));
    const ob::SpaceInformationPtr si = setup.getSpaceInformation();
    const clearway::CollisionChecking cc = clearway::setupCollisionChecking(si, scene);
    auto counter = std::make_shared<Counter>(si, cc.validity);
    si->setStateValidityChecker(counter);
    si->setMotionValidator(std::make_shared<Recorder>(si, cc.motion, map, segments, motion_us));
    ob::ScopedState<> start(setup.getStateSpace()), goal(setup.getStateSpace());
    map.fromVector(d.start.data(), start.get());
    map.fromVector(d.goal.data(), goal.get());
    setup.setStartAndGoalStates(start, goal);
    setup.setPlanner(std::make_shared<og::RRTConnect>(si));
    setup.setup();
    const Clock::time_point t = Clock::now();
    // (A condition without a checking thread: SimpleSetup::solve(seconds) starts one, about a millisecond.)
    solved += setup.solve(ob::timedPlannerTerminationCondition(30.0)) == ob::PlannerStatus::EXACT_SOLUTION;
    solve_us += microseconds(t);
    state_us += counter->us;
  }
  // The replay: [free][kind] with kind 0 certified, 1 sampled over Clearway, 2 sampled over FCL. One checker
  // over all the segments at a time: interleaved per segment, each would evict the others' data.
  const clearway::MotionChecker certified(scene);
  clearway::MotionContext context = certified.makeContext();
  // The clearance grid, which the environment builds once asked enough (a few ms), now: the runs above may
  // not have asked enough, and its one build would land on whichever replayed motion asked last.
  scene->environment().prepareClearanceGrid();
  Sampled ours(*scene, [&](const ob::SpaceInformationPtr& si) { return std::make_shared<clearway::ValidityChecker>(si, scene); });
  Sampled fcl(*scene, [&](const ob::SpaceInformationPtr& si) { return std::make_shared<clearway::bench::FclValidity>(si, scene); });
  double us[2][3] = {}, queries[2] = {}, states[2] = {};
  long count[2] = {};
  std::vector<int> is_free(segments.size());
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const Clock::time_point t = Clock::now();
    const clearway::MotionResult r = certified.check(segments[i].from.data(), segments[i].to.data(), context, false);
    const double spent = microseconds(t);
    const int f = is_free[i] = r.free ? 1 : 0;
    ++count[f];
    us[f][0] += spent;
    queries[f] += r.distance_queries;
  }
  ob::ScopedState<> a(ours.setup.getStateSpace()), b(ours.setup.getStateSpace());
  for (int kind = 1; kind <= 2; ++kind) {
    Sampled& sampled = kind == 1 ? ours : fcl;
    for (std::size_t i = 0; i < segments.size(); ++i) {
      map.fromVector(segments[i].from.data(), a.get());
      map.fromVector(segments[i].to.data(), b.get());
      const long before = sampled.counter->calls;
      const Clock::time_point t = Clock::now();
      sampled.motion->checkMotion(a.get(), b.get());
      us[is_free[i]][kind] += microseconds(t);
      if (kind == 1) states[is_free[i]] += static_cast<double>(sampled.counter->calls - before);
    }
  }
  std::printf("%s: %d runs (%d solved), solve %.0f us per run: motion checks %.0f%%, state checks %.0f%%, the rest %.0f%%\n",
              scene->name().c_str(), seeds, solved, solve_us / seeds, 100.0 * motion_us / solve_us,
              100.0 * state_us / solve_us, 100.0 * (solve_us - motion_us - state_us) / solve_us);
  for (int f = 1; f >= 0; --f) {
    const double n = static_cast<double>(std::max(1L, count[f]));
    std::printf("  %-9s %6ld motions: certified %6.1f us (%.1f queries) | 1%% sampled: %.1f states, over Clearway %6.1f us, "
                "over FCL %7.1f us | FCL/certified %.2f\n",
                f ? "free" : "colliding", count[f], us[f][0] / n, queries[f] / n, states[f] / n, us[f][1] / n,
                us[f][2] / n, us[f][2] / std::max(1e-9, us[f][0]));
  }
  // Planning over FCL, estimated from this solve: its motion checks at the replays' ratio to the certified
  // ones, its state checks at the sampled replays' ratio (FCL's state check to ours), the same rest. (The
  // Recorder's copies count as the rest: well under 1%.)
  const double certified_all = us[0][0] + us[1][0], fcl_all = us[0][2] + us[1][2], ours_all = us[0][1] + us[1][1];
  const double motion_ratio = fcl_all / std::max(1e-9, certified_all), state_ratio = fcl_all / std::max(1e-9, ours_all);
  const double rest = solve_us - motion_us - state_us;
  std::printf("  all motions: FCL/certified %.2f; planning, estimated: %.2f\n", motion_ratio,
              (motion_ratio * motion_us + state_ratio * state_us + rest) / std::max(1e-9, solve_us));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s SEEDS SCENE.yaml...\n", argv[0]);
    return 2;
  }
  ompl::msg::setLogLevel(ompl::msg::LOG_NONE);
  const int seeds = std::atoi(argv[1]);
  if (seeds < 1) {
    std::fprintf(stderr, "%s: SEEDS must be a whole number of at least 1, not '%s'\n", argv[0], argv[1]);
    return 2;
  }
  try {
    for (int i = 2; i < argc; ++i) replay(argv[i], seeds);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_plan_replay: %s\n", e.what());
    return 1;
  }
  return 0;
}
