// Certified motion (src/motion/certified.cpp): never tunnels (thin walls, thin posts, moving walls, analytic
// contact parameters), agrees with dense sampling on our robots and the shared ones, and leaves a free state
// at any clearance.
#include <clearway/environment/voxel_blocks.h>

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

TEST(MotionCertified, ThinWallIsNeverTunnelled) {
  // A 1 mm wall at x = 0: the 0.1 m block slides from x = −1 to x = 1. Sampling at 0.25 steps over it;
  // the certified check finds the contact at s = (1 − 0.0505) / 2, within contact_distance.
  TempDir dir;
  const auto scene =
      sliderScene(dir, "    - {name: wall, box: {size: [0.001, 2, 2]}, pose: {position: [0, 0, 0]}}\n");
  const double q0[2] = {-1, 0}, q1[2] = {1, 0};
  const MotionChecker coarse(scene, sampled(0.3));
  MotionContext cc = coarse.makeContext();
  EXPECT_TRUE(coarse.check(q0, q1, cc).free) << "the test needs a resolution that tunnels";

  const MotionChecker certified(scene);
  MotionContext ctx = certified.makeContext();
  const MotionResult r = certified.check(q0, q1, ctx);
  ASSERT_FALSE(r.free);
  EXPECT_FALSE(r.capped);
  EXPECT_EQ(r.report.kind, CollisionReport::Kind::Environment);
  const double touch = (1.0 - 0.0505) / 2.0;                                // distance 0
  const double near = (1.0 - 0.0505 - certified.options().contact_distance) / 2.0;  // distance = contact
  EXPECT_LE(r.first_contact, touch + 1e-9);
  EXPECT_GE(r.first_contact, near - 1e-9);
  EXPECT_LE(r.last_valid, r.first_contact);
  double q[2];
  certified.interpolate(q0, q1, r.last_valid, q);
  EXPECT_TRUE(scene->isFree(std::vector<double>(q, q + 2)));
  // Few steps: the block is far from the wall most of the way.
  EXPECT_LT(r.steps, 200);
  // The verdict only: the same verdict and what collides, found at a parameter where the block is within
  // contact_distance of the wall or through it (the segment's middle, here), with less work: its probe's
  // states and no distance query, where locating the contact measures and advances.
  const MotionResult loose = certified.check(q0, q1, ctx, /*locate_contact=*/false);
  ASSERT_FALSE(loose.free);
  EXPECT_EQ(loose.report.kind, r.report.kind);
  EXPECT_GE(loose.first_contact, near - 1e-9);
  EXPECT_LE(loose.first_contact, (1.0 + 0.0505 + certified.options().contact_distance) / 2.0 + 1e-9);
  EXPECT_EQ(loose.last_valid, 0.0);
  EXPECT_LT(loose.distance_queries, r.distance_queries);
  EXPECT_LE(loose.steps, r.steps);

  // Turning while sliding (the block's corners sweep wider) is caught as well, and sooner.
  const double t1[2] = {1, 3.0};
  const MotionResult turning = certified.check(q0, t1, ctx);
  EXPECT_FALSE(turning.free);
  EXPECT_LE(turning.first_contact, touch + 1e-9);

  // Sliding away from the wall is free, and every end of the certified segment agrees with sampling.
  const double a0[2] = {-1, 0}, a1[2] = {-0.2, 2.0};
  EXPECT_TRUE(certified.check(a0, a1, ctx).free);
  const MotionChecker fine(scene, sampled(1e-3));
  MotionContext fc = fine.makeContext();
  EXPECT_TRUE(fine.check(a0, a1, fc).free);
}

TEST(MotionCertified, ThinPostAnalyticContact) {
  // A post of radius 5 mm at (1.4, 0) and the planar arm's link2 (radius 0.05, along the arm from 1.0
  // to 1.5 m) turning through it: the distance is 1.4·|sin q1| − 0.055, so contact is at
  // q1 = asin(0.055 / 1.4). With OMPL's default resolution the sampled check steps over the post.
  TempDir dir;
  const auto scene = planarScene(
      dir, "    - {name: post, cylinder: {radius: 0.005, length: 1}, pose: {position: [1.4, 0, 0]}}\n");
  const double q0[2] = {1.55, 0}, q1[2] = {-1.45, 0};
  const MotionChecker coarse(scene, sampled(0.3));
  MotionContext cc = coarse.makeContext();
  EXPECT_TRUE(coarse.check(q0, q1, cc).free) << "the test needs a resolution that tunnels";

  const MotionChecker certified(scene);
  MotionContext ctx = certified.makeContext();
  const MotionResult r = certified.check(q0, q1, ctx);
  ASSERT_FALSE(r.free);
  EXPECT_EQ(r.report.kind, CollisionReport::Kind::Environment);
  EXPECT_EQ(r.report.link, scene->robot().linkIndex("link2"));
  auto s_at = [&](double distance) { return (1.55 - std::asin((0.055 + distance) / 1.4)) / 3.0; };
  EXPECT_LE(r.first_contact, s_at(0.0) + 1e-9);
  EXPECT_GE(r.first_contact, s_at(certified.options().contact_distance) - 1e-9);

  // The reverse direction meets the post from the other side, at the mirrored parameter.
  const MotionResult back = certified.check(q1, q0, ctx);
  ASSERT_FALSE(back.free);
  const double back_touch = (1.45 - std::asin(0.055 / 1.4)) / 3.0;
  EXPECT_LE(back.first_contact, back_touch + 1e-9);
  EXPECT_GE(back.first_contact, back_touch - 1e-3 / 1.4 / 3.0 * 2);
}

TEST(MotionCertified, AVerdictMeetsTheCollidingLinkBeforeCoveringAHoveringOne) {
  // The planar arm turns its shoulder from 0 to 1 rad: link1 sweeps 1 cm above a plate the whole way (covering
  // it takes a measurement every few hundredths of a radian), and link2 goes through a thin post at 0.6 rad,
  // where the probe's states (1, 1/2, 1/4, 3/4) do not look. Link by link, a verdict would cover link1 to
  // the end before measuring link2 once; in turns, link2 meets the post after a few of each.
  TempDir dir;
  const double top = 0.05 - 0.01;  // the links' undersides are at z = 0.05
  const auto scene =
      planarScene(dir,
                  "    - {name: plate, box: {size: [0.75, 0.35, 0.02]}, pose: {position: [0.525, 0.075, " +
                      std::to_string(top - 0.01) + "]}}\n" +
                      "    - {name: post, cylinder: {radius: 0.005, length: 1}, pose: {position: [" +
                      std::to_string(1.25 * std::cos(0.6)) + ", " + std::to_string(1.25 * std::sin(0.6)) + ", 0.1]}}\n",
                  "[environment, continuous]");
  const double q0[2] = {0, 0}, q1[2] = {1, 0};
  const MotionChecker certified(scene);
  MotionContext ctx = certified.makeContext();
  const MotionResult located = certified.check(q0, q1, ctx);
  ASSERT_FALSE(located.free);
  EXPECT_EQ(located.report.link, scene->robot().linkIndex("link2"));
  // Link1 alone, over the plate without the post: what covering it costs.
  const auto plate_only =
      planarScene(dir,
                  "    - {name: plate, box: {size: [0.75, 0.35, 0.02]}, pose: {position: [0.525, 0.075, " +
                      std::to_string(top - 0.01) + "]}}\n",
                  "[environment, continuous]");
  const MotionChecker hover(plate_only);
  MotionContext hc = hover.makeContext();
  const MotionResult covered = hover.check(q0, q1, hc, /*locate_contact=*/false);
  ASSERT_TRUE(covered.free);
  MotionContext fresh = certified.makeContext();  // (no lead from the located check)
  const MotionResult verdict = certified.check(q0, q1, fresh, /*locate_contact=*/false);
  ASSERT_FALSE(verdict.free);
  EXPECT_EQ(verdict.report.link, scene->robot().linkIndex("link2"));
  EXPECT_GT(covered.distance_queries, 40) << "the test needs a link that takes many measurements to cover";
  EXPECT_LT(verdict.distance_queries, covered.distance_queries / 2)
      << "located: " << located.distance_queries << ", link1 covered alone: " << covered.distance_queries;
}

TEST(MotionCertified, RigidBodiesAreOneItemUntilNear) {
  TempDir dir;
  // Far from everything: one query per item. The environment sees the arm and the gripper body (not its
  // three links); self-collision the base body against the gripper body (six link pairs in one), the
  // tower against the arm, and the arm against each finger (still on this segment: measured once).
  {
    const auto tabled = gripperScene(dir, "{name: far, box: {size: [0.2, 0.2, 0.2]}, pose: {position: [0, 2.5, 0]}}",
                                     "[self, environment, continuous]");
    SceneOptions without;
    without.pair_tables = false;
    const auto scene = std::make_shared<const Scene>(tabled->description(), without);
    MotionOptions measured;  // (the rake's bounding balls would settle every item: measured, each counts once)
    measured.rake = false;
    const MotionChecker certified(scene, measured), fast(tabled, measured), raked(scene);
    MotionContext ctx = certified.makeContext(), fctx = fast.makeContext(), rctx = raked.makeContext();
    const double q0[2] = {0, 0}, q1[2] = {0.02, 0};
    const MotionResult r = certified.check(q0, q1, ctx);
    EXPECT_TRUE(r.free);
    EXPECT_EQ(r.distance_queries, 2 + 4) << "link by link it would be 4 + 9";
    const MotionResult raked_result = raked.check(q0, q1, rctx);
    EXPECT_TRUE(raked_result.free);
    EXPECT_EQ(raked_result.distance_queries, 0) << "far from everything, the bounding balls settle every item";
    // Items whose pairs are moved by one or two joints, which their tables prove apart over the whole
    // segment, are not measured at all.
    const MotionResult t = fast.check(q0, q1, fctx);
    EXPECT_TRUE(t.free);
    EXPECT_LT(t.distance_queries, r.distance_queries);
  }
  // A post between the fingers: the gripper's merged hull covers it, so the fingers take over and
  // decide exactly. Panning ±0.03 keeps the post 38 mm from either finger: free, as dense sampling says.
  const auto scene = gripperScene(dir, "{name: post, cylinder: {radius: 0.02, length: 1}, pose: {position: [1.4, 0, 0]}}",
                                   "[environment, continuous]");
  const MotionChecker certified(scene);
  const MotionChecker fine(scene, sampled(1e-3));
  MotionContext ctx = certified.makeContext(), fc = fine.makeContext();
  const double a0[2] = {-0.03, 0}, a1[2] = {0.03, 0};
  const MotionResult straddle = certified.check(a0, a1, ctx);
  EXPECT_TRUE(fine.check(a0, a1, fc).free);
  EXPECT_TRUE(straddle.free);
  EXPECT_GT(straddle.distance_queries, 2) << "the merged hull touches the post: the fingers must be measured";
  // Panning on to 0.1 brings the right finger's inner face onto the post: in the palm's frame the post's
  // centre is at y = −1.4·sin(pan), so the gap 0.10 − 0.02 closes at pan = asin(0.08 / 1.4).
  const double b1[2] = {0.1, 0};
  const MotionResult hit = certified.check(a0, b1, ctx);
  ASSERT_FALSE(hit.free);
  EXPECT_EQ(hit.report.kind, CollisionReport::Kind::Environment);
  EXPECT_EQ(hit.report.link, scene->robot().linkIndex("finger_r")) << "a member link is reported, never the body";
  const auto s_at = [](double gap) { return (std::asin((0.08 - gap) / 1.4) + 0.03) / 0.13; };
  EXPECT_LE(hit.first_contact, s_at(0.0) + 1e-9);
  EXPECT_GE(hit.first_contact, s_at(certified.options().contact_distance) - 1e-9);
  EXPECT_LE(hit.first_contact, fine.check(a0, b1, fc).first_contact + 1e-9);
}

TEST(MotionCertified, AMergedBodyIsItsOwnScenesAndRobots) {
  // An arm and a flap on a held joint at its end move as one body, merged once per robot and remembered:
  // yet each scene merges at its own held value and each robot from its own links. Turning the arm 0.4 rad
  // sweeps a flap that points on along the arm (fold 0) through the post at radius 0.74, while a flap
  // folded back (fold -pi/2) stays within radius 0.59 and 0.2 m of the post's side.
  const auto urdf = [](double flap_length) {
    const std::string l = std::to_string(flap_length);
    return "<robot name=\"flap\"><link name=\"base\"/><link name=\"arm\"><collision><origin xyz=\"0.25 0 0\"/>"
           "<geometry><box size=\"0.5 0.05 0.05\"/></geometry></collision></link><link name=\"flap\"><collision>"
           "<origin xyz=\"" +
           std::to_string(flap_length / 2) + " 0 0\"/><geometry><box size=\"" + l +
           " 0.05 0.05\"/></geometry></collision></link><joint name=\"turn\" type=\"revolute\"><parent link=\"base\"/>"
           "<child link=\"arm\"/><axis xyz=\"0 0 1\"/><limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/>"
           "</joint><joint name=\"fold\" type=\"revolute\"><origin xyz=\"0.5 0 0\"/><parent link=\"arm\"/>"
           "<child link=\"flap\"/><axis xyz=\"0 0 1\"/><limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/>"
           "</joint></robot>";
  };
  TempDir dir;
  const auto description = [&](const std::string& urdf_file, double fold) {
    return parseSceneFile(dir.write(
        "flap.yaml", "format: 1\nname: flap\nrobot:\n  urdf: " + urdf_file +
                         "\n  group: [turn]\n  hold: {fold: " + std::to_string(fold) +
                         "}\nenvironment:\n  obstacles:\n    - {name: post, box: {size: [0.05, "
                         "0.05, 0.3]}, pose: {position: [0.7, 0.25, 0]}}\nchecks: [environment, continuous]\n"));
  };
  const double q0[1] = {0}, q1[1] = {0.4};
  const auto free = [&](const SceneDescription& d, const std::shared_ptr<const RobotGeometry>& robot) {
    const auto scene = std::make_shared<const Scene>(d, robot, loadEnvironment(d));
    const MotionChecker certified(scene);
    MotionContext ctx = certified.makeContext();
    const MotionResult r = certified.check(q0, q1, ctx);
    EXPECT_FALSE(r.capped);
    return r.free;
  };
  const std::string long_flap = dir.write("long.urdf", urdf(0.3));
  {
    // (Folded first: a merge remembered without its offsets would place the flap folded at fold 0 too.)
    const std::shared_ptr<const RobotGeometry> robot = loadRobotGeometry(description(long_flap, 0.0));
    for (const double fold : {-M_PI / 2, 0.0, -M_PI / 2, 0.0})
      EXPECT_EQ(free(description(long_flap, fold), robot), fold != 0.0) << "fold " << fold;
  }
  // Two robots alive at once, alike but for the flap's length, whose merged bodies have the same links and
  // offsets: each is merged from its own links (the short flap does not reach the post).
  const SceneDescription short_scene = description(dir.write("short.urdf", urdf(0.1)), 0.0);
  const SceneDescription long_scene = description(long_flap, 0.0);
  const auto short_robot = loadRobotGeometry(short_scene), long_robot = loadRobotGeometry(long_scene);
  for (int k = 0; k < 4; ++k)
    EXPECT_EQ(k % 2 == 0 ? free(short_scene, short_robot) : free(long_scene, long_robot), k % 2 == 0) << "robot " << k;
}

TEST(MotionCertified, ConcaveLinkAroundAPostIsDecidedByItsElements) {
  // One link, a fork of three boxes (the gripper's palm and fingers as one link): its hull covers the
  // post between the prongs, but the prongs stay 38 mm clear of it, as dense sampling says.
  TempDir dir;
  const std::string urdf = dir.write("fork.urdf", R"(<?xml version="1.0"?>
<robot name="fork">
  <link name="base"/>
  <link name="fork">
    <collision><origin xyz="1.25 0 0"/><geometry><box size="0.06 0.3 0.08"/></geometry></collision>
    <collision><origin xyz="1.38 0.12 0"/><geometry><box size="0.2 0.04 0.08"/></geometry></collision>
    <collision><origin xyz="1.38 -0.12 0"/><geometry><box size="0.2 0.04 0.08"/></geometry></collision>
  </link>
  <joint name="pan" type="revolute">
    <parent link="base"/><child link="fork"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="1" effort="1"/>
  </joint>
</robot>
)");
  const auto scene = Scene::load(dir.write("fork.yaml", "format: 1\nname: fork\nrobot:\n  urdf: " + urdf +
                                                          "\n  group: [pan]\nenvironment:\n  obstacles:\n    - {name: post, "
                                                          "cylinder: {radius: 0.02, length: 1}, pose: {position: [1.4, 0, 0]}}\n"
                                                          "checks: [environment, continuous]\nstart: [0]\ngoal: [0.03]\n"));
  const MotionChecker certified(scene);
  const MotionChecker fine(scene, sampled(1e-3));
  MotionContext ctx = certified.makeContext(), fc = fine.makeContext();
  const double a0[1] = {-0.03}, a1[1] = {0.03};
  EXPECT_TRUE(fine.check(a0, a1, fc).free);
  const MotionResult r = certified.check(a0, a1, ctx);
  EXPECT_TRUE(r.free) << "the hull touches the post; the boxes do not";
  const double b1[1] = {0.1};
  const MotionResult hit = certified.check(a0, b1, ctx);
  ASSERT_FALSE(hit.free);
  EXPECT_LE(hit.first_contact, fine.check(a0, b1, fc).first_contact + 1e-9);
  EXPECT_EQ(hit.report.kind, CollisionReport::Kind::Environment);
}

TEST(MotionCertified, RigidPairThatOverlapsCollidesEverywhere) {
  // Both fingers at y = −0.12: they overlap, and no joint of the group can part them.
  TempDir dir;
  const auto scene = gripperScene(dir, "{name: far, box: {size: [0.2, 0.2, 0.2]}, pose: {position: [0, 2.5, 0]}}",
                                   "[self, continuous]", "-0.12");
  const MotionChecker certified(scene);
  MotionContext ctx = certified.makeContext();
  const double q0[2] = {0, 0}, q1[2] = {1, -1};
  const MotionResult r = certified.check(q0, q1, ctx);
  ASSERT_FALSE(r.free);
  EXPECT_EQ(r.first_contact, 0.0);
  EXPECT_EQ(r.last_valid, 0.0);
  EXPECT_EQ(r.report.kind, CollisionReport::Kind::Self);
  const int l = scene->robot().linkIndex("finger_l"), rr = scene->robot().linkIndex("finger_r");
  EXPECT_EQ(std::minmax(r.report.link, r.report.other_link), std::minmax(l, rr));
  EXPECT_FALSE(scene->isFree(std::vector<double>{0.5, 0.5})) << "the discrete check agrees";
}

TEST(MotionCertified, RandomSegmentsNeverMissWhatDenseSamplingFinds) {
  // The planar arm among two posts: random segments between free states. Dense sampling finding a
  // collision means the certified check must find one, no later along the segment.
  TempDir dir;
  const auto scene = planarScene(dir,
                                 "    - {name: post, cylinder: {radius: 0.03, length: 1}, pose: {position: [0, 1.2, 0]}}\n"
                                 "    - {name: rod, box: {size: [0.02, 0.02, 1]}, pose: {position: [-0.9, -0.9, 0]}}\n");
  const MotionChecker certified(scene);
  MotionContext ctx = certified.makeContext();
  const MotionChecker fine(scene, sampled(2e-3));
  MotionContext fc = fine.makeContext();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> s1(-3.1, 3.1), s2(-2.5, 2.5);
  int collide = 0, free = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const double q0[2] = {s1(rng), s2(rng)}, q1[2] = {s1(rng), s2(rng)};
    if (!scene->isFree(std::vector<double>(q0, q0 + 2)) || !scene->isFree(std::vector<double>(q1, q1 + 2))) continue;
    const MotionResult c = certified.check(q0, q1, ctx);
    const MotionResult d = fine.check(q0, q1, fc);
    if (!d.free) {
      EXPECT_FALSE(c.free) << "trial " << trial << ": certified missed a collision sampling found";
      EXPECT_LE(c.first_contact, d.first_contact + 1e-9);
    }
    (c.free ? free : collide)++;
  }
  EXPECT_GT(collide, 20);
  EXPECT_GT(free, 20);
}

TEST(MotionCertified, PlanarAndFloatingNeverMissWhatDenseSamplingFinds) {
  // The rover between thin walls, the flyer through a thin plate: random segments between free states.
  TempDir dir;
  for (const auto& scene : {roverScene(dir), flyerScene(dir)}) {
    const MotionChecker certified(scene);
    MotionContext ctx = certified.makeContext();
    const MotionChecker fine(scene, sampled(2e-3));
    MotionContext fc = fine.makeContext();
    std::mt19937 rng(8);
    int collide = 0, free = 0;
    for (int trial = 0; trial < 150; ++trial) {
      const std::vector<double> q0 = randomState(*scene, rng), q1 = randomState(*scene, rng);
      if (!scene->isFree(q0) || !scene->isFree(q1)) continue;
      const MotionResult c = certified.check(q0.data(), q1.data(), ctx);
      const MotionResult d = fine.check(q0.data(), q1.data(), fc);
      if (!d.free) {
        EXPECT_FALSE(c.free) << scene->name() << " trial " << trial << ": certified missed a collision";
        EXPECT_LE(c.first_contact, d.first_contact + 1e-9);
      }
      EXPECT_FALSE(c.capped);
      (c.free ? free : collide)++;
    }
    EXPECT_GT(collide, 15) << scene->name();
    EXPECT_GT(free, 15) << scene->name();
  }
  // Past the post, along x above the plate: sampling at 0.5 steps over it; the certified check finds
  // the plate's edge (x + 0.15) meeting the post's side (x = 0.69).
  const auto flyer = flyerScene(dir);
  const double a0[7] = {-1, 0.7, 0.5, 0, 0, 0, 1}, a1[7] = {2, 0.7, 0.5, 0, 0, 0, 1};
  const MotionChecker coarse(flyer, sampled(0.5));
  MotionContext cc = coarse.makeContext();
  EXPECT_TRUE(coarse.check(a0, a1, cc).free) << "the test needs a resolution that tunnels";
  const MotionChecker certified(flyer);
  MotionContext ctx = certified.makeContext();
  const MotionResult r = certified.check(a0, a1, ctx);
  ASSERT_FALSE(r.free);
  EXPECT_LE(r.first_contact, (0.69 - 0.15 + 1) / 3 + 1e-9);
  EXPECT_GE(r.first_contact, (0.69 - 0.15 + 1 - certified.options().contact_distance) / 3 - 1e-9);
}

// A planar or floating joint without bounds (robot.bounds is optional): its slides may take the robot anywhere,
// so the links' distances from the axes above them have no bound, while those from the joints below do.
// The rover and the flyer with their bounds struck out still get real answers (a motion bound that
// subtracted one unbounded sum from another was NaN, and the check called every such segment colliding at
// its start), and never miss what dense sampling finds.
TEST(MotionCertified, UnboundedPlanarAndFloatingJointsStillAnswer) {
  TempDir dir;
  for (const char* robot : {"rover", "flyer"}) {
    const std::string file = std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/" + (robot == std::string("rover") ? "rover_gap.yaml" : "flyer_post.yaml");
    std::ifstream in(file);
    std::string text, line;
    while (std::getline(in, line)) {
      if (line.find("bounds:") != std::string::npos) continue;
      const std::string relative = std::string("../") + robot + "/";
      if (const std::size_t at = line.find(relative); at != std::string::npos)
        line.replace(at, relative.size(), std::string(CLEARWAY_SOURCE_DIR) + "/robots/" + robot + "/");
      text += line + "\n";
    }
    const auto bounded = Scene::load(file);
    const auto open = Scene::load(dir.write(std::string(robot) + "_open.yaml", text));
    ASSERT_FALSE(std::isfinite(open->lower(0)) && std::isfinite(open->upper(0))) << robot << ": the bounds were not struck out";
    const MotionChecker b(bounded), u(open), fine(open, sampled(2e-3));
    MotionContext bc = b.makeContext(), uc = u.makeContext(), fc = fine.makeContext();
    std::mt19937 rng(23);
    int free_bounded = 0, free_open = 0, collide = 0;
    for (int trial = 0; trial < 150; ++trial) {
      const std::vector<double> q0 = randomState(*bounded, rng), q1 = randomState(*bounded, rng);
      if (!open->isFree(q0) || !open->isFree(q1)) continue;
      const MotionResult c = u.check(q0.data(), q1.data(), uc);
      const MotionResult d = fine.check(q0.data(), q1.data(), fc);
      if (!d.free) EXPECT_FALSE(c.free) << robot << " trial " << trial << ": certified missed a collision";
      EXPECT_FALSE(c.capped) << robot << " trial " << trial;
      free_open += c.free;
      collide += !d.free;
      free_bounded += b.check(q0.data(), q1.data(), bc).free;
    }
    std::printf("%s without bounds: %d segments free (%d with them), %d colliding\n", robot, free_open, free_bounded, collide);
    EXPECT_GT(free_open, 15) << robot;
    EXPECT_GE(free_open, free_bounded * 9 / 10) << robot;
    EXPECT_GT(collide, 15) << robot;
  }
}

TEST(MotionCertified, BranchingPaddedRobotNeverMissesWhatDenseSamplingFinds) {
  // The two arms over a table, by a thin post and under a thin bar, with 1 cm of padding: random steps
  // between free states, checked by the certified loop and by dense sampling (2 mm in the joint vector).
  // A collision sampling finds must be found no later; the arms meet each other often enough that
  // self-collisions across the fork are among them.
  const auto scene = twinArmScene();
  ASSERT_GT(scene->description().padding, 0.0);
  const MotionChecker certified(scene);
  MotionContext ctx = certified.makeContext();
  const MotionChecker fine(scene, sampled(2e-3));
  MotionContext fc = fine.makeContext();
  const int n = scene->dimension();
  int across = 0;
  const DenseRun run = compareWithDenseSampling(scene, 14, 6000, 1 << 30, [&](const MotionResult& d) {
    if (d.report.kind != CollisionReport::Kind::Self) return;
    const std::string a = scene->robot().link(d.report.link).name, b = scene->robot().link(d.report.other_link).name;
    across += (a.rfind("left_", 0) == 0 && b.rfind("right_", 0) == 0) || (a.rfind("right_", 0) == 0 && b.rfind("left_", 0) == 0);
  });
  const int collide = run.collide, free = run.segments - run.collide, misses = run.misses;
  std::printf("twin_arm: %d segments free, %d collide (%d first between the arms), %d missed\n", free, collide, across,
              misses);
  EXPECT_EQ(misses, 0);
  EXPECT_GT(collide, 30);
  EXPECT_GT(free, 30);
  // Random segments meet the torso, table and bar first; one that folds the left forearm across the right
  // arm meets the other branch: both checks find it, the certified one no later.
  std::vector<double> q0(n, 0.0), q1(n, 0.0);
  q1[3] = -2.5;  // left_elbow
  ASSERT_TRUE(scene->isFree(q0));
  const MotionResult c = certified.check(q0.data(), q1.data(), ctx);
  const MotionResult d = fine.check(q0.data(), q1.data(), fc);
  ASSERT_FALSE(d.free);
  ASSERT_EQ(d.report.kind, CollisionReport::Kind::Self) << scene->describe(d.report);
  const std::string a = scene->robot().link(d.report.link).name, b = scene->robot().link(d.report.other_link).name;
  EXPECT_TRUE((a.rfind("left_", 0) == 0 && b.rfind("right_", 0) == 0) || (a.rfind("right_", 0) == 0 && b.rfind("left_", 0) == 0))
      << scene->describe(d.report);
  EXPECT_FALSE(c.free);
  EXPECT_LE(c.first_contact, d.first_contact + 1e-9);
}

// Our mobile two-armed robot of URDF primitives (robots/dual_arm: 27 joints, all 528 non-adjacent pairs
// checked) before a table and a shelf: segments between free states, certified against dense sampling
// (2 mm in the joint vector). A collision sampling finds must be found, no later; a self-collision too.
TEST(MotionCertified, ManyPairRobotNeverMissesWhatDenseSamplingFinds) {
  const auto scene = Scene::load(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/dual_arm_shelf.yaml");
  ASSERT_GT(scene->selfCollision().pairs().size(), 500u);
  const DenseRun run = compareWithDenseSampling(scene, 43, 20000, 200, [](const MotionResult&) {});
  std::printf("dual_arm: %d segments, %d collide (certified), %d missed\n", run.segments, run.collide, run.misses);
  EXPECT_EQ(run.segments, 200);
  EXPECT_EQ(run.misses, 0);
  EXPECT_GT(run.collide, 10);
  EXPECT_LT(run.collide, run.segments - 10);
  // Random segments meet the table, the shelf and the torso first; this one (found by a search) closes
  // the right hand's fingers on each other on the way: both checks find the fingertips, the certified one
  // no later.
  const std::vector<double> q0 = {0.231, 0.899, 1.225, 0.087, 0.680, -2.148, -1.827, 0.389, -0.840, 1.400, -0.959,
                                  0.154, 0.222, -0.427, -0.314, 0.143, -1.302, 1.686, -0.987, 1.616, -0.788, 0.418,
                                  1.930, -0.416, 0.267, 0.392, -0.379};
  const std::vector<double> q1 = {0.094, 0.625, -0.558, -1.668, 0.243, -0.467, -0.082, 1.234, -0.072, -1.066, -0.796,
                                  0.348, 0.165, 0.438, 0.123, -1.252, -0.531, 2.557, 0.187, -2.350, -0.559, -1.096,
                                  0.487, -0.478, -0.427, -0.027, 0.011};
  ASSERT_TRUE(scene->isFree(q0) && scene->isFree(q1));
  const MotionChecker certified(scene), fine(scene, sampled(2e-3));
  MotionContext ctx = certified.makeContext(), fc = fine.makeContext();
  const MotionResult c = certified.check(q0.data(), q1.data(), ctx), d = fine.check(q0.data(), q1.data(), fc);
  ASSERT_FALSE(d.free);
  EXPECT_EQ(d.report.kind, CollisionReport::Kind::Self) << scene->describe(d.report);
  EXPECT_FALSE(c.free);
  EXPECT_LE(c.first_contact, d.first_contact + 1e-9);
}

// With hundreds of items, each item's intervals are measured at dyadic parameters, which items share, and
// the sweep keeps the poses of its last few parameters: a free segment of RRTConnect's range places far
// fewer parameters than it measures (at the intervals' own midpoints, about one in two).
TEST(MotionCertified, ManyItemsShareTheParametersTheyAreMeasuredAt) {
  const auto scene = Scene::load(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/dual_arm_shelf.yaml");
  MotionOptions measured;  // (every item measured: the rake settles most of them)
  measured.rake = false;
  const MotionChecker certified(scene, measured);
  MotionContext ctx = certified.makeContext();
  std::mt19937_64 rng(7);
  const int dim = scene->dimension();
  double extent = 0.0;
  for (int i = 0; i < dim; ++i) extent += (scene->upper(i) - scene->lower(i)) * (scene->upper(i) - scene->lower(i));
  const double range = 0.2 * std::sqrt(extent);  // (OMPL's default for RRTConnect)
  std::vector<double> q0(dim), q1(dim);
  long steps = 0, queries = 0;
  int free = 0;
  for (int tries = 0; tries < 20000 && free < 20; ++tries) {
    for (int i = 0; i < dim; ++i) q0[i] = std::uniform_real_distribution<double>(scene->lower(i), scene->upper(i))(rng);
    if (!scene->isFree(q0)) continue;
    double length = 0.0;
    for (int i = 0; i < dim; ++i) {
      q1[i] = std::uniform_real_distribution<double>(scene->lower(i), scene->upper(i))(rng);
      length += (q1[i] - q0[i]) * (q1[i] - q0[i]);
    }
    length = std::sqrt(length);
    for (int i = 0; i < dim; ++i) q1[i] = q0[i] + (q1[i] - q0[i]) * std::min(1.0, range / length);
    const MotionResult r = certified.check(q0.data(), q1.data(), ctx, /*locate_contact=*/false);
    if (!r.free) continue;
    ++free;
    steps += r.steps;
    queries += r.distance_queries;
  }
  ASSERT_EQ(free, 20);
  std::printf("dual_arm: 20 free segments, %.1f parameters placed and %.1f distances measured per segment\n",
              steps / 20.0, queries / 20.0);
  EXPECT_GT(queries, 20 * 300);  // (hundreds of items, each measured)
  EXPECT_LT(steps, queries / 3);
}

TEST(MotionCertified, MovingWallIsNeverTunnelled) {
  // The block (0.1 m) holds still at x = 0 from t = 0 to t = 2 while the wall sweeps from x = −1 to x = 1:
  // both ends are free, so sampling the (zero-length) segment sees nothing; the certified check finds the
  // wall's face reaching the block's at t = 1 − 0.0505, s = t / 2, within contact_distance (1 m/s).
  TempDir dir;
  const auto scene = movingWallScene(dir, -1.0);
  const double q[2] = {0, 0};
  const MotionChecker coarse(scene, sampled(0.01));
  MotionContext cc = coarse.makeContext();
  EXPECT_TRUE(coarse.check(q, 0.0, q, 2.0, cc).free) << "the test needs a sampling that tunnels";
  const MotionChecker certified(scene);
  MotionContext ctx = certified.makeContext();
  const MotionResult r = certified.check(q, 0.0, q, 2.0, ctx);
  ASSERT_FALSE(r.free);
  EXPECT_EQ(r.report.kind, CollisionReport::Kind::Environment);
  const double touch = (1.0 - 0.0505) / 2.0, near = (1.0 - 0.0505 - certified.options().contact_distance) / 2.0;
  EXPECT_LE(r.first_contact, touch + 1e-9);
  EXPECT_GE(r.first_contact, near - 1e-9);
  EXPECT_LE(r.last_valid, r.first_contact);
  SceneContext sc = scene->makeContext();
  EXPECT_TRUE(scene->isFree(q, sc, nullptr, 2.0 * r.last_valid));
  // Without times (or later, once the wall is past) the same segment is free; the block running away from
  // the wall at 1.2 m/s is never caught, at 0.1 m/s it is.
  EXPECT_TRUE(certified.check(q, q, ctx).free);
  EXPECT_TRUE(certified.check(q, 3.0, q, 5.0, ctx).free);
  // At t = 1 the wall is inside the block: a segment that takes no time there collides, in every mode
  // (cast mode casts nothing that moves, and holds the obstacles where they are at t0).
  for (const MotionMode mode : {MotionMode::Certified, MotionMode::Cast, MotionMode::Sampled}) {
    MotionOptions o;
    o.mode = mode;
    const MotionChecker m(scene, o);
    MotionContext mctx = m.makeContext();
    EXPECT_FALSE(m.check(q, 1.0, q, 1.0, mctx).free) << static_cast<int>(mode);
    EXPECT_TRUE(m.check(q, 3.0, q, 3.0, mctx).free) << static_cast<int>(mode);
  }
  const auto ahead = movingWallScene(dir, -0.6);  // the wall's face at −0.5995, the block's back at −0.55
  const MotionChecker runner(ahead);
  MotionContext rc = runner.makeContext();
  const double away0[2] = {-0.5, 0}, away1[2] = {0.7, 0};
  EXPECT_TRUE(runner.check(away0, 0.0, away1, 1.0, rc).free);
  EXPECT_FALSE(runner.check(away0, 0.0, away1, 12.0, rc).free);
}

// Random segments of the slider and turning block against walls that cross its path at 1 m/s: the certified
// check never says free where a dense sampling in time (1e-4 of the segment) finds a collision.
TEST(MotionCertified, MovingObstaclesNeverMissWhatDenseSamplingFinds) {
  TempDir dir;
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int segments = 0, hits = 0, misses = 0, extras = 0;
  for (int scene_k = 0; scene_k < 3; ++scene_k) {
    const auto scene = movingWallScene(dir, -1.5 + 0.5 * scene_k);
    const MotionChecker certified(scene);
    MotionContext ctx = certified.makeContext();
    SceneContext sc = scene->makeContext();
    for (int trial = 0; trial < 60; ++trial) {
      const double q0[2] = {u(rng), 3 * u(rng)}, q1[2] = {u(rng), 3 * u(rng)};
      const double t0 = 1.5 * (u(rng) + 1), t1 = t0 + 0.8 * (u(rng) + 1);
      if (!scene->isFree(q0, sc, nullptr, t0) || !scene->isFree(q1, sc, nullptr, t1)) continue;
      ++segments;
      bool dense_hit = false;
      double q[2];
      for (int k = 0; k <= 10000 && !dense_hit; ++k) {
        const double s = k / 10000.0;
        for (int i = 0; i < 2; ++i) q[i] = q0[i] + s * (q1[i] - q0[i]);
        dense_hit = !scene->isFree(q, sc, nullptr, t0 + s * (t1 - t0));
      }
      const MotionResult r = certified.check(q0, t0, q1, t1, ctx);
      hits += dense_hit;
      misses += dense_hit && r.free;
      extras += !dense_hit && !r.free;
    }
  }
  std::printf("%d segments: %d collide (dense), %d missed, %d said colliding only by the certified check\n", segments,
              hits, misses, extras);
  EXPECT_GT(segments, 100);
  EXPECT_GT(hits, 20) << "the walls must cross some segments";
  EXPECT_EQ(misses, 0);
  EXPECT_LE(extras, segments / 20) << "said colliding far more often than dense sampling finds (contact_distance is 1 mm)";
}

// The shared Panda and UR5 problems: segments from the start towards random states. Dense sampling
// (1e-3 rad) finding a collision means the certified check must find one no later; the certified check
// reporting a contact that sampling does not see is allowed only where the robot is truly within
// contact_distance (clearance measured at the contact parameter).
TEST(MotionCertified, SharedProblemsAgreeWithDenseSampling) {
  CLEARWAY_REQUIRE_SHARED("robots/panda/panda.urdf");
  CLEARWAY_SHARED_OR_SKIP(root, "scenes");
  int segments = 0, both_free = 0, both_hit = 0, certified_only = 0;
  std::mt19937 rng(3);
  for (const char* name : {"bookshelf_small_panda/bookshelf_small_panda_0001.yaml", "box_ur5/box_ur5_0002.yaml",
                           "cage_panda/cage_panda_0003.yaml"}) {
    SceneDescription d = parseSceneFile(root + "/" + name);
    d.effects.clearance = true;  // to measure the clearance where the certified check stops
    const auto scene = std::make_shared<const Scene>(d);
    const MotionChecker certified(scene);
    MotionOptions dense = sampled(1e-3);
    const MotionChecker fine(scene, dense);
    MotionContext c = certified.makeContext(), f = fine.makeContext();
    SceneContext sc = scene->makeContext();
    const int n = scene->dimension();
    std::vector<double> q1(n), mid(n);
    for (int trial = 0; trial < 40; ++trial) {
      const std::vector<double>& q0 = trial % 2 ? d.start : d.goal;
      for (int i = 0; i < n; ++i) {
        std::uniform_real_distribution<double> u(-0.6, 0.6);
        q1[i] = std::clamp(q0[i] + u(rng), scene->lower(i), scene->upper(i));
      }
      if (!scene->isFree(q1)) continue;
      ++segments;
      const MotionResult a = certified.check(q0.data(), q1.data(), c);
      const MotionResult b = fine.check(q0.data(), q1.data(), f);
      EXPECT_FALSE(a.capped) << name << " trial " << trial;
      if (!b.free) {
        EXPECT_FALSE(a.free) << name << " trial " << trial << ": certified missed what sampling found";
        EXPECT_LE(a.first_contact, b.first_contact + 1e-9) << name << " trial " << trial;
        ++both_hit;
      } else if (a.free) {
        ++both_free;
      } else {
        ++certified_only;
        certified.interpolate(q0.data(), q1.data(), a.first_contact, mid.data());
        const double clearance = scene->clearance(mid.data(), sc);
        EXPECT_LE(clearance, certified.options().contact_distance * 1.5 + 1e-6)
            << name << " trial " << trial << " at s = " << a.first_contact;
      }
    }
  }
  std::printf("%d segments: %d free, %d collide (both), %d within contact_distance (certified only)\n", segments,
              both_free, both_hit, certified_only);
  EXPECT_GT(segments, 60);
  EXPECT_GT(both_free, 10);
  EXPECT_GT(both_hit, 10);
}

// Hull mode: the hulls decide, which hold more than the parts whose clearances split a pair's steps in
// Mesh mode. Segments of the shared Panda problem (self and environment), certified against dense sampling,
// both in Hull mode.
TEST(MotionCertified, HullModeNeverMissesWhatDenseSamplingFinds) {
  CLEARWAY_SHARED_OR_SKIP(path, "scenes/bookshelf_small_panda/bookshelf_small_panda_0001.yaml");
  SceneOptions hull;
  hull.mode = GeometryMode::Hull;
  const auto scene = Scene::load(path, hull);
  const MotionChecker certified(scene);
  const MotionChecker fine(scene, sampled(1e-3));
  MotionContext c = certified.makeContext(), f = fine.makeContext();
  const int n = scene->dimension();
  std::mt19937 rng(5);
  std::vector<double> q0(n), q1(n);
  int segments = 0, hit = 0;
  while (segments < 400) {
    for (int i = 0; i < n; ++i) q0[i] = std::uniform_real_distribution<double>(scene->lower(i), scene->upper(i))(rng);
    if (!scene->isFree(q0)) continue;
    for (int i = 0; i < n; ++i)
      q1[i] = std::clamp(q0[i] + std::uniform_real_distribution<double>(-2.0, 2.0)(rng), scene->lower(i), scene->upper(i));
    if (!scene->isFree(q1)) continue;
    ++segments;
    const MotionResult a = certified.check(q0.data(), q1.data(), c);
    const MotionResult b = fine.check(q0.data(), q1.data(), f);
    if (!b.free) {
      ++hit;
      EXPECT_FALSE(a.free) << "segment " << segments << ": certified missed what sampling found";
      EXPECT_LE(a.first_contact, b.first_contact + 1e-9) << "segment " << segments;
    }
  }
  EXPECT_GT(hit, 20);
}

// Pair tables skip self items they prove apart along a segment: the verdicts with and without them are
// the same on random segments of the shared problems and our arm (a skipped item is one the sweep would
// also have found clear: more than padding + 2·contact_distance apart throughout), and the skipping saves
// distance queries.
TEST(MotionCertified, PairTablesKeepEveryVerdict) {
  std::vector<SceneDescription> scenes = {parseSceneText(test::armScene("", ""), "<arm>", "")};
  const std::string shared = test::sharedPath("scenes");
  if (!shared.empty() && std::filesystem::exists(shared + "/box_panda"))
    for (const char* name : {"box_panda/box_panda_0001.yaml", "cage_ur5/cage_ur5_0002.yaml"})
      scenes.push_back(parseSceneFile(shared + "/" + name));
  for (const SceneDescription& d : scenes) {
    SCOPED_TRACE(d.name);
    SceneOptions without;
    without.pair_tables = false;
    const auto fast = std::make_shared<const Scene>(d);
    const auto plain = std::make_shared<const Scene>(d, fast->geometryPtr(), fast->environmentPtr(), without);
    for (const MotionMode mode : {MotionMode::Certified, MotionMode::Cast}) {
      MotionOptions o;
      o.mode = mode;
      const MotionChecker a(fast, o), b(plain, o);
      MotionContext ca = a.makeContext(), cb = b.makeContext();
      SceneContext sc = fast->makeContext();
      std::mt19937 rng(41);
      long queries_a = 0, queries_b = 0;
      int segments = 0, free = 0;
      std::vector<double> q0(fast->dimension()), q1(fast->dimension());
      while (segments < 300) {
        for (int i = 0; i < fast->dimension(); ++i) {
          q0[i] = std::uniform_real_distribution<double>(fast->lower(i), fast->upper(i))(rng);
          q1[i] = std::clamp(q0[i] + std::uniform_real_distribution<double>(-2.0, 2.0)(rng), fast->lower(i), fast->upper(i));
        }
        if (!fast->isFree(q0.data(), sc)) continue;
        ++segments;
        const MotionResult ra = a.check(q0.data(), q1.data(), ca, false), rb = b.check(q0.data(), q1.data(), cb, false);
        ASSERT_EQ(ra.free, rb.free) << "segment " << segments;
        free += ra.free;
        queries_a += ra.distance_queries;
        queries_b += rb.distance_queries;
      }
      std::printf("%s: %d of %d segments free; %ld distance queries with tables, %ld without\n", d.name.c_str(), free,
                  segments, queries_a, queries_b);
      EXPECT_GT(free, 30);
      EXPECT_LT(free, segments);
      EXPECT_LE(queries_a, queries_b);
    }
  }
}

TEST(MotionCertified, FreeStatesNearContactCanBeLeft) {
  // The block (0.1 m, at x = 0) has a wall 0.5 mm, then 1 µm, beyond its face (contact_distance is
  // 1 mm): a motion of length zero and one away from the wall are free, in both directions and every
  // mode; one into the wall is not.
  for (const double gap : {5e-4, 1e-6}) {
    TempDir dir;
    const double x = 0.05 + gap + 0.005;  // the wall's centre: the block's face + gap + half its width
    const auto scene = sliderScene(dir, "    - {name: wall, box: {size: [0.01, 2, 2]}, pose: {position: [" +
                                            exactNumber(x) + ", 0, 0]}}\n");
    const double q0[2] = {0.0, 0.0}, away[2] = {-0.5, 0.0}, into[2] = {0.1, 0.0};
    ASSERT_TRUE(scene->isFree(std::vector<double>(q0, q0 + 2))) << "gap " << gap;
    for (const MotionMode mode : {MotionMode::Certified, MotionMode::Cast}) {
      MotionOptions o;
      o.mode = mode;
      const MotionChecker checker(scene, o);
      MotionContext c = checker.makeContext();
      for (const bool locate : {true, false}) {
        const MotionResult zero = checker.check(q0, q0, c, locate);
        EXPECT_TRUE(zero.free) << "gap " << gap << ": a free state must be leavable";
        EXPECT_FALSE(zero.capped);
        EXPECT_TRUE(checker.check(q0, away, c, locate).free) << "gap " << gap;
        EXPECT_TRUE(checker.check(away, q0, c, locate).free) << "gap " << gap;
        EXPECT_FALSE(checker.check(q0, into, c, locate).free) << "gap " << gap;
        EXPECT_FALSE(checker.check(into, q0, c, locate).free) << "gap " << gap;
      }
    }
  }
}

TEST(MotionCertified, FreeStatesNearContactLeaveInEveryDirection) {
  // The planar arm's link2 tip 0.3 mm from a post: short motions from there are free when dense sampling
  // keeps them beyond 1.2 times the contact distance along the way (half the nearer end's clearance, grown
  // by kContactGrowth of the motion bound away from it; measured with GJK's relative error 0.1), and
  // never free when they touch.
  TempDir dir;
  // link2 at q = (0, 0) is a cylinder of radius 0.05 along x from the elbow at x = 1 to 1.5, 0.1 up (see the URDF);
  // the post stands beside it, its near face 0.3 mm beyond the cylinder's side: turning either joint one
  // way moves link2 into it, the other way away.
  const double y = 0.05 + 0.05 + 3e-4;
  const auto scene = planarScene(dir, "    - {name: post, box: {size: [0.1, 0.1, 0.1]}, pose: {position: [1.25, " +
                                          exactNumber(y) + ", 0.1]}}\n",
                                 "[self, environment, continuous, clearance]");
  const double q_start[2] = {0.0, 0.0};
  SceneContext sc = scene->makeContext();
  const double c0 = scene->clearance(q_start, sc);
  ASSERT_GT(c0, 1e-4);
  ASSERT_LT(c0, 5e-4);
  const MotionChecker certified(scene);
  MotionContext c = certified.makeContext();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  int free = 0, hit = 0, near = 0;
  std::vector<double> q(2);
  for (int trial = 0; trial < 120; ++trial) {
    const double q1[2] = {u(rng), u(rng)};
    if (!scene->isFree(std::vector<double>(q1, q1 + 2))) {
      EXPECT_FALSE(certified.check(q_start, q1, c).free);
      ++hit;
      continue;
    }
    const double c1 = scene->clearance(q1, sc);
    const MotionResult a = certified.check(q_start, q1, c, trial % 2 == 0);
    EXPECT_FALSE(a.capped) << "trial " << trial;
    // The contact distance along the segment, with a motion bound at least the checker's (twice the
    // larger link's), so that clearing it proves the checker's smaller one cleared.
    const double dq[2] = {q1[0] - q_start[0], q1[1] - q_start[1]};
    double bound = 0.0;
    for (int l = 0; l < scene->robot().linkCount(); ++l) bound = std::max(bound, 2.0 * certified.bound().link(l, dq));
    const double cd = certified.options().contact_distance;
    const auto contact = [&](double s) {
      return std::min({cd, 0.5 * c0 + kContactGrowth * bound * s, 0.5 * c1 + kContactGrowth * bound * (1.0 - s)});
    };
    // Densely: does it touch, and does it keep beyond 1.2 times the contact distance?
    bool touches = false, beyond = true;
    for (int k = 1; k < 1000; ++k) {
      certified.interpolate(q_start, q1, k / 1000.0, q.data());
      const double cl = scene->clearance(q.data(), sc);
      touches = touches || !(cl > 0.0);
      beyond = beyond && cl > 1.2 * contact(k / 1000.0) + 1e-9;
    }
    if (touches) {
      EXPECT_FALSE(a.free) << "trial " << trial;
      ++hit;
    } else if (beyond) {
      EXPECT_TRUE(a.free) << "trial " << trial << ": ends " << c0 << ", " << c1;
      ++free;
    } else {
      ++near;
    }
  }
  std::printf("from %.3g m: %d free, %d collide, %d pass within 1.2 contact distances\n", c0, free, hit, near);
  EXPECT_GT(free, 30);
  EXPECT_GT(hit, 20);
}

TEST(MotionCertified, FreeStatesAtAnyClearanceAreLeftInFewQueries) {
  // The slider's block approaches a wall until it is 1e-10 m, 1e-12 m, and the last bit the validity
  // checker accepts, from it. From there: a motion of length zero and one straight back are free; one
  // into the wall is not; one that turns the block while backing off just enough to keep it within a few
  // nanometres at first (its corner recedes only with the square of the turn) ends within contact in a
  // few hundred queries. With a contact distance of half the start's clearance all along, that motion
  // crawled along the wall in steps of that size (200,000 queries, capped); and states within 1e-10 of
  // the block's size were accepted but could not be left (the distances called them touching).
  TempDir dir;
  SceneDescription d =
      sliderScene(dir, "    - {name: wall, box: {size: [0.01, 2, 2]}, pose: {position: [0.06, 0, 0]}}\n")->description();
  d.effects.clearance = true;  // (to find the states)
  const auto scene = std::make_shared<const Scene>(d);
  for (const MotionMode mode : {MotionMode::Certified, MotionMode::Cast}) {
    MotionOptions o;
    o.mode = mode;
    const MotionChecker checker(scene, o);
    MotionContext c = checker.makeContext();
    for (const double target : {1e-10, 1e-12, 0.0}) {
      SCOPED_TRACE("clearance above " + std::to_string(target));
      const std::vector<double> q = stateNearContact(*scene, checker, {0.0, 0.0}, {0.01, 0.0}, target);
      ASSERT_TRUE(scene->isFree(q));
      ASSERT_LT(q[0], 0.005 + 1e-9);
      const double back[2] = {q[0] - 0.05, 0.0}, into[2] = {q[0] + 1e-3, 0.0};
      const double turn[2] = {q[0] - 0.05 * 0.1, 0.1};  // the corner's lead grows by 0.05·θ, the slide takes it back
      for (const bool locate : {true, false}) {
        const MotionResult zero = checker.check(q.data(), q.data(), c, locate);
        EXPECT_TRUE(zero.free) << "a free state must be leavable";
        const MotionResult away = checker.check(q.data(), back, c, locate);
        EXPECT_TRUE(away.free);
        EXPECT_LT(away.distance_queries, 1000);
        EXPECT_FALSE(checker.check(q.data(), into, c, locate).free);
        const MotionResult slow = checker.check(q.data(), turn, c, locate);
        EXPECT_FALSE(slow.capped);
        EXPECT_LT(slow.distance_queries, 2000);
        std::printf("%s, clearance above %g, locate %d: away %d queries, turning %s in %d\n",
                    mode == MotionMode::Cast ? "cast" : "certified", target, locate, away.distance_queries,
                    slow.free ? "free" : "within contact", slow.distance_queries);
      }
    }
  }
}

// The shared Panda and UR5: states 1e-10 m, 1e-12 m and a rounding's width from contact (found between a
// free and a colliding random state) can be left: a motion of length zero is free, and short motions in
// random directions answer in a few thousand queries at most, never capped; some of them are free. (The
// UR5's 104k triangles make measuring clearances slow under the sanitizers: its states are the last ones
// the validity checker accepts, a rounding's width from contact.)
TEST(MotionCertified, SharedRobotsLeaveStatesNearContact) {
  CLEARWAY_REQUIRE_SHARED("robots/panda/panda.urdf");
  CLEARWAY_SHARED_OR_SKIP(root, "scenes");
  for (const char* name : {"box_panda/box_panda_0001.yaml", "bookshelf_small_ur5/bookshelf_small_ur5_0002.yaml",
                           "cage_panda/cage_panda_0003.octomap.yaml"}) {
    SCOPED_TRACE(name);
    const bool measured = std::string(name).find("ur5") == std::string::npos;
    const auto started = std::chrono::steady_clock::now();
    SceneDescription d = parseSceneFile(root + "/" + name);
    d.effects.clearance = measured;
    const auto scene = std::make_shared<const Scene>(d);
    const MotionChecker checker(scene);
    MotionContext c = checker.makeContext();
    const int n = scene->dimension();
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0), v(-1.0, 1.0);
    std::vector<double> a(n), b(n), q1(n);
    int states = 0, motions = 0, free = 0, most = 0;
    while (states < 6) {
      for (int i = 0; i < n; ++i) a[i] = scene->lower(i) + u(rng) * (scene->upper(i) - scene->lower(i));
      for (int i = 0; i < n; ++i) b[i] = scene->lower(i) + u(rng) * (scene->upper(i) - scene->lower(i));
      if (!scene->isFree(a) || scene->isFree(b)) continue;
      const double target = !measured ? 0.0 : states % 3 == 0 ? 1e-10 : states % 3 == 1 ? 1e-12 : 0.0;
      const std::vector<double> q = stateNearContact(*scene, checker, a, b, target);
      if (!scene->isFree(q)) continue;
      ++states;
      const MotionResult zero = checker.check(q.data(), q.data(), c, states % 2 == 0);
      EXPECT_TRUE(zero.free) << "state " << states << ", clearance above " << target << ": cannot be left";
      EXPECT_FALSE(zero.capped);
      for (int k = 0; k < 6; ++k) {
        double norm = 0.0;
        for (int i = 0; i < n; ++i) norm += (q1[i] = v(rng)) * q1[i];
        for (int i = 0; i < n; ++i)
          q1[i] = std::clamp(q[i] + 0.05 * q1[i] / std::sqrt(norm), scene->lower(i), scene->upper(i));
        if (!scene->isFree(q1)) continue;
        const MotionResult r = checker.check(q.data(), q1.data(), c, k % 2 == 0);
        ++motions;
        free += r.free;
        most = std::max(most, r.distance_queries);
        EXPECT_FALSE(r.capped) << "state " << states << " motion " << k;
        EXPECT_LT(r.distance_queries, 5000) << "state " << states << " motion " << k;
      }
    }
    std::printf("%s: %d states near contact, %d short motions from them, %d free, at most %d queries (%.1f s)\n",
                name, states, motions, free, most,
                std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
    EXPECT_GT(free, 0);
  }
}

TEST(MotionCertified, InsideAClosedMeshIsACollision) {
  // A closed tetrahedron mesh (scaled 3, corner at −0.5): x, y, z > −0.5 and x + y + z < 1.5. The slider's
  // block lies wholly inside it for x in (−0.45, 1.35), touching no triangle: a solid, so those states
  // collide, and so does every segment through them, even one that stays inside, in every mode.
  TempDir dir;
  const std::string stl = dir.write("tet.stl", test::tetrahedronStl());
  const auto scene = sliderScene(dir, "    - {name: tent, mesh: {file: " + stl +
                                          ", scale: 3}, pose: {position: [-0.5, -0.5, -0.5]}}\n");
  EXPECT_FALSE(scene->isFree(std::vector<double>{0.0, 0.0}));
  EXPECT_FALSE(scene->isFree(std::vector<double>{0.9, 1.0}));
  EXPECT_TRUE(scene->isFree(std::vector<double>{-1.0, 0.0}));
  for (const MotionOptions& o : {MotionOptions{}, sampled(0.01)}) {
    for (const MotionMode mode : {MotionMode::Certified, MotionMode::Cast, MotionMode::Sampled}) {
      if ((mode == MotionMode::Sampled) != (o.mode == MotionMode::Sampled)) continue;
      MotionOptions with = o;
      with.mode = mode;
      const MotionChecker checker(scene, with);
      MotionContext c = checker.makeContext();
      const double in0[2] = {-0.2, 0.0}, in1[2] = {0.2, 0.5}, out0[2] = {-1.0, 0.0}, out1[2] = {-0.8, 0.0};
      EXPECT_FALSE(checker.check(in0, in1, c).free) << static_cast<int>(mode);
      EXPECT_FALSE(checker.check(in0, in1, c, false).free) << static_cast<int>(mode);
      EXPECT_TRUE(checker.check(out0, out1, c).free) << static_cast<int>(mode);
      const double into[2] = {0.0, 0.0};
      const MotionResult r = checker.check(out0, into, c);
      EXPECT_FALSE(r.free);
      // The block's face reaches the mesh's face x = −0.5 at x = −0.55: s = 0.45.
      EXPECT_LE(r.first_contact, 0.45 + 1e-9) << static_cast<int>(mode);
      EXPECT_GE(r.first_contact, mode == MotionMode::Sampled ? 0.4 : 0.445) << static_cast<int>(mode);
    }
  }
}

// Our arm's scene and problem 0001 of every shared family in each of these forms (".yaml", ".octomap.yaml").
std::vector<std::string> shortcutScenes(const std::vector<std::string>& forms) {
  std::vector<std::string> scenes = {std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/arm6_wall.yaml"};
  const std::string root = test::sharedPath("scenes");
  if (!root.empty())
    for (const auto& family : std::filesystem::directory_iterator(root)) {
      if (!family.is_directory()) continue;
      const std::string stem = family.path().string() + "/" + family.path().filename().string() + "_0001";
      for (const std::string& form : forms)
        if (std::filesystem::exists(stem + form)) scenes.push_back(stem + form);
    }
  return scenes;
}

// Certified motions of each scene with its environment and with `without(environment)` (a shortcut taken
// away): the same verdicts on `per_scene` random segments between free states, and on every other one
// (located) the same first contact and last valid parameter; or, with `same_bounds` false (the shortcut
// measures other certified bounds, so the advancement takes other steps and may stop within contact
// elsewhere), each first contact after a free stretch: 200 states before it free, and the last valid one.
// Counts the segments that collide.
void expectShortcutKeepsMotions(const std::vector<std::string>& scenes, Environment (*without)(const Environment&),
                                int per_scene, unsigned seed, int& colliding, int& total, bool same_bounds = true) {
  std::mt19937 rng(seed);
  for (const std::string& path : scenes) {
    const auto with = test::loadScene(path);
    const auto other = with->withEnvironment(std::make_shared<Environment>(without(with->environment())));
    with->environment().prepareClearanceGrid();
    const MotionChecker a(with), b(other);
    MotionContext ca = a.makeContext(), cb = b.makeContext();
    SceneContext sc = with->makeContext();
    const int d = with->dimension();
    std::vector<double> q0(d), q1(d);
    for (int k = 0; k < per_scene;) {
      for (int i = 0; i < d; ++i) {
        const double lo = std::max(with->lower(i), -M_PI), hi = std::min(with->upper(i), M_PI);
        q0[i] = std::uniform_real_distribution<double>(lo, hi)(rng);
        q1[i] = std::clamp(q0[i] + std::uniform_real_distribution<double>(-0.6, 0.6)(rng), lo, hi);
      }
      if (!with->isFree(q0.data(), sc) || !with->isFree(q1.data(), sc)) continue;
      ++k;
      const bool locate = k % 2 == 0;
      const MotionResult ra = a.check(q0.data(), q1.data(), ca, locate), rb = b.check(q0.data(), q1.data(), cb, locate);
      ASSERT_EQ(ra.free, rb.free) << path << " segment " << k;
      if (locate && !ra.free && same_bounds) {
        EXPECT_EQ(ra.first_contact, rb.first_contact) << path << " segment " << k;
        EXPECT_EQ(ra.last_valid, rb.last_valid) << path << " segment " << k;
      } else if (locate && !ra.free) {
        std::vector<double> q(d);
        for (const MotionResult* r : {&ra, &rb}) {
          for (int j = 0; j <= 200; ++j) {
            const double s = j < 200 ? r->first_contact * j / 200.0 : r->last_valid;
            for (int i = 0; i < d; ++i) q[i] = q0[i] + s * (q1[i] - q0[i]);
            ASSERT_TRUE(with->isFree(q.data(), sc)) << path << " segment " << k << " at " << s;
          }
        }
      }
      colliding += !ra.free;
      ++total;
    }
  }
}

// Certified motions with the environment's clearance grid (which settles a link's measurement when its
// ball is beyond what the step needs) and without, on our arm and every shared family in both forms.
TEST(MotionCertified, TheClearanceGridChangesNoVerdict) {
  int colliding = 0, total = 0;
  expectShortcutKeepsMotions(
      shortcutScenes({".yaml", ".octomap.yaml"}), [](const Environment& e) { return e.withoutClearanceGrid(); }, 40, 31,
      colliding, total);
  EXPECT_GT(colliding, 0) << "no segment collided: the test shows nothing near obstacles";
  std::printf("%d of %d segments collide, with and without the grid\n", colliding, total);
  CLEARWAY_REQUIRE_SHARED("scenes");  // (our arm is checked either way)
}

// Certified motions with the obstacles' boxes (which settle a link's measurement when its ball is beyond
// what the step needs, before the walk over the obstacles) and without, on our arm and every shared
// family's primitive form (a map's voxels have no boxes).
TEST(MotionCertified, TheObstacleBoxesChangeNoVerdict) {
  int colliding = 0, total = 0;
  const auto without = [](const Environment& e) {
    EXPECT_NE(e.obstacleBoxes(), nullptr) << "a scene of primitives has no boxes";
    return e.withoutObstacleBoxes();
  };
  expectShortcutKeepsMotions(shortcutScenes({".yaml"}), without, 60, 37, colliding, total);
  EXPECT_GT(colliding, 0) << "no segment collided: the test shows nothing near obstacles";
  std::printf("%d of %d segments collide, with and without the boxes\n", colliding, total);
  CLEARWAY_REQUIRE_SHARED("scenes");  // (our arm is checked either way)
}

// Certified motions with the map's voxels merged into blocks (what every environment query walks) and
// unmerged, on every shared family's map form: the same verdicts, first contacts and last valid states.
TEST(MotionCertified, TheVoxelBlocksChangeNoVerdict) {
  CLEARWAY_REQUIRE_SHARED("scenes");
  int colliding = 0, total = 0;
  const auto without = [](const Environment& e) {
    EXPECT_TRUE(e.voxelBlocks() == nullptr || e.voxelBlocks()->boxes().size() < e.map()->occupied.size());
    return e.withoutVoxelBlocks();
  };
  expectShortcutKeepsMotions(shortcutScenes({".octomap.yaml"}), without, 120, 41, colliding, total, false);
  EXPECT_GT(colliding, 0) << "no segment collided: the test shows nothing near obstacles";
  std::printf("%d of %d segments collide, with and without the blocks\n", colliding, total);
}

}  // namespace
}  // namespace clearway
