// Aabb operations and AabbTree: build invariants for both splits and every leaf size, box queries,
// tree-vs-tree descent and the distance-pruned traversals against brute force over random cases
// (fixed seeds), refit.
#include <clearway/narrowphase/gjk.h>
#include <clearway/tree/aabb_tree.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

#include "tree/mesh_reference.h"

namespace clearway {
namespace {

using tree_ref::randomRotation;

constexpr double kBand = 1e-9;

// ---- Aabb ----------------------------------------------------------------------------------------------

TEST(Aabb, EmptyGrowMerge) {
  Aabb e;
  EXPECT_TRUE(e.isEmpty());
  EXPECT_EQ(e.surfaceArea(), 0.0);
  Aabb b = e;
  b.grow(Vec3(1, 2, 3));
  EXPECT_FALSE(b.isEmpty());
  EXPECT_EQ(b.min, Vec3(1, 2, 3));
  EXPECT_EQ(b.max, Vec3(1, 2, 3));
  b.grow(Vec3(-1, 4, 0));
  EXPECT_EQ(b.min, Vec3(-1, 2, 0));
  EXPECT_EQ(b.max, Vec3(1, 4, 3));
  EXPECT_EQ(b.center(), Vec3(0, 3, 1.5));
  EXPECT_EQ(b.halfExtents(), Vec3(1, 1, 1.5));
  EXPECT_DOUBLE_EQ(b.surfaceArea(), 2.0 * (2 * 2 + 2 * 3 + 3 * 2));
  Aabb c = b;
  c.merge(e);  // merging the empty box changes nothing
  EXPECT_EQ(c.min, b.min);
  EXPECT_EQ(c.max, b.max);
  const Aabb d = merged(b, Aabb::fromMinMax(Vec3(5, 5, 5), Vec3(6, 6, 6)));
  EXPECT_EQ(d.min, Vec3(-1, 2, 0));
  EXPECT_EQ(d.max, Vec3(6, 6, 6));
  EXPECT_TRUE(d.contains(b));
  EXPECT_FALSE(b.contains(d));
  EXPECT_TRUE(b.contains(e));
  EXPECT_TRUE(b.contains(Vec3(1, 4, 3)));  // closed
  EXPECT_FALSE(b.contains(Vec3(1, 4, 3.0000001)));
  const Aabb f = b.inflated(0.5);
  EXPECT_EQ(f.min, Vec3(-1.5, 1.5, -0.5));
  EXPECT_EQ(f.max, Vec3(1.5, 4.5, 3.5));
  const Aabb g = Aabb::fromCenterHalf(Vec3(1, 1, 1), Vec3(1, 2, 3));
  EXPECT_EQ(g.min, Vec3(0, -1, -2));
  EXPECT_EQ(g.max, Vec3(2, 3, 4));
}

TEST(Aabb, OverlapIsClosedAndDistance) {
  const Aabb a = Aabb::fromMinMax(Vec3(0, 0, 0), Vec3(1, 1, 1));
  EXPECT_TRUE(overlaps(a, Aabb::fromMinMax(Vec3(1, 0, 0), Vec3(2, 1, 1))));  // shared face
  EXPECT_TRUE(overlaps(a, Aabb::fromMinMax(Vec3(1, 1, 1), Vec3(2, 2, 2))));  // shared corner
  EXPECT_FALSE(overlaps(a, Aabb::fromMinMax(Vec3(1.001, 0, 0), Vec3(2, 1, 1))));
  EXPECT_FALSE(overlaps(a, Aabb()));
  EXPECT_EQ(boxDistance(a, Aabb::fromMinMax(Vec3(0.5, 0.5, 0.5), Vec3(3, 3, 3))), 0.0);
  EXPECT_DOUBLE_EQ(boxDistance(a, Aabb::fromMinMax(Vec3(4, 5, 1), Vec3(6, 6, 2))), 5.0);  // gaps 3, 4, 0
  EXPECT_DOUBLE_EQ(boxDistance(a, Aabb::fromMinMax(Vec3(-3, 0, 0), Vec3(-2, 1, 1))), 2.0);
}

TEST(Aabb, TransformedContainsTheRotatedBoxAndIsTight) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-2.0, 2.0), h(0.0, 1.0);
  for (int trial = 0; trial < 2000; ++trial) {
    const Vec3 c(u(rng), u(rng), u(rng));
    const Vec3 half(h(rng), h(rng), trial % 5 == 0 ? 0.0 : h(rng));
    const Aabb box = Aabb::fromCenterHalf(c, half);
    Pose pose;
    pose.R = randomRotation(rng);
    pose.t = Vec3(u(rng), u(rng), u(rng)) * 10.0;
    const Aabb t = transformed(box, pose);
    Vec3 lo = Vec3::Constant(tree_ref::kInf), hi = -lo;
    for (int k = 0; k < 8; ++k) {
      const Vec3 corner = c + Vec3(k & 1 ? half.x() : -half.x(), k & 2 ? half.y() : -half.y(), k & 4 ? half.z() : -half.z());
      const Vec3 p = pose * corner;
      ASSERT_TRUE(t.contains(p)) << "trial " << trial;
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    // Tight: each face of the transformed box is reached by a corner, up to rounding.
    EXPECT_LT((t.min - lo).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((t.max - hi).cwiseAbs().maxCoeff(), 1e-12);
  }
  EXPECT_TRUE(transformed(Aabb(), Pose::translation(Vec3(1, 2, 3))).isEmpty());
}

// ---- Random item sets ------------------------------------------------------------------------------------

std::vector<Aabb> randomBoxes(std::mt19937_64& rng, int n, double spread = 1.0) {
  std::uniform_real_distribution<double> u(-spread, spread), h(0.0, 0.12), kind(0.0, 1.0);
  std::vector<Aabb> boxes;
  for (int i = 0; i < n; ++i) {
    Vec3 half(h(rng), h(rng), h(rng));
    const double k = kind(rng);
    if (k < 0.15) half.z() = 0.0;     // flat (a triangle in an axis plane)
    else if (k < 0.2) half.setZero();  // a point
    boxes.push_back(Aabb::fromCenterHalf(Vec3(u(rng), u(rng), u(rng)), half));
  }
  return boxes;
}

// Depth of the subtree at `node`, checking the invariants on the way: every node's box contains its
// children's (or its items') boxes, leaves hold 1 … leaf_size items, children follow their parent.
int checkSubtree(const AabbTree& tree, int node, int leaf_size, const std::vector<Aabb>& boxes, std::vector<int>& seen) {
  const AabbTree::Node& n = tree.nodes()[node];
  if (n.isLeaf()) {
    EXPECT_GE(n.count, 1);
    EXPECT_LE(n.count, leaf_size);
    for (int s = n.first; s < n.first + n.count; ++s) {
      const int item = tree.items()[s];
      ++seen[item];
      EXPECT_TRUE(n.box.contains(boxes[item])) << "leaf " << node << " item " << item;
      EXPECT_EQ(tree.slotBoxes()[s].min, boxes[item].min);
      EXPECT_EQ(tree.slotBoxes()[s].max, boxes[item].max);
    }
    return 0;
  }
  EXPECT_GT(n.first, node);
  EXPECT_LT(n.first + 1, tree.nodeCount());
  EXPECT_TRUE(n.box.contains(tree.nodes()[n.first].box));
  EXPECT_TRUE(n.box.contains(tree.nodes()[n.first + 1].box));
  return 1 + std::max(checkSubtree(tree, n.first, leaf_size, boxes, seen),
                      checkSubtree(tree, n.first + 1, leaf_size, boxes, seen));
}

void checkTree(const AabbTree& tree, int leaf_size, const std::vector<Aabb>& boxes) {
  ASSERT_EQ(tree.itemCount(), static_cast<int>(boxes.size()));
  if (boxes.empty()) {
    EXPECT_TRUE(tree.empty());
    return;
  }
  std::vector<int> seen(boxes.size(), 0);
  const int depth = checkSubtree(tree, 0, leaf_size, boxes, seen);
  EXPECT_EQ(depth, tree.depth());
  EXPECT_LE(depth, AabbTree::kMaxDepth);
  for (std::size_t i = 0; i < boxes.size(); ++i) EXPECT_EQ(seen[i], 1) << "item " << i << " in " << seen[i] << " leaves";
  Aabb all;
  for (const Aabb& b : boxes) all.merge(b);
  EXPECT_EQ(tree.bounds().min, all.min);
  EXPECT_EQ(tree.bounds().max, all.max);
}

const TreeSplit kSplits[] = {TreeSplit::Median, TreeSplit::Sah};

TEST(AabbTree, BuildInvariantsForEverySplitAndLeafSize) {
  std::mt19937_64 rng(1);
  for (const TreeSplit split : kSplits)
    for (int leaf = 1; leaf <= AabbTree::kMaxLeafSize; ++leaf)
      for (const int n : {1, 2, 3, 5, 17, 256, 1000}) {
        const std::vector<Aabb> boxes = randomBoxes(rng, n);
        const AabbTree tree(boxes, {split, leaf});
        SCOPED_TRACE(testing::Message() << "split " << static_cast<int>(split) << " leaf " << leaf << " n " << n);
        checkTree(tree, leaf, boxes);
        if (split == TreeSplit::Median) {
          // The median split halves: depth ⌈log₂ ⌈n / leaf⌉⌉ at most.
          EXPECT_LE(tree.depth(), static_cast<int>(std::ceil(std::log2(std::max(1.0, std::ceil(double(n) / leaf))))) + 1);
        }
      }
}

TEST(AabbTree, DegenerateInputsKeepTheDepthBounded) {
  // All boxes equal: no split separates the centres, so both splits cut by position.
  const std::vector<Aabb> same(3000, Aabb::fromMinMax(Vec3(0, 0, 0), Vec3(1, 1, 1)));
  for (const TreeSplit split : kSplits) {
    const AabbTree tree(same, {split, 1});
    checkTree(tree, 1, same);
    EXPECT_LE(tree.depth(), 12);
  }
  // Centres at 2^i: binned SAH peels one item per level; the median takes over at depth 32.
  std::vector<Aabb> spread;
  for (int i = 0; i < 1000; ++i) spread.push_back(Aabb::ofPoint(Vec3(std::ldexp(1.0, i % 1000 - 500), 0, 0)));
  const AabbTree sah(spread, {TreeSplit::Sah, 1});
  checkTree(sah, 1, spread);
  EXPECT_LE(sah.depth(), 32 + 10);
}

TEST(AabbTree, EmptyTreeAndBadInput) {
  const AabbTree empty(std::vector<Aabb>{});
  EXPECT_TRUE(empty.empty());
  EXPECT_TRUE(empty.bounds().isEmpty());
  int calls = 0;
  EXPECT_FALSE(empty.query(Aabb::fromMinMax(Vec3::Constant(-1e9), Vec3::Constant(1e9)), [&](int) { ++calls; }));
  const AabbTree one({Aabb::ofPoint(Vec3::Zero())});
  EXPECT_FALSE(forEachOverlap(empty, one, Pose::identity(), [&](int, int) { ++calls; }));
  EXPECT_FALSE(forEachOverlap(one, empty, Pose::identity(), [&](int, int) { ++calls; }));
  EXPECT_EQ(calls, 0);

  const Aabb ok = Aabb::ofPoint(Vec3::Zero());
  EXPECT_THROW(AabbTree({ok, Aabb()}), std::invalid_argument);
  EXPECT_THROW(AabbTree({ok, Aabb::fromMinMax(Vec3(0, 0, 0), Vec3(NAN, 1, 1))}), std::invalid_argument);
  EXPECT_THROW(AabbTree({ok, Aabb::fromMinMax(Vec3(0, 0, 0), Vec3(INFINITY, 1, 1))}), std::invalid_argument);
  EXPECT_THROW(AabbTree({ok}, {TreeSplit::Median, 0}), std::invalid_argument);
  EXPECT_THROW(AabbTree({ok}, {TreeSplit::Median, AabbTree::kMaxLeafSize + 1}), std::invalid_argument);
  AabbTree tree({ok, ok});
  EXPECT_THROW(tree.refit({ok}), std::invalid_argument);
  EXPECT_THROW(tree.refit({ok, Aabb()}), std::invalid_argument);
}

// ---- Box queries -----------------------------------------------------------------------------------------

std::set<int> bruteQuery(const std::vector<Aabb>& boxes, const Aabb& q) {
  std::set<int> r;
  for (std::size_t i = 0; i < boxes.size(); ++i)
    if (overlaps(boxes[i], q)) r.insert(static_cast<int>(i));
  return r;
}

TEST(AabbTree, BoxQueryMatchesBruteForce) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-1.2, 1.2), h(0.0, 0.4);
  for (const TreeSplit split : kSplits)
    for (int leaf = 1; leaf <= AabbTree::kMaxLeafSize; ++leaf) {
      const std::vector<Aabb> boxes = randomBoxes(rng, 400);
      const AabbTree tree(boxes, {split, leaf});
      for (int q = 0; q < 300; ++q) {
        const Aabb query = Aabb::fromCenterHalf(Vec3(u(rng), u(rng), u(rng)), Vec3(h(rng), h(rng), h(rng)));
        std::set<int> found;
        tree.query(query, [&](int item) { EXPECT_TRUE(found.insert(item).second) << "item reported twice"; });
        ASSERT_EQ(found, bruteQuery(boxes, query)) << "query " << q;
      }
      // Touching counts: the query is exactly an item's box shifted to share a face.
      const Aabb& b = boxes[7];
      const Aabb touching = Aabb::fromMinMax(Vec3(b.max.x(), b.min.y(), b.min.z()), Vec3(b.max.x() + 1, b.max.y(), b.max.z()));
      bool hit = false;
      tree.query(touching, [&](int item) { hit = hit || item == 7; });
      EXPECT_TRUE(hit);
    }
}

TEST(AabbTree, QueryStopsWhenTheCallbackSaysSo) {
  std::mt19937_64 rng(3);
  const std::vector<Aabb> boxes = randomBoxes(rng, 200);
  const AabbTree tree(boxes, {TreeSplit::Median, 2});
  int calls = 0;
  EXPECT_TRUE(tree.query(tree.bounds(), [&](int) { ++calls; return true; }));
  EXPECT_EQ(calls, 1);
  calls = 0;
  EXPECT_FALSE(tree.query(tree.bounds(), [&](int) { ++calls; return false; }));
  EXPECT_EQ(calls, 200);
}

TEST(AabbTree, ForEachWithinFindsTheNearestBox) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-3.0, 3.0), h(0.0, 0.2);
  for (const TreeSplit split : kSplits)
    for (int leaf = 1; leaf <= AabbTree::kMaxLeafSize; leaf += 3) {
      const std::vector<Aabb> boxes = randomBoxes(rng, 300);
      const AabbTree tree(boxes, {split, leaf});
      for (int q = 0; q < 200; ++q) {
        const Aabb query = Aabb::fromCenterHalf(Vec3(u(rng), u(rng), u(rng)), Vec3(h(rng), h(rng), h(rng)));
        double best = tree_ref::kInf;
        for (const Aabb& b : boxes) best = std::min(best, boxDistance(b, query));
        double cutoff = tree_ref::kInf;
        tree.forEachWithin(query, cutoff, [&](int item) { cutoff = std::min(cutoff, boxDistance(boxes[item], query)); });
        ASSERT_EQ(cutoff, best);
        // A fixed cutoff visits at least every box within it.
        double fixed = 0.3;
        std::set<int> found;
        tree.forEachWithin(query, fixed, [&](int item) { found.insert(item); });
        for (std::size_t i = 0; i < boxes.size(); ++i)
          if (boxDistance(boxes[i], query) <= 0.3) ASSERT_TRUE(found.count(static_cast<int>(i))) << i;
      }
    }
}

TEST(AabbTree, ForEachWithinAnOrientedBoxMissesNoBoxWithinTheCutoff) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-3.0, 3.0), h(0.0, 0.6), angle(-M_PI, M_PI);
  const std::vector<Aabb> boxes = randomBoxes(rng, 300);
  const AabbTree tree(boxes, {TreeSplit::Sah, 3});
  for (int q = 0; q < 300; ++q) {
    const Vec3 half(h(rng), h(rng), 0.01 + h(rng));
    const Aabb local = Aabb::fromCenterHalf(Vec3::Zero(), half);
    const Pose pose{Mat3(Eigen::AngleAxisd(angle(rng), Vec3(u(rng), u(rng), u(rng)).normalized())),
                    Vec3(u(rng), u(rng), u(rng))};
    double cutoff = 0.25;
    std::set<int> found;
    tree.forEachWithin(local, pose, cutoff, [&](int item) { found.insert(item); });
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      const Vec3 c = 0.5 * (boxes[i].min + boxes[i].max), bh = 0.5 * (boxes[i].max - boxes[i].min);
      const DistanceResult d = gjkDistance(Box(half), pose, Box(bh), Pose{Mat3::Identity(), c});
      if (d.distance <= 0.25 - 1e-9) ASSERT_TRUE(found.count(static_cast<int>(i))) << "query " << q << " box " << i;
    }
  }
  // A slab turned 45° about z reaches everything inside its axis-aligned bounds, but only the boxes along
  // its diagonal are near it.
  std::vector<Aabb> grid;
  for (int x = -10; x <= 10; ++x)
    for (int y = -10; y <= 10; ++y) grid.push_back(Aabb::fromCenterHalf(Vec3(0.1 * x, 0.1 * y, 0), Vec3::Constant(0.01)));
  const AabbTree flat(grid, {});
  const Aabb slab = Aabb::fromCenterHalf(Vec3::Zero(), Vec3(1.5, 0.005, 0.5));
  const Pose turned{Mat3(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitZ())), Vec3::Zero()};
  int oriented = 0, aligned = 0;
  double c1 = 0.02, c2 = 0.02;
  flat.forEachWithin(slab, turned, c1, [&](int) { ++oriented; });
  flat.forEachWithin(transformed(slab, turned), c2, [&](int) { ++aligned; });
  EXPECT_EQ(aligned, 21 * 21);
  EXPECT_LE(oriented, 3 * 21) << "the turned slab's own axes prune the grid off its diagonal";
  EXPECT_GE(oriented, 21);
}

// ---- Tree vs tree ----------------------------------------------------------------------------------------

// Every box's extent along the 15 unit axes of a pose (A's 3 face normals, B's 3, and the 9 normalised
// cross products; a near-zero cross product is skipped: it is a face axis again), from its 8 corners in
// A's frame: independent of the library's centre/half-extent formulas.
struct AxisIntervals {
  std::vector<Vec3> axes;
  std::vector<std::vector<std::pair<double, double>>> boxes;  // per box, per axis: [min, max]
};

AxisIntervals project(const std::vector<Aabb>& boxes, const Pose& pose, const Mat3& R) {
  AxisIntervals r;
  for (int i = 0; i < 3; ++i) r.axes.push_back(Vec3::Unit(i));
  for (int j = 0; j < 3; ++j) r.axes.push_back(R.col(j));
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const Vec3 L = Vec3::Unit(i).cross(R.col(j));
      if (L.norm() > 1e-6) r.axes.push_back(L.normalized());
    }
  for (const Aabb& b : boxes) {
    std::vector<std::pair<double, double>> iv(r.axes.size(), {tree_ref::kInf, -tree_ref::kInf});
    for (int k = 0; k < 8; ++k) {
      const Vec3 p = pose * Vec3(k & 1 ? b.max.x() : b.min.x(), k & 2 ? b.max.y() : b.min.y(), k & 4 ? b.max.z() : b.min.z());
      for (std::size_t a = 0; a < r.axes.size(); ++a) {
        const double x = r.axes[a].dot(p);
        iv[a].first = std::min(iv[a].first, x);
        iv[a].second = std::max(iv[a].second, x);
      }
    }
    r.boxes.push_back(iv);
  }
  return r;
}

struct ObbGaps {
  double faces;  // largest gap along the 6 face normals
  double all;    // largest gap along the 15 axes (the boxes overlap iff ≤ 0)
};

ObbGaps obbGaps(const std::vector<std::pair<double, double>>& a, const std::vector<std::pair<double, double>>& b) noexcept {
  ObbGaps g{-tree_ref::kInf, -tree_ref::kInf};
  for (std::size_t k = 0; k < a.size(); ++k) {
    const double gap = std::max(b[k].first - a[k].second, a[k].first - b[k].second);
    if (k < 6) g.faces = std::max(g.faces, gap);
    g.all = std::max(g.all, gap);
  }
  return g;
}

template <bool kFull>
void checkTreeVsTree(TreeSplit split, int leaf, double margin, std::uint64_t seed, int cases) {
  std::mt19937_64 rng(seed);
  for (int c = 0; c < cases; ++c) {
    const std::vector<Aabb> ba = randomBoxes(rng, 50), bb = randomBoxes(rng, 50, 0.6);
    const AabbTree ta(ba, {split, leaf}), tb(bb, {split, leaf});
    Pose b_in_a;
    b_in_a.R = randomRotation(rng);
    b_in_a.t = tree_ref::randomInBall(rng, 1.5);
    std::vector<char> found(ba.size() * bb.size(), 0);
    forEachOverlap<kFull>(
        ta, tb, b_in_a,
        [&](int i, int j) { ASSERT_EQ(found[i * bb.size() + j]++, 0) << "pair reported twice"; }, margin);
    const AxisIntervals pa = project(ba, Pose::identity(), b_in_a.R), pb = project(bb, b_in_a, b_in_a.R);
    for (std::size_t i = 0; i < ba.size(); ++i)
      for (std::size_t j = 0; j < bb.size(); ++j) {
        const ObbGaps g = obbGaps(pa.boxes[i], pb.boxes[j]);
        const bool reported = found[i * bb.size() + j] != 0;
        // Complete: every pair of boxes within the margin (minus the band) is reported.
        if (g.all < margin - kBand) ASSERT_TRUE(reported) << "case " << c << " pair " << i << "," << j;
        // Sound: a reported pair is not apart along a face normal by more than the margin.
        if (reported) ASSERT_LE(g.faces, margin + kBand) << "case " << c << " pair " << i << "," << j;
        if (reported && kFull && margin == 0.0) ASSERT_LE(g.all, kBand) << "case " << c << " pair " << i << "," << j;
      }
  }
}

TEST(AabbTree, TreeVsTreeMatchesBruteForce) {
  std::uint64_t seed = 100;
  for (const TreeSplit split : kSplits)
    for (int leaf = 1; leaf <= AabbTree::kMaxLeafSize; ++leaf) {
      SCOPED_TRACE(testing::Message() << "split " << static_cast<int>(split) << " leaf " << leaf);
      checkTreeVsTree<false>(split, leaf, 0.0, ++seed, 30);
      checkTreeVsTree<true>(split, leaf, 0.0, ++seed, 30);
      checkTreeVsTree<true>(split, leaf, 0.05, ++seed, 15);
    }
}

TEST(AabbTree, TreeVsTreeTouchingCountsAndEarlyExit) {
  // Unit boxes sharing a face exactly, then an ulp apart in the other direction.
  const AabbTree a({Aabb::fromMinMax(Vec3(0, 0, 0), Vec3(1, 1, 1))});
  const AabbTree b({Aabb::fromMinMax(Vec3(0, 0, 0), Vec3(1, 1, 1))});
  int calls = 0;
  forEachOverlap(a, b, Pose::translation(Vec3(1, 0, 0)), [&](int, int) { ++calls; });
  EXPECT_EQ(calls, 1);
  calls = 0;
  forEachOverlap(a, b, Pose::translation(Vec3(1.001, 0, 0)), [&](int, int) { ++calls; });
  EXPECT_EQ(calls, 0);
  forEachOverlap(a, b, Pose::translation(Vec3(1.001, 0, 0)), [&](int, int) { ++calls; }, 0.0011);
  EXPECT_EQ(calls, 1);

  std::mt19937_64 rng(5);
  const std::vector<Aabb> boxes = randomBoxes(rng, 300);
  const AabbTree t(boxes, {TreeSplit::Sah, 3});
  calls = 0;
  EXPECT_TRUE(forEachOverlap(t, t, Pose::identity(), [&](int, int) { ++calls; return true; }));
  EXPECT_EQ(calls, 1);
}

// forEachOverlapDeeperFirst: forEachOverlap's pairs, each once, in another order (small trees, and large
// ones whose descent goes past the ordered unfoldings into the plain depth-first rest); a search that
// stops does so at a pair it wants, and only where there is one.
template <bool kFull>
void checkDeeperFirst(TreeSplit split, int leaf, int boxes, double margin, std::uint64_t seed, int cases) {
  std::mt19937_64 rng(seed);
  for (int c = 0; c < cases; ++c) {
    const std::vector<Aabb> ba = randomBoxes(rng, boxes), bb = randomBoxes(rng, boxes, 0.6);
    const AabbTree ta(ba, {split, leaf}), tb(bb, {split, leaf});
    Pose b_in_a;
    b_in_a.R = randomRotation(rng);
    b_in_a.t = tree_ref::randomInBall(rng, 1.0);
    const std::size_t nb = bb.size();
    std::vector<char> plain(ba.size() * nb, 0), deeper(ba.size() * nb, 0);
    forEachOverlap<kFull>(
        ta, tb, b_in_a, [&](int i, int j) { ++plain[i * nb + j]; }, margin);
    forEachOverlapDeeperFirst<kFull>(
        ta, tb, b_in_a, [&](int i, int j) { ++deeper[i * nb + j]; }, margin);
    ASSERT_EQ(plain, deeper) << "case " << c << ": another set of pairs, or one twice";
    // Stopping at the first pair of a wanted subset: found exactly when the subset meets the pairs.
    const auto wanted = [&](int i, int j) { return (i * 7 + j * 13 + c) % 29 == 0; };
    bool any = false;
    for (std::size_t k = 0; k < plain.size(); ++k) any = any || (plain[k] && wanted(k / nb, k % nb));
    int stopped_at = -1;
    const bool stopped = forEachOverlapDeeperFirst<kFull>(
        ta, tb, b_in_a,
        [&](int i, int j) {
          if (!wanted(i, j)) return false;
          stopped_at = i * static_cast<int>(nb) + j;
          return true;
        },
        margin);
    ASSERT_EQ(stopped, any) << "case " << c;
    if (stopped) ASSERT_TRUE(plain[stopped_at] && wanted(stopped_at / nb, stopped_at % nb));
  }
}

TEST(AabbTree, DeeperFirstVisitsTheSamePairsAndStopsOnlyAtAWantedOne) {
  std::uint64_t seed = 700;
  for (const TreeSplit split : kSplits)
    for (int leaf = 1; leaf <= AabbTree::kMaxLeafSize; leaf += 2) {
      SCOPED_TRACE(testing::Message() << "split " << static_cast<int>(split) << " leaf " << leaf);
      checkDeeperFirst<false>(split, leaf, 50, 0.0, ++seed, 20);
      checkDeeperFirst<true>(split, leaf, 50, 0.05, ++seed, 10);
      checkDeeperFirst<true>(split, leaf, 400, 0.0, ++seed, 4);
    }
}

TEST(AabbTree, PairsWithinACutoffAndTheNearestPair) {
  // Point items: the box distance is the point distance, known exactly.
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const TreeSplit split : kSplits)
    for (int leaf = 1; leaf <= AabbTree::kMaxLeafSize; leaf += 3)
      for (int c = 0; c < 25; ++c) {
        std::vector<Aabb> pa, pb;
        for (int i = 0; i < 100; ++i) {
          pa.push_back(Aabb::ofPoint(Vec3(u(rng), u(rng), u(rng))));
          pb.push_back(Aabb::ofPoint(Vec3(u(rng), u(rng), u(rng)) * 0.5));
        }
        const AabbTree ta(pa, {split, leaf}), tb(pb, {split, leaf});
        Pose b_in_a;
        b_in_a.R = randomRotation(rng);
        b_in_a.t = tree_ref::randomInBall(rng, 2.0);
        auto dist = [&](int i, int j) { return (pa[i].min - b_in_a * pb[j].min).norm(); };
        double best = tree_ref::kInf;
        for (int i = 0; i < 100; ++i)
          for (int j = 0; j < 100; ++j) best = std::min(best, dist(i, j));
        double cutoff = tree_ref::kInf;
        forEachPairWithin(ta, tb, b_in_a, cutoff, [&](int i, int j) { cutoff = std::min(cutoff, dist(i, j)); });
        ASSERT_NEAR(cutoff, best, 1e-15) << "case " << c;
        double fixed = 0.2;
        std::set<std::pair<int, int>> found;
        forEachPairWithin(ta, tb, b_in_a, fixed, [&](int i, int j) { found.insert({i, j}); });
        for (int i = 0; i < 100; ++i)
          for (int j = 0; j < 100; ++j)
            if (dist(i, j) <= 0.2 - kBand) ASSERT_TRUE(found.count({i, j})) << "case " << c;
        // The caller's bound: here the exact least distance below the two nodes (points, by brute force),
        // so that the pairs visited are exactly those within the cutoff, and none of the others' subtrees.
        std::vector<std::vector<int>> below_a(ta.nodes().size()), below_b(tb.nodes().size());
        const auto collect = [](const AabbTree& t, std::vector<std::vector<int>>& below) {
          for (int n = static_cast<int>(t.nodes().size()) - 1; n >= 0; --n) {
            const AabbTree::Node& node = t.nodes()[n];
            if (node.isLeaf())
              for (int s = node.first; s < node.first + node.count; ++s) below[n].push_back(t.items()[s]);
            else
              for (int k = 0; k < 2; ++k)
                below[n].insert(below[n].end(), below[node.first + k].begin(), below[node.first + k].end());
          }
        };
        collect(ta, below_a);
        collect(tb, below_b);
        int asked = 0;
        const auto exact = [&](std::int32_t na, std::int32_t nb, double gap) {
          ++asked;
          double least = tree_ref::kInf;
          for (int i : below_a[na])
            for (int j : below_b[nb]) least = std::min(least, dist(i, j));
          EXPECT_LE(gap, least + 1e-12) << "the boxes' gap exceeds the distance";
          return std::max(gap, least);
        };
        double bounded = 0.2;
        std::set<std::pair<int, int>> bounded_found;
        forEachPairWithinBy(ta, tb, b_in_a, bounded, exact, [&](int i, int j) { bounded_found.insert({i, j}); });
        if (best <= 0.2) EXPECT_GT(asked, 0) << "case " << c;
        for (int i = 0; i < 100; ++i)
          for (int j = 0; j < 100; ++j) {
            if (dist(i, j) <= 0.2 - kBand) ASSERT_TRUE(bounded_found.count({i, j})) << "case " << c;
            // (A leaf of several items is visited whole when its nearest pair is within the cutoff.)
            if (leaf == 1 && dist(i, j) > 0.2 + kBand) ASSERT_FALSE(bounded_found.count({i, j})) << "case " << c;
          }
      }
}

TEST(AabbTree, RefitKeepsTopologyAndAnswersForTheNewBoxes) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.2, 1.2), h(0.0, 0.3), move(-0.3, 0.3);
  for (const TreeSplit split : kSplits) {
    std::vector<Aabb> boxes = randomBoxes(rng, 500);
    AabbTree tree(boxes, {split, 2});
    const std::vector<AabbTree::Node> before = tree.nodes();
    const std::vector<std::int32_t> items = tree.items();
    for (int round = 0; round < 5; ++round) {
      for (Aabb& b : boxes) {
        const Vec3 d(move(rng), move(rng), move(rng));
        b.min += d;
        b.max += d;
      }
      tree.refit(boxes);
      ASSERT_EQ(tree.nodeCount(), static_cast<int>(before.size()));
      for (std::size_t i = 0; i < before.size(); ++i) {
        ASSERT_EQ(tree.nodes()[i].first, before[i].first);
        ASSERT_EQ(tree.nodes()[i].count, before[i].count);
      }
      ASSERT_EQ(tree.items(), items);
      checkTree(tree, 2, boxes);
      for (int q = 0; q < 100; ++q) {
        const Aabb query = Aabb::fromCenterHalf(Vec3(u(rng), u(rng), u(rng)), Vec3(h(rng), h(rng), h(rng)));
        std::set<int> found;
        tree.query(query, [&](int item) { found.insert(item); });
        ASSERT_EQ(found, bruteQuery(boxes, query));
      }
    }
  }
}

}  // namespace
}  // namespace clearway
