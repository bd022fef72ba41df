// downstream SCENE: loads the scene, sets up OMPL with Clearway's checkers as the README shows, and checks
// the scene's start through OMPL: exit 0 when it is free, 1 when not.
#include <clearway/ompl/collision_checking.h>

#include <ompl/geometric/SimpleSetup.h>

#include <iostream>

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const auto scene = clearway::Scene::load(argv[1]);
  ompl::geometric::SimpleSetup setup(clearway::makeStateSpace(*scene));
  clearway::setupCollisionChecking(setup.getSpaceInformation(), scene);
  ompl::base::ScopedState<> start(setup.getStateSpace());
  clearway::StateMap(*scene).fromVector(scene->description().start.data(), start.get());
  const bool start_free = setup.getSpaceInformation()->isValid(start.get());
  std::cout << "start " << (start_free ? "free" : "in collision") << "\n";
  return start_free ? 0 : 1;
}
