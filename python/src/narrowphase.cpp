// The narrow phase from Python: convex shapes, and the five queries of `clearway query` on a posed pair.
#include "bindings.h"
#include "convert.h"

#include <clearway/narrowphase/epa.h>
#include <clearway/narrowphase/gjk.h>
#include <clearway/narrowphase/ray_cast.h>
#include <clearway/narrowphase/status.h>
#include <clearway/shape/shape.h>

#include <pybind11/stl.h>

#include <cmath>
#include <sstream>

namespace clearway::python {

namespace {

// The subclasses of PyShape (convert.h) only name the kind and its parameters.
struct PyPoint : PyShape {};
struct PySegment : PyShape {};
struct PyTriangle : PyShape {};
struct PyBox : PyShape {};
struct PySphere : PyShape {};
struct PyCapsule : PyShape {};
struct PyCylinder : PyShape {};
struct PyCone : PyShape {};
struct PyConvexHull : PyShape {};

template <class T, class S>
T make(S&& s) {
  T t;
  t.shape = std::forward<S>(s);
  return t;
}

// As the query files' "tolerance": the relative tolerance of GJK, the casts and EPA at once.
Tolerances tolerances(const py::object& tolerance) {
  Tolerances tol;
  if (tolerance.is_none()) return tol;
  if (!py::isinstance<py::float_>(tolerance) && !py::isinstance<py::int_>(tolerance))
    throw py::type_error("tolerance must be a number or None");
  const double t = tolerance.cast<double>();
  if (!(t > 0.0) || !std::isfinite(t)) throw py::value_error("tolerance must be finite and > 0, got " + py::str(tolerance).cast<std::string>());
  tol.gjk_relative = tol.cast_relative = tol.epa_relative = t;
  return tol;
}

double nonNegative(double x, const char* name) {
  if (!(x >= 0.0) || !std::isfinite(x)) throw py::value_error(std::string(name) + " must be finite and >= 0, got " + std::to_string(x));
  return x;
}

template <class R>
std::string statusOf(const R& r) { return statusName(r.status); }

std::string vecText(const Vec3& v) {
  std::ostringstream s;
  s.precision(6);
  s << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return s.str();
}

}  // namespace

void bindNarrowphase(py::module_& m) {
  py::class_<PyShape>(m, "Shape", "A convex shape in its local frame (immutable).")
      .def_property_readonly("type", [](const PyShape& s) { return shapeTypeName(s.shape); },
                             "The shape's name in query files: 'box', 'convex', ...")
      .def_property_readonly("bounding_radius", [](const PyShape& s) { return boundingRadius(s.shape); },
                             "Radius of the ball about the local origin that contains the shape.")
      .def("__repr__", [](const PyShape& s) { return std::string("<clearway.Shape ") + shapeTypeName(s.shape) + ">"; });

  py::class_<PyPoint, PyShape>(m, "Point", "A single point.")
      .def(py::init([](const py::object& p) { return make<PyPoint>(p.is_none() ? Point() : Point(toVec3(p, "p"))); }),
           py::arg("p") = py::none(), "The point p (the local origin when None).");
  py::class_<PySegment, PyShape>(m, "Segment", "The segment between p0 and p1.")
      .def(py::init([](const py::object& p0, const py::object& p1) {
             return make<PySegment>(Segment(toVec3(p0, "p0"), toVec3(p1, "p1")));
           }),
           py::arg("p0"), py::arg("p1"));
  py::class_<PyTriangle, PyShape>(m, "Triangle", "The closed triangle with vertices a, b, c.")
      .def(py::init([](const py::object& a, const py::object& b, const py::object& c) {
             return make<PyTriangle>(Triangle(toVec3(a, "a"), toVec3(b, "b"), toVec3(c, "c")));
           }),
           py::arg("a"), py::arg("b"), py::arg("c"));
  py::class_<PyBox, PyShape>(m, "Box", "An axis-aligned box centred at the local origin.")
      .def(py::init([](const py::object& h) { return make<PyBox>(Box(toVec3(h, "half_extents"))); }),
           py::arg("half_extents"), "Half extents, each finite and >= 0.")
      .def_property_readonly("half_extents", [](const PyBox& b) { return toArray(std::get<Box>(b.shape).half); }, "Half extents.");
  py::class_<PySphere, PyShape>(m, "Sphere", "A sphere centred at the local origin.")
      .def(py::init([](double r) { return make<PySphere>(Sphere(r)); }), py::arg("radius"))
      .def_property_readonly("radius", [](const PySphere& s) { return std::get<Sphere>(s.shape).r; }, "Radius.");
  py::class_<PyCapsule, PyShape>(m, "Capsule", "A capsule along local z: the segment |z| <= half_length swept by radius.")
      .def(py::init([](double r, double h) { return make<PyCapsule>(Capsule(r, h)); }), py::arg("radius"), py::arg("half_length"))
      .def_property_readonly("radius", [](const PyCapsule& s) { return std::get<Capsule>(s.shape).r; }, "Radius.")
      .def_property_readonly("half_length", [](const PyCapsule& s) { return std::get<Capsule>(s.shape).h; }, "Half length along z.");
  py::class_<PyCylinder, PyShape>(m, "Cylinder", "A solid cylinder along local z, |z| <= half_length.")
      .def(py::init([](double r, double h) { return make<PyCylinder>(Cylinder(r, h)); }), py::arg("radius"), py::arg("half_length"))
      .def_property_readonly("radius", [](const PyCylinder& s) { return std::get<Cylinder>(s.shape).r; }, "Radius.")
      .def_property_readonly("half_length", [](const PyCylinder& s) { return std::get<Cylinder>(s.shape).h; }, "Half length along z.");
  py::class_<PyCone, PyShape>(m, "Cone", "A solid cone along local z: base at z = -half_length, apex at +half_length.")
      .def(py::init([](double r, double h) { return make<PyCone>(Cone(r, h)); }), py::arg("radius"), py::arg("half_length"))
      .def_property_readonly("radius", [](const PyCone& s) { return std::get<Cone>(s.shape).r; }, "Radius.")
      .def_property_readonly("half_length", [](const PyCone& s) { return std::get<Cone>(s.shape).h; }, "Half length along z.");
  py::class_<PyConvexHull, PyShape>(m, "ConvexHull", "The convex hull of a point set (duplicates and interior points allowed).")
      .def(py::init([](const py::object& points) {
             const DoubleArray a = DoubleArray::ensure(points);
             if (!a) throw py::value_error("points must be an (N, 3) array of numbers");
             requireRows(a, "points", 3);
             std::vector<Vec3> ps(static_cast<std::size_t>(a.shape(0)));
             for (py::ssize_t i = 0; i < a.shape(0); ++i) {
               ps[i] = Vec3(a.at(i, 0), a.at(i, 1), a.at(i, 2));
               if (!ps[i].allFinite()) throw py::value_error("points[" + std::to_string(i) + "] is not finite");
             }
             py::gil_scoped_release release;  // quickhull on many points takes a while
             return make<PyConvexHull>(ConvexHull(ps));
           }),
           py::arg("points"))
      .def_property_readonly("vertices", [](const PyConvexHull& s) {
        const auto& v = std::get<ConvexHull>(s.shape).vertices();
        py::array_t<double> out({static_cast<py::ssize_t>(v.size()), py::ssize_t{3}});
        auto w = out.mutable_unchecked<2>();
        for (std::size_t i = 0; i < v.size(); ++i)
          for (int k = 0; k < 3; ++k) w(i, k) = v[i][k];
        return out;
      }, "The hull's vertices, an (n, 3) array (a subset of the points).");

  py::class_<DistanceResult>(m, "DistanceResult", "A distance query's answer; points and normal in the world frame.")
      .def_readonly("distance", &DistanceResult::distance, "Upper bound on the distance, 0 when the shapes overlap.")
      .def_readonly("lower_bound", &DistanceResult::lower_bound, "Certified lower bound on the distance.")
      .def_property_readonly("point_a", [](const DistanceResult& r) { return toArray(r.point_a); }, "Closest point on A.")
      .def_property_readonly("point_b", [](const DistanceResult& r) { return toArray(r.point_b); }, "Closest point on B.")
      .def_property_readonly("normal", [](const DistanceResult& r) { return toArray(r.normal); }, "Unit, from A towards B.")
      .def_property_readonly("status", &statusOf<DistanceResult>,
                             "Why the query stopped: 'converged', 'overlapping', ...; 'not_converged' and 'invalid_input' carry no certificate.")
      .def_readonly("iterations", &DistanceResult::iterations, "GJK / EPA / cast iterations taken.")
      .def("may_collide", &DistanceResult::mayCollide, "True on overlap, touching, or a failed query (never free by accident).")
      .def("__repr__", [](const DistanceResult& r) {
        return "<DistanceResult distance=" + std::to_string(r.distance) + " status=" + statusName(r.status) + ">";
      });
  py::class_<IntersectResult>(m, "IntersectResult", "An intersection query's answer.")
      .def_readonly("intersecting", &IntersectResult::intersecting, "True also when the query failed: assume a collision.")
      .def_property_readonly("status", &statusOf<IntersectResult>,
                             "Why the query stopped: 'converged', 'overlapping', ...; 'not_converged' and 'invalid_input' carry no certificate.")
      .def_readonly("iterations", &IntersectResult::iterations, "GJK / EPA / cast iterations taken.")
      .def("__bool__", [](const IntersectResult& r) { return r.intersecting; })
      .def("__repr__", [](const IntersectResult& r) {
        return std::string("<IntersectResult intersecting=") + (r.intersecting ? "True" : "False") + " status=" + statusName(r.status) + ">";
      });
  py::class_<PenetrationResult>(m, "PenetrationResult", "A penetration query's answer; points and normal in the world frame.")
      .def_readonly("depth", &PenetrationResult::depth, "> 0 when overlapping, 0 when apart.")
      .def_readonly("signed_distance", &PenetrationResult::signed_distance, "The distance when apart, -depth when overlapping.")
      .def_property_readonly("normal", [](const PenetrationResult& r) { return toArray(r.normal); }, "Unit: B moves along it to separate.")
      .def_property_readonly("point_a", [](const PenetrationResult& r) { return toArray(r.point_a); }, "Deepest (or closest) point of A.")
      .def_property_readonly("point_b", [](const PenetrationResult& r) { return toArray(r.point_b); }, "Deepest (or closest) point of B.")
      .def_property_readonly("status", &statusOf<PenetrationResult>,
                             "Why the query stopped: 'converged', 'overlapping', ...; 'not_converged' and 'invalid_input' carry no certificate.")
      .def_readonly("iterations", &PenetrationResult::iterations, "GJK / EPA / cast iterations taken.")
      .def("__repr__", [](const PenetrationResult& r) {
        return "<PenetrationResult signed_distance=" + std::to_string(r.signed_distance) + " status=" + statusName(r.status) + ">";
      });
  py::class_<CastResult>(m, "CastResult", "A ray or shape cast's answer; normal and point in the world frame.")
      .def_readonly("hit", &CastResult::hit, "True also when the query failed: assume contact at t.")
      .def_readonly("t", &CastResult::t, "Time of impact (0 when starting in contact).")
      .def_property_readonly("normal", [](const CastResult& r) { return toArray(r.normal); }, "Outward normal of the still shape.")
      .def_property_readonly("point", [](const CastResult& r) { return toArray(r.point); }, "Contact point on the still shape.")
      .def_property_readonly("status", &statusOf<CastResult>,
                             "Why the query stopped: 'converged', 'overlapping', ...; 'not_converged' and 'invalid_input' carry no certificate.")
      .def_readonly("iterations", &CastResult::iterations, "GJK / EPA / cast iterations taken.")
      .def("__repr__", [](const CastResult& r) {
        return std::string("<CastResult hit=") + (r.hit ? "True" : "False") + " t=" + std::to_string(r.t) +
               " normal=" + vecText(r.normal) + " status=" + statusName(r.status) + ">";
      });

  // Poses: None, (position, quaternion x y z w) or a 4x4 matrix; tolerance: as a query file's.
  m.def("distance",
        [](const PyShape& a, const py::object& pose_a, const PyShape& b, const py::object& pose_b, const py::object& tolerance) {
          const Pose pa = toPose(pose_a, "pose_a"), pb = toPose(pose_b, "pose_b");
          const Tolerances tol = tolerances(tolerance);
          py::gil_scoped_release release;
          return gjkDistance(a.shape, pa, b.shape, pb, tol);
        },
        py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"), py::arg("tolerance") = py::none(),
        "GJK distance between two posed shapes.");
  m.def("intersect",
        [](const PyShape& a, const py::object& pose_a, const PyShape& b, const py::object& pose_b, const py::object& tolerance) {
          const Pose pa = toPose(pose_a, "pose_a"), pb = toPose(pose_b, "pose_b");
          const Tolerances tol = tolerances(tolerance);
          py::gil_scoped_release release;
          SimplexCache cache;  // fresh: each call stands alone, as each line of a query file
          return gjkIntersect(a.shape, pa, b.shape, pb, tol, cache);
        },
        py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"), py::arg("tolerance") = py::none(),
        "GJK intersection test of two posed shapes.");
  m.def("penetration",
        [](const PyShape& a, const py::object& pose_a, const PyShape& b, const py::object& pose_b, const py::object& tolerance) {
          const Pose pa = toPose(pose_a, "pose_a"), pb = toPose(pose_b, "pose_b");
          const Tolerances tol = tolerances(tolerance);
          py::gil_scoped_release release;
          return epaPenetration(a.shape, pa, b.shape, pb, tol);
        },
        py::arg("a"), py::arg("pose_a"), py::arg("b"), py::arg("pose_b"), py::arg("tolerance") = py::none(),
        "Penetration depth (EPA) of two posed shapes, or their distance when apart.");
  m.def("raycast",
        [](const PyShape& shape, const py::object& pose, const py::object& origin, const py::object& direction,
           double max_t, const py::object& tolerance) {
          const Pose p = toPose(pose, "pose");
          Ray ray;
          ray.origin = toVec3(origin, "origin");
          ray.direction = toVec3(direction, "direction");
          ray.max_t = nonNegative(max_t, "max_t");
          const Tolerances tol = tolerances(tolerance);
          py::gil_scoped_release release;
          return gjkRayCast(shape.shape, p, ray, tol);
        },
        py::arg("shape"), py::arg("pose"), py::arg("origin"), py::arg("direction"), py::arg("max_t"),
        py::arg("tolerance") = py::none(), "The smallest t in [0, max_t] with origin + t*direction in the shape.");
  m.def("shapecast",
        [](const PyShape& a, const py::object& pose_a, const py::object& velocity_a, const PyShape& b,
           const py::object& pose_b, double max_t, const py::object& tolerance) {
          const Pose pa = toPose(pose_a, "pose_a"), pb = toPose(pose_b, "pose_b");
          const Vec3 v = toVec3(velocity_a, "velocity_a");
          const double t = nonNegative(max_t, "max_t");
          const Tolerances tol = tolerances(tolerance);
          py::gil_scoped_release release;
          return gjkShapeCast(a.shape, pa, v, b.shape, pb, t, tol);
        },
        py::arg("a"), py::arg("pose_a"), py::arg("velocity_a"), py::arg("b"), py::arg("pose_b"), py::arg("max_t"),
        py::arg("tolerance") = py::none(), "The first t in [0, max_t] at which A, moved by t*velocity_a, touches B.");
}

}  // namespace clearway::python
