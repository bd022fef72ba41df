// The probe (src/motion/probe.cpp): a verdict-only check learns which state collides first and keeps every
// verdict of the located check.
#include "motion/motion_fixtures.h"
#include "scene_cache.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace clearway {
namespace {

using namespace test;

// The probe checks first the state that collided first most often lately. The slider between a post in
// the middle of its travel and one at its end: segment a meets both (at s = 1/2 and at its end), b only
// the middle one. A fresh probe finds a's end; after segments like b, a's middle.
TEST(MotionCertified, TheProbeLearnsWhichStateCollidesFirst) {
  TempDir dir;
  const std::string urdf = dir.write("slider.urdf", kSliderUrdf);
  const auto scene = Scene::load(dir.write(
      "posts.yaml", "format: 1\nname: posts\nrobot:\n  urdf: " + urdf +
                        "\n  group: [slide, turn]\nenvironment:\n  obstacles:\n"
                        "    - {name: middle, box: {size: [0.02, 0.5, 0.5]}, pose: {position: [0, 0, 0]}}\n"
                        "    - {name: end, box: {size: [0.02, 0.5, 0.5]}, pose: {position: [1, 0, 0]}}\n"
                        "checks: [environment]\nstart: [-1, 0]\ngoal: [-1, 0]\n"));
  const MotionChecker checker(scene);
  MotionContext ctx = checker.makeContext();
  const double a0[2] = {-1, 0}, a1[2] = {1, 0}, b0[2] = {-0.5, 0}, b1[2] = {0.5, 0};
  MotionResult r = checker.check(a0, a1, ctx, false);
  ASSERT_FALSE(r.free);
  EXPECT_EQ(r.first_contact, 1.0) << "a fresh probe checks the end first";
  EXPECT_EQ(r.distance_queries, 0) << "settled by the probe";
  for (int k = 0; k < 10; ++k) {
    r = checker.check(b0, b1, ctx, false);
    ASSERT_FALSE(r.free);
    EXPECT_EQ(r.first_contact, 0.5);
    EXPECT_EQ(r.distance_queries, 0) << "settled by the probe";
  }
  r = checker.check(a0, a1, ctx, false);
  ASSERT_FALSE(r.free);
  EXPECT_EQ(r.first_contact, 0.5) << "the middle, which collided first lately, goes first";
  // Locating the first contact does not probe: the same verdict, at the middle post's face.
  r = checker.check(a0, a1, ctx);
  ASSERT_FALSE(r.free);
  EXPECT_NEAR(r.first_contact, (1.0 - 0.06) / 2.0, 2e-3);
}

// The probe (motion/probe.cpp) ends a verdict-only check at the first of a few states of the segment that
// collides. Its verdicts equal the located check's (which never probes), segment by segment, on
// planner-like segments of which many collide, with moving obstacles too; every segment it settles has a
// colliding state where it says; and where segments seldom collide it runs only now and then.
TEST(MotionCertified, ProbeKeepsEveryVerdict) {
  TempDir dir;
  struct Case {
    std::string name;
    std::shared_ptr<const Scene> scene;
    bool timed = false;
  };
  std::vector<Case> cases;
  cases.push_back({"arm", Scene::load(dir.write("arm.yaml", test::armScene("",
                                           "    - {name: wall, box: {size: [0.004, 1.0, 3.0]}, pose: {position: [0.3, 0, 1.5]}}\n"
                                           "    - {name: shelf, box: {size: [1.0, 1.0, 0.02]}, pose: {position: [0, 0.5, 0.4]}}\n")))});
  cases.push_back({"moving wall", movingWallScene(dir, -1.0, 0.4), true});
  const std::string shared = test::sharedPath("scenes");
  if (!shared.empty() && std::filesystem::exists(shared + "/box_panda"))
    for (const char* name : {"box_panda/box_panda_0001.yaml", "cage_ur5/cage_ur5_0001.yaml",
                             "cage_panda/cage_panda_0001.octomap.yaml"})
      cases.push_back({name, test::loadScene(shared + "/" + name)});
  else
    std::printf("shared scenes not found: the probe is compared on our own scenes only\n");
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const Scene& scene = *c.scene;
    const MotionChecker checker(c.scene);
    MotionContext located = checker.makeContext(), verdict = checker.makeContext();
    SceneContext sc = scene.makeContext();
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const int n = scene.dimension();
    std::vector<double> q0(n), q1(n), at(n);
    int segments = 0, colliding = 0, settled = 0, at_end = 0;
    while (segments < 300) {
      for (int i = 0; i < n; ++i) {
        q0[i] = scene.lower(i) + u(rng) * (scene.upper(i) - scene.lower(i));
        q1[i] = scene.lower(i) + u(rng) * (scene.upper(i) - scene.lower(i));  // (RRTConnect's connect steps are long)
      }
      const double t0 = c.timed ? u(rng) : 0.0, t1 = c.timed ? t0 + 2.0 * u(rng) : 0.0;
      // Every third segment is an extension of RRTConnect's start tree, whose end nothing has checked.
      const bool extension = segments % 3 == 2;
      if (!scene.isFree(q0.data(), sc, nullptr, t0) || (!extension && !scene.isFree(q1.data(), sc, nullptr, t1))) continue;
      ++segments;
      const MotionResult a = checker.check(q0.data(), t0, q1.data(), t1, located);
      const MotionResult v = checker.check(q0.data(), t0, q1.data(), t1, verdict, /*locate_contact=*/false);
      ASSERT_EQ(v.free, a.free) << "segment " << segments;
      colliding += !a.free;
      if (v.free || v.distance_queries > 0) continue;
      ++settled;  // by the probe: no item was measured
      EXPECT_TRUE(v.first_contact == 1.0 || v.first_contact == 0.5 || v.first_contact == 0.25 || v.first_contact == 0.75)
          << v.first_contact;
      at_end += v.first_contact == 1.0;
      checker.interpolate(q0.data(), q1.data(), v.first_contact, at.data());
      CollisionReport report;
      EXPECT_FALSE(scene.isFree(at.data(), sc, &report, t0 + v.first_contact * (t1 - t0))) << "segment " << segments;
      EXPECT_EQ(report.kind, v.report.kind) << "segment " << segments;
    }
    std::printf("%s: %d of %d segments collide, %d settled by the probe (%d at the end)\n", c.name.c_str(), colliding,
                segments, settled, at_end);
    EXPECT_GT(colliding, segments / 3);
    EXPECT_LT(colliding, segments);
    EXPECT_GT(settled, colliding / 3);
    EXPECT_GT(at_end, segments / 30) << "the start tree's extensions should often end in a collision";
    // An end out of bounds: not free either way; where the probe settles it, the report says Invalid.
    for (int k = 0; k < 10; ++k) {
      do {
        for (int i = 0; i < n; ++i) q0[i] = scene.lower(i) + u(rng) * (scene.upper(i) - scene.lower(i));
      } while (!scene.isFree(q0.data(), sc));
      q1 = q0;
      q1[k % n] = scene.upper(k % n) + 0.1;
      const MotionResult a = checker.check(q0.data(), q1.data(), located);
      const MotionResult v = checker.check(q0.data(), q1.data(), verdict, false);
      EXPECT_FALSE(a.free || v.free) << "out of bounds " << k;
      if (v.distance_queries == 0 && v.first_contact == 1.0)
        EXPECT_EQ(v.report.kind, CollisionReport::Kind::Invalid) << "out of bounds " << k;
    }
    // Then segments that never collide (a free state held still): the probe stops running on all of
    // them, but still runs on every eighth. A free segment it ran on took four states more than the located
    // check's.
    int probed = 0, quiet = 0;
    while (!scene.isFree(q1.data(), sc))
      for (int i = 0; i < n; ++i) q1[i] = scene.lower(i) + u(rng) * (scene.upper(i) - scene.lower(i));
    for (int k = 0; k < 400; ++k) {
      const MotionResult a = checker.check(q1.data(), 0.0, q1.data(), 0.0, located);
      const MotionResult v = checker.check(q1.data(), 0.0, q1.data(), 0.0, verdict, false);
      ASSERT_TRUE(a.free && v.free);
      ASSERT_TRUE(v.steps == a.steps || v.steps == a.steps + 4) << v.steps << " " << a.steps;
      probed += v.steps > a.steps;
      quiet += k >= 100 && v.steps == a.steps;
    }
    EXPECT_GE(probed, 400 / 8);
    EXPECT_LE(probed, 40 + 400 / 8);
    EXPECT_GE(quiet, 300 * 7 / 8 - 1);
  }
}

}  // namespace
}  // namespace clearway
