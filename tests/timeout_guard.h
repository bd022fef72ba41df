#pragma once
// A guard for tests of input that once made Clearway hang or run away: the call runs on a thread of its
// own, and a call that has not ended in time fails the test instead of blocking the suite.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <future>
#include <memory>
#include <thread>

namespace clearway::test {

/// Runs call and rethrows what it throws. When it has not ended after `seconds`: records a failure, then
/// runs unblock (which should make the call end, e.g. by opening the other end of a FIFO) and waits as
/// long again; a call still running then ends the test process (exit status 1), since nothing else can
/// stop it.
inline void endsWithin(double seconds, const std::function<void()>& call, const std::function<void()>& unblock = {}) {
  auto done = std::make_shared<std::promise<void>>();
  std::future<void> ended = done->get_future();
  // Detached: a call that never ends must not hold the test at the thread's join.
  std::thread([call, done] {
    try {
      call();
      done->set_value();
    } catch (...) {
      done->set_exception(std::current_exception());
    }
  }).detach();
  const auto limit = std::chrono::duration<double>(seconds);
  if (ended.wait_for(limit) != std::future_status::ready) {
    ADD_FAILURE() << "the call did not end within " << seconds << " s";
    if (unblock) unblock();
    if (!unblock || ended.wait_for(limit) != std::future_status::ready) {
      std::fprintf(stderr, "endsWithin: the call still runs after %g s: ending the test process\n", 2 * seconds);
      std::fflush(stderr);
      std::_Exit(1);
    }
  }
  ended.get();
}

}  // namespace clearway::test
