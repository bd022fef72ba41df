// Edit a World while another thread plans in it: each edit publishes a new snapshot, and every query of
// the planner sees one whole snapshot, before the edit or after it. Planning again after the edit needs
// no new space information.
//   edit_while_planning SCENE.yaml
#include <clearway/ompl/collision_checking.h>

#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>

#include <iostream>
#include <thread>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: edit_while_planning SCENE.yaml\n";
    return 2;
  }
  const auto world = clearway::World::load(argv[1]);
  const auto scene = world->current().scene;
  ompl::geometric::SimpleSetup setup(clearway::makeStateSpace(*scene));
  clearway::setupCollisionChecking(setup.getSpaceInformation(), world);
  const clearway::StateMap map(*scene);
  ompl::base::ScopedState<> start(setup.getStateSpace()), goal(setup.getStateSpace());
  map.fromVector(scene->description().start.data(), start.get());
  map.fromVector(scene->description().goal.data(), goal.get());
  setup.setStartAndGoalStates(start, goal);
  setup.setPlanner(std::make_shared<ompl::geometric::RRTConnect>(setup.getSpaceInformation()));

  // The planner runs in its own thread while this one adds an obstacle, far from the robot here.
  ompl::base::PlannerStatus first;
  std::thread planner([&] { first = setup.solve(5.0); });
  clearway::Obstacle box;
  box.name = "box";
  box.shape = clearway::Box(clearway::Vec3(0.1, 0.1, 0.1));
  box.pose = clearway::Pose::translation(clearway::Vec3(2.0, 2.0, 0.5));
  world->addObstacle(box);
  planner.join();
  std::cout << "during the edit: " << first.asString() << "\n";

  setup.clear();  // the planner's trees belong to the old world; the checkers follow the new one
  const ompl::base::PlannerStatus second = setup.solve(5.0);
  std::cout << "after it (world version " << world->version() << "): " << second.asString() << "\n";
  return second == ompl::base::PlannerStatus::EXACT_SOLUTION ? 0 : 1;
}
