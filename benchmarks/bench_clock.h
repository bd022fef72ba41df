#pragma once
// The clock of every benchmark here: this thread's CPU time, so that other processes on a shared machine
// shift the numbers less than wall time would.
#include <ctime>

namespace clearway::bench {

/// Seconds of CPU time this thread has used.
inline double threadSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

}  // namespace clearway::bench
