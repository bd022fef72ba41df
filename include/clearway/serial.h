#pragma once
// Serial numbers that name an object for as long as the program runs: a context, a per-thread value or a
// cache entry that must know which object made it compares serials, never addresses (a new object may
// reuse a freed one's address).
#include <atomic>
#include <cstdint>

namespace clearway::detail {

/// A serial no earlier call returned (thread-safe; the first is 1, so 0 can mean "none").
inline std::uint64_t nextSerial() noexcept {
  static std::atomic<std::uint64_t> counter{1};
  return counter.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace clearway::detail
