// The rake (src/motion/certified.cpp, MotionOptions::rake): bounding balls settle pieces of a segment before
// any distance is measured. It keeps every verdict of the sweep without it, on our robots (the dual arm's
// 562 items, the twin arm's fork, a rover and a flyer whose joints slide and spin) and the shared ones, in
// both forms of the check, and it saves measurements. Slender pairs are also settled by their hulls' boxes
// (the dual arm's, the gantry's, the UR5's): every test below was seen failing with the boxes' reach not grown
// by the motion over the piece.
#include "motion/motion_fixtures.h"
#include "scene_cache.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace clearway {
namespace {

using namespace test;

struct RakeRun {
  int segments = 0, colliding = 0;
  long queries_with = 0, queries_without = 0;
};

// Segments between free states (half between random states, as RRTConnect's long connections, half short
// random steps), checked with and without the rake, located and verdict-only: the same verdicts.
RakeRun compareRake(const std::shared_ptr<const Scene>& scene, unsigned seed, int most, MotionOptions options = {}) {
  const MotionChecker with(scene, options), without(scene, unraked(options));
  MotionContext a = with.makeContext(), b = without.makeContext(), av = with.makeContext(), bv = without.makeContext();
  SceneContext sc = scene->makeContext();
  std::mt19937 rng(seed);
  const int n = scene->dimension();
  RakeRun run;
  for (int trial = 0; trial < 50 * most && run.segments < most; ++trial) {
    std::vector<double> q0 = randomState(*scene, rng), q1 = randomState(*scene, rng), dq(n);
    if (trial % 2) randomStep(*scene, rng, q0, q1, dq);
    if (!scene->isFree(q0.data(), sc) || !scene->isFree(q1.data(), sc)) continue;
    ++run.segments;
    const MotionResult r = with.check(q0.data(), q1.data(), a);
    const MotionResult s = without.check(q0.data(), q1.data(), b);
    EXPECT_FALSE(r.capped || s.capped) << "trial " << trial;
    EXPECT_EQ(r.free, s.free) << "trial " << trial << " (located)";
    const MotionResult rv = with.check(q0.data(), q1.data(), av, false);
    const MotionResult sv = without.check(q0.data(), q1.data(), bv, false);
    EXPECT_EQ(rv.free, sv.free) << "trial " << trial << " (verdict only)";
    EXPECT_EQ(rv.free, r.free) << "trial " << trial;
    run.colliding += !s.free;
    run.queries_with += r.distance_queries;
    run.queries_without += s.distance_queries;
  }
  return run;
}

TEST(MotionRake, KeepsEveryVerdictOnOurRobots) {
  const std::string dir = std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/";
  for (const char* name : {"arm6_wall", "twin_arm_table", "rover_gap", "flyer_post", "dual_arm_shelf"}) {
    SCOPED_TRACE(name);
    const auto scene = Scene::load(dir + name + ".yaml");
    const RakeRun run = compareRake(scene, 31, 600);
    std::printf("%s: %d segments, %d collide; distances measured %ld with the rake, %ld without\n", name, run.segments,
                run.colliding, run.queries_with, run.queries_without);
    EXPECT_EQ(run.segments, 600);
    EXPECT_GT(run.colliding, 0);
    EXPECT_LT(run.colliding, run.segments);
    EXPECT_LT(run.queries_with, run.queries_without) << "the rake settles nothing";
  }
}

// The rake's first piece for many self pairs at once (in SIMD lanes, past a few dozen due): a pair is settled
// only when its balls, grown by how far the bodies move over the segment, are apart. Segments from a state
// where two links touch to a random state, and back, on our dual arm (500-odd pairs): the touching pair is
// usually apart at the middle, so a test that forgot the motion would settle it and call the segment free.
// (Located checks: the probe of verdict-only ones would find the touching end first.) Seen failing with the
// balls not grown.
TEST(MotionRake, ManyPairsAreSettledOnlyWhereTheyStayApart) {
  const auto scene = Scene::load(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/dual_arm_shelf.yaml");
  const MotionChecker checker(scene);
  MotionContext ctx = checker.makeContext();
  SceneContext sc = scene->makeContext();
  std::mt19937 rng(43);
  int touching = 0;
  for (int trial = 0; trial < 20000 && touching < 300; ++trial) {
    const std::vector<double> q0 = randomState(*scene, rng), q1 = randomState(*scene, rng);
    CollisionReport report;
    if (scene->isFree(q0.data(), sc, &report) || report.kind != CollisionReport::Kind::Self) continue;
    ++touching;
    const MotionResult from = checker.check(q0.data(), q1.data(), ctx);
    EXPECT_FALSE(from.free) << "trial " << trial << ": from a state where links " << report.link << " and "
                            << report.other_link << " touch";
    EXPECT_EQ(from.first_contact, 0.0) << "trial " << trial;
    EXPECT_FALSE(checker.check(q1.data(), q0.data(), ctx).free) << "trial " << trial << ": to it";
  }
  EXPECT_EQ(touching, 300);
}

// Cast mode casts what the rake leaves: the gantry, whose segments mostly translate.
TEST(MotionRake, KeepsEveryVerdictInCastMode) {
  TempDir dir;
  const RakeRun run = compareRake(gantryScene(dir), 41, 600, castMode());
  std::printf("gantry (cast): %d segments, %d collide; distances measured %ld with the rake, %ld without\n",
              run.segments, run.colliding, run.queries_with, run.queries_without);
  EXPECT_EQ(run.segments, 600);
  EXPECT_GT(run.colliding, 0);
  EXPECT_LT(run.queries_with, run.queries_without) << "the rake settles nothing";
}

TEST(MotionRake, KeepsEveryVerdictOnTheSharedRobots) {
  CLEARWAY_SHARED_OR_SKIP(shared, "scenes");
  for (const char* name : {"box_panda/box_panda_0001.yaml", "bookshelf_small_panda/bookshelf_small_panda_0001.yaml",
                           "cage_ur5/cage_ur5_0001.yaml", "box_ur5/box_ur5_0001.octomap.yaml",
                           "bookshelf_small_panda/bookshelf_small_panda_0001.octomap.yaml"}) {
    SCOPED_TRACE(name);
    const RakeRun run = compareRake(test::loadScene(shared + "/" + name), 37, 300);
    std::printf("%s: %d segments, %d collide; distances measured %ld with the rake, %ld without\n", name, run.segments,
                run.colliding, run.queries_with, run.queries_without);
    EXPECT_EQ(run.segments, 300);
    EXPECT_GT(run.colliding, 0);
    EXPECT_LT(run.queries_with, run.queries_without) << "the rake settles nothing";
  }
}

}  // namespace
}  // namespace clearway
