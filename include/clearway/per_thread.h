#pragma once
// One value per thread for each owner (a scene, a checker, a world): what a const, thread-safe object
// needs to keep scratch without asking its callers for a context.
#include <clearway/serial.h>

#include <cstddef>
#include <cstdint>
#include <iterator>
#include <memory>
#include <unordered_map>

namespace clearway {

/// Each thread's own T for the object that holds this (the owner). A thread's T is found by the owner's
/// serial number, never by its address (which a new owner may reuse); a thread asking the same owner again
/// costs no hash lookup. A thread's T for an owner that is gone is freed when that thread next makes a T for
/// a new owner. A copy is a new owner, with no T on any thread yet. Thread-safe: each thread touches only
/// its own values.
template <class T>
class PerThread {
 public:
  /// A new owner, with no T on any thread.
  PerThread() : serial_(detail::nextSerial()), alive_(std::make_shared<const char>(0)) {}
  ///@{
  /// A copy is a new owner (no T yet); an assignment keeps this one's identity and values.
  PerThread(const PerThread&) : PerThread() {}
  PerThread& operator=(const PerThread&) { return *this; }
  ///@}

  /// This thread's T, made by make() on the thread's first call (for this owner).
  template <class Make>
  T& get(Make&& make) const {
    Thread& mine = thread();
    if (serial_ == mine.last_serial) return *mine.last;
    auto it = mine.values.find(serial_);
    if (it == mine.values.end()) {
      for (auto i = mine.values.begin(); i != mine.values.end();)
        i = i->second.alive.expired() ? mine.values.erase(i) : std::next(i);
      it = mine.values.emplace(serial_, Entry{alive_, make()}).first;
    }
    mine.last_serial = serial_;
    mine.last = &it->second.value;  // (map nodes never move: valid until the entry is erased, never while used)
    return *mine.last;
  }

  /// How many T this thread holds, for owners alive or gone but not yet freed (for tests).
  static std::size_t heldByThisThread() { return thread().values.size(); }

 private:
  struct Entry {
    std::weak_ptr<const char> alive;
    T value;
  };
  struct Thread {
    std::unordered_map<std::uint64_t, Entry> values;
    std::uint64_t last_serial = 0;  // the owner asked last, and its T
    T* last = nullptr;
  };
  static Thread& thread() {
    thread_local Thread mine;
    return mine;
  }
  std::uint64_t serial_;
  std::shared_ptr<const char> alive_;  // expires with the owner
};

}  // namespace clearway
