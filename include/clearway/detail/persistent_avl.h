#pragma once
// A persistent AVL tree whose nodes carry a summary of their subtree. Based on: G. M. Adelson-Velsky and
// E. M. Landis, "An algorithm for the organization of information" (1962), with the deletion and the
// height bound of D. E. Knuth, TAOCP vol. 3, §6.2.3 (an AVL tree of n nodes has height below
// 1.4405·log₂(n + 2) − 0.3277); persistence by path copying, J. R. Driscoll, N. Sarnak, D. D. Sleator and
// R. E. Tarjan, "Making Data Structures Persistent" (JCSS 1989).
//
// Nodes are immutable and shared between versions through std::shared_ptr<const Node>: an edit copies
// the nodes on the path from the root to the key (each rebalancing step makes at most three new nodes)
// and shares every other subtree with the version it started from, which stays as it was. Keys and
// values of the copied nodes are copied, so both should be cheap to copy.
//
// A summary is computed once, when its node is made, from the node's value and its children's summaries
// (Summarize::of(value, left, right), a child's summary pointer null when the child is absent).
#include <algorithm>
#include <climits>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

namespace clearway::detail {

/// The greatest height (nodes on the longest root-to-leaf path) of an AVL tree of at most n nodes. The
/// fewest nodes of height h are N(h) = N(h − 1) + N(h − 2) + 1, with N(0) = 0 and N(1) = 1.
constexpr int avlMaxHeight(std::uint64_t n) noexcept {
  if (n == 0) return 0;
  std::uint64_t fewer = 0, fewest = 1;  // N(h − 1), N(h)
  int h = 1;
  while (fewer + fewest + 1 <= n) {
    const std::uint64_t next = fewer + fewest + 1;
    fewer = fewest;
    fewest = next;
    ++h;
  }
  return h;
}

/// The summary policy of a tree without summaries.
struct NoSummary {
  struct Summary {};
  template <class V>
  static Summary of(const V&, const Summary*, const Summary*) noexcept {
    return {};
  }
};

/// A persistent AVL tree of (key, value) pairs with distinct keys, ordered by Less (a strict weak order),
/// each node holding the Summarize::Summary of its subtree. Every edit returns a new tree in O(log n)
/// time and new nodes; the tree it was made from is unchanged. Const operations are thread-safe, also
/// while other threads make new versions from this one.
template <class K, class V, class Summarize = NoSummary, class Less = std::less<K>>
class PersistentAvl {
 public:
  using Summary = typename Summarize::Summary;
  struct Node;
  using NodePtr = std::shared_ptr<const Node>;

  /// A node: immutable once made; its summary and height are those of its subtree.
  struct Node {
    Node(K k, V v, NodePtr l, NodePtr r)
        : key(std::move(k)),
          value(std::move(v)),
          summary(Summarize::of(value, l ? &l->summary : nullptr, r ? &r->summary : nullptr)),
          left(std::move(l)),
          right(std::move(r)),
          height(1 + std::max(heightOf(left), heightOf(right))) {}
    K key;
    V value;
    Summary summary;
    NodePtr left, right;
    int height;  ///< nodes on the longest path down from this one (1 for a leaf)
  };

  /// The most items a tree holds (size() is an int).
  static constexpr int kMaxSize = INT_MAX;
  /// The greatest height of a tree of at most kMaxSize items.
  static constexpr int kMaxHeight = avlMaxHeight(kMaxSize);

  /// The empty tree.
  PersistentAvl() = default;

  /// The tree of `items`, which must be in strictly increasing key order (else std::invalid_argument),
  /// built balanced in O(n).
  static PersistentAvl fromSorted(std::vector<std::pair<K, V>> items) {
    if (items.size() > static_cast<std::size_t>(kMaxSize)) throw std::length_error("PersistentAvl: too many items");
    for (std::size_t i = 1; i < items.size(); ++i)
      if (!Less{}(items[i - 1].first, items[i].first))
        throw std::invalid_argument("PersistentAvl::fromSorted: keys not strictly increasing");
    PersistentAvl t;
    t.root_ = buildSorted(items, 0, items.size());
    t.size_ = static_cast<int>(items.size());
    return t;
  }

  /// This tree with (key, value) added; throws std::invalid_argument when the key is present.
  PersistentAvl inserted(K key, V value) const { return put(std::move(key), std::move(value), false); }
  /// This tree with key mapped to value, whether or not the key was present.
  PersistentAvl assigned(K key, V value) const { return put(std::move(key), std::move(value), true); }

  /// This tree without `key`; *found (when given) says whether it was present. A missing key gives a
  /// copy of this tree (the same nodes).
  PersistentAvl erased(const K& key, bool* found = nullptr) const {
    bool hit = false;
    PersistentAvl t;
    t.root_ = erase(root_, key, hit);
    t.size_ = size_ - (hit ? 1 : 0);
    if (found) *found = hit;
    return t;
  }

  /// The value of `key`, or null when absent; valid as long as a version holding its node lives.
  const V* find(const K& key) const noexcept {
    const Node* n = root_.get();
    while (n) {
      if (Less{}(key, n->key)) n = n->left.get();
      else if (Less{}(n->key, key)) n = n->right.get();
      else return &n->value;
    }
    return nullptr;
  }

  int size() const noexcept { return size_; }
  bool empty() const noexcept { return size_ == 0; }
  /// Nodes on the longest root-to-leaf path: 0 when empty, never above 1.4405·log₂(size + 2).
  int height() const noexcept { return heightOf(root_); }
  /// The root node, or null when empty.
  const Node* root() const noexcept { return root_.get(); }

  /// Calls f(key, value) for every pair in increasing key order.
  template <class F>
  void forEach(F&& f) const {
    visit(root_.get(), f);
  }

 private:
  static int heightOf(const NodePtr& n) noexcept { return n ? n->height : 0; }

  static NodePtr make(K key, V value, NodePtr l, NodePtr r) {
    return std::make_shared<Node>(std::move(key), std::move(value), std::move(l), std::move(r));
  }

  // The node (key, value, l, r) with the AVL balance restored, given subtrees that are AVL trees whose
  // heights differ by at most 2 (one insertion or deletion below).
  static NodePtr balance(const K& key, const V& value, NodePtr l, NodePtr r) {
    const int hl = heightOf(l), hr = heightOf(r);
    if (hl > hr + 1) {
      // `>=`, not `>`: after a deletion both grandchildren may be equally high, and a single rotation
      // then keeps the balance where a double one would not.
      if (heightOf(l->left) >= heightOf(l->right))
        return make(l->key, l->value, l->left, make(key, value, l->right, std::move(r)));
      const Node& lr = *l->right;
      return make(lr.key, lr.value, make(l->key, l->value, l->left, lr.left), make(key, value, lr.right, std::move(r)));
    }
    if (hr > hl + 1) {
      if (heightOf(r->right) >= heightOf(r->left))
        return make(r->key, r->value, make(key, value, std::move(l), r->left), r->right);
      const Node& rl = *r->left;
      return make(rl.key, rl.value, make(key, value, std::move(l), rl.left), make(r->key, r->value, rl.right, r->right));
    }
    return make(key, value, std::move(l), std::move(r));
  }

  PersistentAvl put(K key, V value, bool replace) const {
    bool added = false;
    PersistentAvl t;
    t.root_ = insert(root_, key, value, replace, added);
    if (added && size_ == kMaxSize) throw std::length_error("PersistentAvl: too many items");
    t.size_ = size_ + (added ? 1 : 0);
    return t;
  }

  // Nothing is allocated before the key is found or its place reached: a duplicate throws with no
  // node made.
  static NodePtr insert(const NodePtr& n, K& key, V& value, bool replace, bool& added) {
    if (!n) {
      added = true;
      return make(std::move(key), std::move(value), nullptr, nullptr);
    }
    if (Less{}(key, n->key)) return balance(n->key, n->value, insert(n->left, key, value, replace, added), n->right);
    if (Less{}(n->key, key)) return balance(n->key, n->value, n->left, insert(n->right, key, value, replace, added));
    if (!replace) throw std::invalid_argument("PersistentAvl::inserted: key already present");
    return make(std::move(key), std::move(value), n->left, n->right);
  }

  static NodePtr erase(const NodePtr& n, const K& key, bool& found) {
    if (!n) return n;
    if (Less{}(key, n->key)) {
      NodePtr l = erase(n->left, key, found);
      return found ? balance(n->key, n->value, std::move(l), n->right) : n;
    }
    if (Less{}(n->key, key)) {
      NodePtr r = erase(n->right, key, found);
      return found ? balance(n->key, n->value, n->left, std::move(r)) : n;
    }
    found = true;
    if (!n->left) return n->right;
    if (!n->right) return n->left;
    // The successor takes the node's place; it stays alive in this version while it is copied.
    const Node* successor = nullptr;
    NodePtr r = eraseMin(n->right, successor);
    return balance(successor->key, successor->value, n->left, std::move(r));
  }

  static NodePtr eraseMin(const NodePtr& n, const Node*& min) {
    if (!n->left) {
      min = n.get();
      return n->right;
    }
    return balance(n->key, n->value, eraseMin(n->left, min), n->right);
  }

  // Halves of sizes differing by at most one: heights differ by at most one at every node.
  static NodePtr buildSorted(std::vector<std::pair<K, V>>& items, std::size_t begin, std::size_t end) {
    if (begin == end) return nullptr;
    const std::size_t mid = begin + (end - begin) / 2;
    NodePtr l = buildSorted(items, begin, mid);
    NodePtr r = buildSorted(items, mid + 1, end);
    return make(std::move(items[mid].first), std::move(items[mid].second), std::move(l), std::move(r));
  }

  template <class F>
  static void visit(const Node* n, F& f) {
    if (!n) return;
    visit(n->left.get(), f);
    f(n->key, n->value);
    visit(n->right.get(), f);
  }

  NodePtr root_;
  int size_ = 0;
};

}  // namespace clearway::detail
