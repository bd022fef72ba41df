// KinematicLanes against computeLinkPoses, bit for bit, with the lanes forced to every SIMD target this
// machine offers (and the portable one): our robots (every joint type among them, planar and floating
// ones in the flyer and the rover), the shared Panda and UR5, batches of every length around the width,
// angles far beyond the joint ranges (where sin and cos fall back to libm), and NaN.
#include <clearway/kinematics/forward_kinematics.h>
#include <clearway/kinematics/kinematic_lanes.h>
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
#include <cstring>
#include <random>
#include <string>
#include <vector>

using namespace clearway;

namespace {

bool sameBits(double a, double b) {
  return std::isnan(a) ? std::isnan(b) : std::memcmp(&a, &b, sizeof a) == 0;
}

// Every pose of every state of `states` from the lanes, across states (KinematicLanes) and across a pose's
// rows (computeLinkPoses), equals the scalar step's (computeLinkPose, link by link), on every target.
void expectLanesEqualScalar(const RobotModel& m, const std::vector<std::vector<double>>& states, const std::string& what) {
  const int n = static_cast<int>(states.size());
  std::vector<std::vector<Pose>> scalar(n, std::vector<Pose>(m.linkCount()));
  for (int s = 0; s < n; ++s)
    for (int i = 1; i < m.linkCount(); ++i) computeLinkPose(m, states[s].data(), scalar[s].data(), i);
  const auto same = [&](const Pose& a, const Pose& b, const std::string& where) -> ::testing::AssertionResult {
    for (int k = 0; k < 9; ++k)
      if (!sameBits(a.R.data()[k], b.R.data()[k]))
        return ::testing::AssertionFailure()
               << where << ", R[" << k << "] = " << a.R.data()[k] << " vs " << b.R.data()[k];
    for (int k = 0; k < 3; ++k)
      if (!sameBits(a.t[k], b.t[k]))
        return ::testing::AssertionFailure() << where << ", t[" << k << "] = " << a.t[k] << " vs " << b.t[k];
    return ::testing::AssertionSuccess();
  };
  std::vector<const double*> q(n);
  for (int s = 0; s < n; ++s) q[s] = states[s].data();
  const std::vector<std::int64_t> targets = KinematicLanes::targets();
  ASSERT_FALSE(targets.empty());
  for (const std::int64_t target : targets) {
    const test::ForcedTarget forced(target);
    ASSERT_STREQ(KinematicLanes::targetName(), hwy::TargetName(target));
    const int w = KinematicLanes::width();
    ASSERT_TRUE(w >= 1 && w <= KinematicLanes::kMaxLanes) << w;
    // One state at a time: every link, and the chain down to each link (from the root, and from its
    // grandparent with the links above it already placed).
    for (int s = 0; s < n; ++s) {
      const std::string at = what + ", target " + hwy::TargetName(target) + ", state " + std::to_string(s);
      std::vector<Pose> all(m.linkCount());
      computeLinkPoses(m, states[s].data(), all.data());
      for (int i = 0; i < m.linkCount(); ++i) ASSERT_TRUE(same(all[i], scalar[s][i], at + ", link " + m.link(i).name));
      for (int i = 1; i < m.linkCount(); ++i) {
        std::vector<int> chain;
        for (int l = i; l > 0; l = m.kinematicStep(l).parent) chain.insert(chain.begin(), l);
        for (const std::size_t from : {std::size_t{0}, chain.size() > 2 ? chain.size() - 2 : std::size_t{0}}) {
          std::vector<Pose> some(m.linkCount(), Pose{Mat3::Constant(-7.0), Vec3::Constant(-7.0)});
          for (std::size_t k = 0; k < from; ++k) some[chain[k]] = scalar[s][chain[k]];
          some[0] = Pose::identity();
          computeLinkPoses(m, states[s].data(), some.data(), chain.data() + from,
                           static_cast<int>(chain.size() - from));
          for (int l = 0; l < m.linkCount(); ++l) {
            const bool placed = l == 0 || std::find(chain.begin(), chain.end(), l) != chain.end();
            const Pose& want =
                placed ? scalar[s][l] : Pose{Mat3::Constant(-7.0), Vec3::Constant(-7.0)};  // (or untouched)
            ASSERT_TRUE(same(some[l], want, at + ", chain to " + m.link(i).name + ", link " + m.link(l).name));
          }
        }
      }
    }
    KinematicLanes lanes(m);
    // Batches of every length up to two passes and one: full passes and a partial last one.
    for (int count = 1; count <= std::min(n, 2 * w + 1); ++count) {
      for (int first = 0; first + count <= n; first += count) {
        std::vector<std::vector<Pose>> out(count, std::vector<Pose>(m.linkCount()));
        std::vector<Pose*> o(count);
        for (int s = 0; s < count; ++s) o[s] = out[s].data();
        lanes.compute(q.data() + first, count, o.data());
        for (int s = 0; s < count; ++s)
          for (int i = 0; i < m.linkCount(); ++i) {
            const Pose& a = out[s][i];
            const Pose& b = scalar[first + s][i];
            for (int k = 0; k < 9; ++k)
              ASSERT_TRUE(sameBits(a.R.data()[k], b.R.data()[k]))
                  << what << ", target " << hwy::TargetName(target) << ", batch of " << count << ", state "
                  << first + s << ", link " << m.link(i).name << ", R[" << k << "] = " << a.R.data()[k] << " vs "
                  << b.R.data()[k];
            for (int k = 0; k < 3; ++k)
              ASSERT_TRUE(sameBits(a.t[k], b.t[k]))
                  << what << ", target " << hwy::TargetName(target) << ", batch of " << count << ", state "
                  << first + s << ", link " << m.link(i).name << ", t[" << k << "]";
          }
      }
    }
  }
}

// States within the limits (continuous and unbounded variables within ±4), and a few far outside.
std::vector<std::vector<double>> randomStates(const RobotModel& m, int n, unsigned seed) {
  // (past 2^16 rad: sin and cos from libm)
  return test::randomJointVectors(m, n, seed, [](int s, int, auto&&) { return s % 7 == 3 ? 1e5 : 1.0; });
}

// A chain of every joint kind (chain_urdf.h).
std::string everyKindChain() { return test::chainUrdf(test::everyJointKind()); }

}  // namespace

TEST(KinematicLanes, EveryJointKindBitForBitOnEveryTarget) {
  test::TempDir dir;
  const RobotModel m = loadRobot(dir.write("chain.urdf", everyKindChain()));
  std::vector<std::vector<double>> states = randomStates(m, 41, 23);
  for (auto& s : states)  // unit quaternions for the floating joint (variables 5..11: x y z qx qy qz qw)
    for (const Joint& j : m.joints())
      if (j.type == JointType::Floating) {
        double* r = s.data() + j.first_variable + 3;
        const double norm = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3]);
        for (int k = 0; k < 4; ++k) r[k] /= norm;
      }
  expectLanesEqualScalar(m, states, "every-kind chain");
}

TEST(KinematicLanes, OurRobotsBitForBitOnEveryTarget) {
  for (const char* rel : {"arm6/arm6.urdf", "planar_arm/planar_arm.urdf", "flyer/flyer.urdf", "rover/rover.urdf",
                          "twin_arm/twin_arm.urdf"}) {
    const RobotModel m = loadRobot(test::sourceRobot(rel));
    expectLanesEqualScalar(m, randomStates(m, 29, 5), rel);
  }
}

TEST(KinematicLanes, SharedRobotsBitForBitOnEveryTarget) {
  for (const char* rel : {"panda/panda.urdf", "ur5/ur5.urdf"}) {
    CLEARWAY_SHARED_ROBOT_OR_SKIP(urdf, rel);
    const RobotModel m = loadRobot(urdf);
    expectLanesEqualScalar(m, randomStates(m, 37, 11), rel);
  }
}

TEST(KinematicLanes, TurnsInEveryQuadrantAndAtTheRangeEdge) {
  // Continuous joints (unbounded), one about z and one about a skew axis, at angles k·π/2 + δ for k across
  // the whole range of the inline sin and cos and both sides of its edge (2^16), where libm takes over.
  test::TempDir dir;
  const RobotModel m = loadRobot(dir.write(
      "turns.urdf",
      "<robot name=\"turns\"><link name=\"a\"/><link name=\"b\"/><link name=\"c\"/>"
      "<joint name=\"z\" type=\"continuous\"><parent link=\"a\"/><child link=\"b\"/><axis xyz=\"0 0 1\"/></joint>"
      "<joint name=\"skew\" type=\"continuous\"><parent link=\"b\"/><child link=\"c\"/>"
      "<origin xyz=\"0.1 0.2 0.3\" rpy=\"0.3 -0.2 0.1\"/><axis xyz=\"0.2 -0.7 0.4\"/></joint></robot>"));
  std::vector<std::vector<double>> states;
  const double deltas[] = {0.0, 1e-9, -0.3, 0.7, -0.78, 0.785398};
  for (long k = -41700; k <= 41700; k += 139)
    states.push_back({k * M_PI / 2 + deltas[k % 6 < 0 ? -(k % 6) : k % 6], -k * M_PI / 2 - deltas[(k / 7 % 6 + 6) % 6]});
  for (const double edge : {0x1p16, std::nextafter(0x1p16, 0.0), std::nextafter(0x1p16, 1e300)})
    for (const double sign : {1.0, -1.0}) states.push_back({sign * edge, -sign * edge});
  expectLanesEqualScalar(m, states, "continuous turns");
}

TEST(KinematicLanes, NaNGivesTheScalarNaNPoses) {
  const RobotModel m = loadRobot(test::sourceRobot("arm6/arm6.urdf"));
  std::vector<std::vector<double>> states = randomStates(m, 9, 3);
  states[2][1] = std::nan("");
  states[5][0] = std::numeric_limits<double>::infinity();
  expectLanesEqualScalar(m, states, "arm6 with NaN and infinity");
}

TEST(KinematicLanes, ChoosesTheWidestTargetOffered) {
  // Unforced, the lanes are the CPU's best compiled target (the first Highway lists).
  EXPECT_STREQ(KinematicLanes::targetName(), hwy::TargetName(KinematicLanes::targets().front()));
  std::printf("lanes: %s, %d doubles; targets tested:", KinematicLanes::targetName(), KinematicLanes::width());
  for (const std::int64_t t : KinematicLanes::targets()) std::printf(" %s", hwy::TargetName(t));
  std::printf("\n");
}
