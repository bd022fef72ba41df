#pragma once
// A bounding-volume hierarchy of axis-aligned boxes over a list of items (triangles, links, obstacles,
// voxels), stored as flat arrays. Based on: G. van den Bergen, "Efficient Collision Detection of Complex
// Deformable Models using AABB Trees" (JGT 1997) and "Collision Detection in Interactive 3D
// Environments" (2003), seeds/000: split on the longest axis; test two trees in different frames by
// descending both at once, always unfolding the larger box, with an oriented-box test that tries the
// 6 face normals first ("SAT lite") and, optionally, the 9 edge-pair axes; refit bottom-up for items
// that move. A binned surface-area heuristic (I. Wald, "On fast Construction of SAH-based Bounding
// Volume Hierarchies", 2007) is the alternative split.
//
// Traversals allocate nothing: their stacks are arrays on the call stack, sized for kMaxDepth, which
// the build guarantees (a depth-first descent of a binary tree of depth D holds at most D + 1 nodes;
// a simultaneous descent of two trees at most D_a + D_b + 1 pairs).
#include <clearway/tree/aabb.h>
#include <clearway/tree/oriented_box_test.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

namespace clearway {

/// How a node's items are divided between its two children.
enum class TreeSplit {
  Median,  ///< the median of the item centres along the longest axis of their bounds (balanced, depth ⌈log₂ n⌉)
  Sah,     ///< binned surface-area heuristic (16 bins per axis); Median below a depth of 32
};

/// Construction parameters of an AabbTree. The defaults descend fastest on the Panda and UR5 meshes
/// (benchmarks/tree_bench.cpp: tree-vs-tree with SAH takes 0.6–0.8 of the median split's time; leaves
/// of 3 beat 1, 2 and 4 by 5–15 %), at 3–4× the build time of the median split.
struct TreeBuildOptions {
  TreeSplit split = TreeSplit::Sah;  ///< how each node divides its items
  /// Maximum items per leaf, 1 … AabbTree::kMaxLeafSize.
  int leaf_size = 3;
};

/// An AABB tree over item boxes, all in one frame (the tree's frame). Immutable after construction
/// except for refit(); queries are const and thread-safe.
class AabbTree {
 public:
  /// Depth bound the build guarantees (root at depth 0); traversal stacks are sized by it.
  static constexpr int kMaxDepth = 64;
  static constexpr int kMaxLeafSize = 4;  ///< the largest TreeBuildOptions::leaf_size a build accepts

  /// A node: its box and either two children (at `first` and `first + 1`) or a range of item slots.
  struct Node {
    Aabb box;  ///< contains the boxes of every item below the node (tree frame)
    std::int32_t first = 0;  ///< inner node: index of the left child (the right one follows it); leaf: first slot
    std::int32_t count = 0;  ///< leaf: number of items (1 … leaf_size); inner node: 0
    /// True for a leaf (count > 0).
    bool isLeaf() const noexcept { return count > 0; }
  };

  /// The empty tree: every query finds nothing.
  AabbTree() = default;
  /// Builds the tree over item_boxes (item i has box item_boxes[i]). Throws std::invalid_argument for an
  /// empty or non-finite box, a leaf size outside 1 … kMaxLeafSize, or more than 2³⁰ items.
  explicit AabbTree(const std::vector<Aabb>& item_boxes, const TreeBuildOptions& options = {});

  /// True for the default tree (a build has at least one item).
  bool empty() const noexcept { return nodes_.empty(); }
  /// The number of items (the size of item_boxes).
  int itemCount() const noexcept { return static_cast<int>(items_.size()); }
  /// The number of nodes, leaves included (0 for the empty tree).
  int nodeCount() const noexcept { return static_cast<int>(nodes_.size()); }
  /// The number of edges on the longest root-to-leaf path (0 for a single leaf, or an empty tree).
  int depth() const noexcept { return depth_; }
  /// The box of all items (the empty box for an empty tree).
  const Aabb& bounds() const noexcept { return nodes_.empty() ? empty_box_ : nodes_[0].box; }

  /// Nodes in depth-first order: node 0 is the root, and every child comes after its parent.
  const std::vector<Node>& nodes() const noexcept { return nodes_; }
  /// The item held in each slot: leaf ranges index this array.
  const std::vector<std::int32_t>& items() const noexcept { return items_; }
  /// The box of the item in each slot.
  const std::vector<Aabb>& slotBoxes() const noexcept { return slot_boxes_; }

  /// New boxes for the same items (item i now has item_boxes[i]): node boxes are recomputed bottom-up,
  /// the topology is kept (queries stay exact; only their speed degrades as items move far).
  /// Throws std::invalid_argument when the count differs or a box is empty or not finite.
  void refit(const std::vector<Aabb>& item_boxes);

  /// Calls on_item(item) for every item whose box overlaps `box` (closed boxes: touching counts).
  /// on_item may return bool: true stops the query. Returns true when stopped that way.
  template <class F>
  bool query(const Aabb& box, F&& on_item) const;

  /// Calls on_item(item) for items whose box is within `cutoff` of `box` (box distance ≤ cutoff), nearer
  /// subtrees first; on_item may lower cutoff (it is read again before each subtree) and may return
  /// true to stop. Every item within the final cutoff is visited.
  template <class F>
  bool forEachWithin(const Aabb& box, double& cutoff, F&& on_item) const;
  /// The same for an oriented box: `box` in its own frame, placed in the tree's frame by `box_in_tree`.
  /// Each node is within reach when both its distance to the placed box's bounds and the oriented
  /// boxes' gap (SAT axes, see OrientedBoxTest::gap) are: a turned slab no longer reaches everything
  /// inside its axis-aligned bounds.
  template <class F>
  bool forEachWithin(const Aabb& box, const Pose& box_in_tree, double& cutoff, F&& on_item) const;

 private:
  // forEachWithin with the node-to-query lower bound `dist(box)`.
  template <class D, class F>
  bool forEachWithinBy(D&& dist, double& cutoff, F&& on_item) const;

  void build(std::int32_t node, std::int32_t begin, std::int32_t end, int depth, const std::vector<Aabb>& boxes,
             const std::vector<Vec3>& centers, const TreeBuildOptions& options);
  void refitNodes() noexcept;

  std::vector<Node> nodes_;
  std::vector<std::int32_t> items_;
  std::vector<Aabb> slot_boxes_;
  int depth_ = 0;
  Aabb empty_box_;
};

namespace detail {

// A traversal callback may return void (visit everything) or something convertible to bool (true stops).
template <class F, class... Args>
bool callbackStops(F& f, Args... args) {
  if constexpr (std::is_void_v<std::invoke_result_t<F&, Args...>>) {
    f(args...);
    return false;
  } else {
    return static_cast<bool>(f(args...));
  }
}

inline double boxSize(const Aabb& b) noexcept { return (b.max - b.min).sum(); }

}  // namespace detail

template <class F>
bool AabbTree::query(const Aabb& box, F&& on_item) const {
  if (nodes_.empty()) return false;
  std::int32_t stack[kMaxDepth + 1];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (!overlaps(n.box, box)) continue;
    if (n.isLeaf()) {
      for (std::int32_t s = n.first; s < n.first + n.count; ++s)
        if ((n.count == 1 || overlaps(slot_boxes_[s], box)) && detail::callbackStops(on_item, items_[s])) return true;
    } else {
      stack[top++] = n.first + 1;
      stack[top++] = n.first;
    }
  }
  return false;
}

template <class F>
bool AabbTree::forEachWithin(const Aabb& box, double& cutoff, F&& on_item) const {
  return forEachWithinBy([&](const Aabb& node) { return boxDistance(node, box); }, cutoff, on_item);
}

template <class F>
bool AabbTree::forEachWithin(const Aabb& box, const Pose& box_in_tree, double& cutoff, F&& on_item) const {
  if (nodes_.empty()) return false;
  const Aabb bounds = transformed(box, box_in_tree);
  const detail::OrientedBoxTest test(box_in_tree, 0.0, detail::treePairScale(nodes_[0].box, box, box_in_tree));
  const detail::OrientedBoxTest::PlacedB placed = test.place(box);
  // The oriented gap only where the bounds' distance leaves the node within the cutoff: beyond it, the gap
  // could only add to a distance already pruned (the cutoff only falls), and it costs ten times more.
  return forEachWithinBy(
      [&](const Aabb& node) {
        const double d = boxDistance(node, bounds);
        return d > cutoff ? d : std::max(d, test.gap(node, placed));
      },
      cutoff, on_item);
}

template <class D, class F>
bool AabbTree::forEachWithinBy(D&& dist, double& cutoff, F&& on_item) const {
  if (nodes_.empty()) return false;
  struct Entry {
    std::int32_t node;
    double dist;
  };
  Entry stack[kMaxDepth + 1];
  int top = 0;
  stack[top++] = {0, dist(nodes_[0].box)};
  while (top > 0) {
    const Entry e = stack[--top];
    if (!(e.dist <= cutoff)) continue;
    const Node& n = nodes_[e.node];
    if (n.isLeaf()) {
      for (std::int32_t s = n.first; s < n.first + n.count; ++s)
        if ((n.count == 1 || dist(slot_boxes_[s]) <= cutoff) && detail::callbackStops(on_item, items_[s])) return true;
    } else {
      const Entry l{n.first, dist(nodes_[n.first].box)};
      const Entry r{n.first + 1, dist(nodes_[n.first + 1].box)};
      // The nearer child goes on top: it is visited first and lowers the cutoff for the other.
      if (l.dist <= r.dist) { stack[top++] = r; stack[top++] = l; }
      else { stack[top++] = l; stack[top++] = r; }
    }
  }
  return false;
}

namespace detail {

// The descent of two trees at once behind forEachOverlap and forEachOverlapDeeperFirst: a pair of nodes
// whose boxes overlap is unfolded on its larger box, into the child pairs that still overlap.
template <bool kFullSat, class F>
struct OverlapDescent {
  using Node = AabbTree::Node;
  const OrientedBoxTest test;
  const Node* na;
  const Node* nb;
  const std::int32_t* items_a;
  const std::int32_t* items_b;
  const Aabb* boxes_a;
  const Aabb* boxes_b;
  F& on_pair;

  OverlapDescent(const AabbTree& a, const AabbTree& b, const Pose& b_in_a, double margin, F& f)
      : test(b_in_a, margin, treePairScale(a.bounds(), b.bounds(), b_in_a)),
        na(a.nodes().data()),
        nb(b.nodes().data()),
        items_a(a.items().data()),
        items_b(b.items().data()),
        boxes_a(a.slotBoxes().data()),
        boxes_b(b.slotBoxes().data()),
        on_pair(f) {}

  // Two leaves: their item pairs whose boxes overlap, to on_pair; true when it stops.
  bool leaves(const Node& x, const Node& y) const {
    if (x.count == 1 && y.count == 1) return callbackStops(on_pair, items_a[x.first], items_b[y.first]);  // (tested)
    for (std::int32_t sa = x.first; sa < x.first + x.count; ++sa)
      for (std::int32_t sb = y.first; sb < y.first + y.count; ++sb)
        if (!test.template separated<kFullSat>(boxes_a[sa], boxes_b[sb]) &&
            callbackStops(on_pair, items_a[sa], items_b[sb]))
          return true;
    return false;
  }

  // How much A's box (centre, half widths) and B's placed box overlap, as a share of the larger one's
  // volume (both as A's axes see them; 0 for flat boxes, which only changes an order).
  static double overlapShare(const double ca[3], const double ha[3], const OrientedBoxTest::PlacedB& b) noexcept {
    double common = 1.0, va = 1.0, vb = 1.0;
    for (int i = 0; i < 3; ++i) {
      const double lo = std::max(ca[i] - ha[i], b.center[i] - b.reach[i]);
      const double hi = std::min(ca[i] + ha[i], b.center[i] + b.reach[i]);
      common *= std::max(hi - lo, 0.0);
      va *= 2.0 * ha[i];
      vb *= 2.0 * b.reach[i];
    }
    const double larger = std::max(va, vb);
    return larger > 0.0 ? common / larger : 0.0;
  }

  // The pair (ia, ib), not two leaves, unfolded: the child pairs whose boxes overlap, in `kids`, in the
  // order to visit them (the left child's first; kDeeper: of two, the one overlapping by the larger share
  // first). Returns how many.
  template <bool kDeeper>
  int unfold(std::int32_t ia, std::int32_t ib, std::int32_t kids[2][2]) const {
    const Node& x = na[ia];
    const Node& y = nb[ib];
    int n = 0;
    double share[2];
    if (!x.isLeaf() && (y.isLeaf() || boxSize(x.box) >= boxSize(y.box))) {
      const OrientedBoxTest::PlacedB placed = test.place(y.box);  // (placed once for both children)
      double cc[2][3], ch[2][3];
      for (std::int32_t c = x.first; c <= x.first + 1; ++c) {
        OrientedBoxTest::centerHalf(na[c].box, cc[n], ch[n]);
        if (test.template separated<kFullSat>(cc[n], ch[n], placed)) continue;
        kids[n][0] = c;
        kids[n][1] = ib;
        ++n;
      }
      if (kDeeper && n == 2)
        share[0] = overlapShare(cc[0], ch[0], placed), share[1] = overlapShare(cc[1], ch[1], placed);
    } else {
      double ca[3], ha[3];
      OrientedBoxTest::centerHalf(x.box, ca, ha);
      OrientedBoxTest::PlacedB placed[2];
      for (std::int32_t c = y.first; c <= y.first + 1; ++c) {
        placed[n] = test.place(nb[c].box);
        if (test.template separated<kFullSat>(ca, ha, placed[n])) continue;
        kids[n][0] = ia;
        kids[n][1] = c;
        ++n;
      }
      if (kDeeper && n == 2) share[0] = overlapShare(ca, ha, placed[0]), share[1] = overlapShare(ca, ha, placed[1]);
    }
    if (kDeeper && n == 2 && share[1] > share[0]) {
      std::swap(kids[0][0], kids[1][0]);
      std::swap(kids[0][1], kids[1][1]);
    }
    return n;
  }

  // Every pair below the roots, depth first in unfold's order (kDeeper for the first kOrdered unfoldings
  // that find two child pairs: past them, a search that has not stopped is probably one that visits
  // every pair, which the ordering only slows); true when on_pair stops.
  template <bool kDeeper>
  bool descend() const {
    if (test.template separated<kFullSat>(na[0].box, nb[0].box)) return false;
    std::int32_t stack[2 * AabbTree::kMaxDepth + 1][2];  // (pairs whose boxes overlap)
    stack[0][0] = 0;
    stack[0][1] = 0;
    int top = 1, ordered = 0;
    while (top > 0) {
      --top;
      const std::int32_t ia = stack[top][0], ib = stack[top][1];
      if (na[ia].isLeaf() && nb[ib].isLeaf()) {
        if (leaves(na[ia], nb[ib])) return true;
        continue;
      }
      std::int32_t kids[2][2];
      const int n = kDeeper && ordered < kOrdered ? unfold<true>(ia, ib, kids) : unfold<false>(ia, ib, kids);
      ordered += n == 2;
      for (int k = n - 1; k >= 0; --k) {  // (the first is pushed last: visited first)
        stack[top][0] = kids[k][0];
        stack[top][1] = kids[k][1];
        ++top;
      }
    }
    return false;
  }
  static constexpr int kOrdered = 64;
};

}  // namespace detail

/// Calls on_pair(item_a, item_b) for every item of tree a and item of tree b whose boxes overlap as
/// oriented boxes (b's frame placed in a's by b_in_a), within `margin` metres and rounding; a pair may
/// also be reported when its boxes are apart only along an axis the test does not try (the 9 edge axes
/// unless kFullSat). Descends both trees at once, unfolding the larger box. on_pair may return bool:
/// true stops the descent; the function then returns true.
template <bool kFullSat = false, class F>
bool forEachOverlap(const AabbTree& a, const AabbTree& b, const Pose& b_in_a, F&& on_pair, double margin = 0.0) {
  if (a.empty() || b.empty()) return false;
  return detail::OverlapDescent<kFullSat, F>(a, b, b_in_a, margin, on_pair).template descend<false>();
}

/// forEachOverlap's pairs, each once, in another order: where both child pairs of an unfolded pair overlap
/// (in its first 64 such unfoldings), the one that overlaps by the larger share of its larger box goes
/// first. A search that stops at the first pair it wants (two meshes that touch) meets it sooner: on random
/// touching poses of Panda links, after half as many triangle pairs.
template <bool kFullSat = false, class F>
bool forEachOverlapDeeperFirst(const AabbTree& a, const AabbTree& b, const Pose& b_in_a, F&& on_pair,
                               double margin = 0.0) {
  if (a.empty() || b.empty()) return false;
  return detail::OverlapDescent<kFullSat, F>(a, b, b_in_a, margin, on_pair).template descend<true>();
}

/// forEachPairWithin with the caller's own lower bound on the distance of what two nodes hold:
/// bound(node_a, node_b, gap), asked for the pairs whose boxes' gap is within the cutoff, answers at
/// least that gap (a pair goes on while it is within the cutoff). Every item pair that neither the boxes
/// nor the bound keep beyond the final cutoff is visited.
template <class B, class F>
bool forEachPairWithinBy(const AabbTree& a, const AabbTree& b, const Pose& b_in_a, double& cutoff, B&& bound,
                         F&& on_pair) {
  using Node = AabbTree::Node;
  if (a.empty() || b.empty()) return false;
  const detail::OrientedBoxTest test(b_in_a, 0.0, detail::treePairScale(a.bounds(), b.bounds(), b_in_a));
  const std::vector<Node>& na = a.nodes();
  const std::vector<Node>& nb = b.nodes();
  const auto gap = [&](std::int32_t ia, std::int32_t ib) {
    const double g = test.gap(na[ia].box, nb[ib].box);
    return g <= cutoff ? bound(ia, ib, g) : g;
  };
  struct Entry {
    std::int32_t a, b;
    double gap;
  };
  Entry stack[2 * AabbTree::kMaxDepth + 1];
  int top = 0;
  stack[top++] = {0, 0, gap(0, 0)};
  while (top > 0) {
    const Entry e = stack[--top];
    if (!(e.gap <= cutoff)) continue;
    const Node& x = na[e.a];
    const Node& y = nb[e.b];
    if (x.isLeaf() && y.isLeaf()) {
      for (std::int32_t sa = x.first; sa < x.first + x.count; ++sa)
        for (std::int32_t sb = y.first; sb < y.first + y.count; ++sb)
          if ((x.count * y.count == 1 || test.gap(a.slotBoxes()[sa], b.slotBoxes()[sb]) <= cutoff) &&
              detail::callbackStops(on_pair, a.items()[sa], b.items()[sb]))
            return true;
      continue;
    }
    const bool unfold_a = !x.isLeaf() && (y.isLeaf() || detail::boxSize(x.box) >= detail::boxSize(y.box));
    Entry c0, c1;
    if (unfold_a) {
      c0 = {x.first, e.b, gap(x.first, e.b)};
      c1 = {x.first + 1, e.b, gap(x.first + 1, e.b)};
    } else {
      c0 = {e.a, y.first, gap(e.a, y.first)};
      c1 = {e.a, y.first + 1, gap(e.a, y.first + 1)};
    }
    if (c0.gap > c1.gap) std::swap(c0, c1);
    stack[top++] = c1;  // the nearer pair on top
    stack[top++] = c0;
  }
  return false;
}

/// Calls on_pair(item_a, item_b) for pairs of items whose oriented boxes may be within `cutoff` metres
/// (the largest gap along the 6 face normals, a lower bound on the box distance, is ≤ cutoff), nearer
/// pairs of subtrees first. on_pair may lower cutoff (read again before each pair of subtrees) and may
/// return true to stop. Every item pair whose boxes are within the final cutoff is visited.
template <class F>
bool forEachPairWithin(const AabbTree& a, const AabbTree& b, const Pose& b_in_a, double& cutoff, F&& on_pair) {
  return forEachPairWithinBy(
      a, b, b_in_a, cutoff, [](std::int32_t, std::int32_t, double gap) { return gap; }, on_pair);
}

}  // namespace clearway
