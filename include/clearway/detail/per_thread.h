#pragma once
// Scratch that each thread keeps per owner (a scene, a checker), found by the owner's serial number and
// never by its address, which a new owner may reuse. A thread asks the same owner again and again, so
// the last one found is remembered and a repeated call costs no hash lookup (map nodes never move, so
// the pointer stays valid). An owner's scratch goes when a thread next makes scratch for a new owner
// after it is gone: a thread that serves one scene after another keeps only what live owners need.
#include <atomic>
#include <cstdint>
#include <iterator>
#include <memory>
#include <unordered_map>

namespace clearway::detail {

/// What identifies an owner of per-thread scratch: a serial never reused, and a token that expires with
/// the owner. A copy is a new owner.
class ScratchOwner {
 public:
  ScratchOwner() : serial_(next()), alive_(std::make_shared<const char>(0)) {}
  ScratchOwner(const ScratchOwner&) : ScratchOwner() {}
  ScratchOwner& operator=(const ScratchOwner&) { return *this; }  // (keeps its own identity)
  std::uint64_t serial() const noexcept { return serial_; }
  const std::shared_ptr<const char>& alive() const noexcept { return alive_; }

 private:
  static std::uint64_t next() {
    static std::atomic<std::uint64_t> counter{1};
    return counter++;
  }
  std::uint64_t serial_;
  std::shared_ptr<const char> alive_;
};

template <class T>
struct ScratchEntry {
  std::weak_ptr<const char> alive;
  T value;
};

/// This thread's scratch of type T, by owner serial.
template <class T>
std::unordered_map<std::uint64_t, ScratchEntry<T>>& threadScratch() {
  thread_local std::unordered_map<std::uint64_t, ScratchEntry<T>> scratch;
  return scratch;
}

/// This thread's T for `owner`, made by make() on the thread's first call for it.
template <class T, class Make>
T& perThread(const ScratchOwner& owner, Make&& make) {
  auto& scratch = threadScratch<T>();
  thread_local std::uint64_t last_serial = 0;
  thread_local T* last = nullptr;
  if (owner.serial() == last_serial) return *last;
  auto it = scratch.find(owner.serial());
  if (it == scratch.end()) {
    for (auto i = scratch.begin(); i != scratch.end();) i = i->second.alive.expired() ? scratch.erase(i) : std::next(i);
    it = scratch.emplace(owner.serial(), ScratchEntry<T>{owner.alive(), make()}).first;
  }
  last_serial = owner.serial();
  last = &it->second.value;
  return *last;
}

}  // namespace clearway::detail
