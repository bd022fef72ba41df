// The enclosing layer: every point of every link lies in its balls as placed (real robots, and random links
// at random poses); at random configurations of our arms and the shared robots, a pair it calls apart
// is farther apart than the padding by the hulls, and its boxes clear pairs the bounding balls alone do
// not (a layer that never fires would pass the first check).
#include <clearway/body/enclosing.h>
#include <clearway/body/proximity.h>
#include <clearway/detail/margins.h>
#include <clearway/kinematics/forward_kinematics.h>
#include <clearway/kinematics/kinematic_lanes.h>
#include <clearway/load/robot_loader.h>

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include "forced_target.h"
#include "tree/mesh_reference.h"

#include <algorithm>
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

TEST(EnclosingBalls, ApartOnlyWhereTheHullsAreApart) {
  CLEARWAY_REQUIRE_SHARED_ARMS();
  const Tolerances tol;
  for (const std::string& urdf : test::allArms()) {
    Arm arm(urdf);
    const auto& [model, geometry, balls] = std::tie(arm.model, arm.geometry, arm.balls);
    ASSERT_TRUE(balls.madeFor(geometry));
    std::vector<Pose> poses(model->linkCount());
    std::mt19937_64 rng(7);
    const std::vector<int>& links = geometry.geometricLinks();
    int apart = 0, by_boxes = 0, pairs = 0;
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
            by_boxes += centres <= ga.sphereRadius() + gb.sphereRadius() + padding;
            // The hulls, which hold the meshes: Hull mode asks this layer too.
            EXPECT_FALSE(meshesIntersect(ga, poses[a], gb, poses[b], tol, GeometryMode::Hull, padding))
                << urdf << ": links " << model->link(a).name << " and " << model->link(b).name << " called apart";
          }
        }
    }
    std::printf("  %s: %d of %d pairs apart, %d of them by the boxes\n", urdf.c_str(), apart, pairs, by_boxes);
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
    EXPECT_GT(by_boxes, 0) << urdf << ": the boxes never clear a pair the bounding balls keep";
    // A non-finite pose is never apart.
    poses[links.back()].t.x() = std::numeric_limits<double>::quiet_NaN();
    balls.place(poses.data());
    for (int a : links)
      if (a != links.back()) EXPECT_FALSE(balls.apart(a, links.back(), 0.0, tol));
  }
}

TEST(EnclosingBalls, BoundsApartInLanesIsApartsFirstTest) {
  // Every pair of every robot at random states, the lanes forced to each target this machine offers (one
  // this kernel is not compiled for falls back to one it is), in lists of every length, so that runs end at
  // every lane: a pair the lanes call apart is apart by apart() and by the exact meshes, and the lanes call
  // apart every pair whose bounding balls are apart by more than the band.
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
    std::vector<std::uint8_t> out(n + BoundsRows::kSpare);
    for (const std::int64_t target : KinematicLanes::targets()) {  // the lanes' targets (simd_targets.h)
      const test::ForcedTarget forced(target);
      for (int s = 0; s < 40; ++s) {
        const std::vector<double> q = randomState(*model, rng);
        computeLinkPoses(*model, q.data(), poses.data());
        balls.place(poses.data());
        const int count = 1 + s % n;  // a prefix of every length up to the pair count
        const BoundsRows rows(std::vector<std::int64_t>(a.begin(), a.begin() + count),
                              std::vector<std::int64_t>(b.begin(), b.begin() + count),
                              std::vector<double>(padding.begin(), padding.begin() + count), model->linkCount());
        balls.boundsApart(rows, tol, out.data());
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

// Points of a link in its own frame: every triangle's corners, and points on each primitive's surface in
// 26 directions and 40 random ones (round primitives are their cores grown by their radius).
std::vector<Vec3> linkPoints(const LinkGeometry& g, std::mt19937_64& rng) {
  std::vector<Vec3> out;
  for (const Triangle& t : g.triangles()) out.insert(out.end(), std::begin(t.v), std::end(t.v));
  std::vector<Vec3> dirs;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z)
        if (x || y || z) dirs.push_back(Vec3(x, y, z).normalized());
  std::normal_distribution<double> normal;
  for (int k = 0; k < 40; ++k) dirs.push_back(Vec3(normal(rng), normal(rng), normal(rng)).normalized());
  for (const LinkGeometry::Primitive& p : g.primitives())
    for (const Vec3& d : dirs)
      std::visit([&](const auto& shape) {
        const Vec3 local = p.pose.R.transpose() * d;
        out.push_back(p.pose * (shape.support(local) + shape.radius() * local));
      }, p.shape);
  return out;
}

// Every point of link i (world, placed by `pose`) lies in its bounding ball as placed, and in one of its
// parts' balls when it has them. Returns the number of points checked.
long expectEnclosed(EnclosingBalls& balls, int i, const LinkGeometry& g, const Pose& pose, const std::vector<Vec3>& points,
                    const std::string& what) {
  const int n = balls.ballCount(i);
  EXPECT_GE(n, 1) << what;
  if (n < 1) return 0;
  const EnclosingBalls::Placed bound = balls.placed(i, 0);
  long checked = 0;
  for (const Vec3& v : points) {
    const Vec3 p = pose * v;
    ++checked;
    EXPECT_LE((p - bound.center).norm(), bound.radius) << what << ": a point outside the bounding ball";
    if (n == 1) continue;
    bool in_part = false;
    for (int k = 1; k < n && !in_part; ++k) {
      const EnclosingBalls::Placed part = balls.placed(i, k);
      in_part = (p - part.center).norm() <= part.radius;
    }
    EXPECT_TRUE(in_part) << what << ": a point in none of the parts' balls (" << g.parts().size() << " parts)";
  }
  return checked;
}

// The enclosing layer encloses: at random configurations of our robots and the shared ones, every
// triangle corner and primitive surface point of every link lies in the link's bounding ball and in one of
// its parts' balls, as placed.
TEST(EnclosingBalls, EveryPointOfEveryLinkLiesInItsBalls) {
  CLEARWAY_REQUIRE_SHARED_ARMS();
  std::vector<std::string> urdfs = test::allArms();
  for (const char* ours : {"/robots/flyer/flyer.urdf", "/robots/rover/rover.urdf", "/robots/planar_arm/planar_arm.urdf",
                           "/robots/dual_arm/dual_arm.urdf"})
    urdfs.push_back(std::string(CLEARWAY_SOURCE_DIR) + ours);
  std::mt19937_64 rng(23);
  for (const std::string& urdf : urdfs) {
    Arm arm(urdf);
    const RobotModel& model = *arm.model;
    std::vector<Pose> poses(model.linkCount());
    std::vector<std::vector<Vec3>> points(model.linkCount());
    for (int i : arm.geometry.geometricLinks()) points[i] = linkPoints(*arm.geometry.link(i), rng);
    long checked = 0;
    for (int s = 0; s < 6; ++s) {
      const std::vector<double> q = randomState(model, rng);
      computeLinkPoses(model, q.data(), poses.data());
      arm.balls.place(poses.data());
      for (int i : arm.geometry.geometricLinks())
        checked += expectEnclosed(arm.balls, i, *arm.geometry.link(i), poses[i], points[i], urdf + " link " + model.link(i).name);
      if (testing::Test::HasFailure()) return;
    }
    EXPECT_GT(checked, 0) << urdf;
  }
}

// The same as a property of random links: triangle soups, closed meshes and primitives in random frames,
// joined in one link, at random poses up to a kilometre from the origin (where the placement rounds most).
TEST(EnclosingBalls, RandomLinksAtRandomPosesLieInTheirBalls) {
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const auto randomPose = [&](double reach) {
    Pose p;
    p.R = tree_ref::randomRotation(rng);
    p.t = Vec3(unit(rng), unit(rng), unit(rng)) * reach;
    return p;
  };
  const std::vector<std::pair<std::string, TriangleMesh>> closed = tree_ref::closedSamples();
  int with_parts = 0;
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<Link> links(2);
    links[0].name = "world";
    links[1].name = "body";
    links[1].parent_joint = 0;
    std::vector<TriangleMesh> meshes;
    // A triangle soup (points in a random box), sometimes a closed mesh beside it.
    TriangleMesh soup;
    const Vec3 size(std::exp(2.0 * unit(rng)), std::exp(2.0 * unit(rng)), std::exp(2.0 * unit(rng)));
    for (int k = 0; k < 3 * (4 + trial * 7); ++k) soup.vertices.push_back(size.cwiseProduct(Vec3(unit(rng), unit(rng), unit(rng))));
    for (int k = 0; k + 2 < static_cast<int>(soup.vertices.size()); k += 3) soup.triangles.push_back({k, k + 1, k + 2});
    meshes.push_back(soup);
    links[1].collisions.push_back({randomPose(1.0), std::nullopt, 0});
    if (trial % 2) {
      meshes.push_back(closed[trial % closed.size()].second);
      links[1].collisions.push_back({randomPose(2.0), std::nullopt, 1});
    }
    const Shape primitives[] = {Box(Vec3(0.3, 0.1, 0.2)), Sphere(0.25), Capsule(0.1, 0.4), Cylinder(0.2, 0.05)};
    for (int k = 0; k < trial % 4; ++k) links[1].collisions.push_back({randomPose(1.5), primitives[(trial + k) % 4], -1});
    Joint j;
    j.name = "float";
    j.type = JointType::Floating;
    j.parent_link = 0;
    j.child_link = 1;
    auto model = std::make_shared<const RobotModel>("random", links, std::vector<Joint>{j}, meshes);
    const RobotGeometry geometry(model);
    EnclosingBalls balls(geometry);
    const LinkGeometry& g = *geometry.link(1);
    with_parts += balls.ballCount(1) > 1;
    const std::vector<Vec3> points = linkPoints(g, rng);
    std::vector<Pose> poses(2);
    for (int s = 0; s < 5; ++s) {
      const Pose at = randomPose(s == 0 ? 0.0 : std::pow(10.0, s - 1));  // 0 to 1000 m
      const Eigen::Quaterniond r(at.R);
      const double q[7] = {at.t.x(), at.t.y(), at.t.z(), r.x(), r.y(), r.z(), r.w()};
      computeLinkPoses(*model, q, poses.data());
      balls.place(poses.data());
      expectEnclosed(balls, 1, g, poses[1], points, "trial " + std::to_string(trial) + " pose " + std::to_string(s));
      if (testing::Test::HasFailure()) return;
    }
  }
  EXPECT_GT(with_parts, 10) << "too few random links had parts' balls to check";
}

TEST(EnclosingBalls, BoundsRowsAnswerEachPairAsAlone) {
  // Pair lists laid out in runs of every shape (sorted as SelfCollision's, shuffled, with repeats at other
  // paddings, reversed pairs, links without geometry), on each target: every pair's verdict is the one it
  // gets in a list of its own, and the formula's (apart()'s first test); the spare bytes past the last pair
  // are the only ones written past it (ASan checks the rest).
  Arm a(std::string(CLEARWAY_SOURCE_DIR) + "/robots/dual_arm/dual_arm.urdf");  // (34 links, some without geometry)
  const int links = a.model->linkCount();
  const Tolerances tol;
  const double band = margins::narrowBand(tol.gjk_absolute);
  std::mt19937_64 rng(17);
  std::vector<Pose> poses(links);
  for (const std::int64_t target : KinematicLanes::targets()) {
    const test::ForcedTarget forced(target);
    for (int trial = 0; trial < 60; ++trial) {
      computeLinkPoses(*a.model, randomState(*a.model, rng).data(), poses.data());
      a.balls.place(poses.data());
      std::vector<std::int64_t> first, second;
      std::vector<double> padding;
      for (int i = 0; i < links; ++i)
        for (int j = 0; j < links; ++j)
          if (i != j && (trial % 3 == 0 ? i < j : std::uniform_int_distribution<int>(0, 2)(rng) == 0)) {
            first.push_back(i);
            second.push_back(j);
            padding.push_back(std::uniform_real_distribution<double>(0.0, 0.05)(rng));
            if (trial % 5 == 1 && first.size() % 7 == 0) {  // a repeat at another padding
              first.push_back(i);
              second.push_back(j);
              padding.push_back(0.3);
            }
          }
      if (trial % 3 == 2) {  // shuffled
        std::vector<std::size_t> order(first.size());
        for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
        std::shuffle(order.begin(), order.end(), rng);
        std::vector<std::int64_t> f, s;
        std::vector<double> p;
        for (std::size_t k : order) f.push_back(first[k]), s.push_back(second[k]), p.push_back(padding[k]);
        first.swap(f), second.swap(s), padding.swap(p);
      }
      const int n = static_cast<int>(first.size());
      const BoundsRows rows(first, second, padding, links);
      ASSERT_EQ(rows.size(), n);
      std::vector<std::uint8_t> out(n + BoundsRows::kSpare + 16, 7);
      a.balls.boundsApart(rows, tol, out.data());
      for (int k = n + BoundsRows::kSpare; k < static_cast<int>(out.size()); ++k) ASSERT_EQ(out[k], 7) << k;
      int apart = 0;
      for (int k = 0; k < n; ++k) {
        std::uint8_t alone[1 + BoundsRows::kSpare];
        a.balls.boundsApart(BoundsRows({first[k]}, {second[k]}, {padding[k]}, links), tol, alone);
        ASSERT_EQ(out[k], alone[0]) << hwy::TargetName(target) << ": pair " << k << " of " << n;
        ASSERT_LE(out[k], 1);
        const LinkGeometry* ga = a.geometry.link(static_cast<int>(first[k]));
        const LinkGeometry* gb = a.geometry.link(static_cast<int>(second[k]));
        bool formula = false;
        if (ga && gb) {  // apart()'s first test, from the balls as placed
          const Vec3 ca = poses[first[k]] * ga->sphereCenter(), cb = poses[second[k]] * gb->sphereCenter();
          const double reach = ga->sphereRadius() + gb->sphereRadius() + padding[k];
          const double limit = reach + band * (ca.norm() + cb.norm() + reach);
          formula = (ca - cb).squaredNorm() > limit * limit;
        }
        EXPECT_EQ(out[k] != 0, formula) << hwy::TargetName(target) << ": pair " << k;
        apart += out[k];
      }
      EXPECT_GT(apart, 0);
      EXPECT_LT(apart, n);
    }
  }
  EXPECT_THROW(BoundsRows({0}, {0}, {0.0}, links), std::invalid_argument);
  EXPECT_THROW(BoundsRows({0}, {links}, {0.0}, links), std::invalid_argument);
  EXPECT_THROW(BoundsRows({-1}, {1}, {0.0}, links), std::invalid_argument);
  EXPECT_THROW(BoundsRows({0, 1}, {1}, {0.0}, links), std::invalid_argument);
  EXPECT_EQ(BoundsRows().size(), 0);
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
