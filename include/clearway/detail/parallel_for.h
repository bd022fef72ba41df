#pragma once
// Work of a load split over threads (a robot's link geometries, its pair tables): each index is done whole
// by one thread, so the results are a plain loop's whatever the order the threads finish in, and so is the
// exception that comes out.
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace clearway::detail {

/// At most this many threads share a load's work.
constexpr unsigned kMaxLoadThreads = 16;

/// The threads `wanted` asks for: itself when positive, else as many as the machine runs at once
/// (std::thread::hardware_concurrency; 1 when it does not say); never more than kMaxLoadThreads.
inline unsigned loadThreads(int wanted) noexcept {
  const unsigned n = wanted > 0 ? static_cast<unsigned>(wanted) : std::thread::hardware_concurrency();
  return std::clamp(n, 1u, kMaxLoadThreads);
}

/// Calls fn(i) for every i < n on up to `threads` threads, the calling one among them (none started for
/// one thread or one index). Indices are taken in increasing order, and a thread takes no more once it sees
/// that one threw; when every thread has stopped, the exception of the least index that threw is rethrown:
/// every index below it was taken before it, so it is the exception the plain loop would have thrown.
template <class Fn>
void parallelFor(std::size_t n, unsigned threads, Fn&& fn) {
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::mutex error_mutex;
  std::exception_ptr error;
  std::size_t error_at = n;
  const auto work = [&] {
    while (!failed.load(std::memory_order_relaxed)) {
      const std::size_t i = next.fetch_add(1);
      if (i >= n) return;
      try {
        fn(i);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (i < error_at) error = std::current_exception(), error_at = i;
        failed = true;
      }
    }
  };
  std::vector<std::thread> pool;
  const std::size_t helpers = std::max<std::size_t>(std::min<std::size_t>(threads, n), 1) - 1;
  try {
    pool.reserve(helpers);
    for (std::size_t t = 0; t < helpers; ++t) pool.emplace_back(work);
  } catch (...) {  // (no more threads to be had: those started and this one do the work)
  }
  work();
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace clearway::detail
