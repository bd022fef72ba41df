#pragma once
// A persistent ordered map: the AVL tree of persistent_avl.h without summaries. Every edit returns a new
// map sharing all untouched nodes with the old one, which stays valid and unchanged.
#include <clearway/detail/persistent_avl.h>

#include <functional>
#include <utility>

namespace clearway::detail {

/// A persistent map from K (ordered by Less) to V; edits O(log n), old versions unchanged. Const
/// operations are thread-safe, also while other threads make new versions from this one.
template <class K, class V, class Less = std::less<K>>
class PersistentMap {
 public:
  /// The empty map.
  PersistentMap() = default;

  /// This map with (key, value) added; throws std::invalid_argument when the key is present.
  PersistentMap inserted(K key, V value) const { return PersistentMap(tree_.inserted(std::move(key), std::move(value))); }
  /// This map with key mapped to value, whether or not the key was present.
  PersistentMap assigned(K key, V value) const { return PersistentMap(tree_.assigned(std::move(key), std::move(value))); }
  /// This map without `key`; *found (when given) says whether it was present.
  PersistentMap erased(const K& key, bool* found = nullptr) const { return PersistentMap(tree_.erased(key, found)); }

  /// The value of `key`, or null when absent; valid as long as a version holding it lives.
  const V* find(const K& key) const noexcept { return tree_.find(key); }
  int size() const noexcept { return tree_.size(); }
  bool empty() const noexcept { return tree_.empty(); }
  /// The AVL tree's height (nodes on the longest root-to-leaf path).
  int height() const noexcept { return tree_.height(); }

  /// Calls f(key, value) for every entry in increasing key order.
  template <class F>
  void forEach(F&& f) const {
    tree_.forEach(f);
  }

 private:
  using Tree = PersistentAvl<K, V, NoSummary, Less>;
  explicit PersistentMap(Tree tree) : tree_(std::move(tree)) {}
  Tree tree_;
};

}  // namespace clearway::detail
