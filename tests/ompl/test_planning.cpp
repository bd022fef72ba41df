// plan() (clearway/ompl/planning.h), the query `clearway plan` and Python's clearway.plan share: certified
// paths checked again here with a motion checker of our own, the same path for the same seed whatever ran
// before, bad requests refused naming the field, colliding ends reported, and an edited scene planned around.
#include <clearway/motion/motion.h>
#include <clearway/ompl/planning.h>

#include "load/robot_files.h"
#include "ompl/obstacle_on_path.h"

#include <gtest/gtest.h>
#include <ompl/util/Console.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace clearway {
namespace {

// OMPL's progress lines would bury the test output.
const bool kQuiet = (ompl::msg::setLogLevel(ompl::msg::LOG_WARN), true);

std::string bundledScene() { return std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/arm6_wall.yaml"; }

// Every segment of r's path certified free in scene by a checker plan() never saw, from start to goal.
void expectCertified(const std::shared_ptr<const Scene>& scene, const PlanResult& r, const std::vector<double>& start,
                     const std::vector<double>& goal) {
  ASSERT_TRUE(r.solved()) << toString(r.status) << ": " << r.message;
  ASSERT_GE(r.stateCount(), 2u);
  ASSERT_EQ(r.path.size(), r.stateCount() * scene->dimension());
  const int n = scene->dimension();
  for (int k = 0; k < n; ++k) {
    EXPECT_DOUBLE_EQ(r.path[k], start[k]);
    EXPECT_DOUBLE_EQ(r.path[(r.stateCount() - 1) * n + k], goal[k]);
  }
  const MotionChecker checker(scene);
  MotionContext ctx = checker.makeContext();
  for (std::size_t i = 0; i + 1 < r.stateCount(); ++i)
    EXPECT_TRUE(checker.check(&r.path[i * n], &r.path[(i + 1) * n], ctx).free) << "segment " << i;
  EXPECT_GT(r.solve_seconds, 0.0);
  EXPECT_GT(r.state_checks, 0u);
  EXPECT_GT(r.motion_checks, 0u);
  EXPECT_GT(r.length, 0.0);
}

TEST(Planning, ReturnsACertifiedPathOnTheBundledScene) {
  const auto scene = Scene::load(bundledScene());
  PlanRequest request;
  request.seed = 5;
  request.time = 30;
  const PlanResult r = plan(scene, request);
  expectCertified(scene, r, scene->description().start, scene->description().goal);
  EXPECT_GE(r.stateCount(), 3u) << "the wall blocks the straight line";
  EXPECT_TRUE(r.message.empty());
  EXPECT_GT(r.simplify_seconds, 0.0);
  EXPECT_GT(r.simplify_motion_checks, 0u);
}

// OMPL's RNGs draw their seeds from one process-wide generator: a seeded query reseeds it, so neither an
// unseeded query nor one of another seed before it changes its path.
// A bar on a continuous joint and a post at angle 0: from 3 to −3 rad the straight values pass the post
// (through 0), the short way (through π, as OMPL's SO(2) turns) does not. The returned path's angles are
// unwrapped, so its straight segments are the ones certified: a checker of raw values agrees.
TEST(Planning, ContinuousJointsAreUnwrappedAlongThePath) {
  test::TempDir dir;
  const std::string urdf = dir.write("spinner.urdf", R"(<?xml version="1.0"?>
<robot name="spinner">
  <link name="base"/>
  <link name="bar">
    <collision><origin xyz="0.5 0 0"/><geometry><box size="1 0.05 0.05"/></geometry></collision>
  </link>
  <joint name="spin" type="continuous">
    <parent link="base"/><child link="bar"/><axis xyz="0 0 1"/>
  </joint>
</robot>
)");
  const auto scene = Scene::load(dir.write(
      "spinner.yaml", "format: 1\nname: spinner\nrobot:\n  urdf: " + urdf +
                          "\n  group: [spin]\nenvironment:\n  obstacles:\n"
                          "    - {name: post, cylinder: {radius: 0.02, length: 1}, pose: {position: [0.8, 0, 0]}}\n"
                          "checks: [environment, continuous]\nstart: [3]\ngoal: [-3]\n"));
  const MotionChecker checker(scene);
  MotionContext ctx = checker.makeContext();
  const double start = 3.0, goal = -3.0;
  ASSERT_FALSE(checker.check(&start, &goal, ctx).free);  // the straight values pass the post
  PlanRequest request;
  request.seed = 3;
  const PlanResult r = plan(scene, request);
  ASSERT_TRUE(r.solved()) << toString(r.status) << ": " << r.message;
  ASSERT_GE(r.stateCount(), 2u);
  EXPECT_DOUBLE_EQ(r.path.front(), start);
  EXPECT_NEAR(std::remainder(r.path.back() - goal, 2.0 * M_PI), 0.0, 1e-9);  // the goal, whole turns apart
  EXPECT_NEAR(r.path.back(), goal + 2.0 * M_PI, 1e-9);                       // reached through π
  for (std::size_t i = 0; i + 1 < r.stateCount(); ++i) {
    EXPECT_LE(std::abs(r.path[i + 1] - r.path[i]), M_PI) << "segment " << i;
    EXPECT_TRUE(checker.check(&r.path[i], &r.path[i + 1], ctx).free) << "segment " << i;
  }
}

TEST(Planning, TheSameSeedGivesTheSamePath) {
  const auto scene = Scene::load(bundledScene());
  PlanRequest request;
  request.time = 30;
  request.seed = 9;
  const PlanResult first = plan(scene, request);
  ASSERT_TRUE(first.solved()) << first.message;
  PlanRequest other = request;
  other.seed.reset();
  ASSERT_TRUE(plan(scene, other).solved());
  other.seed = 10;
  const PlanResult ten = plan(scene, other);
  ASSERT_TRUE(ten.solved());
  EXPECT_NE(ten.path, first.path) << "seeds 9 and 10 planned the same path: is the seed used at all?";
  const PlanResult again = plan(scene, request);
  EXPECT_EQ(again.path, first.path);
  // Seed 0, which OMPL does not take, plans as 1.
  request.seed = 0;
  const PlanResult zero = plan(scene, request);
  request.seed = 1;
  EXPECT_EQ(zero.path, plan(scene, request).path);
  // Without simplification: the planner's own path, as certified.
  request.simplify = false;
  const PlanResult raw = plan(scene, request);
  expectCertified(scene, raw, scene->description().start, scene->description().goal);
  EXPECT_EQ(raw.simplify_seconds, 0.0);
  EXPECT_EQ(raw.simplify_motion_checks, 0u);
}

TEST(Planning, BadRequestsNameTheField) {
  const auto scene = Scene::load(bundledScene());
  const auto refused = [&](PlanRequest request, const std::string& says) {
    try {
      plan(scene, request);
      ADD_FAILURE() << "accepted; expected: " << says;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what() << " should say " << says;
    }
  };
  PlanRequest r;
  r.planner = "Teleport";
  refused(r, "planner: unknown planner 'Teleport' (known: RRTConnect RRT");
  for (double t : {0.0, -1.0, 1e6 * (1 + 1e-15), std::nan(""), std::numeric_limits<double>::infinity()}) {
    r = PlanRequest();
    r.time = t;
    refused(r, "time: needs a number > 0 and <= 1e6");
  }
  r = PlanRequest();
  r.start = {0, 0, 0};
  refused(r, "start: needs 6 values, got 3");
  r.start = {0, 0, 0, 0, 0, 99};
  refused(r, "start: ");
  r = PlanRequest();
  r.goal = {0, 0, 0, 0, std::nan(""), 0};
  refused(r, "goal: ");
  EXPECT_THROW(plan(std::shared_ptr<const Scene>(), PlanRequest()), std::invalid_argument);
  // A scene without a start needs one given.
  SceneDescription d = parseSceneFile(bundledScene());
  d.start.clear();
  const auto no_start = std::make_shared<const Scene>(d);
  try {
    plan(no_start, PlanRequest());
    ADD_FAILURE() << "planned without a start";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("start: none given"), std::string::npos) << e.what();
  }
  PlanRequest given;
  given.start = scene->description().start;
  given.seed = 3;
  EXPECT_TRUE(plan(no_start, given).solved());
}

TEST(Planning, CollidingEndsAreReportedNotPlanned) {
  const auto scene = Scene::load(bundledScene());
  PlanRequest r;
  r.start = {0, 1.7, 0.5, 0, 0, 0};  // into the floor
  PlanResult result = plan(scene, r);
  EXPECT_EQ(result.status, PlanStatus::StartColliding);
  EXPECT_NE(result.message.find("start is in collision"), std::string::npos) << result.message;
  EXPECT_NE(result.message.find("floor"), std::string::npos) << result.message;
  EXPECT_TRUE(result.path.empty());
  r = PlanRequest();
  r.goal = {0, 1.7, 0.5, 0, 0, 0};
  result = plan(scene, r);
  EXPECT_EQ(result.status, PlanStatus::GoalColliding);
  EXPECT_FALSE(result.solved());
}

// An obstacle put where the wrist passes halfway along the first path: that path is no longer free in
// the edited scene, and the edited scene's plan goes around it, certified there.
TEST(Planning, PlansAroundAnObstacleOfAnEditedScene) {
  const auto scene = Scene::load(bundledScene());
  PlanRequest request;
  request.seed = 7;
  request.time = 30;
  const PlanResult first = plan(scene, request);
  ASSERT_TRUE(first.solved()) << first.message;
  const int n = scene->dimension();
  // The middle of the first path's middle segment.
  const std::size_t i = (first.stateCount() - 1) / 2;
  std::vector<double> mid(n);
  for (int k = 0; k < n; ++k) mid[k] = 0.5 * (first.path[i * n + k] + first.path[(i + 1) * n + k]);
  const Obstacle ball = test::ballAtLink(*scene, mid, "wrist_2_link", 0.06);
  const auto edited = scene->withEnvironment(std::make_shared<const Environment>(scene->environment().withObstacle(ball)));
  ASSERT_FALSE(edited->isFree(mid));
  const PlanResult second = plan(edited, request);
  expectCertified(edited, second, scene->description().start, scene->description().goal);
  EXPECT_NE(second.path, first.path);
}

// A checker built once plans as the scene does (the same path for the same seed: `clearway plan --runs` and
// Python's plan reuse one), with its own options (its contact distance certifies the path); a Sampled
// checker, which certifies nothing, is refused.
TEST(Planning, ACheckerBuiltOncePlansAsItsScene) {
  const auto scene = Scene::load(bundledScene());
  PlanRequest request;
  request.seed = 9;
  request.time = 30;
  const auto checker = std::make_shared<const MotionChecker>(scene);
  const PlanResult first = plan(checker, request);
  expectCertified(scene, first, scene->description().start, scene->description().goal);
  EXPECT_EQ(first.path, plan(scene, request).path);
  EXPECT_EQ(plan(checker, request).path, first.path);

  MotionOptions wide;
  wide.contact_distance = 0.05;
  const auto wide_checker = std::make_shared<const MotionChecker>(scene, wide);
  const PlanResult kept_off = plan(wide_checker, request);
  ASSERT_TRUE(kept_off.solved()) << kept_off.message;
  EXPECT_NE(kept_off.path, first.path) << "the contact distance of the checker given was not used";
  const MotionChecker fresh(scene, wide);
  MotionContext ctx = fresh.makeContext();
  const int n = scene->dimension();
  for (std::size_t i = 0; i + 1 < kept_off.stateCount(); ++i)
    EXPECT_TRUE(fresh.check(&kept_off.path[i * n], &kept_off.path[(i + 1) * n], ctx).free) << "segment " << i;

  MotionOptions sampled;
  sampled.mode = MotionMode::Sampled;
  try {
    plan(std::make_shared<const MotionChecker>(scene, sampled), request);
    ADD_FAILURE() << "a Sampled checker planned";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("checker"), std::string::npos) << e.what();
  }
  EXPECT_THROW(plan(std::shared_ptr<const MotionChecker>(), request), std::invalid_argument);
}

}  // namespace
}  // namespace clearway
