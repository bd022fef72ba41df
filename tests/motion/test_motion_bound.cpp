// MotionBound (src/motion/motion_bound.cpp): the bound on how far any point of a link moves along a segment
// holds for every joint kind, robot and convex part, on our robots and the shared ones.
#include "motion/motion_fixtures.h"
#include "scene_cache.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
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

TEST(MotionBound, BoundsTheMotionOfEveryPoint) {
  // The planar arm: the tip of link2 (1.5 m out) moves at most 1.5·|Δq1| + 0.5·|Δq2|; random steps
  // must never move a corner of a link farther than the bound says.
  TempDir dir;
  const auto scene = planarScene(dir, "    - {name: far, sphere: {radius: 0.1}, pose: {position: [5, 5, 0]}}\n");
  const MotionBound bound(*scene);
  const int link2 = scene->robot().linkIndex("link2");
  const int link1 = scene->robot().linkIndex("link1");
  ASSERT_GE(link2, 0);
  // The elbow's reach is the farthest point of link2's (circumscribed) hull from the elbow.
  EXPECT_GE(bound.linkCoefficient(link2, 1), std::hypot(0.5, 0.05));
  EXPECT_LE(bound.linkCoefficient(link2, 1), 0.51);
  EXPECT_GE(bound.linkCoefficient(link2, 0), 1.5);
  EXPECT_EQ(bound.linkCoefficient(link1, 1), 0.0);  // the elbow does not move link1
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  SceneContext c0 = scene->makeContext(), c1 = scene->makeContext();
  for (int trial = 0; trial < 500; ++trial) {
    const double q0[2] = {u(rng), u(rng) * 1.2}, dq[2] = {u(rng) * 0.3, u(rng) * 0.3};
    const double q1[2] = {q0[0] + dq[0], q0[1] + dq[1]};
    scene->computePoses(q0, c0);
    scene->computePoses(q1, c1);
    // The corners of link2's bounding cylinder (end points on its surface).
    for (const Vec3 p : {Vec3(0.5, 0.05, 0), Vec3(0, -0.05, 0.05), Vec3(0.5, 0, -0.05)}) {
      const double moved = (c1.poses()[link2] * p - c0.poses()[link2] * p).norm();
      EXPECT_LE(moved, bound.link(link2, dq) + 1e-12);
    }
    // The pair bound: link2's motion relative to link1 depends on the elbow only; watched from link2,
    // link1 turns about the elbow's axis, so the bound may be lower still. No distance between a point
    // of each link changes by more.
    const double pair = bound.pair(link1, link2, dq);
    EXPECT_LE(pair, bound.linkCoefficient(link2, 1) * std::abs(dq[1]) + 1e-12);
    for (const Vec3 p1 : {Vec3(1.0, 0.05, 0), Vec3(0.2, -0.05, 0.05), Vec3(0, 0, 0)})
      for (const Vec3 p2 : {Vec3(0.5, 0.05, 0), Vec3(0, -0.05, 0.05), Vec3(0.25, 0, -0.05)}) {
        const double before = (c0.poses()[link2] * p2 - c0.poses()[link1] * p1).norm();
        const double after = (c1.poses()[link2] * p2 - c1.poses()[link1] * p1).norm();
        EXPECT_LE(std::abs(after - before), pair + 1e-12);
      }
  }
}

TEST(MotionBound, HoldsForPlanarAndFloatingJoints) {
  // Along the interpolated path (slerp for the quaternion), no hull vertex moves farther than s·link(dq)
  // with dq the change between the path's normalized ends; and the path's ends are the states.
  TempDir dir;
  for (const auto& scene : {roverScene(dir), flyerScene(dir)}) {
    const MotionChecker checker(scene);
    const int n = scene->dimension();
    SceneContext ctx = scene->makeContext();
    std::mt19937 rng(3);
    std::vector<double> q(n), a(n), b(n), dq(n);
    double tightest = 0.0;
    for (int trial = 0; trial < 60; ++trial) {
      const std::vector<double> q0 = randomState(*scene, rng), q1 = randomState(*scene, rng);
      checker.interpolate(q0.data(), q1.data(), 0.0, a.data());
      checker.interpolate(q0.data(), q1.data(), 1.0, b.data());
      for (int i = 0; i < n; ++i) dq[i] = b[i] - a[i];
      std::vector<std::vector<Vec3>> start;
      scene->computePoses(a.data(), ctx);
      const std::vector<Pose> p0 = ctx.poses();
      for (int k = 1; k <= 20; ++k) {
        const double t = k / 20.0;
        checker.interpolate(q0.data(), q1.data(), t, q.data());
        scene->computePoses(q.data(), ctx);
        for (int link = 0; link < scene->robot().linkCount(); ++link) {
          const LinkGeometry* g = scene->geometry().link(link);
          if (!g) continue;
          const double bound = t * checker.bound().link(link, dq.data());
          for (const Vec3& v : g->hull().vertices()) {
            const double moved = (ctx.poses()[link] * v - p0[link] * v).norm();
            ASSERT_LE(moved, bound * (1 + 1e-9) + 1e-12) << scene->name() << " trial " << trial << " link " << link;
            tightest = std::max(tightest, moved / bound);
          }
        }
      }
      // The ends: the states themselves (a quaternion up to its sign and norm).
      scene->computePoses(q1.data(), ctx);
      const std::vector<Pose> end = ctx.poses();
      scene->computePoses(b.data(), ctx);
      for (int link = 0; link < scene->robot().linkCount(); ++link)
        EXPECT_LT((ctx.poses()[link].t - end[link].t).norm() + (ctx.poses()[link].R - end[link].R).norm(), 1e-9);
    }
    EXPECT_GT(tightest, 0.3) << scene->name() << ": a bound this loose would make the check slow";
  }
}

// A turret whose mimic joint (multiplier 0: it never moves) carries an unbounded planar cart: the reaches
// above the cart are infinite, and 0·∞ must not make a bound NaN (a NaN step once read as "covered").
TEST(MotionBound, NeverNaNWithAnUnboundedSlideBelowAStillMimic) {
  TempDir dir;
  const std::string urdf = dir.write("turret.urdf", R"(<?xml version="1.0"?>
<robot name="turret">
  <link name="base"/>
  <link name="turret"><collision><geometry><cylinder radius="0.1" length="0.1"/></geometry></collision></link>
  <link name="mount"/>
  <link name="cart"><collision><origin xyz="0.3 0 0"/><geometry><box size="0.4 0.2 0.1"/></geometry></collision></link>
  <joint name="spin" type="revolute"><parent link="base"/><child link="turret"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="1" effort="1"/></joint>
  <joint name="still" type="revolute"><parent link="turret"/><child link="mount"/><origin xyz="0 0 0.2"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" velocity="1" effort="1"/><mimic joint="spin" multiplier="0" offset="0.2"/></joint>
  <joint name="drive" type="planar"><parent link="mount"/><child link="cart"/><axis xyz="0 0 1"/></joint>
</robot>
)");
  const auto scene = Scene::load(dir.write("turret.yaml", "format: 1\nname: turret\nrobot:\n  urdf: " + urdf +
      "\n  group: [spin, drive]\nenvironment:\n  obstacles:\n    - {name: post, cylinder: {radius: 0.02, length: 2}, "
      "pose: {position: [0.4, 0, 0]}}\nchecks: [environment, continuous]\nstart: [0, 0, 0, 0]\ngoal: [1, 0, 0, 0]\n"));
  ASSERT_FALSE(std::isfinite(scene->upper(1)));
  const MotionBound bound(*scene);
  const int cart = scene->robot().linkIndex("cart"), turret = scene->robot().linkIndex("turret");
  SceneContext ctx = scene->makeContext();
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const std::vector<double> q = {2.5 * u(rng), 0.5 * u(rng), 0.5 * u(rng), 3.0 * u(rng)};
    std::vector<double> dq = {u(rng), trial % 2 ? 0.0 : u(rng), trial % 3 ? 0.0 : u(rng), trial % 5 ? 0.0 : u(rng)};
    scene->computePoses(q.data(), ctx);
    for (const double b : {bound.link(cart, dq.data()), bound.pair(turret, cart, dq.data()),
                           bound.linkStep(cart, dq.data(), ctx.poses().data(), 0.05),
                           bound.pairStep(turret, cart, dq.data(), ctx.poses().data(), 0.05)})
      EXPECT_FALSE(std::isnan(b)) << "trial " << trial;
  }
  // The cart swung through the post by the turret (the cart's slides still), and past it: as dense sampling.
  const MotionChecker checker(scene), fine(scene, sampled(1e-3));
  MotionContext mc = checker.makeContext(), fc = fine.makeContext();
  const double q0[4] = {-1.0, 0, 0, 0}, q1[4] = {1.0, 0, 0, 0}, q2[4] = {-1.0, 2.0, 0, 0}, q3[4] = {1.0, 2.0, 0, 0};
  ASSERT_FALSE(fine.check(q0, q1, fc).free);
  EXPECT_FALSE(checker.check(q0, q1, mc).free);
  ASSERT_TRUE(fine.check(q2, q3, fc).free);
  EXPECT_TRUE(checker.check(q2, q3, mc).free);
}

TEST(MotionBound, HoldsOnTheSharedRobots) {
  CLEARWAY_REQUIRE_SHARED("robots/panda/panda.urdf");
  CLEARWAY_SHARED_OR_SKIP(root, "scenes");
  std::mt19937 rng(11);
  for (const char* name : {"box_panda/box_panda_0001.yaml", "box_ur5/box_ur5_0001.yaml"})
    expectBoundsHold(std::make_shared<const Scene>(parseSceneFile(root + "/" + name)), rng);
}

TEST(MotionBound, HoldsForLinksOnTwoBranchesOfAFork) {
  const auto scene = twinArmScene();
  int across = 0;
  for (const LinkPair& p : scene->selfCollision().pairs()) {
    const std::string a = scene->robot().link(p.a).name, b = scene->robot().link(p.b).name;
    across += (a.rfind("left_", 0) == 0 && b.rfind("right_", 0) == 0) || (a.rfind("right_", 0) == 0 && b.rfind("left_", 0) == 0);
  }
  EXPECT_EQ(across, 16);  // every link of one arm against every link of the other
  std::mt19937 rng(13);
  for (int round = 0; round < 3; ++round) expectBoundsHold(scene, rng);
}

TEST(MotionBound, VelocityFieldHoldsOnOurRobots) {
  TempDir dir;
  const std::string urdf = dir.write("mimic_arm.urdf", kMimicArmUrdf);
  const auto mimic = Scene::load(dir.write("mimic.yaml", "format: 1\nname: mimic\nrobot:\n  urdf: " + urdf +
                                                            "\n  group: [j1, j2]\nchecks: [environment]\nstart: [0, 0]\ngoal: [1, 1]\n"));
  expectTwistHoldsOn({mimic, twinArmScene(), Scene::load(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/arm6_wall.yaml")}, 17);
}

TEST(MotionBound, VelocityFieldHoldsOnTheSharedRobots) {
  CLEARWAY_REQUIRE_SHARED("robots/panda/panda.urdf");
  CLEARWAY_SHARED_OR_SKIP(root, "scenes");
  std::vector<std::shared_ptr<const Scene>> scenes;
  for (const char* name : {"box_panda/box_panda_0001.yaml", "box_ur5/box_ur5_0001.yaml"})
    scenes.push_back(std::make_shared<const Scene>(parseSceneFile(root + "/" + name)));
  expectTwistHoldsOn(scenes, 19);
}

// The bound of file's robot with every convex part a body of its own, over 20 random steps (in every third,
// some joints still): visit(bound, bodies, dq, trial) for each.
template <class Visit>
void forBoundSteps(const std::string& file, std::mt19937& rng, Visit&& visit) {
  const auto scene = test::loadScene(file);  // (the robot and its tables loaded once per process)
  std::vector<MotionBound::Body> parts;
  for (const int l : scene->geometry().geometricLinks())
    for (const LinkGeometry::Part& part : scene->geometry().link(l)->parts())
      parts.push_back({l, &part.hull, part.center, part.radius});
  const MotionBound bound(*scene, parts);
  const int bodies = scene->robot().linkCount() + static_cast<int>(parts.size()), n = scene->dimension();
  std::vector<double> q0(n), q1(n), dq(n);
  for (int trial = 0; trial < 20; ++trial) {
    randomStep(*scene, rng, q0, q1, dq);
    for (int i = 0; i < n; ++i)
      if (trial % 3 == 0 && rng() % 3 == 0) dq[i] = 0.0;
    visit(bound, bodies, dq, trial);
  }
}

// Our robots' scenes and the shared Panda's and UR5's (the latter only where the shared data is).
const char* const kOurScenes[] = {"arm6_wall", "twin_arm_table", "rover_gap", "flyer_post", "dual_arm_shelf"};
const char* const kSharedScenes[] = {"box_panda/box_panda_0001.yaml", "box_ur5/box_ur5_0001.yaml"};

// pair(path(a, b), dq), the certified check's form (its paths set up once), is pair(a, b, dq) to the bit: on
// our robots (a forked twin arm, a planar rover and a floating flyer, with their unbounded slides) and the
// shared ones, for every pair of links and of the links' convex parts, over random steps that leave some
// joints still.
TEST(MotionBound, PathsGiveThePairBoundExactly) {
  std::mt19937 rng(31);
  long compared = 0;
  const auto check = [&](const std::string& file) {
    forBoundSteps(file, rng, [&](const MotionBound& bound, int links, const std::vector<double>& dq, int trial) {
      for (int a = 0; a < links; a += 1 + (trial + a) % 3)
        for (int b = 0; b < links; ++b) {
          const MotionBound::PairPath path = bound.path(a, b);
          EXPECT_EQ(bound.pair(path, dq.data()), bound.pair(a, b, dq.data())) << file << ": " << a << " / " << b;
          ++compared;
        }
    });
  };
  for (const char* f : kOurScenes) check(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/" + f + ".yaml");
  EXPECT_GT(compared, 5000);
  CLEARWAY_REQUIRE_SHARED("robots/panda/panda.urdf");
  CLEARWAY_SHARED_OR_SKIP(root, "scenes");
  for (const char* f : kSharedScenes) check(root + "/" + f);
}

// links() is link() of every body, bit for bit (∞ past the last); and the sum of two bodies' own bounds is
// never below their pair's (the rake settles a far pair by it before walking the pair's path): our robots
// with every convex part as a body of its own, steps where some joints stand still, the shared Panda and UR5.
TEST(MotionBound, LinksAreEachLinksAndTheirSumBoundsThePair) {
  std::mt19937 rng(37);
  long compared = 0;
  const auto check = [&](const std::string& file) {
    forBoundSteps(file, rng, [&](const MotionBound& bound, int links, const std::vector<double>& dq, int trial) {
      std::vector<double> own(links + 2);  // (two past the last body: no bound there)
      bound.links(dq.data(), links + 2, own.data());
      EXPECT_EQ(own[links], INFINITY);
      EXPECT_EQ(own[links + 1], INFINITY);
      for (int a = 0; a < links; ++a) {
        ASSERT_EQ(own[a], bound.link(a, dq.data())) << file << ": " << a;
        for (int b = 0; b < links; b += 1 + (trial + b) % 3) {
          const double pair = bound.pair(a, b, dq.data());
          EXPECT_GE((own[a] + own[b]) * (1.0 + 1e-12), pair) << file << ": " << a << " / " << b;
          ++compared;
        }
      }
    });
  };
  for (const char* f : kOurScenes) check(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/" + f + ".yaml");
  EXPECT_GT(compared, 5000);
  CLEARWAY_REQUIRE_SHARED("robots/panda/panda.urdf");
  CLEARWAY_SHARED_OR_SKIP(root, "scenes");
  for (const char* f : kSharedScenes) check(root + "/" + f);
}

// A link's convex parts as links of the bound of their own (as the certified check splits a pair whose
// hulls are near): no distance between a part's hull vertices and the other link's changes by more than
// pair(part, other) says; and a part next to the axes that turn it gets a bound well below its link's
// (the UR5's upper arm turns about the shoulder, where its near end sits beside the base).
// pairStep with a StepCache is the same number as without, bit for bit, for every checked pair either way
// round in any order: the dual arm (its pairs share links and forks), the twin arm and arm6, at several
// poses one after another, each under its own id (terms kept for other poses never serve). Nor does another
// robot's cache: arm6 with two bodies has as many bound links as the twin arm, whose cache is offered to it
// under the id its terms were kept under.
TEST(MotionBound, CachedPairStepsAreThePairSteps) {
  struct Case {
    const char* scene;
    int bodies;
  };
  MotionBound::StepCache other;  // the previous robot's
  int other_links = 0;
  std::uint64_t other_id = 0;  // the id its last terms were kept under
  for (const Case& c : {Case{"dual_arm_shelf.yaml", 0}, Case{"twin_arm_table.yaml", 0}, Case{"arm6_wall.yaml", 2}}) {
    const auto scene = Scene::load(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/" + c.scene);
    std::vector<MotionBound::Body> bodies;
    const int l = scene->geometry().geometricLinks().back();
    for (int k = 0; k < c.bodies; ++k) {
      const LinkGeometry::Part& part = scene->geometry().link(l)->parts()[0];
      bodies.push_back({l, &part.hull, part.center, part.radius});
    }
    if (c.bodies > 0)
      ASSERT_EQ(scene->robot().linkCount() + c.bodies, other_links) << "the bodies make the counts equal";
    const MotionBound bound(*scene, bodies);
    MotionBound::StepCache cache = bound.makeStepCache();
    const SelfCollision& self = scene->selfCollision();
    std::vector<std::pair<int, int>> pairs;
    for (const LinkPair& p : self.pairs()) pairs.push_back({p.a, p.b}), pairs.push_back({p.b, p.a});
    ASSERT_FALSE(pairs.empty());
    std::mt19937 rng(11);
    SceneContext ctx = scene->makeContext();
    std::uint64_t id = 0;
    int compared = 0;
    for (int round = 0; round < 6; ++round) {
      const std::vector<double> q0 = randomState(*scene, rng), q1 = randomState(*scene, rng);
      std::vector<double> dq(q0.size());
      for (std::size_t i = 0; i < q0.size(); ++i) dq[i] = q1[i] - q0[i];
      scene->computePoses(q0.data(), ctx);
      ++id;
      std::shuffle(pairs.begin(), pairs.end(), rng);
      for (const auto& [a, b] : pairs)
        for (const double d : {1e-3, 0.05, 0.4}) {
          const double plain = bound.pairStep(a, b, dq.data(), ctx.poses().data(), d);
          const double cached = bound.pairStep(a, b, dq.data(), ctx.poses().data(), d, cache, id);
          ASSERT_EQ(std::memcmp(&plain, &cached, sizeof plain), 0)
              << scene->robot().link(a).name << "/" << scene->robot().link(b).name << " at d = " << d << ": " << plain
              << " vs " << cached;
          const double foreign = bound.pairStep(a, b, dq.data(), ctx.poses().data(), d, other, other_id);
          ASSERT_EQ(std::memcmp(&plain, &foreign, sizeof plain), 0) << "another robot's cache served";
          ++compared;
        }
    }
    std::printf("%s: %d pair steps compared\n", scene->robot().name().c_str(), compared);
    other = std::move(cache);
    other_links = scene->robot().linkCount() + c.bodies;
    other_id = id;
  }
}

TEST(MotionBound, HoldsForConvexParts) {
  CLEARWAY_REQUIRE_SHARED("robots/panda/panda.urdf");
  CLEARWAY_SHARED_OR_SKIP(root, "scenes");
  std::mt19937 rng(5);
  for (const char* name : {"box_panda/box_panda_0001.yaml", "box_ur5/box_ur5_0001.yaml"}) {
    const auto scene = std::make_shared<const Scene>(parseSceneFile(root + "/" + name));
    const int links = scene->robot().linkCount();
    std::vector<MotionBound::Body> parts;
    std::vector<int> first(links, -1);  // per link: the bound's link of its first part
    for (const int l : scene->geometry().geometricLinks()) {
      first[l] = links + static_cast<int>(parts.size());
      for (const LinkGeometry::Part& part : scene->geometry().link(l)->parts())
        parts.push_back({l, &part.hull, part.center, part.radius});
    }
    const MotionBound bound(*scene, parts);
    const int n = scene->dimension();
    SceneContext c0 = scene->makeContext(), c1 = scene->makeContext();
    std::vector<double> q0(n), q1(n), dq(n);
    int checked = 0, much_lower = 0;
    for (int trial = 0; trial < 20; ++trial) {
      randomStep(*scene, rng, q0, q1, dq);
      scene->computePoses(q0.data(), c0);
      scene->computePoses(q1.data(), c1);
      for (const LinkPair& p : scene->selfCollision().pairs()) {
        const double whole = bound.pair(p.a, p.b, dq.data());
        const std::vector<LinkGeometry::Part>& pa = scene->geometry().link(p.a)->parts();
        const std::vector<Vec3>& vb = scene->geometry().link(p.b)->hull().vertices();
        for (std::size_t k = 0; k < pa.size(); ++k) {
          const double b = bound.pair(first[p.a] + static_cast<int>(k), p.b, dq.data());
          EXPECT_LE(b, whole * (1 + 1e-12) + 1e-12) << name;  // a part's points are among its link's
          much_lower += b < 0.5 * whole;
          const std::vector<Vec3>& va = pa[k].hull.vertices();
          for (std::size_t i = 0; i < va.size(); i += 1 + va.size() / 8)
            for (std::size_t j = 0; j < vb.size(); j += 1 + vb.size() / 8) {
              const double before = (c0.poses()[p.b] * vb[j] - c0.poses()[p.a] * va[i]).norm();
              const double after = (c1.poses()[p.b] * vb[j] - c1.poses()[p.a] * va[i]).norm();
              EXPECT_LE(std::abs(after - before), b + 1e-9)
                  << name << ": part " << k << " of " << scene->robot().link(p.a).name << " / " << scene->robot().link(p.b).name;
              ++checked;
            }
        }
      }
    }
    EXPECT_GT(checked, 1000) << name;
    EXPECT_GT(much_lower, 20) << name << ": no part is bounded well below its link";
  }
}

}  // namespace
}  // namespace clearway
