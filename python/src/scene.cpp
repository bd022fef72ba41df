// Scenes from Python: load a scene file, classify states and segments in batches. Every call runs with
// the GIL released in a context of its own, made fresh: the colliding pair a check reports depends on
// what the context met before (the last colliding pair is tried first), so a fresh context makes each
// call's answers depend on its arguments alone, whichever thread calls and whatever it asked before, and
// equal to the tool's on the same rows. Several Python threads may share one scene.
#include "bindings.h"
#include "convert.h"
#include "py_scene.h"

#include <clearway/motion/motion.h>
#include <clearway/scene/scene.h>

#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <list>
#include <memory>
#include <mutex>
#include <tuple>

namespace clearway::python {

namespace {

// A scene over an edited environment, for Python.
std::shared_ptr<PyScene> edited(const PyScene& s, const Environment& environment) {
  return std::make_shared<PyScene>(s.scene->withEnvironment(std::make_shared<const Environment>(environment)));
}

// The reason a state is rejected, as `clearway check` prints it after "error ".
[[noreturn]] void invalidRow(const Scene& scene, const char* name, py::ssize_t row, const double* q) {
  std::string why;
  scene.validState(q, &why);
  throw py::value_error(std::string(name) + "[" + std::to_string(row) + "]: " + why);
}

// What a report names after "collision " in `clearway check`: (link, other link or obstacle name,
// 'octomap' or 'environment'); ('invalid state',) for a segment that leaves the bounds.
py::object pairOf(const Scene& scene, const CollisionReport& r) {
  if (r.kind == CollisionReport::Kind::None) return py::none();
  const std::string text = scene.describe(r);
  if (r.kind == CollisionReport::Kind::Invalid) return py::make_tuple(text);
  const RobotModel& model = scene.robot();
  const std::string& link = model.link(r.link).name;
  return py::make_tuple(link, text.substr(link.size() + 1));
}

MotionOptions motionOptions(const std::string& mode, double contact_distance) {
  if (!(contact_distance > 0.0) || !std::isfinite(contact_distance))
    throw py::value_error("contact_distance must be finite and > 0, got " + std::to_string(contact_distance));
  MotionOptions o;
  o.contact_distance = contact_distance;
  if (mode == "certified") {
    o.mode = MotionMode::Certified;
  } else if (mode == "cast") {
    o.mode = MotionMode::Cast;
  } else if (mode.rfind("sampled:", 0) == 0) {
    const std::string res = mode.substr(8);
    char* end = nullptr;
    o.mode = MotionMode::Sampled;
    o.resolution = std::strtod(res.c_str(), &end);
    if (res.empty() || *end != '\0' || !(o.resolution > 0.0) || !std::isfinite(o.resolution))
      throw py::value_error("sampled:RES needs a resolution > 0, got '" + res + "'");
  } else {
    throw py::value_error("unknown mode '" + mode + "' (certified, cast or sampled:RES)");
  }
  return o;
}

GeometryMode geometryMode(const std::string& mode) {
  if (mode == "mesh") return GeometryMode::Mesh;
  if (mode == "hull") return GeometryMode::Hull;
  throw py::value_error("unknown geometry '" + mode + "' (mesh or hull)");
}

// A batch's times: None (all 0) or `cols` finite numbers per row; only scenes that declare `moving` look at them.
std::vector<double> batchTimes(const py::object& times, py::ssize_t n, py::ssize_t cols) {
  std::vector<double> t(static_cast<std::size_t>(n * cols), 0.0);
  if (times.is_none()) return t;
  const DoubleArray a = DoubleArray::ensure(times);
  if (!a) throw py::value_error("times must be an array of numbers");
  if (cols == 1) requireVector(a, "times", n);
  else requireRows(a, "times", cols);
  if (a.shape(0) != n) throw py::value_error("times must have a row per state, got " + shapeText(a));
  for (py::ssize_t i = 0; i < n * cols; ++i) {
    t[i] = a.data()[i];
    if (!(std::abs(t[i]) <= kMaxTime))
      throw py::value_error("times[" + std::to_string(i / cols) + "] is not finite or beyond ±1e6 s, the largest a query may give");
  }
  return t;
}

py::object stateOrNone(const std::vector<double>& q) {
  if (q.empty()) return py::none();
  return py::array_t<double>(static_cast<py::ssize_t>(q.size()), q.data());
}

}  // namespace

void bindScene(py::module_& m) {
  py::class_<Effects>(m, "Effects", "What a scene checks (its `checks:` list).")
      .def_readonly("self", &Effects::self, "Robot link pairs against each other.")
      .def_readonly("environment", &Effects::environment, "Robot links against obstacles and the OctoMap.")
      .def_readonly("continuous", &Effects::continuous, "Motions are certified segment by segment.")
      .def_readonly("clearance", &Effects::clearance, "Distances are computed (Scene.clearance).")
      .def_readonly("moving", &Effects::moving, "Obstacles move with time.")
      .def("__repr__", [](const Effects& e) { return "<Effects " + e.toString() + ">"; });

  py::class_<PyScene, std::shared_ptr<PyScene>>(m, "Scene",
                                                 "A planning scene: robot, environment and declared checks. "
                                                 "Immutable; safe to share between threads.")
      .def_static("load",
                  [](const std::string& path, const std::string& geometry, const std::vector<std::string>& package_paths) {
                    SceneOptions options;
                    options.mode = geometryMode(geometry);
                    options.load.package_paths = package_paths;
                    py::gil_scoped_release release;
                    return std::make_shared<PyScene>(Scene::load(path, options));
                  },
                  py::arg("path"), py::arg("geometry") = "mesh", py::arg("package_paths") = std::vector<std::string>{},
                  "Loads a scene file (YAML) with its robot and environment; raises LoadError naming file, key and reason.")
      .def_property_readonly("name", [](const PyScene& s) { return s.scene->name(); }, "The scene file's name.")
      .def_property_readonly("dof", [](const PyScene& s) { return s.scene->dimension(); }, "The length of a state.")
      .def_property_readonly("joint_names", [](const PyScene& s) {
        std::vector<std::string> names;
        for (int v : s.scene->groupVariables()) names.push_back(s.scene->robot().variables()[v].name);
        return names;
      }, "The state's entries, in order (a planar joint's as 'name/x', ...).")
      .def_property_readonly("limits", [](const PyScene& s) {
        const int n = s.scene->dimension();
        py::array_t<double> out({static_cast<py::ssize_t>(n), py::ssize_t{2}});
        auto w = out.mutable_unchecked<2>();
        for (int i = 0; i < n; ++i) w(i, 0) = s.scene->lower(i), w(i, 1) = s.scene->upper(i);
        return out;
      }, "(dof, 2) array of each entry's lower and upper limit (+-inf when unbounded).")
      .def_property_readonly("effects", [](const PyScene& s) { return s.scene->effects(); }, "What the scene checks.")
      .def_property_readonly("motion_checkers_kept", [](PyScene& s) { return s.kept(); },
                             "How many motion checkers (one per mode, resolution and contact distance asked) the "
                             "scene keeps: the 8 most recently used.")
      .def_property_readonly("warnings", [](const PyScene& s) {
        std::vector<std::string> all = s.scene->description().warnings;
        const std::vector<std::string>& robot = s.scene->robot().loadWarnings();
        all.insert(all.end(), robot.begin(), robot.end());
        return all;
      }, "What loading the scene file and the robot found worth telling (clearway check prints them), as "
         "'FILE: ELEMENT: REASON'.")
      .def_property_readonly("link_names", [](const PyScene& s) {
        std::vector<std::string> names;
        for (const Link& l : s.scene->robot().links()) names.push_back(l.name);
        return names;
      }, "Every link of the robot, in the robot's order.")
      .def_property_readonly("start", [](const PyScene& s) { return stateOrNone(s.scene->description().start); },
                             "The scene file's start state, or None.")
      .def_property_readonly("goal", [](const PyScene& s) { return stateOrNone(s.scene->description().goal); },
                             "The scene file's goal state, or None.")
      .def("is_free",
           [](const PyScene& s, const DoubleArray& q, double t) {
             requireVector(q, "q", s.scene->dimension());
             if (!std::isfinite(t)) throw py::value_error("t is not finite");
             CollisionReport r;
             bool free;
             {
               py::gil_scoped_release release;
               SceneContext ctx = s.scene->makeContext();
               free = s.scene->isFree(q.data(), ctx, &r, t);
             }
             if (r.kind == CollisionReport::Kind::Invalid) invalidRow(*s.scene, "q", 0, q.data());
             return free;
           },
           py::arg("q"), py::arg("t") = 0.0,
           "True when the state is free of every declared collision (moving obstacles where they are at time t); "
           "ValueError for a non-finite or out-of-bounds state.")
      .def("check",
           [](const PyScene& s, const DoubleArray& Q, bool report, const py::object& times) -> py::object {
             const Scene& scene = *s.scene;
             requireRows(Q, "Q", scene.dimension());
             const py::ssize_t n = Q.shape(0), dof = scene.dimension();
             const std::vector<double> t = batchTimes(times, n, 1);
             py::array_t<bool> free(n);
             std::vector<CollisionReport> reports(report ? static_cast<std::size_t>(n) : 0);
             py::ssize_t bad = -1;
             {
               const double* q = Q.data();
               bool* out = free.mutable_data();
               py::gil_scoped_release release;
               SceneContext ctx = scene.makeContext();
               // Verdicts alone, at one time: the batch path (Scene::areFree, kinematics in SIMD lanes), once
               // every row is known valid so that the first invalid one is still the one named.
               const bool one_time = std::all_of(t.begin(), t.end(), [&](double x) { return x == t[0]; });
               if (!report && one_time) {
                 for (py::ssize_t i = 0; i < n && bad < 0; ++i)
                   if (!scene.validState(q + i * dof)) bad = i;
                 constexpr py::ssize_t kSlice = 1 << 20;  // areFree counts in int
                 for (py::ssize_t first = 0; bad < 0 && first < n; first += kSlice)
                   scene.areFree(q + first * dof, static_cast<int>(std::min(kSlice, n - first)), ctx, out + first,
                                 n > 0 ? t[0] : 0.0);
               } else {
                 CollisionReport r;
                 for (py::ssize_t i = 0; i < n; ++i) {
                   out[i] = scene.isFree(q + i * dof, ctx, &r, t[i]);
                   if (r.kind == CollisionReport::Kind::Invalid) { bad = i; break; }
                   if (report) reports[i] = r;
                 }
               }
             }
             if (bad >= 0) invalidRow(scene, "Q", bad, Q.data() + bad * dof);
             if (!report) return std::move(free);
             py::list pairs;
             for (const CollisionReport& r : reports) pairs.append(pairOf(scene, r));
             return py::make_tuple(free, pairs);
           },
           py::arg("Q"), py::arg("report") = false, py::arg("times") = py::none(),
           "Q: (N, dof) states -> (N,) bool, True where free; with report=True also a list giving, per row, None or "
           "the colliding pair (link, other link / obstacle / 'octomap'). times: (N,) seconds at which each state "
           "sees the moving obstacles (default 0). ValueError naming the first invalid row.")
      .def("clearance",
           [](const PyScene& s, const DoubleArray& Q, const py::object& times) {
             const Scene& scene = *s.scene;
             if (!scene.effects().clearance)
               throw py::value_error("scene " + scene.name() + " does not declare clearance (checks: " +
                                     scene.effects().toString() + ")");
             requireRows(Q, "Q", scene.dimension());
             const py::ssize_t n = Q.shape(0), dof = scene.dimension();
             const std::vector<double> t = batchTimes(times, n, 1);
             py::array_t<double> out(n);
             py::ssize_t bad = -1;
             {
               const double* q = Q.data();
               double* c = out.mutable_data();
               py::gil_scoped_release release;
               SceneContext ctx = scene.makeContext();
               for (py::ssize_t i = 0; i < n; ++i) {
                 if (!scene.validState(q + i * dof)) { bad = i; break; }
                 c[i] = scene.clearance(q + i * dof, ctx, nullptr, t[i]);
               }
             }
             if (bad >= 0) invalidRow(scene, "Q", bad, Q.data() + bad * dof);
             return out;
           },
           py::arg("Q"), py::arg("times") = py::none(),
           "Q: (N, dof) states -> (N,) signed clearance in metres (negative: penetration depth); NaN where a query "
           "failed. times as check(). ValueError when the scene does not declare clearance or a row is invalid.")
      .def("check_motions",
           [](PyScene& s, const DoubleArray& Q0, const DoubleArray& Q1, const std::string& mode, double contact_distance,
              bool report, const py::object& times) -> py::object {
             const Scene& scene = *s.scene;
             requireRows(Q0, "Q0", scene.dimension());
             requireRows(Q1, "Q1", scene.dimension());
             if (Q0.shape(0) != Q1.shape(0))
               throw py::value_error("Q0 and Q1 must have as many rows, got " + shapeText(Q0) + " and " + shapeText(Q1));
             const std::shared_ptr<const MotionChecker> held = s.checker(motionOptions(mode, contact_distance));
             const MotionChecker& checker = *held;
             const py::ssize_t n = Q0.shape(0), dof = scene.dimension();
             const std::vector<double> t = batchTimes(times, n, 2);
             py::array_t<bool> free(n);
             py::array_t<double> last_valid(n);
             std::vector<CollisionReport> reports(report ? static_cast<std::size_t>(n) : 0);
             py::ssize_t bad = -1;
             bool bad_end = false;  // Q0 (false) or Q1 (true)
             {
               const double *q0 = Q0.data(), *q1 = Q1.data();
               bool* f = free.mutable_data();
               double* lv = last_valid.mutable_data();
               py::gil_scoped_release release;
               MotionContext ctx = checker.makeContext();
               for (py::ssize_t i = 0; i < n; ++i) {
                 const double *a = q0 + i * dof, *b = q1 + i * dof;
                 // As `clearway motion`: an invalid end is an error, not a colliding segment.
                 if (!scene.validState(a) || !scene.validState(b)) {
                   bad = i;
                   bad_end = scene.validState(a);
                   break;
                 }
                 const MotionResult r = checker.check(a, t[2 * i], b, t[2 * i + 1], ctx);
                 f[i] = r.free;
                 lv[i] = r.free ? 1.0 : r.last_valid;
                 if (report) reports[i] = r.report;
               }
             }
             if (bad >= 0) invalidRow(scene, bad_end ? "Q1" : "Q0", bad, (bad_end ? Q1 : Q0).data() + bad * dof);
             if (!report) return py::make_tuple(free, last_valid);
             py::list pairs;
             for (const CollisionReport& r : reports) pairs.append(pairOf(scene, r));
             return py::make_tuple(free, last_valid, pairs);
           },
           py::arg("Q0"), py::arg("Q1"), py::arg("mode") = "certified", py::arg("contact_distance") = 1e-3,
           py::arg("report") = false, py::arg("times") = py::none(),
           "Checks the straight segments Q0[i] -> Q1[i] -> (free, last_valid): (N,) bool and (N,) the last fraction "
           "known free (1 where free). mode: 'certified' (never steps over an obstacle), 'cast' or 'sampled:RES' (may "
           "tunnel). With report=True also the colliding pair per row, as check(). times: (N, 2) seconds at each end "
           "(moving obstacles move on meanwhile; default 0 and 0). ValueError naming an invalid end.")
      .def_property_readonly("obstacle_names", [](const PyScene& s) {
        std::vector<std::string> names;
        for (const auto& o : s.scene->environment().obstacles()) names.push_back(o->name);
        return names;
      }, "The environment's obstacles by name (edits address them so).")
      .def("with_obstacle",
           [](const PyScene& s, const std::string& name, const PyShape& shape, const py::object& pose) {
             Obstacle o;
             o.name = name;
             o.shape = shape.shape;
             o.pose = toPose(pose, "pose");
             py::gil_scoped_release release;
             return edited(s, s.scene->environment().withObstacle(std::move(o)));
           },
           py::arg("name"), py::arg("shape"), py::arg("pose") = py::none(),
           "This scene with one obstacle more (a clearway.Box, Sphere, Cylinder, ... placed by pose), as a new Scene; "
           "this one is unchanged (the two share all else: O(log n)). ValueError for a name in use or a bad pose.")
      .def("with_obstacle_moved",
           [](const PyScene& s, const std::string& name, const py::object& pose) {
             const Pose p = toPose(pose, "pose");
             py::gil_scoped_release release;
             return edited(s, s.scene->environment().withObstacleMoved(name, p));
           },
           py::arg("name"), py::arg("pose"), "This scene with the named obstacle placed at pose, as a new Scene.")
      .def("without_obstacle",
           [](const PyScene& s, const std::string& name) {
             py::gil_scoped_release release;
             return edited(s, s.scene->environment().withoutObstacle(name));
           },
           py::arg("name"), "This scene without the named obstacle, as a new Scene. ValueError when none has the name.")
      .def("with_points",
           [](const PyScene& s, const DoubleArray& points, double resolution) {
             requireRows(points, "points", 3);
             std::vector<Vec3> list(static_cast<std::size_t>(points.shape(0)));
             for (std::size_t i = 0; i < list.size(); ++i)
               list[i] = Vec3(points.at(i, 0), points.at(i, 1), points.at(i, 2));
             py::gil_scoped_release release;
             return edited(s, s.scene->environment().withPoints(list, resolution));
           },
           py::arg("points"), py::arg("resolution") = 0.0,
           "This scene with the voxel holding each of the (N, 3) points occupied (edge `resolution` on OctoMap's grid; "
           "0: the map's), as a new Scene. Free space is not cleared. Raises ValueError for a point not finite or whose "
           "voxel reaches beyond 1e6 m, or a resolution below 1e-9 m.")
      .def("with_attached",
           [](const PyScene& s, const std::string& name, const std::string& link, const PyShape& shape,
              const py::object& pose, const std::vector<std::string>& touch_links) {
             SceneDescription::AttachedSpec a;
             a.link = link;
             a.body.name = name;
             a.body.shape = shape.shape;
             a.body.pose = toPose(pose, "pose");
             a.touch_links = touch_links;
             py::gil_scoped_release release;
             return std::make_shared<PyScene>(s.scene->withAttached(a));
           },
           py::arg("name"), py::arg("link"), py::arg("shape"), py::arg("pose") = py::none(),
           py::arg("touch_links") = std::vector<std::string>{},
           "This scene with a body (shape, placed by pose in the link's frame) attached to `link`, which it may touch, "
           "as may its touch_links (MoveIt's); a new Scene. ValueError for an unknown link, a name in use, or a body "
           "reaching beyond 1e6 m of its link.")
      .def("without_attached",
           [](const PyScene& s, const std::string& name) {
             py::gil_scoped_release release;
             return std::make_shared<PyScene>(s.scene->withoutAttached(name));
           },
           py::arg("name"), "This scene without the named attached body, as a new Scene.")
      .def("__repr__", [](const PyScene& s) {
        return "<clearway.Scene " + s.scene->name() + ": " + std::to_string(s.scene->dimension()) + " dof, checks " +
               s.scene->effects().toString() + ">";
      });
}

}  // namespace clearway::python
