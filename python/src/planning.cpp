// Planning from Python: clearway.plan runs the query `clearway plan` runs (clearway/ompl/planning.h) with
// the GIL released, and returns the certified path as an (N, dof) array with the tool's statistics.
#include "bindings.h"
#include "convert.h"
#include "py_scene.h"

#include <clearway/ompl/planning.h>

#include <pybind11/stl.h>

#include <ompl/util/Console.h>

#include <cstdio>
#include <optional>
#include <string>

namespace clearway::python {

namespace {

// What Python reads of a query's result.
struct PyPlanResult {
  PlanResult result;
  std::string planner;
  std::optional<std::uint64_t> seed;
};

// None, or a whole number from 0 to 2^64 - 1 (numpy's integers too): ValueError or TypeError otherwise.
std::optional<std::uint64_t> seedOf(const py::object& seed) {
  if (seed.is_none()) return std::nullopt;
  const py::object index = py::reinterpret_steal<py::object>(PyNumber_Index(seed.ptr()));
  if (!index) {
    PyErr_Clear();
    throw py::type_error("seed must be a whole number or None, got " + std::string(py::str(py::type::of(seed))));
  }
  const unsigned long long value = PyLong_AsUnsignedLongLong(index.ptr());
  if (PyErr_Occurred()) {
    PyErr_Clear();
    throw py::value_error("seed must be a whole number from 0 to 2^64 - 1, got " + std::string(py::str(index)));
  }
  return value;
}

// A start or goal from None (the scene file's) or a (dof,) array.
std::vector<double> endOf(const py::object& q, const Scene& scene, const char* name) {
  if (q.is_none()) return {};
  const DoubleArray a = DoubleArray::ensure(q);
  if (!a) throw py::value_error(std::string(name) + " must be an array of numbers");
  requireVector(a, name, scene.dimension());
  return std::vector<double>(a.data(), a.data() + a.size());
}

std::string repr(const PyPlanResult& p) {
  const PlanResult& r = p.result;
  char text[512];
  if (r.stateCount() == 0)
    std::snprintf(text, sizeof text, "<PlanResult %s: %s>", toString(r.status), r.message.c_str());
  else
    std::snprintf(text, sizeof text,
                  "<PlanResult %s: %zu states, length %.4f; %s solved in %.6f s, simplified in %.6f s; %llu state "
                  "checks, %llu motion checks>",
                  toString(r.status), r.stateCount(), r.length, p.planner.c_str(), r.solve_seconds, r.simplify_seconds,
                  static_cast<unsigned long long>(r.state_checks), static_cast<unsigned long long>(r.motion_checks));
  return text;
}

}  // namespace

void bindPlanning(py::module_& m) {
  // OMPL's informational lines ("RRTConnect: Starting planning with ...") would fill a notebook; warnings
  // and errors still show, as with the tool.
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);

  m.attr("planners") = py::cast(plannerNames());

  py::class_<PyPlanResult>(m, "PlanResult",
                           "What clearway.plan returns: the certified path and the statistics `clearway plan` prints.")
      .def_property_readonly("solved", [](const PyPlanResult& p) { return p.result.solved(); },
                             "True when path is a certified path from start to goal (every segment certified free).")
      .def_property_readonly("status", [](const PyPlanResult& p) { return std::string(toString(p.result.status)); },
                             "How the query ended: 'solved', 'no path', 'not certified', 'start colliding', 'goal "
                             "colliding', 'start stuck' or 'goal stuck'.")
      .def_property_readonly("message", [](const PyPlanResult& p) { return p.result.message; },
                             "Why the query is not solved, naming what collides; '' when solved.")
      .def_property_readonly("path", [](const PyPlanResult& p) {
        const PlanResult& r = p.result;
        py::array_t<double> out({static_cast<py::ssize_t>(r.stateCount()), static_cast<py::ssize_t>(r.dimension)});
        std::copy(r.path.begin(), r.path.end(), out.mutable_data());
        return out;
      }, "(N, dof) float64 array of the path's states, start first and goal last; (0, dof) when no path was found.")
      .def_property_readonly("planner", [](const PyPlanResult& p) { return p.planner; }, "The OMPL planner's name.")
      .def_property_readonly("seed", [](const PyPlanResult& p) { return p.seed; },
                             "The seed the query was planned with, or None.")
      .def_property_readonly("ompl_status", [](const PyPlanResult& p) { return p.result.ompl_status; },
                             "OMPL's PlannerStatus as text ('Exact solution', 'Timeout', ...); '' when not planned.")
      .def_property_readonly("length", [](const PyPlanResult& p) { return p.result.length; },
                             "The path's length in OMPL's state space metric (0 without a path).")
      .def_property_readonly("solve_time", [](const PyPlanResult& p) { return p.result.solve_seconds; },
                             "Wall time of the planner's solve, in seconds.")
      .def_property_readonly("simplify_time", [](const PyPlanResult& p) { return p.result.simplify_seconds; },
                             "Wall time of the simplification, in seconds (0 with simplify=False).")
      .def_property_readonly("state_checks", [](const PyPlanResult& p) { return p.result.state_checks; },
                             "State validity checks made by the whole query.")
      .def_property_readonly("motion_checks", [](const PyPlanResult& p) { return p.result.motion_checks; },
                             "Motion checks made by the whole query.")
      .def_property_readonly("state_check_time", [](const PyPlanResult& p) { return p.result.state_check_seconds; },
                             "Seconds spent in state checks (summed over threads).")
      .def_property_readonly("motion_check_time", [](const PyPlanResult& p) { return p.result.motion_check_seconds; },
                             "Seconds spent in motion checks (summed over threads).")
      .def_property_readonly("simplify_state_checks", [](const PyPlanResult& p) { return p.result.simplify_state_checks; },
                             "The state checks the simplification made.")
      .def_property_readonly("simplify_motion_checks", [](const PyPlanResult& p) { return p.result.simplify_motion_checks; },
                             "The motion checks the simplification made.")
      .def_property_readonly("uncertified_segments", [](const PyPlanResult& p) { return p.result.uncertified_segments; },
                             "With status 'not certified': the segments i (path[i] -> path[i+1]) not certified free.")
      .def("__repr__", &repr);

  m.def(
      "plan",
      [](PyScene& scene, const std::string& planner, double time, const py::object& seed, bool simplify,
         const py::object& start, const py::object& goal) {
        PyPlanResult out;
        PlanRequest request;
        request.planner = planner;
        request.time = time;
        request.seed = seedOf(seed);
        request.simplify = simplify;
        request.start = endOf(start, *scene.scene, "start");
        request.goal = endOf(goal, *scene.scene, "goal");
        out.planner = planner;
        out.seed = request.seed;
        {
          py::gil_scoped_release release;
          // (The scene's kept checker: building one per call cost a UR5 a third of a second.)
          out.result = clearway::plan(scene.checker(MotionOptions{}), request);  // std::invalid_argument: ValueError
        }
        return out;
      },
      py::arg("scene"), py::arg("planner") = "RRTConnect", py::arg("time") = 1.0, py::arg("seed") = py::none(),
      py::arg("simplify") = true, py::kw_only(), py::arg("start") = py::none(), py::arg("goal") = py::none(),
      "Plans start -> goal on scene with an OMPL planner (clearway.planners) and Clearway's certified checks, as "
      "`clearway plan` does: the path simplified (unless simplify=False), then certified segment by segment. Returns "
      "a PlanResult (.solved, .path as (N, dof), timings, counts); an unsolved query is a PlanResult too. time: "
      "seconds the planner may take, in (0, 1e6]. seed: with a single-threaded planner, the same seed gives the same "
      "path here and from `clearway plan --seed`; None continues OMPL's sequence. start, goal: (dof,) states "
      "(default: the scene file's). The scene keeps the motion checker its first plan builds (the robot's setup, up "
      "to a third of a second), so later plans on it cost only the query. Runs with the GIL released. ValueError for "
      "an unknown planner, a bad time or seed, or an invalid start or goal.");
}

}  // namespace clearway::python
