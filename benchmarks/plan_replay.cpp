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
#include <string>
#include <vector>

namespace {

namespace ob = ompl::base;
namespace og = ompl::geometric;
using clearway::Scene;
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
  const StateMap map(*scene);
  std::vector<Segment> segments;
  double solve_us = 0.0, motion_us = 0.0, state_us = 0.0;
  for (int seed = 1; seed <= seeds; ++seed) {
    ompl::RNG::setSeed(seed);
    og::SimpleSetup setup(clearway::makeStateSpace(*scene));
    const ob::SpaceInformationPtr si = setup.getSpaceInformation();
    const clearway::CollisionChecking cc = clearway::setupCollisionChecking(si, scene);
    auto counter = std::make_shared<Counter>(si, cc.validity);
    si->setStateValidityChecker(counter);
    si->setMotionValidator(std::make_shared<Recorder>(si, cc.motion, map, segments, motion_us));
    ob::ScopedState<> start(setup.getStateSpace()), goal(setup.getStateSpace());
    map.fromVector(scene->description().start.data(), start.get());
    map.fromVector(scene->description().goal.data(), goal.get());
    setup.setStartAndGoalStates(start, goal);
    setup.setPlanner(std::make_shared<og::RRTConnect>(si));
    setup.setup();
    const Clock::time_point t = Clock::now();
    setup.solve(ob::timedPlannerTerminationCondition(30.0));
    solve_us += microseconds(t);
    state_us += counter->us;
  }
  // The replay: [free][kind] with kind 0 certified, 1 sampled over Clearway, 2 sampled over FCL.
  const clearway::MotionChecker certified(scene);
  clearway::MotionContext context = certified.makeContext();
  Sampled ours(*scene, [&](const ob::SpaceInformationPtr& si) { return std::make_shared<clearway::ValidityChecker>(si, scene); });
  Sampled fcl(*scene, [&](const ob::SpaceInformationPtr& si) { return std::make_shared<clearway::bench::FclValidity>(si, scene); });
  double us[2][3] = {}, queries[2] = {}, states[2] = {};
  long count[2] = {};
  ob::ScopedState<> a(ours.setup.getStateSpace()), b(ours.setup.getStateSpace());
  for (const Segment& s : segments) {
    Clock::time_point t = Clock::now();
    const clearway::MotionResult r = certified.check(s.from.data(), s.to.data(), context, false);
    const double certified_us = microseconds(t);
    const int f = r.free ? 1 : 0;
    ++count[f];
    us[f][0] += certified_us;
    queries[f] += r.distance_queries;
    map.fromVector(s.from.data(), a.get());
    map.fromVector(s.to.data(), b.get());
    const long before = ours.counter->calls;
    t = Clock::now();
    ours.motion->checkMotion(a.get(), b.get());
    us[f][1] += microseconds(t);
    states[f] += static_cast<double>(ours.counter->calls - before);
    t = Clock::now();
    fcl.motion->checkMotion(a.get(), b.get());
    us[f][2] += microseconds(t);
  }
  std::printf("%s: %d runs, solve %.0f us per run: motion checks %.0f%%, state checks %.0f%%, the rest %.0f%%\n",
              scene->name().c_str(), seeds, solve_us / seeds, 100.0 * motion_us / solve_us, 100.0 * state_us / solve_us,
              100.0 * (solve_us - motion_us - state_us) / solve_us);
  for (int f = 1; f >= 0; --f) {
    const double n = static_cast<double>(std::max(1L, count[f]));
    std::printf("  %-9s %6ld motions: certified %6.1f us (%.1f queries) | 1%% sampled: %.1f states, over Clearway %6.1f us, "
                "over FCL %7.1f us | FCL/certified %.2f\n",
                f ? "free" : "colliding", count[f], us[f][0] / n, queries[f] / n, states[f] / n, us[f][1] / n,
                us[f][2] / n, us[f][2] / std::max(1e-9, us[f][0]));
  }
  const double certified_all = us[0][0] + us[1][0], fcl_all = us[0][2] + us[1][2];
  // Planning over FCL, estimated: its motions as replayed, its state checks as ours scaled by the sampled
  // replays' ratio, and the same rest.
  std::printf("  all motions: FCL/certified %.2f; planning, estimated with the rest of the solve: %.2f\n",
              fcl_all / std::max(1e-9, certified_all),
              (fcl_all + state_us * fcl_all / std::max(1e-9, us[0][1] + us[1][1]) + (solve_us - motion_us - state_us)) /
                  std::max(1e-9, solve_us));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s SEEDS SCENE.yaml...\n", argv[0]);
    return 2;
  }
  ompl::msg::setLogLevel(ompl::msg::LOG_NONE);
  try {
    for (int i = 2; i < argc; ++i) replay(argv[i], std::atoi(argv[1]));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_plan_replay: %s\n", e.what());
    return 1;
  }
  return 0;
}
