// A memo of values computed from two shared objects, each entry kept while both objects live.
#pragma once

#include <algorithm>
#include <cstddef>
#include <iterator>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <utility>

namespace clearway::detail {

/// Values remembered by key, each computed from two objects held weakly: an entry is found only while both
/// live (the memo never keeps one alive, and addresses in a key are then theirs alone). Thread-safe.
template <class Key, class Value, class Object>
class WeakMemo {
 public:
  /// The value stored for `key`, if its two objects both still live.
  std::optional<Value> find(const Key& key) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto it = entries_.find(key);
    if (it == entries_.end() || it->second.expired()) return std::nullopt;
    return it->second.value;
  }

  /// Stores `value` for `key`, computed from objects a and b (replacing an entry of the same key).
  void store(Key key, const std::shared_ptr<const Object>& a, const std::shared_ptr<const Object>& b, Value value) {
    const std::lock_guard<std::mutex> lock(mutex_);
    entries_[std::move(key)] = {a, b, std::move(value)};
    ++stored_;
    // Entries of objects gone are dropped as new ones come, in a sweep each time the memo has doubled since
    // the last: a sweep per entry made loading a robot quartic in its links (an entry per pair, each sweep
    // over every entry); this way each entry is swept a constant number of times on average.
    if (entries_.size() >= sweep_at_) {
      swept_ += static_cast<long long>(entries_.size());
      for (auto it = entries_.begin(); it != entries_.end();) it = it->second.expired() ? entries_.erase(it) : std::next(it);
      sweep_at_ = std::max<std::size_t>(kFirstSweep, 2 * entries_.size());
    }
  }

  /// Counts since the memo was made, for tests: what it shares and what keeping it costs.
  struct Stats {
    std::size_t entries = 0;  ///< entries held now (some may be of objects gone, until the next sweep)
    long long stored = 0;     ///< store() calls
    long long swept = 0;      ///< entries visited by the sweeps
  };
  /// A snapshot of the counts.
  Stats stats() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return {entries_.size(), stored_, swept_};
  }

 private:
  static constexpr std::size_t kFirstSweep = 64;
  struct Entry {
    std::weak_ptr<const Object> a, b;
    Value value;
    bool expired() const noexcept { return a.expired() || b.expired(); }
  };
  mutable std::mutex mutex_;
  std::map<Key, Entry> entries_;
  std::size_t sweep_at_ = kFirstSweep;
  long long stored_ = 0, swept_ = 0;
};

}  // namespace clearway::detail
