// Cast mode (src/motion/certified.cpp, MotionMode::Cast): what only translates is measured by one shape cast,
// and its verdicts agree with dense sampling.
#include "motion/motion_fixtures.h"

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

TEST(MotionCast, ThinWallAndColumnInOneCastEach) {
  TempDir dir;
  const auto scene = gantryScene(dir);
  // (Both without the rake, whose bounding balls would settle items before either measures them.)
  const MotionChecker cast(scene, unraked(castMode())), certified(scene, unraked({}));
  MotionContext xc = cast.makeContext(), cc = certified.makeContext();
  const MotionChecker coarse(scene, sampled(0.3));
  MotionContext sc = coarse.makeContext();

  // Through the wall along x at the tool's height: the tool (x from −0.02 to 0.18 about the ram) meets the
  // wall's face at x = −0.3005 when the ram is at −0.3005 − 0.18 (moving +x from −0.8 to 0.3).
  const double q0[4] = {-0.8, 0, 0.05, 0}, q1[4] = {0.3, 0, 0.05, 0};
  EXPECT_TRUE(coarse.check(q0, q1, sc).free) << "the test needs a resolution that tunnels";
  const MotionResult r = cast.check(q0, q1, xc);
  const MotionResult c = certified.check(q0, q1, cc);
  ASSERT_FALSE(r.free);
  EXPECT_EQ(r.report.kind, CollisionReport::Kind::Environment);
  const double contact = cast.options().contact_distance;
  const double touch = (-0.3005 - 0.18 + 0.8) / 1.1;
  EXPECT_LE(r.first_contact, touch + 1e-9);
  EXPECT_GE(r.first_contact, touch - contact / 1.1 - 1e-9);
  EXPECT_NEAR(r.first_contact, c.first_contact, 2 * contact / 1.1);
  double q[4];
  cast.interpolate(q0, q1, r.last_valid, q);
  EXPECT_TRUE(scene->isFree(std::vector<double>(q, q + 4)));
  // Head on, advancement with an exact bound (a translation) is as quick; the random test below shows
  // what casts save on glancing approaches.
  EXPECT_LE(r.distance_queries, c.distance_queries);

  // Into the column (a self pair): the ram at y = 0.6 runs +x; the tool's tip at +0.18 meets the column's
  // face at x = 0.55 when the ram is at 0.37 (from x = 0, above the block, past the wall).
  const double a0[4] = {0.0, 0.6, 0.1, 0}, a1[4] = {1.0, 0.6, 0.1, 0};
  const MotionResult self = cast.check(a0, a1, xc);
  ASSERT_FALSE(self.free);
  EXPECT_EQ(self.report.kind, CollisionReport::Kind::Self);
  EXPECT_LE(self.first_contact, 0.37 + 1e-9);
  EXPECT_GE(self.first_contact, 0.37 - contact - 1e-9);
  EXPECT_LE(self.distance_queries, certified.check(a0, a1, cc).distance_queries);

  // Spinning while sliding is not a translation: the items it turns are left to the certified coverage
  // (only base/ram still translates), with its verdict; the contact found may differ within the contact
  // distance (the tool's tip moves about 1.2 m over the segment: 1 mm is about 1e-3 of it).
  const double s1[4] = {0.3, 0, 0.05, 3.0};
  MotionContext xf = cast.makeContext(), cf = certified.makeContext();
  const MotionResult spun = cast.check(q0, s1, xf), spun_certified = certified.check(q0, s1, cf);
  EXPECT_FALSE(spun.free);
  EXPECT_FALSE(spun_certified.free);
  EXPECT_EQ(spun.report.kind, spun_certified.report.kind);
  EXPECT_NEAR(spun.first_contact, spun_certified.first_contact, 2e-3);
  EXPECT_LE(spun.distance_queries, spun_certified.distance_queries + 2);

  // Clear moves are free in one query per moving item.
  const double b0[4] = {0.0, 0.2, 0.3, 1.0}, b1[4] = {0.3, 0.3, 0.45, 1.0};
  const MotionResult clear = cast.check(b0, b1, xc);
  EXPECT_TRUE(clear.free);
  EXPECT_LE(clear.distance_queries, 4);  // base/ram, base/tool, and the ram and the tool against the environment
}

TEST(MotionCast, RandomSegmentsAgreeWithDenseSampling) {
  // Random segments of the gantry, two in three translations only: dense sampling finding a collision
  // means the cast mode finds one, no later; its verdicts are certified's (both report contact within
  // contact_distance, so they may differ only on segments that come that close).
  TempDir dir;
  const auto scene = gantryScene(dir);
  const MotionChecker cast(scene, unraked(castMode())), certified(scene, unraked({}));
  MotionContext xc = cast.makeContext(), cc = certified.makeContext();
  const MotionChecker fine(scene, sampled(1e-3));
  MotionContext fc = fine.makeContext();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> xy(-1, 1), z(0, 0.5), spin(-3, 3);
  int collide = 0, free = 0, agree = 0, total = 0;
  long cast_queries = 0, certified_queries = 0;
  for (int trial = 0; trial < 150; ++trial) {
    const double q0[4] = {xy(rng), xy(rng), z(rng), spin(rng)};
    double q1[4] = {xy(rng), xy(rng), z(rng), spin(rng)};
    if (trial % 3) q1[3] = q0[3];
    if (!scene->isFree(std::vector<double>(q0, q0 + 4)) || !scene->isFree(std::vector<double>(q1, q1 + 4))) continue;
    const MotionResult x = cast.check(q0, q1, xc), c = certified.check(q0, q1, cc), d = fine.check(q0, q1, fc);
    if (!d.free) {
      EXPECT_FALSE(x.free) << "trial " << trial << ": cast missed a collision sampling found";
      EXPECT_LE(x.first_contact, d.first_contact + 1e-9) << "trial " << trial;
    }
    ++total;
    agree += x.free == c.free;
    if (trial % 3) cast_queries += x.distance_queries, certified_queries += c.distance_queries;
    (x.free ? free : collide)++;
  }
  EXPECT_GT(collide, 20);
  EXPECT_GT(free, 20);
  EXPECT_GE(agree, total - 2) << "cast and certified differ beyond near-contact cases";
  EXPECT_LT(2 * cast_queries, certified_queries) << "casts should save most queries on translations";
}

}  // namespace
}  // namespace clearway
