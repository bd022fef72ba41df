#pragma once
// The module's parts, one per topic; module.cpp calls each once.
#include <pybind11/pybind11.h>

namespace clearway::python {

/// Shapes, distance, intersect, penetration, raycast, shapecast (narrowphase.cpp).
void bindNarrowphase(pybind11::module_& m);
/// Scene: load, is_free, check, clearance, check_motions (scene.cpp).
void bindScene(pybind11::module_& m);
/// load_robot, Robot, audit, AuditResult (robot.cpp).
void bindRobot(pybind11::module_& m);
/// plan, PlanResult, planners (planning.cpp; built with the OMPL plugin).
void bindPlanning(pybind11::module_& m);

}  // namespace clearway::python
