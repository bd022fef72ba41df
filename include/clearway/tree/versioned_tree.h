#pragma once
// A persistent AABB tree: obstacles and voxels are added, moved and removed between planning queries
// while other threads keep querying older versions, without locks. Each item lives in one node of a
// persistent AVL tree (detail/persistent_avl.h) whose summary is the union box of the node's subtree;
// an edit copies O(log n) nodes and shares the rest with the version it started from, which stays valid
// and unchanged.
//
// Items are ordered by the Morton (Z-order) code of their box's centre (G. M. Morton, "A computer oriented
// geodetic data base and a new technique in file sequencing", IBM 1966), ties broken by a serial number,
// so that subtrees gather nearby items and their boxes stay small. The order affects only speed: a
// query descends by the subtree boxes, whatever items they hold.
//
// Traversals allocate nothing: their stacks are arrays on the call stack. A depth-first descent that
// pushes a node's two children holds, when it pops a node of depth d (root depth 1), at most one waiting
// sibling for each depth 2 … d, so at most the height h entries after pushing (children exist only
// below depth h); h ≤ kMaxHeight for any tree of at most 2³¹ − 1 items (static_assert below).
#include <clearway/detail/persistent_avl.h>
#include <clearway/tree/aabb.h>
#include <clearway/tree/aabb_tree.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <utility>
#include <vector>

namespace clearway {

namespace detail {

/// x as 64 bits whose unsigned order is the order of the doubles (−0.0 maps as +0.0; x not NaN).
inline std::uint64_t orderedBits(double x) noexcept {
  if (x == 0.0) x = 0.0;
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  // Negative numbers: flipping every bit reverses their magnitude order and puts them below the rest,
  // which the sign bit lifts above.
  return (b >> 63) ? ~b : (b | (std::uint64_t{1} << 63));
}

/// The 21 low bits of v moved to bits 0, 3, 6, … 60.
inline std::uint64_t spreadBits3(std::uint64_t v) noexcept {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

/// The 63-bit Morton code of p: the top 21 bits of each coordinate's orderedBits, interleaved x y z
/// from the most significant bit down.
inline std::uint64_t mortonCode(const Vec3& p) noexcept {
  return spreadBits3(orderedBits(p.x()) >> 43) << 2 | spreadBits3(orderedBits(p.y()) >> 43) << 1 |
         spreadBits3(orderedBits(p.z()) >> 43);
}

}  // namespace detail

/// A persistent AABB tree of items T with boxes in one frame. Every edit returns a new version in
/// O(log n) that shares untouched nodes with this one; this version never changes. Queries are const,
/// allocate nothing and may run on any thread while other threads make new versions from this or any
/// other version (nodes are immutable; shared_ptr counts are atomic). A tree value itself is a plain
/// value: one thread replacing it while another reads it must synchronise, as for any object.
/// T must be copy-constructible: the nodes an edit copies copy their items.
template <class T>
class VersionedAabbTree {
 public:
  /// Names an item: in the version that added it and in every version derived from that one. Versions
  /// derived separately from one version may give the same key to different items. The default key
  /// names no item.
  class Key {
   public:
    Key() = default;
    /// A strict total order: the Morton order of the items' box centres at insertion, then insertion order.
    friend bool operator<(const Key& a, const Key& b) noexcept {
      return a.morton_ < b.morton_ || (a.morton_ == b.morton_ && a.serial_ < b.serial_);
    }
    /// Equal keys name the same item in versions derived from one another (default keys: none).
    friend bool operator==(const Key& a, const Key& b) noexcept {
      return a.morton_ == b.morton_ && a.serial_ == b.serial_;
    }
    /// !(a == b).
    friend bool operator!=(const Key& a, const Key& b) noexcept { return !(a == b); }

   private:
    friend class VersionedAabbTree;
    Key(std::uint64_t morton, std::uint64_t serial) noexcept : morton_(morton), serial_(serial) {}
    // No item's serial reaches 2⁶⁴ − 1.
    std::uint64_t morton_ = ~std::uint64_t{0};
    std::uint64_t serial_ = ~std::uint64_t{0};
  };

 private:
  struct Item {
    Aabb box;
    T value;
  };
  struct BoxUnion {
    using Summary = Aabb;
    static Aabb of(const Item& item, const Aabb* left, const Aabb* right) noexcept {
      Aabb box = item.box;
      if (left) box.merge(*left);
      if (right) box.merge(*right);
      return box;
    }
  };
  using Avl = detail::PersistentAvl<Key, Item, BoxUnion>;
  using Node = typename Avl::Node;

 public:
  /// The greatest height of any tree (at most 2³¹ − 1 items); traversal stacks are sized by it.
  static constexpr int kMaxHeight = Avl::kMaxHeight;
  static_assert(kMaxHeight == 44, "F(46) − 1 ≤ 2³¹ − 1 < F(47) − 1: an AVL tree of < 2³¹ nodes is at most 44 high");

  /// The empty tree.
  VersionedAabbTree() = default;

  /// The tree of `items` (box, value), built balanced in O(n log n). *keys (when given) receives the
  /// items' keys in input order. Throws std::invalid_argument for an empty or non-finite box.
  static VersionedAabbTree build(std::vector<std::pair<Aabb, T>> items, std::vector<Key>* keys = nullptr) {
    std::vector<std::pair<Key, Item>> sorted;
    sorted.reserve(items.size());
    std::vector<Key> made;
    made.reserve(items.size());
    for (std::size_t i = 0; i < items.size(); ++i) {
      checkBox(items[i].first);
      made.push_back(keyOf(items[i].first, i));
      sorted.push_back({made.back(), Item{items[i].first, std::move(items[i].second)}});
    }
    std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    VersionedAabbTree t;
    t.items_ = Avl::fromSorted(std::move(sorted));
    t.next_serial_ = made.size();
    if (keys) *keys = std::move(made);
    return t;
  }

  /// This tree with `value` added at `box`; *key (when given) receives its key. Throws
  /// std::invalid_argument for an empty or non-finite box.
  VersionedAabbTree inserted(const Aabb& box, T value, Key* key = nullptr) const {
    checkBox(box);
    const Key k = keyOf(box, next_serial_);
    VersionedAabbTree t;
    t.items_ = items_.inserted(k, Item{box, std::move(value)});
    t.next_serial_ = next_serial_ + 1;
    if (key) *key = k;
    return t;
  }

  /// This tree with every (box, value) of `items` added, as inserted() one by one would add them (the
  /// same keys, in input order, to *keys when given), in O(m log n) or, when that is more, by one
  /// rebuild in O(n + m log m) that shares no node with this version. Throws as inserted() does, adding
  /// nothing.
  VersionedAabbTree insertedAll(std::vector<std::pair<Aabb, T>> items, std::vector<Key>* keys = nullptr) const {
    const std::size_t m = items.size(), n = static_cast<std::size_t>(size());
    for (const auto& item : items) checkBox(item.first);
    std::vector<Key> made;
    made.reserve(m);
    for (std::size_t i = 0; i < m; ++i) made.push_back(keyOf(items[i].first, next_serial_ + i));
    VersionedAabbTree t;
    t.next_serial_ = next_serial_ + m;
    // An insertion copies a root-to-leaf path: about height() nodes, where a rebuild makes n + m.
    if (m * static_cast<std::size_t>(std::max(1, height())) < n + m) {
      t.items_ = items_;
      for (std::size_t i = 0; i < m; ++i) t.items_ = t.items_.inserted(made[i], Item{items[i].first, std::move(items[i].second)});
    } else {
      std::vector<std::pair<Key, Item>> added;
      added.reserve(m);
      for (std::size_t i = 0; i < m; ++i) added.push_back({made[i], Item{items[i].first, std::move(items[i].second)}});
      std::sort(added.begin(), added.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
      std::vector<std::pair<Key, Item>> all;
      all.reserve(n + m);
      auto next = added.begin();
      items_.forEach([&](const Key& k, const Item& item) {
        for (; next != added.end() && next->first < k; ++next) all.push_back(std::move(*next));
        all.push_back({k, item});
      });
      for (; next != added.end(); ++next) all.push_back(std::move(*next));
      std::vector<std::pair<Key, Item>>().swap(added);  // (a large batch's peak memory: one copy, not two)
      t.items_ = Avl::fromSorted(std::move(all));
    }
    if (keys) *keys = std::move(made);
    return t;
  }

  /// This tree without the item of `key`; *found (when given) says whether it was there. A missing key
  /// gives a copy of this tree (the same nodes).
  VersionedAabbTree erased(const Key& key, bool* found = nullptr) const {
    VersionedAabbTree t;
    t.items_ = items_.erased(key, found);
    t.next_serial_ = next_serial_;
    return t;
  }

  /// The item of `key`, or null when absent; valid as long as a version holding it lives.
  const T* find(const Key& key) const noexcept {
    const Item* item = items_.find(key);
    return item ? &item->value : nullptr;
  }

  /// The number of items in this version.
  int size() const noexcept { return items_.size(); }
  /// True when this version holds no item.
  bool empty() const noexcept { return items_.empty(); }
  /// Nodes on the longest root-to-leaf path: 0 when empty, below 1.4405·log₂(size + 2).
  int height() const noexcept { return items_.height(); }
  /// The union of all item boxes (the empty box for an empty tree).
  Aabb bounds() const noexcept { return items_.root() ? items_.root()->summary : Aabb::empty(); }

  /// Calls on_item(value, item_box) for every item whose box overlaps `box` (closed boxes: touching
  /// counts). on_item may return bool: true stops the query. Returns true when stopped that way.
  template <class F>
  bool query(const Aabb& box, F&& on_item) const;

  /// Calls on_item(value, item_box) for items whose box is within `cutoff` of `box` (box distance ≤
  /// cutoff), nearer subtrees first; on_item may lower cutoff (it is read again before each node) and may
  /// return true to stop. Every item within the final cutoff is visited.
  template <class F>
  bool forEachWithin(const Aabb& box, double& cutoff, F&& on_item) const;
  /// The same for an oriented box: `box` in its own frame, placed in the tree's frame by `box_in_tree`.
  /// A node is within reach when both its distance to the placed box's bounds and the oriented boxes'
  /// gap (detail::OrientedBoxTest::gap) are, as in AabbTree::forEachWithin.
  template <class F>
  bool forEachWithin(const Aabb& box, const Pose& box_in_tree, double& cutoff, F&& on_item) const;

  /// Calls f(value, item_box) for every item, in key order.
  template <class F>
  void forEach(F&& f) const {
    items_.forEach([&](const Key&, const Item& item) { f(item.value, item.box); });
  }

 private:
  static void checkBox(const Aabb& box) {
    if (box.isEmpty() || !box.min.allFinite() || !box.max.allFinite())
      throw std::invalid_argument("VersionedAabbTree: item box empty or not finite");
  }

  // The centre halves before adding, so that it stays finite for any finite box.
  static Key keyOf(const Aabb& box, std::uint64_t serial) noexcept {
    return Key(detail::mortonCode(0.5 * box.min + 0.5 * box.max), serial);
  }

  template <class F>
  static bool stops(F& on_item, const Item& item) {
    return detail::callbackStops<F, const T&, const Aabb&>(on_item, item.value, item.box);
  }

  // forEachWithin with the node-to-query lower bound `dist(box)`.
  template <class D, class F>
  bool forEachWithinBy(D&& dist, double& cutoff, F& on_item) const;

  Avl items_;
  std::uint64_t next_serial_ = 0;
};

template <class T>
template <class F>
bool VersionedAabbTree<T>::query(const Aabb& box, F&& on_item) const {
  const Node* stack[kMaxHeight + 1];
  int top = 0;
  if (items_.root()) stack[top++] = items_.root();
  while (top > 0) {
    const Node* n = stack[--top];
    if (!overlaps(n->summary, box)) continue;
    if (overlaps(n->value.box, box) && stops(on_item, n->value)) return true;
    if (n->right) stack[top++] = n->right.get();
    if (n->left) stack[top++] = n->left.get();
  }
  return false;
}

template <class T>
template <class F>
bool VersionedAabbTree<T>::forEachWithin(const Aabb& box, double& cutoff, F&& on_item) const {
  return forEachWithinBy([&](const Aabb& node) { return boxDistance(node, box); }, cutoff, on_item);
}

template <class T>
template <class F>
bool VersionedAabbTree<T>::forEachWithin(const Aabb& box, const Pose& box_in_tree, double& cutoff,
                                         F&& on_item) const {
  if (empty()) return false;
  const Aabb placed_bounds = transformed(box, box_in_tree);
  const detail::OrientedBoxTest test(box_in_tree, 0.0, detail::treePairScale(bounds(), box, box_in_tree));
  const detail::OrientedBoxTest::PlacedB placed = test.place(box);
  // (The gap only within the cutoff, as in AabbTree::forEachWithin.)
  return forEachWithinBy(
      [&](const Aabb& node) {
        const double d = boxDistance(node, placed_bounds);
        return d > cutoff ? d : std::max(d, test.gap(node, placed));
      },
      cutoff, on_item);
}

template <class T>
template <class D, class F>
bool VersionedAabbTree<T>::forEachWithinBy(D&& dist, double& cutoff, F& on_item) const {
  if (empty()) return false;
  struct Entry {
    const Node* node;
    double dist;
  };
  Entry stack[kMaxHeight + 1];
  int top = 0;
  stack[top++] = {items_.root(), dist(items_.root()->summary)};
  while (top > 0) {
    const Entry e = stack[--top];
    if (!(e.dist <= cutoff)) continue;
    const Node* n = e.node;
    if (dist(n->value.box) <= cutoff && stops(on_item, n->value)) return true;
    Entry l{n->left.get(), 0.0}, r{n->right.get(), 0.0};
    if (l.node) l.dist = dist(l.node->summary);
    if (r.node) r.dist = dist(r.node->summary);
    // The nearer child goes on top: it is visited first and lowers the cutoff for the other.
    if (l.node && r.node && r.dist < l.dist) std::swap(l, r);
    if (r.node) stack[top++] = r;
    if (l.node) stack[top++] = l;
  }
  return false;
}

}  // namespace clearway
