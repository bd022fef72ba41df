// Scene::areFree and Scene::anyCollides against Scene::isFree, verdict by verdict: every shared family in both its primitive and
// its OctoMap form, our robots' scenes (floating and planar joints among them, and 528 pairs of primitives), batches of every length
// around the lane width, invalid states inside a batch, scenes that check nothing or can never be free,
// a context of another robot, and the lanes forced to every SIMD target this machine offers.
#include <clearway/kinematics/kinematic_lanes.h>
#include <clearway/scene/scene.h>

#include "load/robot_files.h"
#include "scene_cache.h"

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include "forced_target.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace clearway {
namespace {

// `count` states uniform in the scene's bounds (unbounded: ±π; floating joints' quaternions normalised);
// every 50th has a NaN and every 77th an entry out of bounds.
std::vector<double> randomStates(const Scene& scene, int count, unsigned seed) {
  std::mt19937 rng(seed);
  const int n = scene.dimension();
  std::vector<double> out(static_cast<std::size_t>(count) * n);
  for (int s = 0; s < count; ++s) {
    double* q = out.data() + static_cast<std::size_t>(s) * n;
    for (int i = 0; i < n; ++i)
      q[i] = std::uniform_real_distribution<double>(std::max(scene.lower(i), -M_PI), std::min(scene.upper(i), M_PI))(rng);
    if (s % 50 == 49) q[s % n] = std::nan("");
    if (s % 77 == 76) q[(s + 1) % n] = scene.upper((s + 1) % n) + 0.5;
  }
  const RobotModel& model = scene.robot();
  for (const Joint& j : model.joints()) {
    if (j.type != JointType::Floating) continue;
    for (int i = 0; i < n; ++i)  // the state entries of the quaternion, by their robot variables
      if (scene.groupVariables()[i] == j.first_variable + 3)
        for (int s = 0; s < count; ++s) {
          double* r = out.data() + static_cast<std::size_t>(s) * n + i;
          const double norm = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3]);
          if (norm > 0.0)
            for (int k = 0; k < 4; ++k) r[k] /= norm;
        }
  }
  return out;
}

// anyCollides over windows of 1 to 12 states: −1 exactly when isFree calls every state of the window free,
// else the first state isFree calls colliding, with a report.
void expectAnyCollidesAgrees(const Scene& scene, const std::vector<double>& states, const std::vector<char>& expected,
                             SceneContext& ctx, const std::string& what, std::vector<double> times = {}) {
  const int n = scene.dimension();
  const int count = static_cast<int>(expected.size());
  times.resize(count, 0.0);
  for (int length = 1; length <= 12; ++length)
    for (int first = 0; first + length <= count; first += 3 * length) {
      int first_hit = -1;
      for (int s = first; s < first + length && first_hit < 0; ++s)
        if (!expected[s]) first_hit = s - first;
      const bool any = first_hit >= 0;
      CollisionReport report;
      const int hit = scene.anyCollides(states.data() + static_cast<std::size_t>(first) * n, length, ctx, &report,
                                        times.data() + first);
      if (!any) {
        EXPECT_EQ(hit, -1) << what << ": states " << first << " + " << length << " are free";
        continue;
      }
      ASSERT_GE(hit, 0) << what << ": states " << first << " + " << length << " hold a collision";
      EXPECT_EQ(hit, first_hit) << what << ": states " << first << " + " << length;
      EXPECT_NE(report.kind, CollisionReport::Kind::None) << what;
    }
}

// areFree's verdicts equal isFree's for every state, in one batch and in batches of one, of a pass less
// or more one, and of two passes and one, on every target. Returns the number of colliding states.
int expectBatchEqualsOneByOne(const Scene& scene, const std::vector<double>& states, const std::string& what) {
  const int n = scene.dimension();
  const int count = static_cast<int>(states.size()) / n;
  SceneContext ctx = scene.makeContext();
  std::vector<char> expected(count);
  int colliding = 0;
  for (int s = 0; s < count; ++s) {
    expected[s] = scene.isFree(states.data() + static_cast<std::size_t>(s) * n, ctx);
    colliding += !expected[s];
  }
  for (const std::int64_t target : KinematicLanes::targets()) {
    const test::ForcedTarget forced(target);
    const int w = KinematicLanes::width();
    for (const int batch : {1, std::max(1, w - 1), w, w + 1, 2 * w + 1}) {
      std::unique_ptr<bool[]> got(new bool[count]);
      for (int first = 0; first < count; first += batch)
        scene.areFree(states.data() + static_cast<std::size_t>(first) * n, std::min(batch, count - first), ctx,
                      got.get() + first);
      for (int s = 0; s < count; ++s)
        EXPECT_EQ(got[s], static_cast<bool>(expected[s]))
            << what << ", target " << hwy::TargetName(target) << ", batches of " << batch << ", state " << s;
    }
    std::unique_ptr<bool[]> all(new bool[count]);
    scene.areFree(states.data(), count, ctx, all.get());
    for (int s = 0; s < count; ++s)
      EXPECT_EQ(all[s], static_cast<bool>(expected[s])) << what << ", target " << hwy::TargetName(target) << ", state " << s;
    expectAnyCollidesAgrees(scene, states, expected, ctx, what + ", target " + hwy::TargetName(target));
  }
  return colliding;
}

std::string bundledScene(const std::string& name) { return std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/" + name; }

}  // namespace

TEST(SceneBatch, EverySharedFamilyInBothForms) {
  CLEARWAY_REQUIRE_SHARED("scenes");
  CLEARWAY_REQUIRE_SHARED("robots/panda/panda.urdf");
  int scenes = 0, colliding = 0, states = 0;
  for (const auto& family : std::filesystem::directory_iterator(test::sharedPath("scenes"))) {
    if (!family.is_directory()) continue;
    const std::string stem = family.path().string() + "/" + family.path().filename().string() + "_0001";
    for (const std::string file : {stem + ".yaml", stem + ".octomap.yaml"}) {
      if (!std::filesystem::exists(file)) continue;
      const auto loaded = test::loadScene(file);
      const Scene& scene = *loaded;
      const std::vector<double> q = randomStates(scene, 240, 7 + scenes);
      colliding += expectBatchEqualsOneByOne(scene, q, file);
      states += static_cast<int>(q.size()) / scene.dimension();
      ++scenes;
    }
  }
  EXPECT_EQ(scenes, 12);
  EXPECT_GT(colliding, states / 10) << "too few colliding states to compare";
  EXPECT_LT(colliding, states * 9 / 10) << "too few free states to compare";
  std::printf("%d scenes, %d states, %d colliding\n", scenes, states, colliding);
}

TEST(SceneBatch, OurScenesWithEveryJointType) {
  for (const char* name : {"arm6_wall.yaml", "flyer_post.yaml", "rover_gap.yaml", "twin_arm_table.yaml", "dual_arm_shelf.yaml"}) {
    const Scene scene(parseSceneFile(bundledScene(name)));
    const std::vector<double> q = randomStates(scene, 300, 3);
    const int colliding = expectBatchEqualsOneByOne(scene, q, name);
    EXPECT_GT(colliding, 0) << name;
    EXPECT_LT(colliding, 300) << name;
  }
}

TEST(SceneBatch, ScenesThatCheckNothingOrCanNeverBeFree) {
  // Without checks every valid state is free; with a static link inside an obstacle none is.
  SceneDescription d = parseSceneFile(bundledScene("arm6_wall.yaml"));
  d.effects.self = d.effects.environment = false;
  const Scene nothing(d);
  const std::vector<double> q = randomStates(nothing, 120, 5);
  expectBatchEqualsOneByOne(nothing, q, "no checks");
  std::unique_ptr<bool[]> got(new bool[120]);
  SceneContext ctx = nothing.makeContext();
  nothing.areFree(q.data(), 120, ctx, got.get());
  for (int s = 0; s < 120; ++s) EXPECT_EQ(got[s], s % 50 != 49 && s % 77 != 76) << s;

  SceneDescription stuck = parseSceneFile(bundledScene("arm6_wall.yaml"));
  SceneDescription::ObstacleSpec block;
  block.name = "around the base";
  block.shape = Box(Vec3(3, 3, 0.2));
  stuck.obstacles.push_back(block);
  const Scene never(stuck);
  ASSERT_NE(never.staticCollision().kind, CollisionReport::Kind::None);
  SceneContext never_ctx = never.makeContext();
  never.areFree(q.data(), 120, never_ctx, got.get());
  for (int s = 0; s < 120; ++s) EXPECT_FALSE(got[s]) << s;
  CollisionReport report;
  EXPECT_EQ(never.anyCollides(q.data(), 5, never_ctx, &report), 0);
  EXPECT_EQ(report.kind, never.staticCollision().kind);
  SceneContext nothing_ctx = nothing.makeContext();
  EXPECT_EQ(nothing.anyCollides(q.data(), 40, nothing_ctx), -1);  // (states 0-39: all valid)
}

TEST(SceneBatch, AnyCollidesReadsEachStatesTime) {
  // The planar arm and a ball falling through its reach: each state is checked where the ball is at its own
  // time, as isFree checks it.
  test::TempDir dir;
  const std::string file = dir.write(
      "moving.yaml", "format: 1\nname: moving\nrobot:\n  urdf: " + test::sourceRobot("planar_arm/planar_arm.urdf") +
                         "\n  group: [shoulder, elbow]\nenvironment:\n  obstacles:\n"
                         "    - {name: ball, sphere: {radius: 0.3}, pose: {position: [0.8, 2, 0]}, velocity: [0, -1, 0]}\n"
                         "checks: [self, environment, moving]\n");
  const Scene scene(parseSceneFile(file));
  const std::vector<double> q = randomStates(scene, 300, 21);
  std::vector<double> times(300);
  std::mt19937 rng(4);
  for (double& t : times) t = std::uniform_real_distribution<double>(0.0, 4.0)(rng);
  SceneContext ctx = scene.makeContext();
  std::vector<char> expected(300);
  int colliding = 0, by_time = 0;
  for (int s = 0; s < 300; ++s) {
    const double* x = q.data() + static_cast<std::size_t>(s) * scene.dimension();
    expected[s] = scene.isFree(x, ctx, nullptr, times[s]);
    colliding += !expected[s];
    by_time += static_cast<bool>(expected[s]) != scene.isFree(x, ctx, nullptr, 0.0);
  }
  EXPECT_GT(by_time, 10) << "the ball's time decides too few states to tell";
  EXPECT_GT(colliding, 0);
  expectAnyCollidesAgrees(scene, q, expected, ctx, "moving ball", times);
}

TEST(SceneBatch, AContextOfAnotherRobotTakesTheStatesOneByOne) {
  // A context made for the twin arm, used with the arm6 scene: no lanes of the wrong robot's kinematics,
  // the verdicts isFree gives (which refuses the misfit context: every state invalid).
  const Scene arm(parseSceneFile(bundledScene("arm6_wall.yaml"))), twin(parseSceneFile(bundledScene("twin_arm_table.yaml")));
  SceneContext other = twin.makeContext();
  const std::vector<double> q = randomStates(arm, 40, 9);
  std::unique_ptr<bool[]> got(new bool[40]);
  arm.areFree(q.data(), 40, other, got.get());
  for (int s = 0; s < 40; ++s) EXPECT_EQ(got[s], arm.isFree(q.data() + s * arm.dimension(), other)) << s;
  SceneContext none;  // default-made: no lanes, no poses
  arm.areFree(q.data(), 40, none, got.get());
  for (int s = 0; s < 40; ++s) EXPECT_FALSE(got[s]) << s;
  CollisionReport report;
  EXPECT_EQ(arm.anyCollides(q.data(), 40, none, &report), 0);
  EXPECT_EQ(report.kind, CollisionReport::Kind::Invalid);
}

}  // namespace clearway
