// The clearance grid (environment/clearance_grid.h): never above the distance to the boxes, anywhere,
// for any boxes and budget; and close enough below it to be worth reading. Then the environment's own
// grid: built once enough queries were asked, by each version of the static items, never while unasked.
#include <clearway/environment/clearance_grid.h>
#include <clearway/environment/environment.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

namespace clearway {
namespace {

double boxesDistance(const std::vector<Aabb>& boxes, const Vec3& p) {
  double d = std::numeric_limits<double>::infinity();
  for (const Aabb& b : boxes) d = std::min(d, (b.min - p).cwiseMax(p - b.max).cwiseMax(0.0).stableNorm());
  return d;
}

// Random boxes around `centre`: cubes, slabs, needles and single points, some far apart.
std::vector<Aabb> randomBoxes(std::mt19937& rng, const Vec3& centre, double spread) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = std::uniform_int_distribution<int>(1, 40)(rng);
  std::vector<Aabb> boxes;
  for (int i = 0; i < n; ++i) {
    const Vec3 c = centre + spread * Vec3(u(rng), u(rng), u(rng));
    Vec3 h = 0.1 * spread * Vec3(std::abs(u(rng)), std::abs(u(rng)), std::abs(u(rng)));
    switch (i % 4) {
      case 1: h.z() = 0.0; break;               // a slab
      case 2: h.x() = h.y() = 0.0; break;       // a needle
      case 3: if (i % 8 == 3) h.setZero(); break;  // a point
    }
    boxes.push_back(Aabb::fromCenterHalf(c, h));
  }
  return boxes;
}

TEST(ClearanceGrid, NeverAboveTheDistanceToTheBoxesAndCloseBelowIt) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  long points = 0, useful = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const double spread = std::pow(10.0, std::uniform_real_distribution<double>(-2.0, 1.5)(rng));
    const Vec3 centre = (trial % 3 == 0 ? 1e3 : 1.0) * Vec3(u(rng), u(rng), u(rng));
    const std::vector<Aabb> boxes = randomBoxes(rng, centre, spread);
    const int budget = std::uniform_int_distribution<int>(1000, 1 << 16)(rng);
    const ClearanceGrid grid(boxes, budget);
    const auto n = grid.cells();
    EXPECT_LE(static_cast<long>(n[0]) * n[1] * n[2], budget);
    const double h = grid.cellSize();
    Aabb all;
    for (const Aabb& b : boxes) all.merge(b);
    for (int k = 0; k < 2000; ++k) {
      Vec3 p;
      if (k % 4 == 0) {  // on or inside a box: distance 0
        const Aabb& b = boxes[std::uniform_int_distribution<std::size_t>(0, boxes.size() - 1)(rng)];
        p = b.min + (b.max - b.min).cwiseProduct(Vec3(std::abs(u(rng)), std::abs(u(rng)), std::abs(u(rng))));
      } else {  // near the boxes, and sometimes far outside the grid
        p = centre + (k % 10 == 1 ? 20.0 : 1.5) * spread * Vec3(u(rng), u(rng), u(rng));
      }
      const double exact = boxesDistance(boxes, p);
      const double bound = grid.lowerBound(p);
      ++points;
      ASSERT_LE(bound, exact) << "trial " << trial << " point " << k << " h " << h;
      // Inside the boxes' box (beyond it the bound is the distance to that box) and within the window
      // (bounds are capped beyond it): at most 5.2 cells below the distance (the marks reach 1.5 cells
      // beyond a box on each axis, and the point may be half a cell diagonal from the centre it reads).
      if (all.contains(p) && exact < (ClearanceGrid::kWindow - 6) * h) {
        EXPECT_GE(bound, exact - 5.25 * h) << "trial " << trial << " point " << k << ": " << (exact - bound) / h << " cells below";
        if (bound > 0.0) ++useful;
      }
    }
  }
  EXPECT_GT(useful, points / 10) << "the grid proves almost nothing";
}

TEST(ClearanceGrid, EdgeCases) {
  const ClearanceGrid none({});
  EXPECT_EQ(none.lowerBound(Vec3::Zero()), std::numeric_limits<double>::infinity());
  const ClearanceGrid one({Aabb::fromCenterHalf(Vec3(1, 2, 3), Vec3(0.5, 0.5, 0.5))});
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(one.lowerBound(Vec3(nan, 0, 0)), 0.0);
  EXPECT_EQ(one.lowerBound(Vec3(0, inf, 0)), 0.0);
  EXPECT_EQ(one.lowerBound(Vec3(0, 0, -inf)), 0.0);
  EXPECT_EQ(one.lowerBound(Vec3(1e200, 0, nan)), 0.0);  // (a max over the gaps would pass over the NaN)
  EXPECT_EQ(one.lowerBound(Vec3(nan, 1e200, 0)), 0.0);
  EXPECT_LE(one.lowerBound(Vec3(1, 2, 3)), 0.0);
  EXPECT_GT(one.lowerBound(Vec3(1, 2, 4.5)), 0.5);  // 1 m above the top face
  EXPECT_LE(one.lowerBound(Vec3(1, 2, 4.5)), 1.0);
  EXPECT_GT(one.lowerBound(Vec3(1, 2, 100)), 96.0);  // outside the grid: the distance to the boxes' box
  // Boxes near the doubles' end: still never above the distance.
  const double big = std::numeric_limits<double>::max() / 2;
  const std::vector<Aabb> far = {Aabb::fromCenterHalf(Vec3(big, 0, 0), Vec3(1, 1, 1)),
                                 Aabb::fromCenterHalf(Vec3(-big, 0, 0), Vec3(1, 1, 1)),
                                 Aabb::fromCenterHalf(Vec3(1e200, 1e200, 0), Vec3(1, 1, 1))};
  const ClearanceGrid huge(far);
  // Cells beyond the floats' range (1e40 m apart): bounds rounded down to the largest float.
  const std::vector<Aabb> vast = {Aabb::fromCenterHalf(Vec3(1e40, 0, 0), Vec3(1, 1, 1)),
                                  Aabb::fromCenterHalf(Vec3(-1e40, 0, 0), Vec3(1, 1, 1))};
  const ClearanceGrid wide(vast);
  for (const Vec3& p : {Vec3(0, 0, 0), Vec3(1e40, 0, 5), Vec3(0, 3e39, 0), Vec3(-1e40, 0, 1e30)}) {
    const double bound = wide.lowerBound(p);
    EXPECT_FALSE(std::isnan(bound));
    EXPECT_LE(bound, boxesDistance(vast, p)) << p.transpose();
  }
  EXPECT_GT(wide.lowerBound(Vec3(0, 0, 0)), 1e38);
  for (const Vec3& p : {Vec3(0, 0, 0), Vec3(big, 0, 5), Vec3(-big, 3, 0), Vec3(0, big, big), Vec3(1e200, 1e200, 10)}) {
    const double bound = huge.lowerBound(p);
    EXPECT_FALSE(std::isnan(bound));
    EXPECT_LE(bound, boxesDistance(far, p)) << p.transpose();
  }
  EXPECT_THROW(ClearanceGrid({Aabb()}), std::invalid_argument);
  EXPECT_THROW(ClearanceGrid({Aabb::fromMinMax(Vec3(0, 0, 0), Vec3(nan, 1, 1))}), std::invalid_argument);
  EXPECT_THROW(ClearanceGrid({Aabb::fromMinMax(Vec3(0, 0, 0), Vec3(inf, 1, 1))}), std::invalid_argument);
}

Obstacle box(const std::string& name, const Vec3& at, const Vec3& half) {
  Obstacle o;
  o.name = name;
  o.shape = Box(half);
  o.pose = Pose::translation(at);
  return o;
}

TEST(ClearanceGrid, EachVersionBuildsItsOwnOnceAskedEnough) {
  const Environment env({box("a", Vec3(1, 0, 0), Vec3(0.1, 0.1, 0.1)), box("b", Vec3(-1, 0, 0), Vec3(0.2, 0.1, 0.1))});
  CollisionElement ball;
  ball.primitive = Sphere(0.05);
  const auto link = std::make_shared<LinkGeometry>(std::vector<CollisionElement>{ball}, std::vector<TriangleMesh>{});
  const Tolerances tol;
  const auto ask = [&](const Environment& e, int times) {
    for (int i = 0; i < times; ++i)
      e.linkIntersects(*link, Pose::translation(Vec3(0, 0, 0.01 * (i % 7))), tol, {0.0, GeometryMode::Mesh});
  };
  EXPECT_EQ(env.clearanceGrid(), nullptr);
  ask(env, Environment::kClearanceAfter);
  EXPECT_EQ(env.clearanceGrid(), nullptr) << "built before it was asked enough";
  ask(env, 1);
  const ClearanceGrid* grid = env.clearanceGrid();
  ASSERT_NE(grid, nullptr);
  EXPECT_GT(grid->lowerBound(Vec3(0, 0, 0)), 0.05);  // (0.8 m from both: beyond the window)
  // A copy shares it; an edit of the static items starts anew; a moving obstacle keeps the static grid.
  const Environment copy = env;
  EXPECT_EQ(copy.clearanceGrid(), grid);
  const Environment edited = env.withObstacle(box("c", Vec3(0, 0, 0.5), Vec3(0.1, 0.1, 0.1)));
  EXPECT_EQ(edited.clearanceGrid(), nullptr);
  edited.prepareClearanceGrid();
  ASSERT_NE(edited.clearanceGrid(), nullptr);
  EXPECT_LT(edited.clearanceGrid()->lowerBound(Vec3(0, 0, 0.5)), 0.0);
  EXPECT_GT(grid->lowerBound(Vec3(0, 0, 0.5)), 0.3) << "the old version changed with the edit";
  EXPECT_EQ(env.withoutObstacle("a").clearanceGrid(), nullptr);
  EXPECT_EQ(env.withObstacleMoved("a", Pose::translation(Vec3(2, 0, 0))).clearanceGrid(), nullptr);
  EXPECT_EQ(env.withPoints({Vec3(0, 0, 0)}, 0.05).clearanceGrid(), nullptr);
  Obstacle mover = box("m", Vec3(0, 1, 0), Vec3(0.1, 0.1, 0.1));
  mover.velocity = Vec3(0.1, 0, 0);
  EXPECT_EQ(env.withObstacle(mover).clearanceGrid(), grid);
  // Never, when asked not to: not even when asked to build one, nor after an edit.
  const Environment without = env.withoutClearanceGrid();
  EXPECT_EQ(without.clearanceGrid(), nullptr);
  ask(without, Environment::kClearanceAfter + 10);
  without.prepareClearanceGrid();
  EXPECT_EQ(without.clearanceGrid(), nullptr);
  const Environment without_edited = without.withObstacle(box("d", Vec3(0, 0, -0.5), Vec3(0.1, 0.1, 0.1)));
  without_edited.prepareClearanceGrid();
  EXPECT_EQ(without_edited.clearanceGrid(), nullptr) << "an edit brought the grid back";
}

TEST(ClearanceGrid, CoversVoxelsAndPointVoxels) {
  auto map = std::make_shared<OccupancyMap>();
  map->resolution = 0.05;
  map->occupied = {Aabb::fromMinMax(Vec3(0.5, 0.5, 0.5), Vec3(0.55, 0.55, 0.55))};
  const Environment env = Environment({box("a", Vec3(-1, 0, 0), Vec3(0.1, 0.1, 0.1))}, map).withPoints({Vec3(0, -0.7, 0.02)});
  env.prepareClearanceGrid();
  const ClearanceGrid* grid = env.clearanceGrid();
  ASSERT_NE(grid, nullptr);
  EXPECT_LE(grid->lowerBound(Vec3(0.52, 0.52, 0.52)), 0.0);  // in the map's voxel
  EXPECT_LE(grid->lowerBound(Vec3(0.02, -0.68, 0.02)), 0.0);  // in the point's voxel
  EXPECT_LE(grid->lowerBound(Vec3(0, 0, 0)), 0.65);
  EXPECT_GT(grid->lowerBound(Vec3(0, 0, 0)), 0.1);
}

}  // namespace
}  // namespace clearway
