// The OMPL plugin: state spaces (bounded joints, SO(2), SE(2) and SE(3)), the validity checker agreeing with the
// scene, the continuous motion validator's lastValid, planning end to end on the bundled scene, and
// many threads on one checker.
#include <clearway/ompl/collision_checking.h>

#include "load/robot_files.h"
#include "ompl/obstacle_on_path.h"

#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/base/spaces/SE2StateSpace.h>
#include <ompl/base/spaces/SE3StateSpace.h>
#include <ompl/base/spaces/SO2StateSpace.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/prm/PRM.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/geometric/planners/rrt/pRRT.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <memory>
#include <random>
#include <thread>

namespace clearway {
namespace {

namespace ob = ompl::base;
namespace og = ompl::geometric;
using test::TempDir;

// One link (a 1 m bar) on a continuous joint, and a post at angle π: the short way from 3 to −3 rad
// passes the post, the long way does not.
const char* kSpinnerUrdf = R"(<?xml version="1.0"?>
<robot name="spinner">
  <link name="base"/>
  <link name="bar">
    <collision><origin xyz="0.5 0 0"/><geometry><box size="1 0.05 0.05"/></geometry></collision>
  </link>
  <link name="slider_link"/>
  <joint name="spin" type="continuous">
    <parent link="base"/><child link="bar"/><axis xyz="0 0 1"/>
  </joint>
  <joint name="lift" type="prismatic">
    <parent link="base"/><child link="slider_link"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="0.5" velocity="1" effort="1"/>
  </joint>
</robot>
)";

std::shared_ptr<const Scene> spinnerScene(const TempDir& dir) {
  const std::string urdf = dir.write("spinner.urdf", kSpinnerUrdf);
  return Scene::load(dir.write("spinner.yaml", "format: 1\nname: spinner\nrobot:\n  urdf: " + urdf +
                                                   "\n  group: [spin, lift]\nenvironment:\n  obstacles:\n"
                                                   "    - {name: post, cylinder: {radius: 0.02, length: 1}, "
                                                   "pose: {position: [-0.8, 0, 0]}}\n"
                                                   "checks: [environment, continuous]\nstart: [3, 0]\ngoal: [-3, 0]\n"));
}

std::string bundledScene() { return std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/arm6_wall.yaml"; }
std::string ourScene(const std::string& name) { return std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/" + name; }

TEST(OmplPlugin, StateSpaces) {
  TempDir dir;
  const auto spinner = spinnerScene(dir);
  const ob::StateSpacePtr space = makeStateSpace(*spinner);
  ASSERT_TRUE(space->isCompound());
  auto* compound = space->as<ob::CompoundStateSpace>();
  ASSERT_EQ(compound->getSubspaceCount(), 2u);
  EXPECT_NE(dynamic_cast<ob::SO2StateSpace*>(compound->getSubspace(0).get()), nullptr);
  const auto* lift = dynamic_cast<ob::RealVectorStateSpace*>(compound->getSubspace(1).get());
  ASSERT_NE(lift, nullptr);
  EXPECT_EQ(lift->getBounds().low[0], 0.0);
  EXPECT_EQ(lift->getBounds().high[0], 0.5);

  const StateMap map(*spinner);
  ob::ScopedState<> s(space);
  const double v[2] = {3.5, 0.25};  // 3.5 rad wraps into SO(2)'s range
  map.fromVector(v, s.get());
  double back[2];
  map.toVector(s.get(), back);
  EXPECT_NEAR(back[0], 3.5 - 2 * M_PI, 1e-12);
  EXPECT_EQ(back[1], 0.25);
  double from[2] = {3.0, 0}, to[2] = {-3.0, 0};
  map.unwrap(from, to);
  EXPECT_NEAR(to[0], 2 * M_PI - 3.0, 1e-12);  // the short way, through π

  const auto arm = Scene::load(bundledScene());
  const ob::StateSpacePtr real = makeStateSpace(*arm);
  ASSERT_EQ(real->getType(), ob::STATE_SPACE_REAL_VECTOR);
  EXPECT_EQ(real->getDimension(), 6u);
  EXPECT_EQ(real->as<ob::RealVectorStateSpace>()->getDimensionName(0), "shoulder_pan_joint");
}

TEST(OmplPlugin, ValidityCheckerAgreesWithTheScene) {
  ompl::RNG::setSeed(11);  // sampled states: a failure replays with the same ones
  const auto scene = Scene::load(bundledScene());
  auto si = std::make_shared<ob::SpaceInformation>(makeStateSpace(*scene));
  const CollisionChecking c = setupCollisionChecking(si, scene);
  const StateMap map(*scene);
  ob::ScopedState<> s(si->getStateSpace());
  auto sampler = si->allocStateSampler();
  std::vector<double> q(scene->dimension());
  int valid = 0;
  for (int i = 0; i < 500; ++i) {
    sampler->sampleUniform(s.get());
    map.toVector(s.get(), q.data());
    const bool expected = scene->isFree(q);
    EXPECT_EQ(si->isValid(s.get()), expected);
    valid += expected;
  }
  EXPECT_GT(valid, 50);
  EXPECT_LT(valid, 450);
  EXPECT_GE(c.validity->counters().states.load(), 500u);
  // Without `clearance` in the scene, OMPL is told that there is none to ask for.
  EXPECT_EQ(c.validity->getSpecs().clearanceComputationType, ob::StateValidityCheckerSpecs::NONE);
}

TEST(OmplPlugin, AreValidGivesIsValidsVerdicts) {
  // A batch of sampled states (the bundled arm, the rover's SE(2) and the flyer's SE(3)) in one call and in
  // slices of odd lengths: each verdict is isValid's, and each state is counted once.
  ompl::RNG::setSeed(13);
  for (const std::string file : {bundledScene(), ourScene("rover_gap.yaml"), ourScene("flyer_post.yaml")}) {
    const auto scene = Scene::load(file);
    auto si = std::make_shared<ob::SpaceInformation>(makeStateSpace(*scene));
    const CollisionChecking c = setupCollisionChecking(si, scene);
    auto sampler = si->allocStateSampler();
    constexpr std::size_t kCount = 301;
    std::vector<ob::State*> states(kCount);
    for (ob::State*& st : states) {
      st = si->allocState();
      sampler->sampleUniform(st);
    }
    std::vector<char> expected(kCount);
    int valid = 0;
    for (std::size_t k = 0; k < kCount; ++k) valid += expected[k] = c.validity->isValid(states[k]);
    const std::uint64_t before = c.validity->counters().states.load();
    std::unique_ptr<bool[]> got(new bool[kCount]);
    c.validity->areValid(states.data(), kCount, got.get());
    EXPECT_EQ(c.validity->counters().states.load(), before + kCount) << file;
    for (std::size_t k = 0; k < kCount; ++k) EXPECT_EQ(got[k], static_cast<bool>(expected[k])) << file << " state " << k;
    for (std::size_t first = 0; first < kCount; first += 7)
      c.validity->areValid(states.data() + first, std::min<std::size_t>(7, kCount - first), got.get() + first);
    for (std::size_t k = 0; k < kCount; ++k) EXPECT_EQ(got[k], static_cast<bool>(expected[k])) << file << " slices, state " << k;
    EXPECT_GT(valid, 10) << file;
    EXPECT_LT(valid, static_cast<int>(kCount) - 10) << file;
    for (ob::State* st : states) si->freeState(st);
  }
}

TEST(OmplPlugin, MovingObstaclesAreRefused) {
  // OMPL's states carry no time: a scene with moving obstacles is refused, not checked at t = 0.
  TempDir dir;
  const std::string urdf = dir.write("spinner.urdf", kSpinnerUrdf);
  const auto scene = Scene::load(dir.write("moving.yaml", "format: 1\nname: moving\nrobot:\n  urdf: " + urdf +
                                                              "\n  group: [spin, lift]\nenvironment:\n  obstacles:\n"
                                                              "    - {name: ball, sphere: {radius: 0.1}, pose: {position: [0, 1, 0]}, "
                                                              "velocity: [0, -1, 0]}\nchecks: [environment, moving]\n"));
  auto si = std::make_shared<ob::SpaceInformation>(makeStateSpace(*scene));
  EXPECT_THROW(setupCollisionChecking(si, scene), std::invalid_argument);
}

TEST(OmplPlugin, MotionValidatorTakesTheShortWayAndReportsLastValid) {
  TempDir dir;
  const auto scene = spinnerScene(dir);
  auto si = std::make_shared<ob::SpaceInformation>(makeStateSpace(*scene));
  si->setStateValidityCheckingResolution(0.5);  // coarse: the sampled check would step over the post
  const CollisionChecking c = setupCollisionChecking(si, scene);
  const StateMap map(*scene);
  ob::ScopedState<> a(si->getStateSpace()), b(si->getStateSpace()), last(si->getStateSpace());
  const double qa[2] = {3.0, 0}, qb[2] = {-3.0, 0};
  map.fromVector(qa, a.get());
  map.fromVector(qb, b.get());
  ASSERT_TRUE(si->isValid(a.get()));
  ASSERT_TRUE(si->isValid(b.get()));
  EXPECT_FALSE(si->checkMotion(a.get(), b.get()));
  std::pair<ob::State*, double> lv(last.get(), -1.0);
  ASSERT_FALSE(si->checkMotion(a.get(), b.get(), lv));
  // The bar's far end (1 m, half-width 0.025) meets the post (0.8 m, radius 0.02) where
  // 0.8·sin(π − θ) = 0.045: θ = π − asin(0.045 / 0.8); the segment runs 3 → 2π − 3.
  const double theta = M_PI - std::asin(0.045 / 0.8);
  const double s_touch = (theta - 3.0) / (2 * M_PI - 6.0);
  EXPECT_GT(lv.second, 0.0);
  EXPECT_LE(lv.second, s_touch + 1e-9);
  EXPECT_GE(lv.second, s_touch - 0.01);
  EXPECT_TRUE(si->isValid(last.get()));
  // The long way round (through 0) is free: split it in two short segments.
  ob::ScopedState<> zero(si->getStateSpace());
  const double q0[2] = {0.0, 0.3};
  map.fromVector(q0, zero.get());
  EXPECT_TRUE(si->checkMotion(a.get(), zero.get()));
  EXPECT_TRUE(si->checkMotion(zero.get(), b.get()));
  EXPECT_EQ(c.motion->counters().motions.load(), 4u);
}

// The validator remembers a thread's last 64 answers (OMPL's simplifier asks many segments again): an answer
// given again equals the one a validator without that memory computes, a verdict alone never stands in for a
// located contact, and an edit of the world forgets every answer.
TEST(OmplPlugin, TheMotionValidatorRemembersItsLastAnswers) {
  auto world = World::load(bundledScene());
  const auto scene = world->current().scene;
  auto si = std::make_shared<ob::SpaceInformation>(makeStateSpace(*scene));
  const CollisionChecking c = setupCollisionChecking(si, world);
  auto fresh_si = std::make_shared<ob::SpaceInformation>(makeStateSpace(*scene));
  const CollisionChecking fresh = setupCollisionChecking(fresh_si, scene);  // asked each segment once
  ompl::RNG::setSeed(11);
  const ob::StateSamplerPtr sampler = si->allocStateSampler();
  std::vector<ob::ScopedState<>> a, b;
  for (int k = 0; k < 48; ++k) {
    a.emplace_back(si->getStateSpace());
    b.emplace_back(si->getStateSpace());
    sampler->sampleUniform(a.back().get());
    sampler->sampleUniform(b.back().get());
  }
  int colliding = 0;
  for (int k = 0; k < 48; ++k) {
    const bool locate = k % 2 == 0;
    const MotionResult want = fresh.motion->check(a[k].get(), b[k].get(), locate);
    const std::uint64_t kept = c.motion->counters().remembered.load();
    const MotionResult first = c.motion->check(a[k].get(), b[k].get(), locate);
    EXPECT_EQ(c.motion->counters().remembered.load(), kept) << "segment " << k;
    const MotionResult again = c.motion->check(a[k].get(), b[k].get(), locate);
    EXPECT_EQ(c.motion->counters().remembered.load(), kept + 1) << "segment " << k;
    for (const MotionResult* got : {&first, &again}) {
      ASSERT_EQ(got->free, want.free) << "segment " << k;
      EXPECT_EQ(got->first_contact, want.first_contact) << "segment " << k;
      EXPECT_EQ(got->last_valid, want.last_valid) << "segment " << k;
      EXPECT_EQ(got->report.kind, want.report.kind) << "segment " << k;
      EXPECT_EQ(got->report.link, want.report.link) << "segment " << k;
    }
    EXPECT_EQ(again.steps, 0) << "segment " << k;  // (no work for a remembered answer)
    colliding += !want.free;
  }
  EXPECT_GT(colliding, 0);
  EXPECT_LT(colliding, 48);
  EXPECT_EQ(c.motion->counters().motions.load(), 96u);
  // Not remembering (a benchmark timing the check itself), every answer is computed again.
  c.motion->setRemembering(false);
  const std::uint64_t kept_off = c.motion->counters().remembered.load();
  EXPECT_GT(c.motion->check(a[0].get(), b[0].get(), true).steps, 0);
  EXPECT_EQ(c.motion->counters().remembered.load(), kept_off);
  c.motion->setRemembering(true);

  // A colliding segment asked for its verdict alone, then for its first contact: computed again, and equal to
  // the located answer of a validator that never saw it.
  int k = 0;
  while (k < 48 && fresh.motion->check(a[k].get(), b[k].get(), false).free) ++k;
  ASSERT_LT(k, 48);
  ob::ScopedState<> c0(si->getStateSpace()), c1(si->getStateSpace());
  si->getStateSpace()->interpolate(a[k].get(), b[k].get(), 0.0, c0.get());  // (new states: not remembered yet)
  si->copyState(c1.get(), b[k].get());
  EXPECT_FALSE(c.motion->checkMotion(c0.get(), c1.get()));
  const std::uint64_t kept = c.motion->counters().remembered.load();
  std::pair<ob::State*, double> last(nullptr, -1.0);
  EXPECT_FALSE(c.motion->checkMotion(c0.get(), c1.get(), last));
  EXPECT_EQ(c.motion->counters().remembered.load(), kept);
  EXPECT_EQ(last.second, fresh.motion->check(c0.get(), c1.get(), true).last_valid);
  // Asked again for either, the located answer serves both.
  EXPECT_FALSE(c.motion->checkMotion(c0.get(), c1.get()));
  EXPECT_EQ(c.motion->counters().remembered.load(), kept + 1);

  // A free segment, then an obstacle on it: the edited world's answer, not the one remembered.
  int f = 0;
  while (f < 48 && !fresh.motion->check(a[f].get(), b[f].get(), false).free) ++f;
  ASSERT_LT(f, 48);
  ASSERT_TRUE(c.motion->checkMotion(a[f].get(), b[f].get()));
  std::vector<double> q(scene->dimension());
  const StateMap map(*scene);
  ob::ScopedState<> mid(si->getStateSpace());
  si->getStateSpace()->interpolate(a[f].get(), b[f].get(), 0.5, mid.get());
  map.toVector(mid.get(), q.data());
  world->addObstacle(test::ballAtLink(*scene, q, "wrist_2_link", 0.05));
  const std::uint64_t before_edit = c.motion->counters().remembered.load();
  EXPECT_FALSE(c.motion->checkMotion(a[f].get(), b[f].get()));
  EXPECT_EQ(c.motion->counters().remembered.load(), before_edit);
}

// A segment between points OMPL interpolates on a segment certified free is answered free at once, as lying
// within it (counters().within), and its states are free; a segment that runs past the free one's end is
// checked, and so is one after an edit of the world (a new snapshot keeps nothing).
TEST(OmplPlugin, SegmentsWithinAFreeOneAreAnsweredFree) {
  auto world = World::load(bundledScene());
  const auto scene = world->current().scene;
  auto si = std::make_shared<ob::SpaceInformation>(makeStateSpace(*scene));
  const CollisionChecking c = setupCollisionChecking(si, world);
  const ob::StateSpacePtr& space = si->getStateSpace();
  const StateMap map(*scene);
  ompl::RNG::setSeed(12);
  const ob::StateSamplerPtr sampler = si->allocStateSampler();
  ob::ScopedState<> a(space), b(space), x(space), y(space);
  std::vector<double> q(scene->dimension());
  int answered = 0;
  for (int k = 0; k < 3000 && answered < 12; ++k) {
    sampler->sampleUniform(a.get());
    sampler->sampleUniform(b.get());
    if (!si->isValid(a.get()) || !c.motion->checkMotion(a.get(), b.get())) continue;
    const double s = 0.1 * (k % 5), t = 1.0 - 0.07 * (k % 7);
    space->interpolate(a.get(), b.get(), s, x.get());
    space->interpolate(a.get(), b.get(), t, y.get());
    const std::uint64_t before = c.motion->counters().within.load();
    const MotionResult r = c.motion->check(x.get(), y.get(), /*locate_contact=*/k % 2 == 0);
    ASSERT_TRUE(r.free) << "segment " << k;
    EXPECT_EQ(c.motion->counters().within.load(), before + 1) << "segment " << k;
    EXPECT_EQ(r.steps, 0) << "segment " << k;
    for (int i = 0; i <= 100; ++i) {
      space->interpolate(x.get(), y.get(), i / 100.0, a.get());
      map.toVector(a.get(), q.data());
      EXPECT_TRUE(scene->isFree(q)) << "segment " << k << " at " << i / 100.0;
    }
    ++answered;
  }
  EXPECT_EQ(answered, 12);
  // Past the end of a free segment: checked.
  int f = 0;
  for (; f < 3000; ++f) {
    sampler->sampleUniform(a.get());
    sampler->sampleUniform(b.get());
    space->interpolate(a.get(), b.get(), 0.9, x.get());
    if (si->isValid(a.get()) && c.motion->checkMotion(a.get(), x.get())) break;
  }
  ASSERT_LT(f, 3000);
  const std::uint64_t before = c.motion->counters().within.load();
  space->interpolate(a.get(), b.get(), 0.5, y.get());
  c.motion->checkMotion(y.get(), b.get());
  EXPECT_EQ(c.motion->counters().within.load(), before);
  EXPECT_TRUE(c.motion->checkMotion(y.get(), x.get()));
  EXPECT_EQ(c.motion->counters().within.load(), before + 1);
  // An obstacle on the free segment: the sub-segment through it is checked in the edited world, and collides.
  space->interpolate(a.get(), x.get(), 0.6, b.get());
  map.toVector(b.get(), q.data());
  world->addObstacle(test::ballAtLink(*scene, q, "wrist_2_link", 0.05));
  EXPECT_FALSE(c.motion->checkMotion(y.get(), x.get()));
  EXPECT_EQ(c.motion->counters().within.load(), before + 1);
}

// Plans on the bundled scene with the given planner and checks the path independently: every segment
// certified free, and dense samples along it valid.
void planAndCertify(const std::function<ob::PlannerPtr(const ob::SpaceInformationPtr&)>& makePlanner,
                    const std::string& scene_file = bundledScene()) {
  const auto scene = Scene::load(scene_file);
  og::SimpleSetup setup(makeStateSpace(*scene));
  const CollisionChecking c = setupCollisionChecking(setup.getSpaceInformation(), scene);
  const StateMap map(*scene);
  ob::ScopedState<> start(setup.getStateSpace()), goal(setup.getStateSpace());
  map.fromVector(scene->description().start.data(), start.get());
  map.fromVector(scene->description().goal.data(), goal.get());
  setup.setStartAndGoalStates(start, goal);
  setup.setPlanner(makePlanner(setup.getSpaceInformation()));
  ASSERT_EQ(setup.solve(60.0), ob::PlannerStatus::EXACT_SOLUTION);
  setup.simplifySolution();
  og::PathGeometric& path = setup.getSolutionPath();
  ASSERT_GE(path.getStateCount(), 2u);
  // The straight line is blocked: the planner had to find a way round.
  EXPECT_FALSE(setup.getSpaceInformation()->checkMotion(start.get(), goal.get()));
  const MotionChecker certified(scene);
  MotionOptions dense;
  dense.mode = MotionMode::Sampled;
  dense.resolution = 2e-3;
  const MotionChecker sampled(scene, dense);
  MotionContext cc = certified.makeContext(), sc = sampled.makeContext();
  std::vector<double> q0(scene->dimension()), q1(scene->dimension());
  for (std::size_t i = 0; i + 1 < path.getStateCount(); ++i) {
    map.toVector(path.getState(i), q0.data());
    map.toVector(path.getState(i + 1), q1.data());
    map.unwrap(q0.data(), q1.data());
    EXPECT_TRUE(certified.check(q0.data(), q1.data(), cc).free) << "segment " << i;
    EXPECT_TRUE(sampled.check(q0.data(), q1.data(), sc).free) << "segment " << i;
  }
  EXPECT_GT(c.motion->counters().motions.load(), 0u);
  // OMPL's own counters, as DiscreteMotionValidator keeps them (Planner Arena's "valid segment fraction").
  EXPECT_GT(c.motion->getValidMotionCount(), 0u);
  EXPECT_GT(c.motion->getInvalidMotionCount(), 0u);
  EXPECT_GT(c.motion->getValidMotionFraction(), 0.0);
  EXPECT_LT(c.motion->getValidMotionFraction(), 1.0);
}


TEST(OmplPlugin, PlanarAndFloatingJointsAreSE2AndSE3) {
  ompl::RNG::setSeed(12);  // sampled states: a failure replays with the same ones
  const auto rover = Scene::load(ourScene("rover_gap.yaml"));
  const auto flyer = Scene::load(ourScene("flyer_post.yaml"));
  const ob::StateSpacePtr rs = makeStateSpace(*rover), fs = makeStateSpace(*flyer);
  ASSERT_TRUE(rs->isCompound());
  ASSERT_EQ(rs->as<ob::CompoundStateSpace>()->getSubspaceCount(), 2u);
  const auto* se2 = dynamic_cast<ob::SE2StateSpace*>(rs->as<ob::CompoundStateSpace>()->getSubspace(0).get());
  ASSERT_NE(se2, nullptr);
  EXPECT_EQ(se2->getBounds().low[0], -2.0);
  EXPECT_EQ(se2->getBounds().high[1], 2.0);
  ASSERT_TRUE(fs->isCompound());
  ASSERT_EQ(fs->as<ob::CompoundStateSpace>()->getSubspaceCount(), 1u);
  EXPECT_NE(dynamic_cast<ob::SE3StateSpace*>(fs->as<ob::CompoundStateSpace>()->getSubspace(0).get()), nullptr);

  // The segment the motion validator checks is the one OMPL's planners interpolate: SE(2)'s yaw the
  // short way round, SE(3)'s rotation by slerp the short way.
  for (const auto& scene : {rover, flyer}) {
    const ob::StateSpacePtr space = makeStateSpace(*scene);
    const StateMap map(*scene);
    const MotionChecker checker(scene);
    const int n = scene->dimension();
    ob::ScopedState<> a(space), b(space), c(space);
    auto sampler = space->allocStateSampler();
    std::vector<double> qa(n), qb(n), qc(n), ours(n), back(n);
    for (int trial = 0; trial < 200; ++trial) {
      sampler->sampleUniform(a.get());
      sampler->sampleUniform(b.get());
      const double t = (trial % 9 + 1) / 10.0;
      space->interpolate(a.get(), b.get(), t, c.get());
      map.toVector(a.get(), qa.data());
      map.toVector(b.get(), qb.data());
      map.toVector(c.get(), qc.data());
      map.unwrap(qa.data(), qb.data());
      checker.interpolate(qa.data(), qb.data(), t, ours.data());
      map.fromVector(ours.data(), c.get());  // (wraps the angle the way OMPL keeps it)
      map.toVector(c.get(), back.data());
      for (int i = 0; i < n; ++i) ASSERT_NEAR(back[i], qc[i], 1e-9) << scene->name() << " trial " << trial << " entry " << i;
    }
  }

  // A planar joint without bounds on its position cannot be sampled: a clear error.
  TempDir dir;
  const std::string urdf = std::string(CLEARWAY_SOURCE_DIR) + "/robots/rover/rover.urdf";
  const auto unbounded = Scene::load(dir.write("u.yaml", "format: 1\nname: unbounded\nrobot:\n  urdf: " + urdf +
                                                          "\n  group: [drive]\nchecks: [self]\n"));
  try {
    makeStateSpace(*unbounded);
    ADD_FAILURE() << "no error for an unbounded planar joint";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("drive/x"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("robot.bounds"), std::string::npos) << e.what();
  }
}

TEST(OmplPlugin, PlansForARoverAndAFreeFlyer) {
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  ompl::RNG::setSeed(42);
  const auto rrt = [](const ob::SpaceInformationPtr& si) { return std::make_shared<og::RRTConnect>(si); };
  planAndCertify(rrt, ourScene("rover_gap.yaml"));
  planAndCertify(rrt, ourScene("flyer_post.yaml"));
}

TEST(OmplPlugin, PlansOnTheBundledScene) {
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  ompl::RNG::setSeed(42);
  planAndCertify([](const ob::SpaceInformationPtr& si) { return std::make_shared<og::RRTConnect>(si); });
}

// A world edited between two plans, with the same space information: the first path is blocked by an
// obstacle added on it, and the second plan goes around it, every segment certified in the edited world.
TEST(OmplPlugin, PlansAgainAfterAnEditWithoutNewSpaceInformation) {
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  ompl::RNG::setSeed(7);
  auto world = World::load(bundledScene());
  const auto scene = world->current().scene;
  og::SimpleSetup setup(makeStateSpace(*scene));
  const CollisionChecking c = setupCollisionChecking(setup.getSpaceInformation(), world);
  const StateMap map(*scene);
  ob::ScopedState<> start(setup.getStateSpace()), goal(setup.getStateSpace());
  map.fromVector(scene->description().start.data(), start.get());
  map.fromVector(scene->description().goal.data(), goal.get());
  setup.setStartAndGoalStates(start, goal);
  setup.setPlanner(std::make_shared<og::RRTConnect>(setup.getSpaceInformation()));
  ASSERT_EQ(setup.solve(30.0), ob::PlannerStatus::EXACT_SOLUTION);
  og::PathGeometric first = setup.getSolutionPath();
  first.interpolate(50);
  // A ball where the wrist is halfway along the first path.
  std::vector<double> q(scene->dimension());
  map.toVector(first.getState(first.getStateCount() / 2), q.data());
  world->addObstacle(test::ballAtLink(*scene, q, "wrist_2_link", 0.06));
  EXPECT_FALSE(c.validity->isValid(first.getState(first.getStateCount() / 2)));
  bool first_blocked = false;
  for (std::size_t i = 0; i + 1 < first.getStateCount(); ++i)
    first_blocked = first_blocked || !c.motion->check(first.getState(i), first.getState(i + 1)).free;
  EXPECT_TRUE(first_blocked);

  setup.clear();  // the planner's trees were grown in the old world; the space information stays
  ASSERT_EQ(setup.solve(30.0), ob::PlannerStatus::EXACT_SOLUTION);
  og::PathGeometric& second = setup.getSolutionPath();
  for (std::size_t i = 0; i + 1 < second.getStateCount(); ++i)
    EXPECT_TRUE(c.motion->check(second.getState(i), second.getState(i + 1)).free) << "segment " << i;
  EXPECT_EQ(c.validity->world().version(), 2u);
}

// A Panda start 0.5 mm below a ceiling: within the certified check's contact distance (1 mm), but free,
// so it must be leavable and the problem planned (it once used up the whole time limit).
TEST(OmplPlugin, PlansFromAStartJustBelowACeiling) {
  CLEARWAY_REQUIRE_SHARED("robots/panda/panda.urdf");
  CLEARWAY_SHARED_OR_SKIP(file, "scenes/box_panda/box_panda_0001.yaml");
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  ompl::RNG::setSeed(5);
  SceneDescription d = parseSceneFile(file);
  d.octomap.clear();
  d.effects.clearance = true;
  SceneDescription::ObstacleSpec ceiling;
  ceiling.name = "ceiling";
  ceiling.shape = Box(Vec3(2.0, 2.0, 0.05));
  ceiling.pose = Pose::translation(Vec3(0, 0, 3.0));
  d.obstacles = {ceiling};
  d.effects.self = false;  // (clearance from the ceiling alone)
  const auto ceilingClearance = [&] {
    const Scene probe(d);
    SceneContext pc = probe.makeContext();
    return probe.clearance(d.start.data(), pc);
  };
  const double high = ceilingClearance();
  ASSERT_GT(high, 0.5);
  d.obstacles[0].pose = Pose::translation(Vec3(0, 0, 3.0 - high + 5e-4));
  const double gap = ceilingClearance();
  ASSERT_GT(gap, 4e-4);
  ASSERT_LT(gap, 6e-4);
  d.effects.self = true;
  d.effects.clearance = false;
  const auto scene = std::make_shared<const Scene>(d);
  ASSERT_TRUE(scene->isFree(d.start));
  ASSERT_TRUE(scene->isFree(d.goal));

  og::SimpleSetup setup(makeStateSpace(*scene));
  const CollisionChecking c = setupCollisionChecking(setup.getSpaceInformation(), scene);
  const StateMap map(*scene);
  ob::ScopedState<> start(setup.getStateSpace()), goal(setup.getStateSpace());
  map.fromVector(d.start.data(), start.get());
  map.fromVector(d.goal.data(), goal.get());
  EXPECT_TRUE(c.motion->check(start.get(), start.get()).free);
  setup.setStartAndGoalStates(start, goal);
  setup.setPlanner(std::make_shared<og::RRTConnect>(setup.getSpaceInformation()));
  ASSERT_EQ(setup.solve(30.0), ob::PlannerStatus::EXACT_SOLUTION);
  og::PathGeometric& path = setup.getSolutionPath();
  for (std::size_t i = 0; i + 1 < path.getStateCount(); ++i)
    EXPECT_TRUE(c.motion->check(path.getState(i), path.getState(i + 1)).free) << "segment " << i;
}

// OMPL's parallel planners call the checkers from several threads at once (pRRT: two trees grown in
// parallel; PRM: the roadmap grows in one thread while another looks for a solution). Run under
// ThreadSanitizer by scripts/tsan.sh.
TEST(OmplPlugin, ParallelPlannersShareTheCheckers) {
  ompl::RNG::setSeed(13);  // sampled states: a failure replays with the same ones
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  planAndCertify([](const ob::SpaceInformationPtr& si) {
    auto p = std::make_shared<og::pRRT>(si);
    p->setThreadCount(2);
    return p;
  });
  planAndCertify([](const ob::SpaceInformationPtr& si) { return std::make_shared<og::PRM>(si); });
}

// Four threads ask the same checkers what one thread asked them: the answers must not change.
TEST(OmplPlugin, ThreadsShareTheCheckers) {
  ompl::RNG::setSeed(14);  // sampled states: a failure replays with the same ones
  const auto scene = Scene::load(bundledScene());
  auto si = std::make_shared<ob::SpaceInformation>(makeStateSpace(*scene));
  setupCollisionChecking(si, scene);
  const StateMap map(*scene);
  // Serial answers first.
  constexpr int kStates = 200;
  std::vector<ob::State*> states(kStates + 1);
  auto sampler = si->allocStateSampler();
  for (auto& s : states) {
    s = si->allocState();
    sampler->sampleUniform(s);
  }
  std::vector<char> valid(kStates), motion(kStates);
  for (int i = 0; i < kStates; ++i) {
    valid[i] = si->isValid(states[i]);
    motion[i] = si->checkMotion(states[i], states[i + 1]);
  }
  std::vector<int> wrong(4, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int i = t; i < kStates; i += 2) {
        wrong[t] += si->isValid(states[i]) != static_cast<bool>(valid[i]);
        wrong[t] += si->checkMotion(states[i], states[i + 1]) != static_cast<bool>(motion[i]);
      }
    });
  for (auto& th : threads) th.join();
  for (int t = 0; t < 4; ++t) EXPECT_EQ(wrong[t], 0) << "thread " << t;
  for (auto* s : states) si->freeState(s);
}

}  // namespace
}  // namespace clearway
