// MotionChecker (src/motion/motion_checker.cpp): what a check refuses or caps (joint values, times, stop
// conditions, bad options), and that verdicts depend on the segment alone, from any thread.
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

// A planar joint has no limits of its own: a state of x = 1e16 m, where a link's size has no digit left,
// made a segment that starts inside a wall free (certified and cast), and a change beyond 1e154 made
// sampling check only the ends. Every joint value lies within ±kMaxJointValue (1e6), or the state is
// invalid, in every mode; scene bounds beyond it are refused.
TEST(MotionCertified, JointValuesBeyondTheLargestAreNeverFree) {
  TempDir dir;
  const std::string head = "format: 1\nname: rover\nrobot:\n  urdf: " + test::sourceRobot("rover/rover.urdf") +
                           "\n  group: [drive, swing]\n";
  const std::string tail = "environment:\n  obstacles:\n"
                           "    - {name: wall, box: {size: [0.002, 1.5, 1]}, pose: {position: [0, -1.25, 0.5]}}\n"
                           "checks: [self, environment]\n";
  const auto scene = Scene::load(dir.write("rover.yaml", head + tail));
  const double inside[4] = {0, -1.25, 0, 0}, far[4] = {1e16, -1.25, 0, 0}, huge[4] = {1.3e155, -1.25, 0, 0};
  const double edge[4] = {1e6, 5, 0, 0}, beyond[4] = {std::nextafter(1e6, 2e6), 5, 0, 0};
  EXPECT_FALSE(scene->isFree(std::vector<double>(inside, inside + 4)));
  EXPECT_TRUE(scene->isFree(std::vector<double>(edge, edge + 4)));
  std::string why;
  EXPECT_FALSE(scene->validState(beyond, &why));
  EXPECT_NE(why.find("(drive/x) = 1000000.0000000001 is beyond ±1e6, the largest joint value a state may hold"),
            std::string::npos) << why;
  for (const MotionMode mode : {MotionMode::Certified, MotionMode::Cast, MotionMode::Sampled}) {
    MotionOptions options;
    options.mode = mode;
    const MotionChecker checker(scene, options);
    MotionContext ctx = checker.makeContext();
    for (const double* end : {far, huge}) {
      EXPECT_FALSE(checker.check(inside, end, ctx).free) << static_cast<int>(mode);
      EXPECT_FALSE(checker.check(end, inside, ctx).free) << static_cast<int>(mode);
    }
    EXPECT_FALSE(checker.check(edge, beyond, ctx).free) << static_cast<int>(mode);
  }
  EXPECT_LOAD_ERROR(Scene::load(dir.write("wide.yaml", head + "  bounds: {drive/x: [-1e17, 1e17]}\n" + tail)),
                    dir.path("wide.yaml"), "key 'robot.bounds.drive/x'",
                    "[-1e+17, 1e+17] reaches beyond ±1e6, the largest joint value a state may hold");
}

// Moments are finite and within ±kMaxTime (1e6 s): a segment spanning 1e17 s with a moving obstacle was
// called free though it started inside a wall. Beyond it a state or segment is invalid, never free.
TEST(MotionCertified, TimesBeyondTheLargestAreNeverFree) {
  TempDir dir;
  const auto scene = Scene::load(dir.write("moving.yaml", "format: 1\nname: moving\nrobot:\n  urdf: " +
      test::sourceRobot("planar_arm/planar_arm.urdf") + "\n  group: [shoulder, elbow]\nenvironment:\n  obstacles:\n"
      "    - {name: wall, box: {size: [0.1, 2, 1]}, pose: {position: [1.2, 0, 0]}}\n"
      "    - {name: ball, sphere: {radius: 0.05}, pose: {position: [5, 5, 0]}, velocity: [1e-12, 0, 0]}\n"
      "checks: [self, environment, moving]\n"));
  const double inside[2] = {0, 0}, clear[2] = {1.5, 0};
  SceneContext sc = scene->makeContext();
  EXPECT_TRUE(scene->isFree(clear, sc, nullptr, 1e6));
  EXPECT_FALSE(scene->isFree(clear, sc, nullptr, std::nextafter(1e6, 2e6)));
  EXPECT_FALSE(scene->isFree(clear, sc, nullptr, -1e17));
  for (const MotionMode mode : {MotionMode::Certified, MotionMode::Cast, MotionMode::Sampled}) {
    MotionOptions options;
    options.mode = mode;
    const MotionChecker checker(scene, options);
    MotionContext ctx = checker.makeContext();
    EXPECT_TRUE(checker.check(clear, 0.0, clear, 1e6, ctx).free) << static_cast<int>(mode);
    for (const double t1 : {1e17, -1e17, 2e6, std::nan("")}) {
      EXPECT_FALSE(checker.check(inside, 0.0, clear, t1, ctx).free) << static_cast<int>(mode) << " " << t1;
      EXPECT_FALSE(checker.check(clear, 0.0, clear, t1, ctx).free) << static_cast<int>(mode) << " " << t1;
      EXPECT_FALSE(checker.check(clear, t1, clear, 0.0, ctx).free) << static_cast<int>(mode) << " " << t1;
    }
  }
}

// MotionOptions::stop (a planner's termination condition) is asked every 256 distance queries; true ends
// the check capped, never free: a segment near contact could run for tens of seconds past a time limit.
TEST(MotionCertified, AStopConditionEndsTheCheckCappedNeverFree) {
  TempDir dir;
  // The block slides 2 m beside a wall 1.5 mm away (contact distance 1 mm): free, in many small steps.
  const auto scene =
      sliderScene(dir, "    - {name: wall, box: {size: [3, 0.01, 1]}, pose: {position: [0, 0.0565, 0]}}\n");
  const double q0[2] = {-1, 0}, q1[2] = {1, 0};
  const MotionChecker plain(scene);
  MotionContext pc = plain.makeContext();
  const MotionResult free = plain.check(q0, q1, pc);
  ASSERT_TRUE(free.free);
  ASSERT_GT(free.distance_queries, 600) << "the test needs a segment of many queries";
  MotionOptions options;
  int asked = 0;
  options.stop = [&asked] { return ++asked == 2; };
  const MotionChecker stopped(scene, options);
  MotionContext sc = stopped.makeContext();
  const MotionResult r = stopped.check(q0, q1, sc);
  EXPECT_FALSE(r.free);
  EXPECT_TRUE(r.capped);
  EXPECT_EQ(asked, 2);
  EXPECT_EQ(r.distance_queries, 512);
  options.stop = [] { return false; };
  const MotionChecker never(scene, options);
  MotionContext nc = never.makeContext();
  EXPECT_TRUE(never.check(q0, q1, nc).free);
  options.stop = []() -> bool { throw std::runtime_error("no"); };
  const MotionChecker throwing(scene, options);
  MotionContext tc = throwing.makeContext();
  EXPECT_FALSE(throwing.check(q0, q1, tc).free);
}

TEST(MotionCertified, EveryCapEndsInACollision) {
  // The planar arm among two posts, with each cap forced: the certified loop's query cap, the sampled
  // check's state cap, and the narrow phase's iteration caps (GJK, EPA, casts at 0) under the scene's
  // states and every motion mode. A capped answer is a collision, never free; no capped checker is freer
  // than the uncapped one; and each cap is reached at least once, or this proves nothing.
  TempDir dir;
  const std::string obstacles =
      "    - {name: post, cylinder: {radius: 0.03, length: 1}, pose: {position: [0, 1.2, 0]}}\n"
      "    - {name: rod, box: {size: [0.02, 0.02, 1]}, pose: {position: [-0.9, -0.9, 0]}}\n"
      // A ball: oriented boxes clear states near boxes and posts without GJK, but not within its box's corners.
      "    - {name: ball, sphere: {radius: 0.2}, pose: {position: [0.3, -1.3, 0]}}\n";
  const auto scene = planarScene(dir, obstacles);
  SceneOptions no_iterations;
  no_iterations.tolerances.gjk_max_iterations = 0;
  no_iterations.tolerances.epa_max_iterations = 0;
  no_iterations.tolerances.cast_max_iterations = 0;
  const auto uncertain = Scene::load(dir.path("planar.yaml"), no_iterations);
  MotionOptions one_query, one_state = sampled(1e-3), cast;
  one_query.max_queries = 1;
  one_state.max_samples = 1;
  cast.mode = MotionMode::Cast;
  const MotionChecker exact(scene), query_capped(scene, one_query), state_capped(scene, one_state);
  const MotionChecker gjk_capped(uncertain), cast_capped(uncertain, cast), sampled_capped(uncertain, sampled(0.05));
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> s1(-3.1, 3.1), s2(-2.5, 2.5);
  int query_caps = 0, state_caps = 0, refused_states = 0, segments = 0;
  int narrow_collisions[3] = {0, 0, 0}, exact_collisions = 0;
  for (int trial = 0; trial < 150; ++trial) {
    const std::vector<double> q0{s1(rng), s2(rng)}, q1{s1(rng), s2(rng)};
    // States: the scene without iterations may refuse free states, never accept colliding ones.
    for (const auto& q : {q0, q1}) {
      const bool free = scene->isFree(q), capped_free = uncertain->isFree(q);
      if (capped_free) EXPECT_TRUE(free) << "trial " << trial;
      refused_states += free && !capped_free;
    }
    if (!scene->isFree(q0) || !scene->isFree(q1)) continue;
    ++segments;
    MotionContext c = exact.makeContext();
    const MotionResult reference = exact.check(q0.data(), q1.data(), c);
    MotionContext cq = query_capped.makeContext();
    const MotionResult q = query_capped.check(q0.data(), q1.data(), cq);
    if (q.capped) {
      ++query_caps;
      EXPECT_FALSE(q.free) << "trial " << trial;
    }
    MotionContext cs = state_capped.makeContext();
    const MotionResult st = state_capped.check(q0.data(), q1.data(), cs);
    if (st.capped) {
      ++state_caps;
      EXPECT_FALSE(st.free) << "trial " << trial;
    }
    int k = 0;
    for (const MotionChecker* m : {&gjk_capped, &cast_capped, &sampled_capped}) {
      MotionContext cm = m->makeContext();
      const MotionResult r = m->check(q0.data(), q1.data(), cm);
      if (!reference.free) EXPECT_FALSE(r.free) << "trial " << trial << " checker " << k;
      narrow_collisions[k++] += !r.free;
    }
    exact_collisions += !reference.free;
    for (const MotionResult* r : {&q, &st})
      if (!reference.free) EXPECT_FALSE(r->free) << "trial " << trial;
  }
  EXPECT_GT(segments, 20);
  EXPECT_GT(query_caps, segments / 2);
  EXPECT_EQ(state_caps, segments);  // a 1 mm resolution needs more than one state on any segment drawn
  EXPECT_GT(refused_states, 0);
  // With no iterations nothing near an obstacle can be certified: motions that pass near one end there.
  // The certified and cast loops decide most items by bounds that need no GJK iterations (boxes, spheres,
  // the parts' lower bounds give 0 and fall through to contact), so they may refuse no more than the
  // exact scene; sampling over the capped scene refuses more.
  EXPECT_GT(narrow_collisions[2], exact_collisions);
  for (int k = 0; k < 2; ++k) EXPECT_GE(narrow_collisions[k], exact_collisions) << "checker " << k;
}

TEST(MotionCertified, BadInput) {
  TempDir dir;
  const auto scene =
      sliderScene(dir, "    - {name: wall, box: {size: [0.001, 2, 2]}, pose: {position: [0, 0, 0]}}\n");
  const MotionChecker certified(scene);
  MotionContext ctx = certified.makeContext();
  MotionOptions cast_options;
  cast_options.mode = MotionMode::Cast;
  const MotionChecker cast(scene, cast_options);
  const double ok[2] = {-1, 0};
  {  // a context not made by a checker: a collision, never free
    MotionContext empty;
    EXPECT_TRUE(certified.check(ok, ok, ctx).free);
    EXPECT_FALSE(certified.check(ok, ok, empty).free);
    EXPECT_EQ(certified.check(ok, ok, empty).report.kind, CollisionReport::Kind::Invalid);
    empty = certified.makeContext();
    EXPECT_TRUE(certified.check(ok, ok, empty).free);
    // A context of a checker for another group of the same robot (its items fit, its state buffers do not).
    const std::string urdf = dir.write("slider.urdf", kSliderUrdf);
    const auto one = Scene::load(dir.write("one.yaml", "format: 1\nname: one\nrobot:\n  urdf: " + urdf +
                                                           "\n  group: [slide]\nenvironment:\n  obstacles:\n"
                                                           "    - {name: wall, box: {size: [0.001, 2, 2]}, pose: {position: [0, 0, 0]}}\n"
                                                           "checks: [environment, continuous]\n"));
    const MotionChecker other(one);
    MotionContext misfit = other.makeContext();
    EXPECT_FALSE(certified.check(ok, ok, misfit).free);
    EXPECT_EQ(certified.check(ok, ok, misfit).report.kind, CollisionReport::Kind::Invalid);
  }
  for (const double bad : {std::nan(""), std::numeric_limits<double>::infinity(), 5.0}) {
    const double q[2] = {-0.5, bad};
    const double p[2] = {bad, 0};
    for (const MotionChecker* m : {&certified, &cast}) {
      MotionContext ctx = m->makeContext();
      EXPECT_FALSE(m->check(ok, q, ctx).free) << bad;
      EXPECT_FALSE(m->check(q, ok, ctx).free) << bad;
      const MotionResult r = m->check(ok, p, ctx);
      EXPECT_FALSE(r.free) << bad;
      if (bad == 5.0) {  // clear of the wall, but the turn leaves its limit (3.2) at s = 3.2 / 5
        const MotionResult out = m->check(ok, q, ctx);
        EXPECT_EQ(out.report.kind, CollisionReport::Kind::Invalid);
        EXPECT_NEAR(out.first_contact, 3.2 / 5.0, 1e-9);
        EXPECT_NEAR(out.last_valid, 3.2 / 5.0, 1e-9);
        double at[2];
        m->interpolate(ok, q, out.last_valid, at);
        EXPECT_TRUE(scene->validState(at));
        // Into the wall at s ≈ 0.85, after leaving the limit at 0.64: the bounds come first.
        const double far[2] = {0.1, 5.0};
        const MotionResult both = m->check(ok, far, ctx);
        EXPECT_EQ(both.report.kind, CollisionReport::Kind::Invalid);
        EXPECT_NEAR(both.last_valid, 3.2 / 5.0, 1e-9);
        // Into the wall before leaving the limit: the wall comes first, and the last valid state is valid.
        const double soon[2] = {0.5, 4.0};
        const MotionResult wall = m->check(ok, soon, ctx);
        EXPECT_EQ(wall.report.kind, CollisionReport::Kind::Environment);
        EXPECT_LT(wall.first_contact, 3.2 / 4.0);
        m->interpolate(ok, soon, wall.last_valid, at);
        EXPECT_TRUE(scene->isFree(std::vector<double>(at, at + 2)));
      }
    }
  }
  const MotionChecker coarse(scene, sampled(0.01));
  MotionContext cc = coarse.makeContext();
  const double nan_end[2] = {std::nan(""), 0};
  EXPECT_FALSE(coarse.check(ok, nan_end, cc).free);
  EXPECT_FALSE(coarse.check(nan_end, ok, cc).free);
  // A zero-length motion is its state's verdict, in both modes.
  const double inside[2] = {0.0, 0.0};  // the block in the wall
  for (const MotionChecker* m : {&certified, &cast, &coarse}) {
    MotionContext c = m->makeContext();
    EXPECT_TRUE(m->check(ok, ok, c).free);
    const MotionResult r = m->check(inside, inside, c);
    EXPECT_FALSE(r.free);
    EXPECT_EQ(r.first_contact, 0.0);
    EXPECT_EQ(r.last_valid, 0.0);
  }
  // Options out of range are refused when the checker is made.
  for (auto edit : std::vector<void (*)(MotionOptions&)>{
           [](MotionOptions& o) { o.contact_distance = 0; }, [](MotionOptions& o) { o.contact_distance = NAN; },
           [](MotionOptions& o) { o.resolution = -1; }, [](MotionOptions& o) { o.max_queries = 0; },
           [](MotionOptions& o) { o.max_samples = 0; },
           [](MotionOptions& o) { o.distance_relative_error = -0.1; }}) {
    MotionOptions o;
    edit(o);
    EXPECT_THROW(MotionChecker(scene, o), std::invalid_argument);
  }
  // A query cap that is reached reports a collision, never a free segment.
  MotionOptions capped;
  capped.max_queries = 1;
  const MotionChecker tight(scene, capped);
  MotionContext tc = tight.makeContext();
  const double far[2] = {0.5, 0};
  const double from[2] = {-0.9, 0};
  const MotionResult r = tight.check(from, far, tc);
  EXPECT_FALSE(r.free);
  EXPECT_TRUE(r.capped);

  // Sampled: a resolution so fine that the step count passes every int (len / 1e-9 > 2^31) once wrapped
  // to one step and called a colliding segment free; now more states than the cap is a collision.
  MotionOptions fine;
  fine.mode = MotionMode::Sampled;
  for (const double resolution : {1e-9, 1e-12, 1e-320}) {
    fine.resolution = resolution;
    const MotionChecker sampled(scene, fine);
    MotionContext sc = sampled.makeContext();
    const MotionResult s = sampled.check(from, far, sc);
    EXPECT_FALSE(s.free) << resolution;
    EXPECT_TRUE(s.capped) << resolution;
    EXPECT_EQ(s.last_valid, 0.0);
  }
  fine.resolution = 1e-3;  // about 1,400 states: within the cap, and the wall is seen
  const int needed = static_cast<int>(std::ceil((far[0] - from[0]) / fine.resolution));
  fine.max_samples = needed;
  const MotionChecker within(scene, fine);
  MotionContext wc = within.makeContext();
  const MotionResult w = within.check(from, far, wc);
  EXPECT_FALSE(w.free);
  EXPECT_FALSE(w.capped);
  fine.max_samples = needed - 1;
  const MotionChecker beyond(scene, fine);
  MotionContext bc = beyond.makeContext();
  EXPECT_TRUE(beyond.check(from, far, bc).capped);
}

TEST(MotionCertified, AContextOfAnotherCheckerIsRefused) {
  // Two scenes of one robot (the same items: a merged gripper body, its links against one obstacle): a
  // context of the first scene's checker, warmed and then outliving its checker, holds pairs on geometry
  // that checker owned and warm starts for its obstacle. The second refuses it: a collision, never free.
  TempDir da, db;
  const auto far = gripperScene(da, "{name: far, box: {size: [0.2, 0.2, 0.2]}, pose: {position: [0, 2.5, 0]}}",
                                "[self, environment, continuous]");
  const auto posts =
      gripperScene(db, "{name: post, cylinder: {radius: 0.02, length: 1}, pose: {position: [0, -2.5, 0]}}",
                   "[self, environment, continuous]");
  const double q0[2] = {0, 0}, q1[2] = {0.3, 0.1};
  MotionContext stale;
  {
    const MotionChecker first(far);
    stale = first.makeContext();
    ASSERT_TRUE(first.check(q0, q1, stale).free);
  }
  const MotionChecker second(posts);
  MotionContext own = second.makeContext();
  ASSERT_TRUE(second.check(q0, q1, own).free);
  for (const bool locate : {true, false}) {
    const MotionResult r = second.check(q0, q1, stale, locate);
    EXPECT_FALSE(r.free);
    EXPECT_EQ(r.report.kind, CollisionReport::Kind::Invalid);
  }
  // Another checker of the same scene is another checker; a copy shares the items, and the contexts.
  const MotionChecker again(posts);
  EXPECT_FALSE(again.check(q0, q1, own).free);
  const MotionChecker copy = second;
  EXPECT_TRUE(copy.check(q0, q1, own).free);
}

// A random walk of `count` states in 0.4 rad steps from the middle of the limits: on arm6_wall, some
// segments free, some meeting the wall or the arm itself.
std::vector<std::vector<double>> randomWalk(const Scene& scene, std::size_t count, unsigned seed) {
  std::mt19937 rng(seed);
  const int n = scene.dimension();
  std::vector<std::vector<double>> q(count, std::vector<double>(n));
  for (std::size_t k = 0; k < q.size(); ++k)
    for (int i = 0; i < n; ++i)
      q[k][i] = k == 0 ? 0.5 * (scene.lower(i) + scene.upper(i))
                       : std::clamp(q[k - 1][i] + std::uniform_real_distribution<double>(-0.4, 0.4)(rng),
                                    scene.lower(i), scene.upper(i));
  return q;
}

// A checker made from another with other options (plan() makes one per query, with its time limit) answers
// as one built with those options: the same verdicts and the very same work, its pair tables built again
// for another contact distance (a table built with the old one would skip a pair now within contact).
TEST(MotionCertified, ACheckerWithOtherOptionsAnswersAsOneBuiltWithThem) {
  const auto scene = Scene::load(test::sourceRobot("scenes/arm6_wall.yaml"));
  const std::vector<std::vector<double>> q = randomWalk(*scene, 121, 23);
  MotionOptions wide, cast, sampled_options, one_query;
  wide.contact_distance = 0.2;
  cast.mode = MotionMode::Cast;
  sampled_options.mode = MotionMode::Sampled;
  sampled_options.resolution = 0.05;
  one_query.max_queries = 1;
  const MotionChecker base(scene);
  const MotionChecker from_sampled(scene, sampled_options);
  int differ = 0;  // segments checked at 20 cm otherwise than at 1 mm
  for (const MotionOptions* o : {&wide, &cast, &sampled_options, &one_query}) {
    for (const MotionChecker* b : {&base, &from_sampled}) {
      const MotionChecker made(*b, *o), fresh(scene, *o);
      MotionContext base_ctx = b->makeContext(), made_ctx = made.makeContext(), fresh_ctx = fresh.makeContext();
      EXPECT_EQ(made.check(q[0].data(), q[1].data(), base_ctx).report.kind, CollisionReport::Kind::Invalid)
          << "a context of the base fits the checker made from it";
      for (std::size_t k = 0; k + 1 < q.size(); ++k)
        for (const bool locate : {true, false}) {
          const MotionResult a = made.check(q[k].data(), q[k + 1].data(), made_ctx, locate);
          const MotionResult e = fresh.check(q[k].data(), q[k + 1].data(), fresh_ctx, locate);
          ASSERT_EQ(a.free, e.free) << "segment " << k;
          EXPECT_EQ(a.capped, e.capped) << "segment " << k;
          EXPECT_EQ(a.first_contact, e.first_contact) << "segment " << k;
          EXPECT_EQ(a.distance_queries, e.distance_queries) << "segment " << k;
          EXPECT_EQ(a.steps, e.steps) << "segment " << k;
          if (o == &wide && b == &base && locate) {
            MotionContext ctx = base.makeContext();
            const MotionResult narrow = base.check(q[k].data(), q[k + 1].data(), ctx);
            differ += narrow.free != a.free || narrow.distance_queries != a.distance_queries;
          }
        }
    }
  }
  EXPECT_GT(differ, 0) << "no segment tells 20 cm from 1 mm: the test cannot see the options";
  MotionOptions bad;
  bad.contact_distance = -1.0;
  EXPECT_THROW(MotionChecker(base, bad), std::invalid_argument);
}

TEST(MotionCertified, ThreadsShareOneChecker) {
  TempDir dir;
  const auto scene = planarScene(
      dir, "    - {name: post, cylinder: {radius: 0.005, length: 1}, pose: {position: [1.4, 0, 0]}}\n");
  const MotionChecker certified(scene);
  const double q0[2] = {1.55, 0}, q1[2] = {-1.45, 0};
  MotionContext ctx = certified.makeContext();
  const MotionResult expected = certified.check(q0, q1, ctx);
  std::vector<std::thread> threads;
  std::vector<int> wrong(4, 0);
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      MotionContext mine = certified.makeContext();
      for (int k = 0; k < 50; ++k) {
        const MotionResult r = certified.check(q0, q1, mine);
        wrong[t] += r.free != expected.free || r.first_contact != expected.first_contact;
      }
    });
  for (auto& th : threads) th.join();
  for (int t = 0; t < 4; ++t) EXPECT_EQ(wrong[t], 0);
}

TEST(MotionCertified, VerdictDependsOnlyOnTheSegment) {
  // Two contexts check the same segments in opposite orders (so different items lead, and different
  // segments came before): a planner's threads and a later re-check of its path must agree, even on
  // segments that pass within the contact distance. Free segments take the very same queries.
  const auto scene = Scene::load(test::sourceRobot("scenes/arm6_wall.yaml"));
  const MotionChecker certified(scene);
  const std::vector<std::vector<double>> q = randomWalk(*scene, 201, 17);
  MotionContext forward = certified.makeContext(), backward = certified.makeContext();
  std::vector<MotionResult> a(200), b(200);
  for (int k = 0; k < 200; ++k) a[k] = certified.check(q[k].data(), q[k + 1].data(), forward);
  for (int k = 200; k-- > 0;) b[k] = certified.check(q[k].data(), q[k + 1].data(), backward);
  int free = 0;
  for (int k = 0; k < 200; ++k) {
    ASSERT_EQ(a[k].free, b[k].free) << "segment " << k;
    if (a[k].free) {
      ++free;
      EXPECT_EQ(a[k].distance_queries, b[k].distance_queries) << "segment " << k;
    }
  }
  EXPECT_GT(free, 20);
  EXPECT_LT(free, 190);
  // The verdict alone (OMPL's checkMotion(s1, s2)) ends at the first measurement within contact: it too
  // depends only on the segment, and says free exactly where the located check does (both measure the
  // same parameters until a contact; here no segment grazes the wall within contact_distance only).
  std::vector<MotionResult> va(200), vb(200);
  for (int k = 0; k < 200; ++k) va[k] = certified.check(q[k].data(), q[k + 1].data(), forward, false);
  for (int k = 200; k-- > 0;) vb[k] = certified.check(q[k].data(), q[k + 1].data(), backward, false);
  long located_queries = 0, verdict_queries = 0;
  for (int k = 0; k < 200; ++k) {
    ASSERT_EQ(va[k].free, vb[k].free) << "segment " << k;
    EXPECT_EQ(va[k].free, a[k].free) << "segment " << k;
    if (a[k].free) EXPECT_EQ(va[k].distance_queries, a[k].distance_queries) << "segment " << k;
    else located_queries += a[k].distance_queries, verdict_queries += va[k].distance_queries;
  }
  EXPECT_LT(verdict_queries, located_queries) << "the verdict alone should stop sooner on colliding segments";
}

}  // namespace
}  // namespace clearway
