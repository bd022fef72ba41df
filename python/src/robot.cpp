// Robots from Python: load a URDF (+ SRDF), forward kinematics, and the self-collision audit of
// `clearway audit` with its evidence and SRDF.
#include "bindings.h"
#include "convert.h"

#include <clearway/kinematics/forward_kinematics.h>
#include <clearway/load/robot_loader.h>
#include <clearway/scene/audit.h>

#include <pybind11/stl.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>
#include <memory>

namespace clearway::python {

namespace {

struct PyRobot {
  std::shared_ptr<const RobotModel> model;
};

// One audited pair, by link name.
struct AuditPair {
  std::string link_a, link_b;
  std::string reason;       // "Adjacent", "Default", "Always", "Never", or "" (must be checked)
  int samples = 0, colliding = 0;
  double p_upper = 1.0, min_clearance = 0.0;
  bool near_miss = false;
  std::string warning;
  std::string srdf_reason;  // the given SRDF's reason for disabling the pair ("" when it checks it or none was given)
};

struct AuditResult {
  std::shared_ptr<const RobotModel> model;
  std::vector<PairAudit> audit;
  std::vector<AuditPair> pairs;
  int samples = 0;
  std::uint64_t seed = 0;
  std::string srdf_text;  // the given SRDF, which to_srdf() keeps (as clearway audit --srdf-out)
};

LoadOptions loadOptions(const std::vector<std::string>& package_paths) {
  LoadOptions o;
  o.package_paths = package_paths;
  return o;
}

}  // namespace

void bindRobot(py::module_& m) {
  py::class_<PyRobot>(m, "Robot", "A robot as loaded from URDF (+ SRDF): links, joints, joint vector. Immutable.")
      .def_property_readonly("name", [](const PyRobot& r) { return r.model->name(); }, "The URDF's robot name.")
      .def_property_readonly("link_names", [](const PyRobot& r) {
        std::vector<std::string> names;
        for (const Link& l : r.model->links()) names.push_back(l.name);
        return names;
      }, "Every link, root first (the order of link_poses).")
      .def_property_readonly("joint_names", [](const PyRobot& r) {
        std::vector<std::string> names;
        for (const Joint& j : r.model->joints()) names.push_back(j.name);
        return names;
      }, "Every joint, fixed ones included, in the order of their child links.")
      .def_property_readonly("variable_names", [](const PyRobot& r) {
        std::vector<std::string> names;
        for (const JointVariable& v : r.model->variables()) names.push_back(v.name);
        return names;
      }, "The entries of the joint vector q ('joint', or 'joint/x' ... for planar and floating joints).")
      .def_property_readonly("dof", [](const PyRobot& r) { return r.model->variableCount(); }, "The length of q.")
      .def_property_readonly("limits", [](const PyRobot& r) {
        const auto& vars = r.model->variables();
        py::array_t<double> out({static_cast<py::ssize_t>(vars.size()), py::ssize_t{2}});
        auto w = out.mutable_unchecked<2>();
        for (std::size_t i = 0; i < vars.size(); ++i) w(i, 0) = vars[i].lower, w(i, 1) = vars[i].upper;
        return out;
      }, "(dof, 2) array of each entry's limits (+-inf when unbounded).")
      .def_property_readonly("disabled_pairs", [](const PyRobot& r) {
        std::vector<std::tuple<std::string, std::string, std::string>> out;
        for (const DisabledCollision& d : r.model->disabledCollisions())
          out.emplace_back(r.model->link(d.link_a).name, r.model->link(d.link_b).name, d.reason);
        return out;
      }, "The SRDF's disable_collisions pairs: (link, link, reason).")
      .def_property_readonly("warnings", [](const PyRobot& r) { return r.model->loadWarnings(); },
                             "What the loader found worth telling, as 'FILE: ELEMENT: REASON'.")
      .def("link_poses",
           [](const PyRobot& r, const DoubleArray& q) {
             const RobotModel& model = *r.model;
             const py::ssize_t nv = model.variableCount(), nl = model.linkCount();
             const bool batch = q.ndim() == 2;
             if (batch) requireRows(q, "q", nv);
             else requireVector(q, "q", nv);
             const py::ssize_t n = batch ? q.shape(0) : 1;
             for (py::ssize_t i = 0; i < n; ++i) {
               std::string why;
               if (!validateJointVector(model, q.data() + i * nv, &why))
                 throw py::value_error((batch ? "q[" + std::to_string(i) + "]: " : std::string("q: ")) + why);
             }
             py::array_t<double> out(batch ? std::vector<py::ssize_t>{n, nl, 4, 4} : std::vector<py::ssize_t>{nl, 4, 4});
             double* o = out.mutable_data();
             const double* qs = q.data();
             py::gil_scoped_release release;
             std::vector<Pose> poses(static_cast<std::size_t>(nl));
             for (py::ssize_t i = 0; i < n; ++i) {
               computeLinkPoses(model, qs + i * nv, poses.data());
               for (py::ssize_t l = 0; l < nl; ++l, o += 16) {
                 const Pose& p = poses[l];
                 for (int a = 0; a < 3; ++a) {
                   for (int b = 0; b < 3; ++b) o[4 * a + b] = p.R(a, b);
                   o[4 * a + 3] = p.t[a];
                 }
                 o[12] = o[13] = o[14] = 0.0;
                 o[15] = 1.0;
               }
             }
             return out;
           },
           py::arg("q"),
           "World pose of every link as 4x4 matrices: q (dof,) -> (links, 4, 4), or q (N, dof) -> (N, links, 4, 4). "
           "ValueError for a non-finite or out-of-limits q.")
      .def("__repr__", [](const PyRobot& r) {
        return "<clearway.Robot " + r.model->name() + ": " + std::to_string(r.model->linkCount()) + " links, " +
               std::to_string(r.model->variableCount()) + " dof>";
      });

  m.def("load_robot",
        [](const std::string& urdf, const py::object& srdf, const std::vector<std::string>& package_paths) {
          const std::string s = srdf.is_none() ? "" : srdf.cast<std::string>();
          py::gil_scoped_release release;
          return PyRobot{std::make_shared<const RobotModel>(loadRobot(urdf, s, loadOptions(package_paths)))};
        },
        py::arg("urdf"), py::arg("srdf") = py::none(), py::arg("package_paths") = std::vector<std::string>{},
        "Loads a URDF (and SRDF) with its meshes; raises LoadError naming file, element and reason.");

  py::class_<AuditPair>(m, "AuditPair", "One link pair's verdict and evidence.")
      .def_readonly("link_a", &AuditPair::link_a, "The first link (in the robot's order).")
      .def_readonly("link_b", &AuditPair::link_b, "The second link.")
      .def_readonly("reason", &AuditPair::reason, "'Adjacent', 'Default', 'Always', 'Never', or '' (must be checked).")
      .def_readonly("samples", &AuditPair::samples, "Configurations tested (0 for Adjacent pairs).")
      .def_readonly("colliding", &AuditPair::colliding, "Samples in collision.")
      .def_readonly("p_upper", &AuditPair::p_upper, "95% Clopper-Pearson upper bound on the collision probability.")
      .def_readonly("min_clearance", &AuditPair::min_clearance, "Smallest distance seen (0 if it collided, NaN if not measured).")
      .def_readonly("near_miss", &AuditPair::near_miss, "Never, but closer than 1 mm at some sample.")
      .def_readonly("warning", &AuditPair::warning, "Why the verdict may mislead ('' when it does not).")
      .def_readonly("srdf_reason", &AuditPair::srdf_reason, "The given SRDF's reason for disabling it ('' if it checks it).")
      .def("__repr__", [](const AuditPair& p) {
        return "<AuditPair " + p.link_a + " " + p.link_b + ": " + (p.reason.empty() ? "checked" : p.reason) + ", " +
               std::to_string(p.colliding) + "/" + std::to_string(p.samples) + " colliding>";
      });

  py::class_<AuditResult>(m, "AuditResult", "A self-collision audit: every pair of links with geometry, classified.")
      .def_property_readonly("robot_name", [](const AuditResult& a) { return a.model->name(); }, "The URDF's robot name.")
      .def_readonly("pairs", &AuditResult::pairs, "An AuditPair per pair of links with geometry.")
      .def_readonly("samples", &AuditResult::samples, "Random configurations per pair.")
      .def_readonly("seed", &AuditResult::seed, "The seed: the same seed gives the same audit.")
      .def("counts", [](const AuditResult& a) {
        std::map<std::string, int> counts{{"Adjacent", 0}, {"Default", 0}, {"Always", 0}, {"Never", 0}, {"checked", 0}};
        for (const PairAudit& p : a.audit) ++counts[p.reason.empty() ? "checked" : p.reason];
        return counts;
      }, "Pairs per verdict: {'Adjacent': n, 'Default': n, 'Always': n, 'Never': n, 'checked': n}.")
      .def("to_srdf", [](const AuditResult& a) { return auditSrdf(*a.model, a.audit, a.srdf_text); },
           "The given SRDF (or a new one) with the disable_collisions of every classified pair replaced, and the "
           "rest kept (as clearway audit --srdf-out).");

  m.def("audit",
        [](const std::string& urdf, const py::object& srdf, int samples, std::uint64_t seed, int threads,
           const std::vector<std::string>& package_paths) {
          AuditOptions options;
          options.samples = samples;
          options.seed = seed;
          options.threads = std::min(threads, maxAuditThreads());
          if (threads > options.threads) {
            const std::string warning = "audit: threads=" + std::to_string(threads) +
                                        " is more than this machine runs at once: " + std::to_string(options.threads) +
                                        " threads used (4 per hardware thread, at most 256)";
            if (PyErr_WarnEx(PyExc_RuntimeWarning, warning.c_str(), 1) != 0) throw py::error_already_set();
          }
          const std::string srdf_path = srdf.is_none() ? "" : srdf.cast<std::string>();
          py::gil_scoped_release release;
          AuditResult result;
          result.samples = samples;
          result.seed = seed;
          // As clearway audit: the audit ignores any SRDF; the given one is loaded only to compare with.
          result.model = std::make_shared<const RobotModel>(loadRobot(urdf, "", loadOptions(package_paths)));
          std::map<std::pair<int, int>, std::string> given;
          if (!srdf_path.empty()) {
            std::ifstream in(srdf_path, std::ios::binary);
            std::ostringstream text;
            text << in.rdbuf();
            result.srdf_text = text.str();
            const RobotModel with_srdf = loadRobot(urdf, srdf_path, loadOptions(package_paths));
            for (const DisabledCollision& d : with_srdf.disabledCollisions())
              given[{std::min(d.link_a, d.link_b), std::max(d.link_a, d.link_b)}] = d.reason;
          }
          result.audit = auditSelfCollision(std::make_shared<const RobotGeometry>(result.model), options);
          for (const PairAudit& p : result.audit) {
            const auto it = given.find({p.a, p.b});
            result.pairs.push_back({result.model->link(p.a).name, result.model->link(p.b).name, p.reason, p.samples,
                                    p.colliding, p.p_upper, p.min_clearance, p.near_miss, p.warning,
                                    it == given.end() ? "" : it->second});
          }
          return result;
        },
        py::arg("urdf"), py::arg("srdf") = py::none(), py::arg("samples") = 10000, py::arg("seed") = 1,
        py::arg("threads") = 2, py::arg("package_paths") = std::vector<std::string>{},
        "Audits every pair of links with geometry as MoveIt's Setup Assistant does, with evidence "
        "(as clearway audit; the same seed gives the same audit). srdf is only compared with. threads beyond 4 per "
        "hardware thread (at most 256) are capped to that, with a RuntimeWarning.");

  m.def("clopper_pearson_upper", &clopperPearsonUpper, py::arg("k"), py::arg("n"),
        "The 95% one-sided Clopper-Pearson upper bound on p after k successes in n trials (1 when n = 0).");
}

}  // namespace clearway::python
