// A map's voxels merged into blocks (src/environment/voxel_blocks.cpp): the blocks cover exactly the voxels'
// union (every cell of the lattice, every corner of both), are disjoint, keep the voxels' faces bit for bit,
// and are few; voxels off the lattice, too wide, or beyond the budget stay whole. Then the queries that walk
// them against brute force over the voxels, on maps that merge.
#include <clearway/environment/voxel_blocks.h>

#include "box_surface.h"
#include "shared_data.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <vector>

namespace clearway {
namespace {

const Tolerances kTol;

// The loader's cube of lattice corner k and span n (octomap_loader.cpp: the same products).
Aabb latticeCube(const std::array<int, 3>& k, int n, double res) {
  return Aabb::fromMinMax(Vec3(k[0] * res, k[1] * res, k[2] * res),
                          Vec3((k[0] + n) * res, (k[1] + n) * res, (k[2] + n) * res));
}

std::shared_ptr<OccupancyMap> mapOf(std::vector<Aabb> boxes, double res) {
  auto map = std::make_shared<OccupancyMap>();
  map->resolution = res;
  map->occupied = std::move(boxes);
  map->occupied_leaves = static_cast<int>(map->occupied.size());
  for (const Aabb& b : map->occupied) map->known_bounds.merge(b);
  return map;
}

// A map as an octree writes it: solid slabs, posts and blobs in aligned cubes of 1, 2, 4 and 8 cells (a
// cube of n cells at a corner that is a multiple of n, where all its cells are occupied and unclaimed), on
// a lattice of edge `res` around `origin` (in cells).
std::vector<Aabb> octreeLikeVoxels(std::mt19937& rng, double res, const std::array<int, 3>& origin) {
  std::set<std::tuple<int, int, int>> cells;
  std::uniform_int_distribution<int> pos(0, 47), len(1, 20);
  for (int shape = 0; shape < 14; ++shape) {
    const int x0 = pos(rng), y0 = pos(rng), z0 = pos(rng);
    const int lx = shape % 3 == 0 ? 1 : len(rng), ly = shape % 3 == 1 ? 2 : len(rng), lz = len(rng);
    for (int x = x0; x < x0 + lx; ++x)
      for (int y = y0; y < y0 + ly; ++y)
        for (int z = z0; z < z0 + lz; ++z) cells.insert({x, y, z});
  }
  for (int i = 0; i < 60; ++i) cells.insert({pos(rng), pos(rng), pos(rng)});  // lone voxels
  std::vector<Aabb> voxels;
  std::set<std::tuple<int, int, int>> claimed;
  for (const int n : {8, 4, 2, 1})
    for (const auto& [x, y, z] : cells) {
      if (x % n || y % n || z % n) continue;
      bool whole = true;
      for (int i = 0; i < n && whole; ++i)
        for (int j = 0; j < n && whole; ++j)
          for (int k = 0; k < n && whole; ++k)
            whole = cells.count({x + i, y + j, z + k}) && !claimed.count({x + i, y + j, z + k});
      if (!whole) continue;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
          for (int k = 0; k < n; ++k) claimed.insert({x + i, y + j, z + k});
      voxels.push_back(latticeCube({origin[0] + x, origin[1] + y, origin[2] + z}, n, res));
    }
  return voxels;
}

// How many of the boxes (in `tree`) hold p.
int holding(const AabbTree& tree, const Vec3& p) {
  int n = 0;
  tree.query(Aabb::ofPoint(p), [&](std::int32_t) { ++n; });
  return n;
}

// The blocks hold exactly the voxels: the centre of every lattice cell of the bounds lies in a block exactly
// when it lies in a voxel; every corner of either lies in the other; blocks overlap in no cell; each block's
// voxelOf shares part of it; its faces are lattice products (k·res) unless it is a voxel kept whole.
void expectSameUnion(const std::vector<Aabb>& voxels, const VoxelBlocks& blocks, double res, const std::string& what) {
  const std::vector<Aabb>& boxes = blocks.boxes();
  ASSERT_FALSE(boxes.empty()) << what;
  const AabbTree voxel_tree(voxels), block_tree(boxes);  // (a box's tree finds the boxes holding a point)
  Aabb bounds;
  for (const Aabb& v : voxels) bounds.merge(v);
  const auto cellOf = [&](double x) { return static_cast<long>(std::floor(x / res)); };
  long checked = 0;
  for (long i = cellOf(bounds.min.x()) - 1; i <= cellOf(bounds.max.x()); ++i)
    for (long j = cellOf(bounds.min.y()) - 1; j <= cellOf(bounds.max.y()); ++j)
      for (long k = cellOf(bounds.min.z()) - 1; k <= cellOf(bounds.max.z()); ++k) {
        const Vec3 c((i + 0.5) * res, (j + 0.5) * res, (k + 0.5) * res);
        const int in_blocks = holding(block_tree, c);
        ASSERT_EQ(in_blocks > 0, holding(voxel_tree, c) > 0) << what << ": cell " << i << " " << j << " " << k;
        ASSERT_LE(in_blocks, 1) << what << ": blocks overlap at cell " << i << " " << j << " " << k;
        ++checked;
      }
  EXPECT_GT(checked, 500) << what;
  const auto corners = [](const Aabb& b) {
    std::vector<Vec3> out;
    for (int m = 0; m < 8; ++m)
      out.emplace_back(m & 1 ? b.max.x() : b.min.x(), m & 2 ? b.max.y() : b.min.y(), m & 4 ? b.max.z() : b.min.z());
    return out;
  };
  for (const Aabb& v : voxels)
    for (const Vec3& p : corners(v)) ASSERT_GT(holding(block_tree, p), 0) << what;
  for (std::size_t b = 0; b < boxes.size(); ++b) {
    for (const Vec3& p : corners(boxes[b])) ASSERT_GT(holding(voxel_tree, p), 0) << what << ": block " << b;
    const Aabb& of = voxels[static_cast<std::size_t>(blocks.voxelOf(static_cast<int>(b)))];
    ASSERT_TRUE((boxes[b].min.cwiseMax(of.min).array() < boxes[b].max.cwiseMin(of.max).array()).all())
        << what << ": block " << b << " shares nothing with its voxel";
    const bool whole = std::find_if(voxels.begin(), voxels.end(), [&](const Aabb& v) {
                         return v.min == boxes[b].min && v.max == boxes[b].max;
                       }) != voxels.end();
    for (int a = 0; a < 3 && !whole; ++a)
      for (const double f : {boxes[b].min[a], boxes[b].max[a]})
        ASSERT_EQ(std::nearbyint(f / res) * res, f) << what << ": block " << b << " has a face off the lattice";
  }
  EXPECT_EQ(static_cast<std::size_t>(blocks.tree().itemCount()), boxes.size()) << what;
}

TEST(VoxelBlocks, CoverExactlyTheVoxelsAndAreFew) {
  std::mt19937 rng(11);
  for (const double res : {0.05, 0.02, 0.1, 1.0 / 3.0}) {
    for (const std::array<int, 3> origin : {std::array<int, 3>{0, 0, 0}, {-30, 5, -24}, {-32768, 32700, 1000}}) {
      const std::vector<Aabb> voxels = octreeLikeVoxels(rng, res, origin);
      const auto map = mapOf(voxels, res);
      const VoxelBlocks blocks(*map);
      const std::string what = "res " + std::to_string(res) + " origin " + std::to_string(origin[0]);
      expectSameUnion(voxels, blocks, res, what);
      EXPECT_LT(blocks.boxes().size() * 3, voxels.size()) << what << ": " << blocks.boxes().size() << " blocks";
      // Unmerged: the voxels themselves, in order.
      const VoxelBlocks each(*map, false);
      ASSERT_EQ(each.boxes().size(), voxels.size());
      for (std::size_t v = 0; v < voxels.size(); ++v) {
        EXPECT_EQ(each.boxes()[v].min, voxels[v].min);
        EXPECT_EQ(each.boxes()[v].max, voxels[v].max);
        EXPECT_EQ(each.voxelOf(static_cast<int>(v)), static_cast<int>(v));
      }
    }
  }
}

TEST(VoxelBlocks, VoxelsOffTheLatticeOrTooWideStayWhole) {
  const double res = 0.1;
  std::vector<Aabb> voxels;
  for (int x = 0; x < 6; ++x) voxels.push_back(latticeCube({x, 0, 0}, 1, res));         // a row: one block
  const Aabb off = Aabb::fromMinMax(Vec3(0.6001, 0, 0), Vec3(0.7001, 0.1, 0.1));        // beside it, off the lattice
  const Aabb flat = Aabb::fromMinMax(Vec3(0, 0.1, 0), Vec3(0.6, 0.2, 0.05));            // not a cube
  const Aabb wide = latticeCube({0, 0, 16}, 16, res);                                   // wider than kMaxSpan
  const Aabb clipped = Aabb::fromMinMax(Vec3(0, 0.3, 0), Vec3(0.1, 0.4, 0.1 + 1e-17));  // a rounding off
  voxels.insert(voxels.end(), {off, flat, wide, clipped});
  const VoxelBlocks blocks(*mapOf(voxels, res));
  ASSERT_EQ(blocks.boxes().size(), 5u);
  const std::vector<Aabb> expected = {off, flat, wide, clipped,
                                      Aabb::fromMinMax(Vec3(0, 0, 0), Vec3(6 * res, res, res))};
  for (const Aabb& e : expected)
    EXPECT_TRUE(std::any_of(blocks.boxes().begin(), blocks.boxes().end(),
                            [&](const Aabb& b) { return b.min == e.min && b.max == e.max; }))
        << e.min.transpose() << " / " << e.max.transpose();
  // No resolution: nothing is on a lattice.
  EXPECT_EQ(VoxelBlocks(*mapOf(voxels, 0.0)).boxes().size(), voxels.size());
  EXPECT_EQ(VoxelBlocks(*mapOf(voxels, std::nan(""))).boxes().size(), voxels.size());
  // Overlapping voxels (a map built in code) share their cells: the union is still exact.
  std::vector<Aabb> twice = {latticeCube({0, 0, 0}, 2, res), latticeCube({1, 1, 1}, 2, res),
                             latticeCube({0, 0, 0}, 1, res)};
  for (int i = 0; i < 40; ++i) twice.push_back(latticeCube({i % 7, i / 7, 5}, 1, res));
  expectSameUnion(twice, VoxelBlocks(*mapOf(twice, res)), res, "overlapping");
  // Beyond the budget of cells, every voxel is its own block.
  std::vector<Aabb> many;
  const int n = static_cast<int>(VoxelBlocks::kMaxCells / 512) + 1;
  for (int i = 0; i < n; ++i) many.push_back(latticeCube({8 * (i % 64), 8 * (i / 64), 0}, 8, res));
  EXPECT_EQ(VoxelBlocks(*mapOf(many, res)).boxes().size(), many.size());
}

// The shared families' maps: the same union, and a tenth of the voxels or fewer.
TEST(VoxelBlocks, SharedMapsShrinkTenfold) {
  CLEARWAY_SHARED_OR_SKIP(root, "scenes");
  int maps = 0;
  for (const auto& family : std::filesystem::directory_iterator(root)) {
    if (!family.is_directory()) continue;
    const std::string path = family.path().string() + "/" + family.path().filename().string() + "_0001.bt";
    if (!std::filesystem::exists(path)) continue;
    const OccupancyMap map = loadOctomap(path);
    const VoxelBlocks blocks(map);
    expectSameUnion(map.occupied, blocks, map.resolution, path);
    EXPECT_LT(blocks.boxes().size() * 10, map.occupied.size()) << path;
    std::printf("%s: %zu voxels, %zu blocks\n", family.path().filename().c_str(), map.occupied.size(),
                blocks.boxes().size());
    ++maps;
  }
  EXPECT_GT(maps, 0);
}

// A link of the given kind: 0 a box, 1 a capsule, 2 a closed mesh (a box's surface: solid), 3 a concave
// mesh (two box surfaces side by side, a gap between them).
std::unique_ptr<LinkGeometry> linkOf(int kind, const Vec3& half) {
  if (kind < 2) {
    CollisionElement e;
    e.primitive = kind == 0 ? Shape(Box(half)) : Shape(Capsule(half.x(), half.z()));
    return std::make_unique<LinkGeometry>(std::vector<CollisionElement>{e}, std::vector<TriangleMesh>{});
  }
  TriangleMesh mesh = test::boxSurface(half);
  if (kind == 3) {
    const TriangleMesh right = test::boxSurface(half);
    for (Vec3& v : mesh.vertices) v.x() -= 2.5 * half.x();
    for (auto t : right.triangles) {
      for (auto& i : t) i += static_cast<std::int32_t>(mesh.vertices.size());
      mesh.triangles.push_back(t);
    }
    for (const Vec3& v : right.vertices) mesh.vertices.push_back(v + Vec3(2.5 * half.x(), 0.0, 0.0));
  }
  return std::make_unique<LinkGeometry>(mesh);
}

// Every query that walks the blocks against brute force over the voxels, on maps that merge: the verdicts
// of linkIntersects (Mesh and Hull) equal, its hit a voxel the link touches; lowerBound never above the
// nearest voxel's distance and, asked within contact, naming a voxel that near; linkDistance the same
// distance; the same answers with the voxels unmerged.
TEST(VoxelBlocks, QueriesAgreeWithEveryVoxel) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * unit(rng); };
  const double res = 0.05;
  const std::vector<Aabb> voxels = octreeLikeVoxels(rng, res, {-24, -24, -24});
  const auto map = mapOf(voxels, res);
  const Environment env({}, map), each = env.withoutVoxelBlocks();
  ASSERT_NE(env.voxelBlocks(), nullptr);
  ASSERT_LT(env.voxelBlocks()->boxes().size() * 3, voxels.size());
  ASSERT_EQ(each.voxelBlocks()->boxes().size(), voxels.size());
  Obstacle post;
  post.name = "post";
  post.shape = Box(Vec3(0.1, 0.1, 0.1));
  post.pose = Pose::translation(Vec3(3, 3, 3));
  EXPECT_EQ(each.withObstacle(post).voxelBlocks()->boxes().size(), voxels.size());  // (edits keep the choice)
  int hits = 0, misses = 0, near = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Vec3 half(uniform(0.02, 0.25), uniform(0.02, 0.25), uniform(0.02, 0.25));
    const std::unique_ptr<LinkGeometry> link = linkOf(trial % 4, half);
    Pose pose;
    pose.R = Eigen::Quaterniond(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1), uniform(-1, 1))
                 .normalized()
                 .toRotationMatrix();
    pose.t = Vec3(uniform(-1.3, 1.3), uniform(-1.3, 1.3), uniform(-1.3, 1.3));
    const double padding = trial % 4 == 0 ? uniform(0.0, 0.03) : 0.0;
    // The brute force visits the voxels nearest the link's origin first, and skips only those that cannot
    // matter by the triangle inequality: every point of linkOf's links lies within 3.5·|half| of pose.t (a
    // corner of the farther box of two is (3.5·hx, hy, hz) in the link's frame), so a voxel whose box is g
    // from pose.t is at least g − reach from the link; reach's extra half |half| (17 mm at least) is far
    // beyond any rounding band. (Every voxel for every trial is most of the test's time sanitized.)
    const double reach = 4.0 * half.norm();
    std::vector<std::pair<double, int>> by_gap;
    for (std::size_t v = 0; v < voxels.size(); ++v)
      by_gap.emplace_back((voxels[v].min - pose.t).cwiseMax(pose.t - voxels[v].max).cwiseMax(Vec3::Zero()).norm(),
                          static_cast<int>(v));
    std::sort(by_gap.begin(), by_gap.end());
    for (const GeometryMode mode : {GeometryMode::Hull, GeometryMode::Mesh}) {
      bool brute = false;
      for (const auto& [gap, v] : by_gap) {
        if (gap > reach + padding + 1e-9) break;
        const Aabb& box = voxels[static_cast<std::size_t>(v)];
        if ((brute = shapeIntersectsLink(Box(box.halfExtents()), Pose::translation(box.center()), *link, pose, kTol,
                                         mode, padding)))
          break;
      }
      EnvironmentHit hit;
      const bool merged = env.linkIntersects(*link, pose, kTol, {padding, mode}, {0.0, nullptr, &hit});
      ASSERT_EQ(merged, brute) << "trial " << trial << " mode " << static_cast<int>(mode);
      ASSERT_EQ(each.linkIntersects(*link, pose, kTol, {padding, mode}), brute) << "trial " << trial;
      if (merged) {
        ASSERT_EQ(hit.kind, EnvironmentHit::Kind::Voxel);
        ASSERT_GE(hit.index, 0);
        const Aabb& v = voxels[static_cast<std::size_t>(hit.index)];
        EXPECT_EQ(hit.voxel.min, v.min);
        EXPECT_TRUE(
            shapeIntersectsLink(Box(v.halfExtents()), Pose::translation(v.center()), *link, pose, kTol, mode, padding))
            << "trial " << trial << ": the hit names a voxel the link does not touch";
      }
      (merged ? hits : misses)++;
    }
    double nearest = INFINITY;
    for (const auto& [gap, v] : by_gap) {
      if (gap - reach > nearest + 1e-9) break;
      const Aabb& box = voxels[static_cast<std::size_t>(v)];
      nearest = std::min(
          nearest,
          shapeLinkDistance(Box(box.halfExtents()), Pose::translation(box.center()), *link, pose, kTol).distance);
    }
    const DistanceResult d = env.linkDistance(*link, pose, kTol);
    EXPECT_NEAR(d.distance, nearest, 1e-9 + 1e-5 * nearest) << "trial " << trial;
    // Every rung climbed: certified and within the relative error. Climbing only within 5 cm, as a motion
    // asks: certified, and within it a voxel that near is named.
    BoundQuery q;
    q.enough = 0.5;
    q.relative = 0.01;
    for (const double climb : {double{INFINITY}, 0.05}) {
      q.climb = climb;
      EnvironmentHit hit;
      const double lower = env.lowerBound(*link, pose, kTol, q, {0.0, nullptr, &hit});
      const double lower_each = each.lowerBound(*link, pose, kTol, q);
      EXPECT_LE(lower, nearest + 1e-12) << "trial " << trial;
      EXPECT_LE(lower_each, nearest + 1e-12) << "trial " << trial;
      if (climb == INFINITY)
        EXPECT_GE(lower, std::min(q.enough, nearest / (1.0 + q.relative)) - 1e-9) << "trial " << trial;
      if (lower <= climb && lower < q.enough) {
        ASSERT_EQ(hit.kind, EnvironmentHit::Kind::Voxel) << "trial " << trial;
        ASSERT_GE(hit.index, 0) << "trial " << trial;
        const Aabb& v = voxels[static_cast<std::size_t>(hit.index)];
        const double named =
            shapeLinkDistance(Box(v.halfExtents()), Pose::translation(v.center()), *link, pose, kTol).distance;
        EXPECT_LE(named, nearest * (1.0 + q.relative) + 1e-9) << "trial " << trial << " climb " << climb;
        near += climb < INFINITY;
      }
    }
  }
  EXPECT_GT(hits, 60);
  EXPECT_GT(misses, 60);
  EXPECT_GT(near, 30);
  std::printf("%d hits, %d misses, %d bounds within contact\n", hits, misses, near);
}

// Environment::ballClear where there are no obstacle boxes (a map; more obstacles than ObstacleBoxes keeps)
// walks the trees: a ball it calls clear is farther than the slack from everything, by the exact distance
// (Environment::linkDistance of a sphere link); and it clears balls in the open, not near the walls. Seen
// failing with the blocks' gap taken from their centres.
TEST(VoxelBlocks, BallClearWalksTheTreesAndIsCertified) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * unit(rng); };
  const double res = 0.05;
  std::vector<Obstacle> obstacles;
  for (int i = 0; i < ObstacleBoxes::kMaxBoxes + 16; ++i) {
    Obstacle o;
    o.name = "o" + std::to_string(i);
    if (i % 2)
      o.shape = Sphere(uniform(0.01, 0.05));
    else
      o.shape = Box(Vec3(uniform(0.01, 0.05), uniform(0.01, 0.05), uniform(0.01, 0.05)));
    o.pose.R = Eigen::Quaterniond(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1), uniform(-1, 1))
                   .normalized()
                   .toRotationMatrix();
    o.pose.t = Vec3(uniform(-1.6, 1.6), uniform(-1.6, 1.6), uniform(-1.6, 1.6));
    obstacles.push_back(o);
  }
  const Environment env(obstacles, mapOf(octreeLikeVoxels(rng, res, {-24, -24, -24}), res));
  ASSERT_EQ(env.obstacleBoxes(), nullptr);
  int clear = 0, not_clear = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const Vec3 c(uniform(-1.8, 1.8), uniform(-1.8, 1.8), uniform(-1.8, 1.8));
    const double r = uniform(0.0, 0.3), slack = trial % 3 == 0 ? 0.0 : uniform(0.0, 0.05);
    if (!env.ballClear(c, r, slack)) {
      ++not_clear;
      continue;
    }
    ++clear;
    CollisionElement e;
    e.primitive = Sphere(r);
    const LinkGeometry ball(std::vector<CollisionElement>{e}, std::vector<TriangleMesh>{});
    const DistanceResult d = env.linkDistance(ball, Pose::translation(c), kTol);
    ASSERT_GT(d.distance, slack) << "trial " << trial << ": a ball called clear is within the slack";
  }
  EXPECT_GT(clear, 500);
  EXPECT_GT(not_clear, 500);
  EXPECT_FALSE(env.ballClear(Vec3(NAN, 0, 0), 0.1, 0.0));
  EXPECT_FALSE(env.ballClear(Vec3(9, 9, 9), INFINITY, 0.0));
  EXPECT_FALSE(env.ballClear(Vec3(9, 9, 9), 0.1, NAN));
  EXPECT_TRUE(env.ballClear(Vec3(9, 9, 9), 0.1, 0.0));
}

}  // namespace
}  // namespace clearway
