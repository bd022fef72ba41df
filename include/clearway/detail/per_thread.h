#pragma once
// Scratch that each thread keeps per owner (a scene, a checker), found by the owner's serial number and
// never by its address, which a new owner may reuse. A thread asks the same owner again and again, so
// the last one found is remembered and a repeated call costs no hash lookup (map nodes never move, so
// the pointer stays valid).
#include <cstdint>
#include <unordered_map>

namespace clearway::detail {

/// This thread's T for `serial` (serials start at 1), made by make() on the thread's first call.
template <class T, class Make>
T& perThread(std::uint64_t serial, Make&& make) {
  thread_local std::unordered_map<std::uint64_t, T> scratch;
  thread_local std::uint64_t last_serial = 0;
  thread_local T* last = nullptr;
  if (serial == last_serial) return *last;
  auto it = scratch.find(serial);
  if (it == scratch.end()) it = scratch.emplace(serial, make()).first;
  last_serial = serial;
  last = &it->second;
  return *last;
}

}  // namespace clearway::detail
