#pragma once
// What the motion tests share: small robots written out (a slider, a gripper, a gantry, a mimic arm) and
// scenes around them and our robots, random states and steps, states found near contact, and the check
// of a motion checker against dense sampling.
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
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace clearway::test {

// A box on a prismatic joint along x (travel ±1 m), and a body that can also turn about z.
inline const char* const kSliderUrdf = R"(<?xml version="1.0"?>
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

inline std::shared_ptr<const Scene> sliderScene(const TempDir& dir, const std::string& obstacles) {
  const std::string urdf = dir.write("slider.urdf", kSliderUrdf);
  const std::string scene = dir.write("slider.yaml", "format: 1\nname: slider\nrobot:\n  urdf: " + urdf +
                                                         "\n  group: [slide, turn]\nenvironment:\n  obstacles:\n" +
                                                         obstacles + "checks: [environment, continuous]\n"
                                                         "start: [-1, 0]\ngoal: [1, 0]\n");
  return Scene::load(scene);
}

// The planar arm (robots/planar_arm) with the given obstacles.
inline std::shared_ptr<const Scene> planarScene(const TempDir& dir, const std::string& obstacles,
                                         const std::string& checks = "[self, environment, continuous]") {
  const std::string scene = dir.write("planar.yaml", "format: 1\nname: planar\nrobot:\n  urdf: " +
                                                         test::sourceRobot("planar_arm/planar_arm.urdf") +
                                                         "\n  group: [shoulder, elbow]\nenvironment:\n  obstacles:\n" +
                                                         obstacles + "checks: " + checks + "\nstart: [1.5, 0]\ngoal: [-1.5, 0]\n");
  return Scene::load(scene);
}

inline MotionOptions sampled(double resolution) {
  MotionOptions o;
  o.mode = MotionMode::Sampled;
  o.resolution = resolution;
  return o;
}

// A turning arm with a two-fingered gripper on a wrist: the palm and its fingers are fixed together
// (one rigid body), and so are the base and a tower beside it. Arm from x = 0.15 to 1.15, palm at
// x = 1.25, fingers from x = 1.28 to 1.48 with inner faces at y = ±0.10 (at pan = wrist = 0).
inline const char* const kGripperUrdf = R"(<?xml version="1.0"?>
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

inline std::shared_ptr<const Scene> gripperScene(const TempDir& dir, const std::string& obstacle, const std::string& checks,
                                          const std::string& left = "0.12") {
  std::string urdf = kGripperUrdf;
  urdf.replace(urdf.find("LEFT"), 4, left);
  const std::string file = dir.write("gripper.urdf", urdf);
  return Scene::load(dir.write("gripper.yaml", "format: 1\nname: gripper\nrobot:\n  urdf: " + file +
                                                   "\n  group: [pan, wrist]\nenvironment:\n  obstacles:\n    - " +
                                                   obstacle + "\nchecks: " + checks + "\nstart: [0, 0]\ngoal: [0.02, 0]\n"));
}

// A gantry: x, y and z slides carry a ram and a tool that may also spin about z; a column stands on the
// base where the tool can run into it (a self pair: base/tool).
inline const char* const kGantryUrdf = R"(<?xml version="1.0"?>
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
inline std::shared_ptr<const Scene> gantryScene(const TempDir& dir) {
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

inline MotionOptions castMode() {
  MotionOptions o;
  o.mode = MotionMode::Cast;
  return o;
}

// The options without the rake (every item measured: for tests of what the measurements do).
inline MotionOptions unraked(MotionOptions o) {
  o.rake = false;
  return o;
}

// The rover (robots/rover: a planar joint and a revolute boom) between two thin walls, and the free flyer
// (robots/flyer: a floating joint) over a thin plate, by a thin post (robots/scenes).
inline std::shared_ptr<const Scene> roverScene(const TempDir&) {
  return Scene::load(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/rover_gap.yaml");
}

inline std::shared_ptr<const Scene> flyerScene(const TempDir&) {
  return Scene::load(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/flyer_post.yaml");
}

// A random state of the scene: within bounds, a random unit quaternion for a floating joint.
inline std::vector<double> randomState(const Scene& scene, std::mt19937& rng) {
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

// A random state within the scene's bounds (and ±3), and a step of up to 0.4 in each entry that stays in them.
inline void randomStep(const Scene& scene, std::mt19937& rng, std::vector<double>& q0, std::vector<double>& q1,
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
inline void expectBoundsHold(const std::shared_ptr<const Scene>& scene, std::mt19937& rng) {
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
        for (const Vec3& v : vertices(link))
          EXPECT_LE((c1.poses()[link] * v - c0.poses()[link] * v).norm(), b + 1e-9) << name;
        // linkStep: over h·dq (and every state on the way) no vertex moves d or farther.
        const double d = std::uniform_real_distribution<double>(0.001, 0.3)(rng);
        const double h = bound.linkStep(link, dq.data(), c0.poses().data(), d);
        EXPECT_GE(h, d / b * (1 - 1e-12)) << name;
        for (double t : {0.25, 0.5, 0.75, 1.0}) {
          std::vector<double> q(n);
          for (int i = 0; i < n; ++i) q[i] = q0[i] + std::min(h, 1.0) * t * dq[i];
          SceneContext ct = scene->makeContext();
          scene->computePoses(q.data(), ct);
          for (const Vec3& v : vertices(link))
            EXPECT_LE((ct.poses()[link] * v - c0.poses()[link] * v).norm(), d + 1e-9)
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
        const double h = std::min(1.0, bound.pairStep(p.a, p.b, dq.data(), c0.poses().data(), d));
        for (double t : {0.5, 1.0}) {
          std::vector<double> q(n);
          for (int i = 0; i < n; ++i) q[i] = q0[i] + h * t * dq[i];
          SceneContext ct = scene->makeContext();
          scene->computePoses(q.data(), ct);
          for (std::size_t i = 0; i < va.size(); i += 1 + va.size() / 6)
            for (std::size_t j = 0; j < vb.size(); j += 1 + vb.size() / 6) {
              const double before = (c0.poses()[p.b] * vb[j] - c0.poses()[p.a] * va[i]).norm();
              const double after = (ct.poses()[p.b] * vb[j] - ct.poses()[p.a] * va[i]).norm();
              EXPECT_LE(std::abs(after - before), d + 1e-9) << name << ": " << scene->robot().link(p.a).name << " / "
                                                            << scene->robot().link(p.b).name << " h " << h;
            }
        }
        for (std::size_t i = 0; i < va.size(); i += 1 + va.size() / 12)
          for (std::size_t j = 0; j < vb.size(); j += 1 + vb.size() / 12) {
            const double before = (c0.poses()[p.b] * vb[j] - c0.poses()[p.a] * va[i]).norm();
            const double after = (c1.poses()[p.b] * vb[j] - c1.poses()[p.a] * va[i]).norm();
            EXPECT_LE(std::abs(after - before), b + 1e-9)
                << name << ": " << scene->robot().link(p.a).name << " / " << scene->robot().link(p.b).name;
            ++checked;
          }
      }
    }
    EXPECT_GT(checked, 1000) << name;
  }
}

// The two-armed robot (robots/twin_arm): its tree forks at the torso, so pairs with one link on each arm
// take the bound's code for links on two branches (their motions relative to each other add up from the
// fork, not along one chain). The shared robots are serial chains, and so are our others.
inline std::shared_ptr<const Scene> twinArmScene() {
  return Scene::load(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/twin_arm_table.yaml");
}

// linkTwist's terms, checked by finite differences along random segments: the speed bounds every hull
// vertex's speed where it was computed, the acceleration bounds every vertex's acceleration anywhere, and a
// step of h moves no vertex h·speed + h²·accel/2 or farther. Steps of up to 0.4 and of up to 2 radians per
// joint (a planner's long segments). Returns the largest ratios seen (speed, acceleration).
inline std::pair<double, double> expectTwistHolds(const Scene& scene, std::mt19937& rng, int trials) {
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
      EXPECT_TRUE(bound.linkTwist(link, dq.data(), ct.poses().data(), speed, accel)) << name << ": every joint turns";
      ++links;
      tighter += speed < bound.link(link, dq.data());
      const std::vector<Vec3>& vertices = scene.geometry().link(link)->hull().vertices();
      for (std::size_t k = 0; k < vertices.size(); k += 1 + vertices.size() / 24) {
        const Vec3 x = ct.poses()[link] * vertices[k];
        constexpr double kV = 1e-6, kA = 1e-3;  // difference steps: truncation and rounding both far below the bounds
        at(s + kV, cp), at(s - kV, cm);
        const double v = (cp.poses()[link] * vertices[k] - cm.poses()[link] * vertices[k]).norm() / (2 * kV);
        EXPECT_LE(v, speed * (1 + 1e-6) + 1e-7) << name << ": " << scene.robot().link(link).name;
        at(s + kA, cp), at(s - kA, cm);
        const double a = (cp.poses()[link] * vertices[k] - 2.0 * x + cm.poses()[link] * vertices[k]).norm() / (kA * kA);
        EXPECT_LE(a, accel * (1 + 1e-3) + 1e-6) << name << ": " << scene.robot().link(link).name;
        worst_speed = std::max(worst_speed, v / speed);
        worst_accel = std::max(worst_accel, a / accel);
        for (const double h : {0.05, 0.3, 1.0}) {
          const double step = h * std::max(s, 1.0 - s);  // either way, as far as the segment goes
          at(s + (s < 0.5 ? step : -step), ch);
          EXPECT_LE((ch.poses()[link] * vertices[k] - x).norm(), step * speed + 0.5 * step * step * accel + 1e-9)
              << name;
        }
      }
    }
  }
  EXPECT_GT(tighter, links / 2) << name << ": the field's speed should usually beat the static bound";
  return {worst_speed, worst_accel};
}

// A three-link arm whose last joint follows the second at −1.5 times its angle (a mimic turning the other
// way): the field adds the joints' turns with their signs.
inline const char* const kMimicArmUrdf = R"(<?xml version="1.0"?>
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

inline void expectTwistHoldsOn(const std::vector<std::shared_ptr<const Scene>>& scenes, unsigned seed) {
  std::mt19937 rng(seed);
  for (const auto& scene : scenes) {
    const auto [speed, accel] = expectTwistHolds(*scene, rng, 40);
    std::printf("%s: at most %.3f of the speed bound and %.3f of the acceleration bound reached\n", scene->name().c_str(),
                speed, accel);
  }
}

// Segments between free states of the scene (half between random states, half short random steps), up to
// `trials` tries or `most` segments, each checked certified and by dense sampling (2 mm in the joint
// vector): a collision sampling finds must be found, no later. `met` sees each collision sampling finds.
struct DenseRun {
  int segments = 0, collide = 0, misses = 0;
};
template <class Met>
inline DenseRun compareWithDenseSampling(const std::shared_ptr<const Scene>& scene, unsigned seed, int trials, int most, Met&& met) {
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

// The slider with a wall (1 mm thick unless given) that starts at x = x0 and moves along +x at 1 m/s (checks: moving).
inline std::shared_ptr<const Scene> movingWallScene(const TempDir& dir, double x0, double thickness = 0.001) {
  const std::string urdf = dir.write("slider.urdf", kSliderUrdf);
  return Scene::load(dir.write("moving.yaml", "format: 1\nname: moving\nrobot:\n  urdf: " + urdf +
                                                  "\n  group: [slide, turn]\nenvironment:\n  obstacles:\n"
                                                  "    - {name: wall, box: {size: [" + std::to_string(thickness) + ", 2, 2]}, pose: {position: [" +
                                                  std::to_string(x0) + ", 0, 0]}, velocity: [1, 0, 0]}\n"
                                                  "checks: [environment, continuous, moving]\nstart: [0, 0]\ngoal: [0, 0]\n"));
}

// A number written back exactly (std::to_string keeps six decimals).
inline std::string exactNumber(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

// A state of the segment a → b (a free, b not) whose clearance is just above `target` (0: the last state
// the validity checker accepts), by bisection on the segment's parameter. A target needs a scene that
// measures clearance.
inline std::vector<double> stateNearContact(const Scene& scene, const MotionChecker& checker, const std::vector<double>& a,
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

}  // namespace clearway::test
