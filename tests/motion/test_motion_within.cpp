// A certified free segment's margin (MotionResult::margin) and the segments within it (MotionChecker::within):
// the margin holds all along the segment, near contact too; sub-segments as OMPL interpolates them are within
// it; a segment whose states move a body farther than the margin is not.
#include <clearway/motion/motion.h>
#include <clearway/scene/scene_file.h>

#include "motion/motion_fixtures.h"
#include "scene_cache.h"
#include "shared_data.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace clearway {
namespace {

// The scenes: our arm by its wall, and the shared Panda's box problem and (unless only a few are asked for:
// its clearances cost a UR5's 104k triangles) the UR5's, when present.
std::vector<std::string> sceneFiles(bool few = false) {
  std::vector<std::string> files{std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/arm6_wall.yaml"};
  for (const char* rel : {"scenes/box_panda/box_panda_0001.yaml", "scenes/box_ur5/box_ur5_0001.yaml"})
    if (!test::sharedPath(rel).empty() && !(few && files.size() == 2)) files.push_back(test::sharedPath(rel));
  return files;
}

// The state OMPL's RealVectorStateSpace::interpolate makes: from + (to − from)·t, entry by entry.
std::vector<double> omplInterpolate(const std::vector<double>& from, const std::vector<double>& to, double t) {
  std::vector<double> q(from.size());
  for (std::size_t i = 0; i < q.size(); ++i) q[i] = from[i] + (to[i] - from[i]) * t;
  return q;
}

// A free start and a segment from it that ends near contact: the state where a located check of a random
// segment from the start last knew it free (or the random end when that segment is free). False when no
// free start was drawn.
bool grazingSegment(const Scene& scene, const MotionChecker& checker, MotionContext& ctx, std::mt19937& rng,
                    std::vector<double>& q0, std::vector<double>& q1) {
  q0 = test::randomState(scene, rng);
  if (!scene.isFree(q0)) return false;
  q1 = q0;
  std::uniform_real_distribution<double> step(-0.8, 0.8);
  for (int i = 0; i < scene.dimension(); ++i) q1[i] = std::clamp(q0[i] + step(rng), scene.lower(i), scene.upper(i));
  const MotionResult r = checker.check(q0.data(), q1.data(), ctx, /*locate_contact=*/true);
  if (!r.free) checker.interpolate(q0.data(), q1.data(), r.last_valid, q1.data());
  return true;
}

// Every state of a segment certified free stays farther than its margin from everything it is checked
// against (Scene::clearance, exact to GJK's relative error), on segments that end near contact: there the
// clearance falls below the contact distance, where a margin as large as that would be wrong.
TEST(MotionWithin, TheMarginHoldsAllAlongAFreeSegment) {
  int free = 0, near = 0;
  const std::vector<std::string> files = sceneFiles(/*few=*/true);
  for (const std::string& file : files) {
    SceneDescription d = parseSceneFile(file);
    d.effects.clearance = true;  // (Scene::clearance measures)
    const auto scene = std::make_shared<const Scene>(d);
    const MotionChecker checker(scene);
    MotionContext ctx = checker.makeContext();
    SceneContext sc = scene->makeContext();
    std::mt19937 rng(11);
    std::vector<double> q0, q1, q(scene->dimension());
    for (int trial = 0, found = 0; trial < 400 && found < 15; ++trial) {
      if (!grazingSegment(*scene, checker, ctx, rng, q0, q1)) continue;
      const MotionResult r = checker.check(q0.data(), q1.data(), ctx, false);
      if (!r.free) continue;
      ++found, ++free;
      EXPECT_GT(r.margin, 0.0) << file << " trial " << trial;
      EXPECT_LE(r.margin, checker.options().contact_distance) << file << " trial " << trial;
      double least = INFINITY;
      for (int k = 0; k <= 32; ++k) {
        checker.interpolate(q0.data(), q1.data(), k / 32.0, q.data());
        least = std::min(least, scene->clearance(q.data(), sc));
      }
      // (GJK's relative error of 1e-6 on clearances of a few millimetres: far below any margin.)
      EXPECT_GE(least, r.margin - 1e-9) << file << " trial " << trial;
      near += least < checker.options().contact_distance;
    }
  }
  std::printf("%d free segments, %d of them within the contact distance somewhere\n", free, near);
  EXPECT_GE(free, 12 * static_cast<int>(files.size()));  // (of at most 15 a scene)
  EXPECT_GT(near, 4);  // the margin is tested where a margin of the contact distance would fail
}

// Sub-segments of a free segment, their ends made as OMPL interpolates (a few roundings off the line), either
// way round, are within it; a segment that runs past an end, or lies beside it, is not.
TEST(MotionWithin, SubSegmentsOfAFreeSegmentAreWithinIt) {
  int free = 0;
  const std::vector<std::string> files = sceneFiles();
  for (const std::string& file : files) {
    const auto scene = test::loadScene(file);
    const MotionChecker checker(scene);
    MotionContext ctx = checker.makeContext();
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<double> p0, p1;
    for (int trial = 0, found = 0; trial < 300 && found < 20; ++trial) {
      if (!grazingSegment(*scene, checker, ctx, rng, p0, p1)) continue;
      const MotionResult r = checker.check(p0.data(), p1.data(), ctx, false);
      if (!r.free || p0 == p1) continue;  // (a segment of length 0 holds only its ends)
      ++found, ++free;
      const double a = unit(rng), b = unit(rng);
      const std::vector<double> x = omplInterpolate(p0, p1, a), y = omplInterpolate(p0, p1, b);
      EXPECT_TRUE(checker.within(x.data(), y.data(), p0.data(), p1.data(), r.margin, ctx))
          << file << " trial " << trial;
      EXPECT_TRUE(checker.within(y.data(), p0.data(), p0.data(), p1.data(), r.margin, ctx))
          << file << " trial " << trial;
      EXPECT_TRUE(checker.within(p0.data(), p1.data(), p0.data(), p1.data(), r.margin, ctx)) << file;
      // Past an end by a hundredth of the segment, beside it by a milliradian in every entry, or no margin.
      const std::vector<double> past = omplInterpolate(p0, p1, 1.01);
      if (scene->validState(past.data()))
        EXPECT_FALSE(checker.within(x.data(), past.data(), p0.data(), p1.data(), r.margin, ctx)) << file;
      std::vector<double> beside = x;
      for (double& v : beside) v += 1e-3;
      if (scene->validState(beside.data()))
        EXPECT_FALSE(checker.within(beside.data(), y.data(), p0.data(), p1.data(), r.margin, ctx)) << file;
      EXPECT_FALSE(checker.within(x.data(), y.data(), p0.data(), p1.data(), 0.0, ctx)) << file;
    }
  }
  EXPECT_GE(free, 15 * static_cast<int>(files.size()));  // (of at most 20 a scene)
}

// A segment beside p0 → p1, each end off it by δ in one joint, moves some hull vertex by A (measured with the
// poses): within() refuses it for a margin below A, which its motion bound must then exceed, and accepts it
// for a margin far above.
TEST(MotionWithin, RefusesWhatMovesABodyFartherThanTheMargin) {
  const auto scene = test::loadScene(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/arm6_wall.yaml");
  const MotionChecker checker(scene);
  MotionContext ctx = checker.makeContext();
  SceneContext sa = scene->makeContext(), sb = scene->makeContext();
  const RobotGeometry& geometry = scene->geometry();
  const RobotModel& model = scene->robot();
  const int n = scene->dimension();
  std::mt19937 rng(9);
  int tried = 0;
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<double> p0 = test::randomState(*scene, rng), p1 = test::randomState(*scene, rng);
    const int j = trial % n;
    const double delta = 1e-7;
    std::vector<double> x = p0, y = p1;
    x[j] += delta, y[j] += delta;
    if (!scene->validState(x.data()) || !scene->validState(y.data())) continue;
    ++tried;
    // The farthest any hull vertex moves between p0 and x.
    scene->computePoses(p0.data(), sa);
    scene->computePoses(x.data(), sb);
    const std::vector<Pose>& a = sa.poses();
    const std::vector<Pose>& b = sb.poses();
    double moved = 0.0;
    for (int l = 0; l < model.linkCount(); ++l) {
      const LinkGeometry* g = geometry.link(l);
      if (!g) continue;
      for (const Vec3& v : g->hull().vertices()) moved = std::max(moved, (a[l] * v - b[l] * v).norm());
    }
    ASSERT_GT(moved, 0.0);
    EXPECT_FALSE(checker.within(x.data(), y.data(), p0.data(), p1.data(), 0.5 * moved, ctx)) << "trial " << trial;
    EXPECT_TRUE(checker.within(x.data(), y.data(), p0.data(), p1.data(), 1e3 * moved, ctx)) << "trial " << trial;
  }
  EXPECT_GT(tried, 20);
}

// A context another checker made, and a scene with moving obstacles, are never within.
TEST(MotionWithin, NeverForAnotherCheckersContextOrMovingObstacles) {
  const auto scene = test::loadScene(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/arm6_wall.yaml");
  const MotionChecker checker(scene), other(scene);
  MotionContext theirs = other.makeContext(), empty;
  const std::vector<double> p0 = scene->description().start, p1 = scene->description().goal;
  EXPECT_FALSE(checker.within(p0.data(), p1.data(), p0.data(), p1.data(), 1e-3, theirs));
  EXPECT_FALSE(checker.within(p0.data(), p1.data(), p0.data(), p1.data(), 1e-3, empty));
  MotionContext mine = checker.makeContext();
  EXPECT_TRUE(checker.within(p0.data(), p1.data(), p0.data(), p1.data(), 1e-3, mine));

  test::TempDir dir;
  const auto moving = test::movingWallScene(dir, -1.0);
  const MotionChecker m(moving);
  MotionContext c = m.makeContext();
  const std::vector<double> a{0.0, 0.0}, b{0.1, 0.0};
  EXPECT_FALSE(m.within(a.data(), b.data(), a.data(), b.data(), 1e-3, c));
}

}  // namespace
}  // namespace clearway
