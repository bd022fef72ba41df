// Continuous motion checks: the certified mode never tunnels (thin walls, thin posts, analytic contact
// parameters), agrees with dense sampling on real robots and scenes, and refuses bad input.
#include <clearway/motion/motion.h>

#include "load/robot_files.h"
#include "scene/arm_scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <thread>

namespace clearway {
namespace {

using test::TempDir;

// A box on a prismatic joint along x (travel ±1 m), and a body that can also turn about z.
const char* kSliderUrdf = R"(<?xml version="1.0"?>
<robot name="slider">
  <link name="base"/>
  <link name="carriage"/>
  <link name="block">
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
  <joint name="slide" type="prismatic">
    <parent link="base"/><child link="carriage"/>
    <axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/>
  </joint>
  <joint name="turn" type="revolute">
    <parent link="carriage"/><child link="block"/>
    <axis xyz="0 0 1"/>
    <limit lower="-3.2" upper="3.2" velocity="1" effort="1"/>
  </joint>
</robot>
)";

std::shared_ptr<const Scene> sliderScene(const TempDir& dir, const std::string& obstacles) {
  const std::string urdf = dir.write("slider.urdf", kSliderUrdf);
  const std::string scene = dir.write("slider.yaml", "format: 1\nname: slider\nrobot:\n  urdf: " + urdf +
                                                         "\n  group: [slide, turn]\nenvironment:\n  obstacles:\n" +
                                                         obstacles + "checks: [environment, continuous]\n"
                                                         "start: [-1, 0]\ngoal: [1, 0]\n");
  return Scene::load(scene);
}

// The planar arm (robots/planar_arm) with the given obstacles.
std::shared_ptr<const Scene> planarScene(const TempDir& dir, const std::string& obstacles,
                                         const std::string& checks = "[self, environment, continuous]") {
  const std::string scene = dir.write("planar.yaml", "format: 1\nname: planar\nrobot:\n  urdf: " +
                                                         test::sourceRobot("planar_arm/planar_arm.urdf") +
                                                         "\n  group: [shoulder, elbow]\nenvironment:\n  obstacles:\n" +
                                                         obstacles + "checks: " + checks + "\nstart: [1.5, 0]\ngoal: [-1.5, 0]\n");
  return Scene::load(scene);
}

MotionOptions sampled(double resolution) {
  MotionOptions o;
  o.mode = MotionMode::Sampled;
  o.resolution = resolution;
  return o;
}

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
      const double moved = (c1.poses[link2] * p - c0.poses[link2] * p).norm();
      EXPECT_LE(moved, bound.link(link2, dq) + 1e-12);
    }
    // The pair bound: link2's motion relative to link1 depends on the elbow only; watched from link2,
    // link1 turns about the elbow's axis, so the bound may be lower still. No distance between a point
    // of each link changes by more.
    const double pair = bound.pair(link1, link2, dq);
    EXPECT_LE(pair, bound.linkCoefficient(link2, 1) * std::abs(dq[1]) + 1e-12);
    for (const Vec3 p1 : {Vec3(1.0, 0.05, 0), Vec3(0.2, -0.05, 0.05), Vec3(0, 0, 0)})
      for (const Vec3 p2 : {Vec3(0.5, 0.05, 0), Vec3(0, -0.05, 0.05), Vec3(0.25, 0, -0.05)}) {
        const double before = (c0.poses[link2] * p2 - c0.poses[link1] * p1).norm();
        const double after = (c1.poses[link2] * p2 - c1.poses[link1] * p1).norm();
        EXPECT_LE(std::abs(after - before), pair + 1e-12);
      }
  }
}

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
  // contact_distance of the wall or through it (the segment's middle, here), with fewer steps.
  const MotionResult loose = certified.check(q0, q1, ctx, /*locate_contact=*/false);
  ASSERT_FALSE(loose.free);
  EXPECT_EQ(loose.report.kind, r.report.kind);
  EXPECT_GE(loose.first_contact, near - 1e-9);
  EXPECT_LE(loose.first_contact, (1.0 + 0.0505 + certified.options().contact_distance) / 2.0 + 1e-9);
  EXPECT_EQ(loose.last_valid, 0.0);
  EXPECT_LT(loose.steps, r.steps);

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

// A turning arm with a two-fingered gripper on a wrist: the palm and its fingers are fixed together
// (one rigid body), and so are the base and a tower beside it. Arm from x = 0.15 to 1.15, palm at
// x = 1.25, fingers from x = 1.28 to 1.48 with inner faces at y = ±0.10 (at pan = wrist = 0).
const char* kGripperUrdf = R"(<?xml version="1.0"?>
<robot name="gripper">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <link name="tower"><collision><geometry><box size="0.1 0.1 0.6"/></geometry></collision></link>
  <link name="arm">
    <collision><origin xyz="0.65 0 0"/><geometry><box size="1.0 0.08 0.08"/></geometry></collision>
  </link>
  <link name="palm"><collision><geometry><box size="0.06 0.3 0.08"/></geometry></collision></link>
  <link name="finger_l"><collision><geometry><box size="0.2 0.04 0.08"/></geometry></collision></link>
  <link name="finger_r"><collision><geometry><box size="0.2 0.04 0.08"/></geometry></collision></link>
  <joint name="tower_fix" type="fixed"><parent link="base"/><child link="tower"/><origin xyz="-0.6 0 0"/></joint>
  <joint name="pan" type="revolute">
    <parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="1" effort="1"/>
  </joint>
  <joint name="wrist" type="revolute">
    <parent link="arm"/><child link="palm"/><origin xyz="1.25 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="1" effort="1"/>
  </joint>
  <joint name="finger_l_fix" type="fixed"><parent link="palm"/><child link="finger_l"/><origin xyz="0.13 LEFT 0"/></joint>
  <joint name="finger_r_fix" type="fixed"><parent link="palm"/><child link="finger_r"/><origin xyz="0.13 -0.12 0"/></joint>
</robot>
)";

std::shared_ptr<const Scene> gripperScene(const TempDir& dir, const std::string& obstacle, const std::string& checks,
                                          const std::string& left = "0.12") {
  std::string urdf = kGripperUrdf;
  urdf.replace(urdf.find("LEFT"), 4, left);
  const std::string file = dir.write("gripper.urdf", urdf);
  return Scene::load(dir.write("gripper.yaml", "format: 1\nname: gripper\nrobot:\n  urdf: " + file +
                                                   "\n  group: [pan, wrist]\nenvironment:\n  obstacles:\n    - " +
                                                   obstacle + "\nchecks: " + checks + "\nstart: [0, 0]\ngoal: [0.02, 0]\n"));
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
    const MotionChecker certified(scene), fast(tabled);
    MotionContext ctx = certified.makeContext(), fctx = fast.makeContext();
    const double q0[2] = {0, 0}, q1[2] = {0.02, 0};
    const MotionResult r = certified.check(q0, q1, ctx);
    EXPECT_TRUE(r.free);
    EXPECT_EQ(r.distance_queries, 2 + 4) << "link by link it would be 4 + 9";
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

// ---- Cast mode: what only translates is measured by one shape cast ---------------------------------------

// A gantry: x, y and z slides carry a ram and a tool that may also spin about z; a column stands on the
// base where the tool can run into it (a self pair: base/tool).
const char* kGantryUrdf = R"(<?xml version="1.0"?>
<robot name="gantry">
  <link name="base">
    <collision><origin xyz="0.6 0.6 0.3"/><geometry><box size="0.1 0.1 0.6"/></geometry></collision>
  </link>
  <link name="x_carriage"/>
  <link name="y_carriage"/>
  <link name="ram">
    <collision><origin xyz="0 0 0.25"/><geometry><box size="0.06 0.06 0.3"/></geometry></collision>
  </link>
  <link name="tool">
    <collision><origin xyz="0.08 0 0"/><geometry><box size="0.2 0.05 0.05"/></geometry></collision>
  </link>
  <joint name="x" type="prismatic">
    <parent link="base"/><child link="x_carriage"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/>
  </joint>
  <joint name="y" type="prismatic">
    <parent link="x_carriage"/><child link="y_carriage"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/>
  </joint>
  <joint name="z" type="prismatic">
    <origin xyz="0 0 0.1"/>
    <parent link="y_carriage"/><child link="ram"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="0.5" velocity="1" effort="1"/>
  </joint>
  <joint name="spin" type="revolute">
    <parent link="ram"/><child link="tool"/><axis xyz="0 0 1"/>
    <limit lower="-3.2" upper="3.2" velocity="1" effort="1"/>
  </joint>
</robot>
)";

// The gantry among a 1 mm wall (x = −0.3), a low block and a ball.
std::shared_ptr<const Scene> gantryScene(const TempDir& dir) {
  const std::string urdf = dir.write("gantry.urdf", kGantryUrdf);
  const std::string scene = dir.write(
      "gantry.yaml", "format: 1\nname: gantry\nrobot:\n  urdf: " + urdf +
                         "\n  group: [x, y, z, spin]\nenvironment:\n  obstacles:\n"
                         "    - {name: wall, box: {size: [0.001, 0.8, 0.4]}, pose: {position: [-0.3, 0, 0.2]}}\n"
                         "    - {name: block, box: {size: [0.3, 0.3, 0.2]}, pose: {position: [0.3, -0.5, 0.1]}}\n"
                         "    - {name: ball, sphere: {radius: 0.1}, pose: {position: [-0.6, -0.6, 0.5]}}\n"
                         "checks: [self, environment, continuous]\nstart: [-0.8, 0, 0, 0]\ngoal: [0.8, 0, 0, 0]\n");
  return Scene::load(scene);
}

MotionOptions castMode() {
  MotionOptions o;
  o.mode = MotionMode::Cast;
  return o;
}

TEST(MotionCast, ThinWallAndColumnInOneCastEach) {
  TempDir dir;
  const auto scene = gantryScene(dir);
  const MotionChecker cast(scene, castMode()), certified(scene);
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
  const MotionChecker cast(scene, castMode()), certified(scene);
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

// ---- Planar and floating joints ----------------------------------------------------------------------

// The rover (robots/rover: a planar joint and a revolute boom) between two thin walls, and the free flyer
// (robots/flyer: a floating joint) over a thin plate, by a thin post (robots/scenes).
std::shared_ptr<const Scene> roverScene(const TempDir&) {
  return Scene::load(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/rover_gap.yaml");
}

std::shared_ptr<const Scene> flyerScene(const TempDir&) {
  return Scene::load(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/flyer_post.yaml");
}

// A random state of the scene: within bounds, a random unit quaternion for a floating joint.
std::vector<double> randomState(const Scene& scene, std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal;
  std::vector<double> q(scene.dimension());
  for (int i = 0; i < scene.dimension(); ++i) {
    const double lo = std::isfinite(scene.lower(i)) ? scene.lower(i) : -M_PI;
    const double hi = std::isfinite(scene.upper(i)) ? scene.upper(i) : M_PI;
    q[i] = lo + (hi - lo) * unit(rng);
  }
  const std::string& name = scene.robot().variables()[scene.groupVariables().back()].name;
  if (name.size() > 3 && name.compare(name.size() - 3, 3, "/qw") == 0)
    for (int c = 0; c < 4; ++c) q[scene.dimension() - 4 + c] = normal(rng);  // (normalized by the check)
  return q;
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
      const std::vector<Pose> p0 = ctx.poses;
      for (int k = 1; k <= 20; ++k) {
        const double t = k / 20.0;
        checker.interpolate(q0.data(), q1.data(), t, q.data());
        scene->computePoses(q.data(), ctx);
        for (int link = 0; link < scene->robot().linkCount(); ++link) {
          const LinkGeometry* g = scene->geometry().link(link);
          if (!g) continue;
          const double bound = t * checker.bound().link(link, dq.data());
          for (const Vec3& v : g->hull().vertices()) {
            const double moved = (ctx.poses[link] * v - p0[link] * v).norm();
            ASSERT_LE(moved, bound * (1 + 1e-9) + 1e-12) << scene->name() << " trial " << trial << " link " << link;
            tightest = std::max(tightest, moved / bound);
          }
        }
      }
      // The ends: the states themselves (a quaternion up to its sign and norm).
      scene->computePoses(q1.data(), ctx);
      const std::vector<Pose> end = ctx.poses;
      scene->computePoses(b.data(), ctx);
      for (int link = 0; link < scene->robot().linkCount(); ++link)
        EXPECT_LT((ctx.poses[link].t - end[link].t).norm() + (ctx.poses[link].R - end[link].R).norm(), 1e-9);
    }
    EXPECT_GT(tightest, 0.3) << scene->name() << ": a bound this loose would make the check slow";
  }
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
                           bound.linkStep(cart, dq.data(), ctx.poses.data(), 0.05),
                           bound.pairStep(turret, cart, dq.data(), ctx.poses.data(), 0.05)})
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

// A random state within the scene's bounds (and ±3), and a step of up to 0.4 in each entry that stays in them.
void randomStep(const Scene& scene, std::mt19937& rng, std::vector<double>& q0, std::vector<double>& q1,
                std::vector<double>& dq) {
  for (int i = 0; i < scene.dimension(); ++i) {
    std::uniform_real_distribution<double> u(std::max(scene.lower(i), -3.0), std::min(scene.upper(i), 3.0));
    q0[i] = u(rng);
    q1[i] = std::clamp(q0[i] + std::uniform_real_distribution<double>(-0.4, 0.4)(rng), scene.lower(i), scene.upper(i));
    dq[i] = q1[i] - q0[i];
  }
}

// The bounds on the shared robots, where the reaches come from real meshes, rigid grippers and chains
// that fork: over random steps, no hull vertex of a link moves farther than link() says, and no distance
// between hull vertices of a checked pair changes by more than pair() says.
void expectBoundsHold(const std::shared_ptr<const Scene>& scene, std::mt19937& rng) {
  const std::string name = scene->name();
  {
    const MotionBound bound(*scene);
    const int n = scene->dimension();
    SceneContext c0 = scene->makeContext(), c1 = scene->makeContext();
    std::vector<double> q0(n), q1(n), dq(n);
    int checked = 0;
    for (int trial = 0; trial < 30; ++trial) {
      randomStep(*scene, rng, q0, q1, dq);
      scene->computePoses(q0.data(), c0);
      scene->computePoses(q1.data(), c1);
      const auto vertices = [&](int link) -> const std::vector<Vec3>& { return scene->geometry().link(link)->hull().vertices(); };
      for (int link : scene->environmentLinks()) {
        const double b = bound.link(link, dq.data());
        for (const Vec3& v : vertices(link)) EXPECT_LE((c1.poses[link] * v - c0.poses[link] * v).norm(), b + 1e-9) << name;
        // linkStep: over h·dq (and every state on the way) no vertex moves d or farther.
        const double d = std::uniform_real_distribution<double>(0.001, 0.3)(rng);
        const double h = bound.linkStep(link, dq.data(), c0.poses.data(), d);
        EXPECT_GE(h, d / b * (1 - 1e-12)) << name;
        for (double t : {0.25, 0.5, 0.75, 1.0}) {
          std::vector<double> q(n);
          for (int i = 0; i < n; ++i) q[i] = q0[i] + std::min(h, 1.0) * t * dq[i];
          SceneContext ct = scene->makeContext();
          scene->computePoses(q.data(), ct);
          for (const Vec3& v : vertices(link))
            EXPECT_LE((ct.poses[link] * v - c0.poses[link] * v).norm(), d + 1e-9)
                << name << ": " << scene->robot().link(link).name << " h " << h << " t " << t;
        }
      }
      for (const LinkPair& p : scene->selfCollision().pairs()) {
        const double b = bound.pair(p.a, p.b, dq.data());
        EXPECT_LE(b, bound.link(p.a, dq.data()) + bound.link(p.b, dq.data()) + 1e-9) << name;
        const auto& va = vertices(p.a);
        const auto& vb = vertices(p.b);
        // pairStep: over h·dq (and every state on the way) no distance between their vertices changes by d.
        const double d = std::uniform_real_distribution<double>(0.001, 0.2)(rng);
        const double h = std::min(1.0, bound.pairStep(p.a, p.b, dq.data(), c0.poses.data(), d));
        for (double t : {0.5, 1.0}) {
          std::vector<double> q(n);
          for (int i = 0; i < n; ++i) q[i] = q0[i] + h * t * dq[i];
          SceneContext ct = scene->makeContext();
          scene->computePoses(q.data(), ct);
          for (std::size_t i = 0; i < va.size(); i += 1 + va.size() / 6)
            for (std::size_t j = 0; j < vb.size(); j += 1 + vb.size() / 6) {
              const double before = (c0.poses[p.b] * vb[j] - c0.poses[p.a] * va[i]).norm();
              const double after = (ct.poses[p.b] * vb[j] - ct.poses[p.a] * va[i]).norm();
              EXPECT_LE(std::abs(after - before), d + 1e-9) << name << ": " << scene->robot().link(p.a).name << " / "
                                                            << scene->robot().link(p.b).name << " h " << h;
            }
        }
        for (std::size_t i = 0; i < va.size(); i += 1 + va.size() / 12)
          for (std::size_t j = 0; j < vb.size(); j += 1 + vb.size() / 12) {
            const double before = (c0.poses[p.b] * vb[j] - c0.poses[p.a] * va[i]).norm();
            const double after = (c1.poses[p.b] * vb[j] - c1.poses[p.a] * va[i]).norm();
            EXPECT_LE(std::abs(after - before), b + 1e-9)
                << name << ": " << scene->robot().link(p.a).name << " / " << scene->robot().link(p.b).name;
            ++checked;
          }
      }
    }
    EXPECT_GT(checked, 1000) << name;
  }
}

TEST(MotionBound, HoldsOnTheSharedRobots) {
  CLEARWAY_REQUIRE_SHARED("robots/panda/panda.urdf");
  CLEARWAY_SHARED_OR_SKIP(root, "scenes");
  std::mt19937 rng(11);
  for (const char* name : {"box_panda/box_panda_0001.yaml", "box_ur5/box_ur5_0001.yaml"})
    expectBoundsHold(std::make_shared<const Scene>(parseSceneFile(root + "/" + name)), rng);
}

// The two-armed robot (robots/twin_arm): its tree forks at the torso, so pairs with one link on each arm
// take the bound's code for links on two branches (their motions relative to each other add up from the
// fork, not along one chain). The shared robots are serial chains, and so are our others.
std::shared_ptr<const Scene> twinArmScene() {
  return Scene::load(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/twin_arm_table.yaml");
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

// linkTwist's terms, checked by finite differences along random segments: the speed bounds every hull
// vertex's speed where it was computed, the acceleration bounds every vertex's acceleration anywhere, and a
// step of h moves no vertex h·speed + h²·accel/2 or farther. Steps of up to 0.4 and of up to 2 radians per
// joint (a planner's long segments). Returns the largest ratios seen (speed, acceleration).
std::pair<double, double> expectTwistHolds(const Scene& scene, std::mt19937& rng, int trials) {
  const MotionBound bound(scene);
  const int n = scene.dimension();
  const std::string name = scene.name();
  std::vector<double> q0(n), q1(n), dq(n), q(n);
  SceneContext ct = scene.makeContext(), cp = scene.makeContext(), cm = scene.makeContext(), ch = scene.makeContext();
  const auto at = [&](double s, SceneContext& c) {
    for (int i = 0; i < n; ++i) q[i] = q0[i] + s * dq[i];
    scene.computePoses(q.data(), c);
  };
  double worst_speed = 0.0, worst_accel = 0.0;
  int tighter = 0, links = 0;
  for (int trial = 0; trial < trials; ++trial) {
    randomStep(scene, rng, q0, q1, dq);
    if (trial % 2) // long: up to 2 radians per joint, within the bounds
      for (int i = 0; i < n; ++i) {
        q1[i] = std::clamp(q0[i] + 5.0 * dq[i], scene.lower(i), scene.upper(i));
        dq[i] = q1[i] - q0[i];
      }
    const double s = std::uniform_real_distribution<double>(0.0, 1.0)(rng);
    at(s, ct);
    for (const int link : scene.environmentLinks()) {
      double speed = 0.0, accel = 0.0;
      EXPECT_TRUE(bound.linkTwist(link, dq.data(), ct.poses.data(), speed, accel)) << name << ": every joint turns";
      ++links;
      tighter += speed < bound.link(link, dq.data());
      const std::vector<Vec3>& vertices = scene.geometry().link(link)->hull().vertices();
      for (std::size_t k = 0; k < vertices.size(); k += 1 + vertices.size() / 24) {
        const Vec3 x = ct.poses[link] * vertices[k];
        constexpr double kV = 1e-6, kA = 1e-3;  // difference steps: truncation and rounding both far below the bounds
        at(s + kV, cp), at(s - kV, cm);
        const double v = (cp.poses[link] * vertices[k] - cm.poses[link] * vertices[k]).norm() / (2 * kV);
        EXPECT_LE(v, speed * (1 + 1e-6) + 1e-7) << name << ": " << scene.robot().link(link).name;
        at(s + kA, cp), at(s - kA, cm);
        const double a = (cp.poses[link] * vertices[k] - 2.0 * x + cm.poses[link] * vertices[k]).norm() / (kA * kA);
        EXPECT_LE(a, accel * (1 + 1e-3) + 1e-6) << name << ": " << scene.robot().link(link).name;
        worst_speed = std::max(worst_speed, v / speed);
        worst_accel = std::max(worst_accel, a / accel);
        for (const double h : {0.05, 0.3, 1.0}) {
          const double step = h * std::max(s, 1.0 - s);  // either way, as far as the segment goes
          at(s + (s < 0.5 ? step : -step), ch);
          EXPECT_LE((ch.poses[link] * vertices[k] - x).norm(), step * speed + 0.5 * step * step * accel + 1e-9) << name;
        }
      }
    }
  }
  EXPECT_GT(tighter, links / 2) << name << ": the field's speed should usually beat the static bound";
  return {worst_speed, worst_accel};
}

// A three-link arm whose last joint follows the second at −1.5 times its angle (a mimic turning the other
// way): the field adds the joints' turns with their signs.
const char* kMimicArmUrdf = R"(<?xml version="1.0"?>
<robot name="mimic_arm">
  <link name="base"/>
  <link name="upper"><collision><origin xyz="0.2 0 0"/><geometry><box size="0.4 0.05 0.05"/></geometry></collision></link>
  <link name="fore"><collision><origin xyz="0.15 0 0"/><geometry><box size="0.3 0.05 0.05"/></geometry></collision></link>
  <link name="hand"><collision><origin xyz="0.1 0 0.02"/><geometry><box size="0.2 0.08 0.04"/></geometry></collision></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" velocity="1" effort="1"/></joint>
  <joint name="j2" type="revolute"><parent link="upper"/><child link="fore"/><origin xyz="0.4 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" velocity="1" effort="1"/></joint>
  <joint name="j3" type="revolute"><parent link="fore"/><child link="hand"/><origin xyz="0.3 0 0" rpy="0.3 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" velocity="1" effort="1"/><mimic joint="j2" multiplier="-1.5" offset="0.1"/></joint>
</robot>
)";

void expectTwistHoldsOn(const std::vector<std::shared_ptr<const Scene>>& scenes, unsigned seed) {
  std::mt19937 rng(seed);
  for (const auto& scene : scenes) {
    const auto [speed, accel] = expectTwistHolds(*scene, rng, 40);
    std::printf("%s: at most %.3f of the speed bound and %.3f of the acceleration bound reached\n", scene->name().c_str(),
                speed, accel);
  }
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

// Segments between free states of the scene (half between random states, half short random steps), up to
// `trials` tries or `most` segments, each checked certified and by dense sampling (2 mm in the joint
// vector): a collision sampling finds must be found, no later. `met` sees each collision sampling finds.
struct DenseRun {
  int segments = 0, collide = 0, misses = 0;
};
template <class Met>
DenseRun compareWithDenseSampling(const std::shared_ptr<const Scene>& scene, unsigned seed, int trials, int most, Met&& met) {
  const MotionChecker certified(scene);
  MotionContext ctx = certified.makeContext();
  const MotionChecker fine(scene, sampled(2e-3));
  MotionContext fc = fine.makeContext();
  std::mt19937 rng(seed);
  const int n = scene->dimension();
  DenseRun run;
  for (int trial = 0; trial < trials && run.segments < most; ++trial) {
    std::vector<double> q0 = randomState(*scene, rng), q1 = randomState(*scene, rng), dq(n);
    if (trial % 2) randomStep(*scene, rng, q0, q1, dq);
    if (!scene->isFree(q0) || !scene->isFree(q1)) continue;
    ++run.segments;
    const MotionResult c = certified.check(q0.data(), q1.data(), ctx);
    const MotionResult d = fine.check(q0.data(), q1.data(), fc);
    EXPECT_FALSE(c.capped);
    run.collide += !c.free;
    if (d.free) continue;
    run.misses += c.free;
    EXPECT_FALSE(c.free) << "trial " << trial << ": certified missed " << scene->describe(d.report);
    EXPECT_LE(c.first_contact, d.first_contact + 1e-9) << "trial " << trial;
    met(d);
  }
  return run;
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

// The slider with a wall (1 mm thick unless given) that starts at x = x0 and moves along +x at 1 m/s (checks: moving).
std::shared_ptr<const Scene> movingWallScene(const TempDir& dir, double x0, double thickness = 0.001) {
  const std::string urdf = dir.write("slider.urdf", kSliderUrdf);
  return Scene::load(dir.write("moving.yaml", "format: 1\nname: moving\nrobot:\n  urdf: " + urdf +
                                                  "\n  group: [slide, turn]\nenvironment:\n  obstacles:\n"
                                                  "    - {name: wall, box: {size: [" + std::to_string(thickness) + ", 2, 2]}, pose: {position: [" +
                                                  std::to_string(x0) + ", 0, 0]}, velocity: [1, 0, 0]}\n"
                                                  "checks: [environment, continuous, moving]\nstart: [0, 0]\ngoal: [0, 0]\n"));
}

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

// pair(path(a, b), dq), the certified check's form (its paths set up once), is pair(a, b, dq) to the bit: on
// our robots (a forked twin arm, a planar rover and a floating flyer, with their unbounded slides) and the
// shared ones, for every pair of links and of the links' convex parts, over random steps that leave some
// joints still.
TEST(MotionBound, PathsGiveThePairBoundExactly) {
  std::mt19937 rng(31);
  long compared = 0;
  const auto check = [&](const std::string& file) {
    const auto scene = Scene::load(file);
    std::vector<MotionBound::Body> parts;
    for (const int l : scene->geometry().geometricLinks())
      for (const LinkGeometry::Part& part : scene->geometry().link(l)->parts())
        parts.push_back({l, &part.hull, part.center, part.radius});
    const MotionBound bound(*scene, parts);
    const int links = scene->robot().linkCount() + static_cast<int>(parts.size()), n = scene->dimension();
    std::vector<double> q0(n), q1(n), dq(n);
    for (int trial = 0; trial < 20; ++trial) {
      randomStep(*scene, rng, q0, q1, dq);
      for (int i = 0; i < n; ++i)
        if (trial % 3 == 0 && rng() % 3 == 0) dq[i] = 0.0;
      for (int a = 0; a < links; a += 1 + (trial + a) % 3)
        for (int b = 0; b < links; ++b) {
          const MotionBound::PairPath path = bound.path(a, b);
          EXPECT_EQ(bound.pair(path, dq.data()), bound.pair(a, b, dq.data())) << file << ": " << a << " / " << b;
          ++compared;
        }
    }
  };
  for (const char* f : {"arm6_wall", "twin_arm_table", "rover_gap", "flyer_post", "dual_arm_shelf"})
    check(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/" + f + ".yaml");
  EXPECT_GT(compared, 5000);
  CLEARWAY_REQUIRE_SHARED("robots/panda/panda.urdf");
  CLEARWAY_SHARED_OR_SKIP(root, "scenes");
  for (const char* f : {"box_panda/box_panda_0001.yaml", "box_ur5/box_ur5_0001.yaml"}) check(root + "/" + f);
}

// A link's convex parts as links of the bound of their own (as the certified check splits a pair whose
// hulls are near): no distance between a part's hull vertices and the other link's changes by more than
// pair(part, other) says; and a part next to the axes that turn it gets a bound well below its link's
// (the UR5's upper arm turns about the shoulder, where its near end sits beside the base).
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
              const double before = (c0.poses[p.b] * vb[j] - c0.poses[p.a] * va[i]).norm();
              const double after = (c1.poses[p.b] * vb[j] - c1.poses[p.a] * va[i]).norm();
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
    const auto fast = std::make_shared<const Scene>(d), plain = std::make_shared<const Scene>(d, without);
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
      cases.push_back({name, Scene::load(shared + "/" + name)});
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

// A number written back exactly (std::to_string keeps six decimals).
std::string exactNumber(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
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

// A state of the segment a → b (a free, b not) whose clearance is just above `target` (0: the last state
// the validity checker accepts), by bisection on the segment's parameter. A target needs a scene that
// measures clearance.
std::vector<double> stateNearContact(const Scene& scene, const MotionChecker& checker, const std::vector<double>& a,
                                     const std::vector<double>& b, double target) {
  SceneContext sc = scene.makeContext();
  EXPECT_TRUE(target == 0.0 || scene.effects().clearance);
  std::vector<double> m(a.size());
  double lo = 0.0, hi = 1.0;
  while (true) {
    const double s = 0.5 * (lo + hi);
    if (s == lo || s == hi) break;
    checker.interpolate(a.data(), b.data(), s, m.data());
    const bool beyond = scene.isFree(m.data(), sc) && (target == 0.0 || scene.clearance(m.data(), sc) > target);
    (beyond ? lo : hi) = s;
  }
  checker.interpolate(a.data(), b.data(), lo, m.data());
  return m;
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
  const int n = scene->dimension();
  std::mt19937 rng(17);
  // A random walk of 0.4 rad steps: some segments free, some meeting the wall or the arm itself.
  std::vector<std::vector<double>> q(201, std::vector<double>(n));
  for (std::size_t k = 0; k < q.size(); ++k)
    for (int i = 0; i < n; ++i)
      q[k][i] = k == 0 ? 0.5 * (scene->lower(i) + scene->upper(i))
                       : std::clamp(q[k - 1][i] + std::uniform_real_distribution<double>(-0.4, 0.4)(rng), scene->lower(i),
                                    scene->upper(i));
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

// Certified motions with the environment's clearance grid (which settles a link's measurement when its
// ball is beyond what the step needs) and without: the same verdicts on random segments of our arm and of
// every shared family, primitive and OctoMap forms.
TEST(MotionCertified, TheClearanceGridChangesNoVerdict) {
  std::vector<std::string> scenes = {std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/arm6_wall.yaml"};
  const std::string root = test::sharedPath("scenes");
  if (!root.empty())
    for (const auto& family : std::filesystem::directory_iterator(root)) {
      if (!family.is_directory()) continue;
      const std::string stem = family.path().string() + "/" + family.path().filename().string() + "_0001";
      for (const std::string form : {".yaml", ".octomap.yaml"})
        if (std::filesystem::exists(stem + form)) scenes.push_back(stem + form);
    }
  std::mt19937 rng(31);
  int colliding = 0, total = 0;
  for (const std::string& path : scenes) {
    const auto with = Scene::load(path);
    const auto without = with->withEnvironment(std::make_shared<Environment>(with->environment().withoutClearanceGrid()));
    with->environment().prepareClearanceGrid();
    const MotionChecker a(with), b(without);
    MotionContext ca = a.makeContext(), cb = b.makeContext();
    SceneContext sc = with->makeContext();
    const int d = with->dimension();
    std::vector<double> q0(d), q1(d);
    for (int k = 0; k < 40;) {
      for (int i = 0; i < d; ++i) {
        const double lo = std::max(with->lower(i), -M_PI), hi = std::min(with->upper(i), M_PI);
        q0[i] = std::uniform_real_distribution<double>(lo, hi)(rng);
        q1[i] = std::clamp(q0[i] + std::uniform_real_distribution<double>(-0.6, 0.6)(rng), lo, hi);
      }
      if (!with->isFree(q0.data(), sc) || !with->isFree(q1.data(), sc)) continue;
      ++k;
      const bool fa = a.check(q0.data(), q1.data(), ca, false).free, fb = b.check(q0.data(), q1.data(), cb, false).free;
      ASSERT_EQ(fa, fb) << path << " segment " << k;
      colliding += !fa;
      ++total;
    }
  }
  EXPECT_GT(colliding, 0) << "no segment collided: the test shows nothing near obstacles";
  std::printf("%d of %d segments collide, with and without the grid\n", colliding, total);
  CLEARWAY_REQUIRE_SHARED("scenes");  // (our arm is checked either way)
}

}  // namespace
}  // namespace clearway
