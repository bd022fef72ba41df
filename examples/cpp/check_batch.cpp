// Check a batch of states at once: Scene::areFree computes the kinematics of several states together in
// SIMD lanes, with the same verdict for each state as Scene::isFree; a context holds one thread's scratch.
//   check_batch SCENE.yaml [COUNT]
#include <clearway/scene/scene.h>

#include <cstdlib>
#include <iostream>
#include <memory>
#include <random>
#include <vector>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: check_batch SCENE.yaml [COUNT]\n";
    return 2;
  }
  const auto scene = clearway::Scene::load(argv[1]);
  const int n = argc > 2 ? std::atoi(argv[2]) : 10000, dof = scene->dimension();

  // Random states within the joint limits, one after another.
  std::mt19937_64 rng(1);
  std::vector<double> states(static_cast<std::size_t>(n) * dof);
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < dof; ++k)
      states[i * dof + k] = std::uniform_real_distribution<double>(scene->lower(k), scene->upper(k))(rng);

  clearway::SceneContext context = scene->makeContext();
  const auto free = std::make_unique<bool[]>(n);
  scene->areFree(states.data(), n, context, free.get());
  int count = 0;
  for (int i = 0; i < n; ++i) count += free[i];
  std::cout << count << " of " << n << " states free\n";
  return 0;
}
