// PointLanes against the double kinematics: every point of every state within its proven error bound, with
// the lanes forced to every SIMD target this machine offers (and the portable one), on a chain of every
// joint kind the lanes serve (mimics and turns about skew axes among them), our robots and the shared Panda
// and UR5; batches of every length; angles far beyond the joint ranges. And what the lanes refuse to serve.
#include <clearway/kinematics/forward_kinematics.h>
#include <clearway/kinematics/kinematic_lanes.h>
#include <clearway/kinematics/point_lanes.h>
#include <clearway/load/robot_loader.h>

#include "load/robot_files.h"

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include "forced_target.h"
#include "kinematics/chain_urdf.h"
#include "kinematics/random_states.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

using namespace clearway;

namespace {

// Each variable's largest magnitude: its limits', ±4 where unbounded.
std::vector<double> magnitudes(const RobotModel& m) {
  std::vector<double> most;
  for (const JointVariable& v : m.variables())
    most.push_back(
        std::max(std::isfinite(v.lower) ? std::abs(v.lower) : 4.0, std::isfinite(v.upper) ? std::abs(v.upper) : 4.0));
  return most;
}

// States within the limits (unbounded ones within ±4); every third state's turning joints far beyond them
// (up to 1e5 rad: sin and cos from libm past 2^16), which the bound allows (only slides' values count).
std::vector<std::vector<double>> randomStates(const RobotModel& m, int n, unsigned seed) {
  return test::randomJointVectors(m, n, seed, [&](int s, int v, auto&& draw) {
    const JointType type = m.joint(m.variables()[v].joint).type;
    return s % 3 == 1 && (type == JointType::Revolute || type == JointType::Continuous) ? 1e5 * draw() : 1.0;
  });
}

// Points on every link given: its origin, and three offsets of up to half a metre.
std::vector<PointLanes::Point> pointsOn(const std::vector<int>& links) {
  std::vector<PointLanes::Point> points;
  for (const int l : links)
    for (const Vec3& p : {Vec3(0, 0, 0), Vec3(0.1, -0.2, 0.05), Vec3(-0.5, 0.01, 0.3), Vec3(0.02, 0.4, -0.45)})
      points.push_back({l, p});
  return points;
}

std::vector<int> allLinks(const RobotModel& m) {
  std::vector<int> links(m.linkCount());
  for (int l = 0; l < m.linkCount(); ++l) links[l] = l;
  return links;
}

// Every point of every state within its bound of R·p + t under the double poses (evaluated in long double,
// so that its own rounding does not count), on every target, in batches of every length. Returns the
// largest error seen as a share of its bound. Each bound must be below `loosest` (metres).
double expectWithinBounds(const RobotModel& m, const std::vector<PointLanes::Point>& points,
                          const std::vector<std::vector<double>>& states, const std::string& what,
                          double loosest = 2e-4) {
  const PointLanes lanes(m, points, magnitudes(m));
  EXPECT_TRUE(lanes.serves()) << what;
  if (!lanes.serves()) return 0.0;
  const int n = static_cast<int>(states.size()), np = lanes.size();
  std::vector<std::vector<Pose>> poses(n, std::vector<Pose>(m.linkCount()));
  for (int s = 0; s < n; ++s) computeLinkPoses(m, states[s].data(), poses[s].data());
  for (int k = 0; k < np; ++k) EXPECT_LT(lanes.error(k), loosest) << what << ": a bound too loose to use";
  std::vector<float> xyz(static_cast<std::size_t>(3 * np * PointLanes::kLanes)), scratch(lanes.scratchSize());
  double worst = 0.0;
  const std::vector<std::int64_t> targets = KinematicLanes::targets();
  EXPECT_FALSE(targets.empty());
  for (const std::int64_t target : targets) {
    const test::ForcedTarget forced(target);
    for (int count = 1; count <= PointLanes::kLanes; ++count)
      for (int first = 0; first + count <= n; first += count) {
        const double* q[PointLanes::kLanes];
        for (int l = 0; l < count; ++l) q[l] = states[first + l].data();
        lanes.compute(q, count, xyz.data(), scratch.data());
        for (int l = 0; l < count; ++l)
          for (int k = 0; k < np; ++k) {
            const Pose& pose = poses[first + l][points[k].link];
            long double d2 = 0.0L;
            for (int r = 0; r < 3; ++r) {
              long double want = pose.t[r];
              for (int c = 0; c < 3; ++c) want += static_cast<long double>(pose.R(r, c)) * points[k].p[c];
              const long double diff = xyz[(3 * k + r) * PointLanes::kLanes + l] - want;
              d2 += diff * diff;
            }
            const double err = static_cast<double>(std::sqrt(d2));
            worst = std::max(worst, err / lanes.error(k));
            if (!(err <= lanes.error(k))) {
              ADD_FAILURE() << what << ", target " << hwy::TargetName(target) << ", batch of " << count << ", state "
                            << first + l << ", point " << k << " on " << m.link(points[k].link).name << ": " << err
                            << " m from the double poses' position, beyond its bound " << lanes.error(k);
              return worst;
            }
          }
      }
  }
  std::printf("%s: largest error %.3g of its bound\n", what.c_str(), worst);
  return worst;
}

// A chain of every joint kind the lanes serve: every kind but planar and floating joints (chain_urdf.h).
std::string servedChain() {
  std::vector<test::ChainJoint> served;
  for (const test::ChainJoint& j : test::everyJointKind())
    if (std::string(j.type) != "planar" && std::string(j.type) != "floating") served.push_back(j);
  return test::chainUrdf(served);
}

}  // namespace

TEST(PointLanes, EveryServedJointKindWithinItsBoundOnEveryTarget) {
  test::TempDir dir;
  const RobotModel m = loadRobot(dir.write("chain.urdf", servedChain()));
  const double worst = expectWithinBounds(m, pointsOn(allLinks(m)), randomStates(m, 61, 7), "served chain",
                                          1e-3);  // (its slides reach 6 m)
  // Not a bound so loose that nothing could come near it: float's own error is a visible share of it.
  EXPECT_GT(worst, 1e-3);
}

TEST(PointLanes, OurRobotsWithinTheirBoundsOnEveryTarget) {
  for (const char* rel : {"arm6/arm6.urdf", "twin_arm/twin_arm.urdf", "dual_arm/dual_arm.urdf"}) {
    const RobotModel m = loadRobot(test::sourceRobot(rel));
    expectWithinBounds(m, pointsOn(allLinks(m)), randomStates(m, 33, 5), rel);
  }
}

TEST(PointLanes, SharedRobotsWithinTheirBoundsOnEveryTarget) {
  for (const char* rel : {"panda/panda.urdf", "ur5/ur5.urdf"}) {
    CLEARWAY_SHARED_ROBOT_OR_SKIP(urdf, rel);
    const RobotModel m = loadRobot(urdf);
    expectWithinBounds(m, pointsOn(allLinks(m)), randomStates(m, 41, 11), rel);
  }
}

TEST(PointLanes, RefusesWhatFloatCannotBound) {
  test::TempDir dir;
  // Planar and floating joints: points beyond them are refused, points before them served.
  const RobotModel flyer = loadRobot(test::sourceRobot("flyer/flyer.urdf"));
  std::vector<int> after_floating;
  for (int l = 1; l < flyer.linkCount(); ++l)
    if (flyer.kinematicStep(l).kind == detail::KinematicStep::Kind::Other) after_floating.push_back(l);
  ASSERT_FALSE(after_floating.empty());
  EXPECT_FALSE(PointLanes(flyer, pointsOn(after_floating), magnitudes(flyer)).serves());
  EXPECT_TRUE(PointLanes(flyer, pointsOn({0}), magnitudes(flyer)).serves());
  // A slide whose values are not bounded, and one that reaches beyond kMaxReach.
  const RobotModel chain = loadRobot(dir.write("chain.urdf", servedChain()));
  const std::vector<PointLanes::Point> points = pointsOn(allLinks(chain));
  std::vector<double> most = magnitudes(chain);
  ASSERT_TRUE(PointLanes(chain, points, most).serves());
  const int slide = chain.kinematicStep(2).variable;  // (j1, the first prismatic joint: link l2)
  ASSERT_EQ(chain.kinematicStep(2).kind, detail::KinematicStep::Kind::Slide);
  most[slide] = INFINITY;
  EXPECT_FALSE(PointLanes(chain, points, most).serves());
  most[slide] = 2 * PointLanes::kMaxReach;
  EXPECT_FALSE(PointLanes(chain, points, most).serves());
  // A chain that reaches 2 km, and a point beyond float's range (refused before anything is rounded).
  const RobotModel far =
      loadRobot(dir.write("far.urdf",
                          "<robot name=\"far\"><link name=\"a\"/><link name=\"b\"/><joint name=\"j\" type=\"revolute\">"
                          "<parent link=\"a\"/><child link=\"b\"/><origin xyz=\"2000 0 0\"/><axis xyz=\"0 0 1\"/>"
                          "<limit lower=\"-1\" upper=\"1\" velocity=\"1\" effort=\"1\"/></joint></robot>"));
  EXPECT_FALSE(PointLanes(far, pointsOn({1}), magnitudes(far)).serves());
  EXPECT_TRUE(PointLanes(far, pointsOn({0}), magnitudes(far)).serves());
  EXPECT_FALSE(PointLanes(chain, {{1, Vec3(1e300, 0, 0)}}, magnitudes(chain)).serves());
  // A point that is not finite, or on a link that does not exist.
  EXPECT_FALSE(PointLanes(chain, {{1, Vec3(NAN, 0, 0)}}, magnitudes(chain)).serves());
  EXPECT_FALSE(PointLanes(chain, {{chain.linkCount(), Vec3::Zero()}}, magnitudes(chain)).serves());
  EXPECT_FALSE(PointLanes().serves());
}
