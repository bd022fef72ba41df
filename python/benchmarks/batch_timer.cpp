// The C++ side of examples/python/batch_overhead.py: the time per state of Scene::isFree over a batch of
// states, in one context, as a C++ caller would loop (Clearway has no batch API of its own), so that the
// Python batch call Scene.check can be measured against it on the same states.
//
//   clearway_batch_timer SCENE STATES REPEATS
// STATES: one state per line (numbers separated by spaces). Prints "states N free F best_ns_per_state T".
#include <clearway/scene/scene.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 4) {
    std::cerr << "usage: clearway_batch_timer SCENE STATES REPEATS\n";
    return 2;
  }
  try {
    const auto scene = clearway::Scene::load(argv[1]);
    const int dof = scene->dimension();
    std::ifstream in(argv[2]);
    std::vector<double> states;
    for (std::string line; std::getline(in, line);) {
      std::istringstream row(line);
      double x;
      int count = 0;
      while (row >> x) states.push_back(x), ++count;
      if (count != 0 && count != dof) {
        std::cerr << "clearway_batch_timer: a line of " << count << " values for " << dof << " joints\n";
        return 2;
      }
    }
    const std::size_t n = states.size() / dof;
    const int repeats = std::max(1, std::atoi(argv[3]));
    clearway::SceneContext ctx = scene->makeContext();
    double best = 1e300;
    long long free = 0;
    for (int r = 0; r < repeats; ++r) {
      free = 0;
      const auto t0 = std::chrono::steady_clock::now();
      for (std::size_t i = 0; i < n; ++i) free += scene->isFree(states.data() + i * dof, ctx);
      const auto t1 = std::chrono::steady_clock::now();
      best = std::min(best, std::chrono::duration<double, std::nano>(t1 - t0).count() / static_cast<double>(n));
    }
    std::printf("states %zu free %lld best_ns_per_state %.1f\n", n, free, best);
  } catch (const std::exception& e) {
    std::cerr << "clearway_batch_timer: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
