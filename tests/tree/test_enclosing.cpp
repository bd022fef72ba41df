// The enclosing layer: at random configurations of our arms and the shared robots, a pair it calls apart
// is farther apart than the padding by the exact meshes, and it clears pairs the bounding balls alone do
// not (a layer that never fires would pass the first check).
#include <clearway/body/enclosing.h>
#include <clearway/kinematics/forward_kinematics.h>
#include <clearway/kinematics/kinematic_lanes.h>
#include <clearway/load/robot_loader.h>

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include "forced_target.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "shared_data.h"

namespace clearway {
namespace {

std::vector<double> randomState(const RobotModel& m, std::mt19937_64& rng) {
  std::vector<double> q(m.variableCount());
  for (int i = 0; i < m.variableCount(); ++i) {
    const JointVariable& v = m.variables()[i];
    const double lo = std::isfinite(v.lower) ? v.lower : -3.0, hi = std::isfinite(v.upper) ? v.upper : 3.0;
    q[i] = std::uniform_real_distribution<double>(lo, hi)(rng);
  }
  return q;
}

// One robot's model, geometry and enclosing balls (which point into it: made in place, never moved).
struct Arm {
  explicit Arm(const std::string& urdf)
      : model(std::make_shared<const RobotModel>(loadRobot(urdf))), geometry(model), balls(geometry) {}
  std::shared_ptr<const RobotModel> model;
  RobotGeometry geometry;
  EnclosingBalls balls;
};

TEST(EnclosingBalls, ApartOnlyWhereTheMeshesAreApart) {
  CLEARWAY_REQUIRE_SHARED_ARMS();
  const Tolerances tol;
  for (const std::string& urdf : test::allArms()) {
    Arm arm(urdf);
    const auto& [model, geometry, balls] = std::tie(arm.model, arm.geometry, arm.balls);
    ASSERT_TRUE(balls.madeFor(geometry));
    std::vector<Pose> poses(model->linkCount());
    std::mt19937_64 rng(7);
    const std::vector<int>& links = geometry.geometricLinks();
    int apart = 0, by_parts = 0, pairs = 0;
    for (int s = 0; s < 150; ++s) {
      const std::vector<double> q = randomState(*model, rng);
      computeLinkPoses(*model, q.data(), poses.data());
      balls.place(poses.data());
      for (std::size_t i = 0; i < links.size(); ++i)
        for (std::size_t j = i + 1; j < links.size(); ++j) {
          const int a = links[i], b = links[j];
          const LinkGeometry &ga = *geometry.link(a), &gb = *geometry.link(b);
          for (double padding : {0.0, 0.02}) {
            ++pairs;
            if (!balls.apart(a, b, padding, tol)) continue;
            ++apart;
            const double centres = (poses[a] * ga.sphereCenter() - poses[b] * gb.sphereCenter()).norm();
            by_parts += centres <= ga.sphereRadius() + gb.sphereRadius() + padding;
            EXPECT_FALSE(meshesIntersect(ga, poses[a], gb, poses[b], tol, GeometryMode::Mesh, padding))
                << urdf << ": links " << model->link(a).name << " and " << model->link(b).name << " called apart";
          }
        }
    }
    std::printf("  %s: %d of %d pairs apart, %d of them by the parts' balls\n", urdf.c_str(), apart, pairs, by_parts);
    // The parts' balls are grown to hold the inside of closed meshes (PartCover proves the margin).
    for (int a : links) {
      const LinkGeometry& g = *geometry.link(a);
      const double margin = g.partBallMargin();
      if (g.parts().size() < 2 || !std::isfinite(margin)) {
        EXPECT_EQ(balls.ballCount(a), 1) << urdf << " link " << model->link(a).name;
        continue;
      }
      ASSERT_EQ(balls.ballCount(a), static_cast<int>(g.parts().size()) + 1);
      if (g.solidCount() > 0) EXPECT_GT(margin, 0.0);
      for (int k = 1; k < balls.ballCount(a); ++k)
        EXPECT_GE(balls.placed(a, k).radius, g.parts()[k - 1].radius + margin) << urdf << " link " << model->link(a).name;
    }
    EXPECT_GT(apart, 0);
    bool several = false;  // (a link of one primitive has one part: only its bounding ball)
    for (int a : links) several |= geometry.link(a)->parts().size() > 1;
    if (several) EXPECT_GT(by_parts, 0) << urdf << ": the parts' balls never clear a pair the bounding balls keep";
    // A non-finite pose is never apart.
    poses[links.back()].t.x() = std::numeric_limits<double>::quiet_NaN();
    balls.place(poses.data());
    for (int a : links)
      if (a != links.back()) EXPECT_FALSE(balls.apart(a, links.back(), 0.0, tol));
  }
}

TEST(EnclosingBalls, BoundsApartInLanesIsApartsFirstTest) {
  // Every pair of every robot at random states, the lanes forced to each target this machine offers (one
  // this kernel is not compiled for falls back to one it is), in batches of every length, so that both the
  // lanes and the one-at-a-time tail run: a pair the lanes call apart is apart by apart() and by the exact
  // meshes, and the lanes call apart every pair whose bounding balls are apart by more than the band.
  CLEARWAY_REQUIRE_SHARED_ARMS();
  const Tolerances tol;
  for (const std::string& urdf : test::allArms()) {
    Arm arm(urdf);
    const auto& [model, geometry, balls] = std::tie(arm.model, arm.geometry, arm.balls);
    std::vector<std::int64_t> a, b;
    std::vector<double> padding;
    const std::vector<int>& links = geometry.geometricLinks();
    for (std::size_t i = 0; i < links.size(); ++i)
      for (std::size_t j = i + 1; j < links.size(); ++j) {
        a.push_back(links[i]);
        b.push_back(links[j]);
        padding.push_back(0.01 * static_cast<double>((i + j) % 3));
      }
    // A link without geometry (the root of our arms has none) is never apart, whatever its pose.
    for (int l = 0; l < model->linkCount(); ++l)
      if (!geometry.link(l)) {
        a.push_back(l);
        b.push_back(links.front());
        padding.push_back(0.0);
      }
    const int n = static_cast<int>(a.size());
    std::vector<Pose> poses(model->linkCount());
    std::mt19937_64 rng(5);
    int apart = 0;
    std::vector<std::uint8_t> out(n);
    for (const std::int64_t target : KinematicLanes::targets()) {  // the lanes' targets (simd_targets.h)
      const test::ForcedTarget forced(target);
      for (int s = 0; s < 40; ++s) {
        const std::vector<double> q = randomState(*model, rng);
        computeLinkPoses(*model, q.data(), poses.data());
        balls.place(poses.data());
        const int count = 1 + s % n;  // a prefix of every length up to the pair count
        balls.boundsApart(a.data(), b.data(), padding.data(), count, tol, out.data());
        for (int k = 0; k < count; ++k) {
          const LinkGeometry* ga = geometry.link(static_cast<int>(a[k]));
          const LinkGeometry* gb = geometry.link(static_cast<int>(b[k]));
          const bool bounding = ga && gb &&
                                (poses[a[k]] * ga->sphereCenter() - poses[b[k]] * gb->sphereCenter()).norm() >
                                    ga->sphereRadius() + gb->sphereRadius() + padding[k] + 1e-9;
          if (!out[k]) {
            EXPECT_FALSE(bounding) << urdf << ", " << hwy::TargetName(target) << ": pair " << k
                                   << " has bounding balls apart by more than the band, and the lanes missed it";
            continue;
          }
          ++apart;
          ASSERT_TRUE(ga && gb) << urdf << ": a link without geometry called apart";
          EXPECT_TRUE(balls.apart(static_cast<int>(a[k]), static_cast<int>(b[k]), padding[k], tol));
          EXPECT_FALSE(meshesIntersect(*ga, poses[a[k]], *gb, poses[b[k]], tol, GeometryMode::Mesh, padding[k]))
              << urdf << ", " << hwy::TargetName(target) << ": pair " << k << " called apart";
        }
      }
    }
    EXPECT_GT(apart, 0) << urdf;
  }
}

TEST(EnclosingBalls, MadeOnlyForItsRobot) {
  auto model = std::make_shared<const RobotModel>(loadRobot(std::string(CLEARWAY_SOURCE_DIR) + "/robots/arm6/arm6.urdf"));
  const RobotGeometry a(model), b(model);
  EXPECT_TRUE(EnclosingBalls(a).madeFor(a));
  EXPECT_FALSE(EnclosingBalls(a).madeFor(b));
  EXPECT_FALSE(EnclosingBalls().madeFor(a));
}

}  // namespace
}  // namespace clearway
