// bench_plan_replay: where a planner's time goes, and what each checker costs on the very motions a planner
// asks for. RRTConnect plans each problem with Clearway's validity checker and certified motion validator
// (seeds 1..N), and OMPL's simplifySolution shortens each path; the time of each phase is split into
// motion checks, state checks and the rest (OMPL's own work, the same for every checker). Every motion
// either phase asked for is then replayed, by phase, free and colliding ones apart: certified (the verdict
// only, as planners ask), and OMPL's DiscreteMotionValidator at its default 1% resolution over Clearway's
// state check and over FCL's (FclValidity). Ratios of one process's times; the state and query counts do
// not depend on the machine.
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

// The phases of a planning query: the planner's solve, then the simplification of its path.
constexpr int kPhases = 2;
const char* const kPhaseName[kPhases] = {"solve", "simplify"};

struct Segment {
  std::vector<double> from, to;
  int phase = 0;
};

// Times the inner motion validator and keeps every segment it is asked about.
class Recorder : public ob::MotionValidator {
 public:
  Recorder(const ob::SpaceInformationPtr& si, ob::MotionValidatorPtr inner, const StateMap& map,
           std::vector<Segment>& out, double* us, const int& phase)
      : ob::MotionValidator(si), inner_(std::move(inner)), map_(map), out_(out), us_(us), phase_(phase) {}
  bool checkMotion(const ob::State* a, const ob::State* b) const override {
    Segment s{std::vector<double>(map_.dimension()), std::vector<double>(map_.dimension()), phase_};
    map_.toVector(a, s.from.data());
    map_.toVector(b, s.to.data());
    map_.unwrap(s.from.data(), s.to.data());
    out_.push_back(std::move(s));
    const Clock::time_point t = Clock::now();
    const bool free = inner_->checkMotion(a, b);
    us_[phase_] += microseconds(t);
    return free;
  }
  // (Neither RRTConnect nor the simplifier asks for the last valid state: not recorded.)
  bool checkMotion(const ob::State* a, const ob::State* b, std::pair<ob::State*, double>& last) const override {
    return inner_->checkMotion(a, b, last);
  }

 private:
  ob::MotionValidatorPtr inner_;
  const StateMap& map_;
  std::vector<Segment>& out_;
  double* us_;        // per phase
  const int& phase_;  // the phase running
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
  double phase_us[kPhases] = {}, motion_us[kPhases] = {}, state_us[kPhases] = {};
  int solved = 0, phase = 0;
  for (int seed = 1; seed <= seeds; ++seed) {
    ompl::RNG::setSeed(seed);
    og::SimpleSetup setup(clearway::makeStateSpace(*scene));
    const ob::SpaceInformationPtr si = setup.getSpaceInformation();
    const clearway::CollisionChecking cc = clearway::setupCollisionChecking(si, scene);
    auto counter = std::make_shared<Counter>(si, cc.validity);
    si->setStateValidityChecker(counter);
    si->setMotionValidator(std::make_shared<Recorder>(si, cc.motion, map, segments, motion_us, phase));
    ob::ScopedState<> start(setup.getStateSpace()), goal(setup.getStateSpace());
    map.fromVector(d.start.data(), start.get());
    map.fromVector(d.goal.data(), goal.get());
    setup.setStartAndGoalStates(start, goal);
    setup.setPlanner(std::make_shared<og::RRTConnect>(si));
    setup.setup();
    phase = 0;
    Clock::time_point t = Clock::now();
    // (A condition without a checking thread: SimpleSetup::solve(seconds) starts one, about a millisecond.)
    const bool exact = setup.solve(ob::timedPlannerTerminationCondition(30.0)) == ob::PlannerStatus::EXACT_SOLUTION;
    phase_us[0] += microseconds(t);
    state_us[0] += counter->us;
    solved += exact;
    if (!exact) continue;
    phase = 1;
    const double states_before = counter->us;
    t = Clock::now();
    setup.simplifySolution();
    phase_us[1] += microseconds(t);
    state_us[1] += counter->us - states_before;
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
  // [phase][free][kind]
  double us[kPhases][2][3] = {}, queries[kPhases][2] = {}, states[kPhases][2] = {};
  long count[kPhases][2] = {};
  std::vector<int> is_free(segments.size());
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const Clock::time_point t = Clock::now();
    const clearway::MotionResult r = certified.check(segments[i].from.data(), segments[i].to.data(), context, false);
    const double spent = microseconds(t);
    const int f = is_free[i] = r.free ? 1 : 0, p = segments[i].phase;
    ++count[p][f];
    us[p][f][0] += spent;
    queries[p][f] += r.distance_queries;
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
      const int p = segments[i].phase;
      us[p][is_free[i]][kind] += microseconds(t);
      if (kind == 1) states[p][is_free[i]] += static_cast<double>(sampled.counter->calls - before);
    }
  }
  std::printf("%s: %d runs (%d solved)\n", scene->name().c_str(), seeds, solved);
  // Planning over FCL, estimated per phase: its motion checks at the replays' ratio to the certified ones,
  // its state checks at the sampled replays' ratio (FCL's state check to ours), the same rest. (The
  // Recorder's copies count as the rest: well under 1%. The certified validator answers a segment asked
  // again from its memory, which the replay does not: the ratio is of computed answers.)
  double estimated[kPhases] = {};
  for (int p = 0; p < kPhases; ++p) {
    const double total = phase_us[p];
    std::printf("  %-8s %8.0f us per run: motion checks %.0f%%, state checks %.0f%%, the rest %.0f%%\n", kPhaseName[p],
                total / seeds, 100.0 * motion_us[p] / std::max(1e-9, total),
                100.0 * state_us[p] / std::max(1e-9, total),
                100.0 * (total - motion_us[p] - state_us[p]) / std::max(1e-9, total));
    for (int f = 1; f >= 0; --f) {
      const double n = static_cast<double>(std::max(1L, count[p][f]));
      std::printf(
          "    %-9s %6ld motions: certified %6.1f us (%.1f queries) | 1%% sampled: %.1f states, over Clearway "
          "%6.1f us, over FCL %7.1f us | FCL/certified %.2f\n",
          f ? "free" : "colliding", count[p][f], us[p][f][0] / n, queries[p][f] / n, states[p][f] / n, us[p][f][1] / n,
          us[p][f][2] / n, us[p][f][2] / std::max(1e-9, us[p][f][0]));
    }
    const double certified_all = us[p][0][0] + us[p][1][0], fcl_all = us[p][0][2] + us[p][1][2],
                 ours_all = us[p][0][1] + us[p][1][1];
    const double motion_ratio = fcl_all / std::max(1e-9, certified_all),
                 state_ratio = fcl_all / std::max(1e-9, ours_all);
    estimated[p] = motion_ratio * motion_us[p] + state_ratio * state_us[p] + (total - motion_us[p] - state_us[p]);
    std::printf("    all motions: FCL/certified %.2f; %s over FCL, estimated: %.2f\n", motion_ratio, kPhaseName[p],
                estimated[p] / std::max(1e-9, total));
  }
  std::printf("  end to end (solve and simplify), over FCL, estimated: %.2f\n",
              (estimated[0] + estimated[1]) / std::max(1e-9, phase_us[0] + phase_us[1]));
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
