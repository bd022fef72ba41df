// Plan on a scene file with OMPL's SimpleSetup and Clearway's checkers: the validity checker and the
// certified motion validator, so that no segment of the path steps over an obstacle.
//   plan_scene SCENE.yaml [SECONDS]
#include <clearway/ompl/collision_checking.h>

#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>

#include <cstdlib>
#include <iostream>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: plan_scene SCENE.yaml [SECONDS]\n";
    return 2;
  }
  const auto scene = clearway::Scene::load(argv[1]);  // robot, obstacles, start and goal
  ompl::geometric::SimpleSetup setup(clearway::makeStateSpace(*scene));
  clearway::setupCollisionChecking(setup.getSpaceInformation(), scene);

  const clearway::StateMap map(*scene);  // Clearway state vectors <-> OMPL states
  ompl::base::ScopedState<> start(setup.getStateSpace()), goal(setup.getStateSpace());
  map.fromVector(scene->description().start.data(), start.get());
  map.fromVector(scene->description().goal.data(), goal.get());
  setup.setStartAndGoalStates(start, goal);
  setup.setPlanner(std::make_shared<ompl::geometric::RRTConnect>(setup.getSpaceInformation()));

  if (setup.solve(argc > 2 ? std::atof(argv[2]) : 5.0) != ompl::base::PlannerStatus::EXACT_SOLUTION) {
    std::cerr << "no path\n";
    return 1;
  }
  setup.simplifySolution();
  setup.getSolutionPath().printAsMatrix(std::cout);
  return 0;
}
