// parallelFor (detail/parallel_for.h): every index once, on any number of threads; the exception that comes
// out is the one a plain loop would throw (the least index's), with every index below it done.
#include <clearway/detail/parallel_for.h>

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace clearway {
namespace {

TEST(ParallelFor, EveryIndexOnceOnAnyNumberOfThreads) {
  for (const unsigned threads : {1u, 2u, 4u, 16u}) {
    for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{3}, std::size_t{1000}}) {
      std::vector<std::atomic<int>> calls(n);
      std::atomic<int> others{0};  // calls on a thread other than this one
      const std::thread::id me = std::this_thread::get_id();
      detail::parallelFor(n, threads, [&](std::size_t i) {
        ++calls[i];
        if (std::this_thread::get_id() != me) ++others;
      });
      for (std::size_t i = 0; i < n; ++i)
        EXPECT_EQ(calls[i].load(), 1) << "index " << i << ", " << threads << " threads";
      if (threads == 1 || n <= 1) EXPECT_EQ(others.load(), 0) << "no thread is started for one";
    }
  }
}

// Two indices throw: the least one's exception comes out, every time, and every index below it was done.
TEST(ParallelFor, TheLeastThrowingIndexIsWhatComesOut) {
  constexpr std::size_t kN = 2000, kFirst = 300, kSecond = 310;
  for (int run = 0; run < 50; ++run) {
    std::vector<std::atomic<int>> calls(kN);
    std::string what;
    try {
      detail::parallelFor(kN, 4, [&](std::size_t i) {
        ++calls[i];
        if (i == kFirst || i == kSecond) throw std::runtime_error(std::to_string(i));
      });
    } catch (const std::runtime_error& e) {
      what = e.what();
    }
    ASSERT_EQ(what, std::to_string(kFirst)) << "run " << run;
    for (std::size_t i = 0; i < kFirst; ++i) ASSERT_EQ(calls[i].load(), 1) << "run " << run << ", index " << i;
  }
}

TEST(ParallelFor, LoadThreadsAreTheAskedOrTheMachinesAndBounded) {
  EXPECT_EQ(detail::loadThreads(1), 1u);
  EXPECT_EQ(detail::loadThreads(3), 3u);
  EXPECT_EQ(detail::loadThreads(1000), detail::kMaxLoadThreads);
  const unsigned machine = std::thread::hardware_concurrency();
  EXPECT_EQ(detail::loadThreads(0), machine == 0 ? 1u : std::min(machine, detail::kMaxLoadThreads));
  EXPECT_EQ(detail::loadThreads(-5), detail::loadThreads(0));
}

}  // namespace
}  // namespace clearway
