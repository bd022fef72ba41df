#include "convert.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace clearway::python {

std::string shapeText(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

void requireRows(const DoubleArray& a, const char* name, py::ssize_t cols) {
  if (a.ndim() != 2 || a.shape(1) != cols)
    throw py::value_error(std::string(name) + " must have shape (N, " + std::to_string(cols) + "), got " + shapeText(a));
}

void requireVector(const DoubleArray& a, const char* name, py::ssize_t n) {
  if (a.ndim() != 1 || a.shape(0) != n)
    throw py::value_error(std::string(name) + " must have shape (" + std::to_string(n) + ",), got " + shapeText(a));
}

namespace {

// The entries of a one-dimensional sequence of n numbers, each finite.
DoubleArray finiteVector(const py::handle& v, const std::string& name, py::ssize_t n) {
  const DoubleArray a = DoubleArray::ensure(v);  // (empty, with the error cleared, when not numbers)
  if (!a) throw py::value_error(name + " must be a sequence of " + std::to_string(n) + " numbers");
  requireVector(a, name.c_str(), n);
  for (py::ssize_t i = 0; i < n; ++i)
    if (!std::isfinite(a.at(i))) throw py::value_error(name + "[" + std::to_string(i) + "] is not finite");
  return a;
}

}  // namespace

Vec3 toVec3(const py::handle& v, const std::string& name) {
  const DoubleArray a = finiteVector(v, name, 3);
  return {a.at(0), a.at(1), a.at(2)};
}

Pose toPose(const py::handle& pose, const std::string& name) {
  if (pose.is_none()) return Pose();
  if ((py::isinstance<py::tuple>(pose) || py::isinstance<py::list>(pose)) && py::len(pose) == 2) {
    const py::sequence pair = py::reinterpret_borrow<py::sequence>(pose);
    const Vec3 t = toVec3(pair[0], name + " position");
    const DoubleArray q = finiteVector(pair[1], name + " quaternion", 4);
    // As the query files: any non-zero length, scaled by the largest entry first so that tiny and huge
    // quaternions normalise exactly.
    const double m = std::max({std::abs(q.at(0)), std::abs(q.at(1)), std::abs(q.at(2)), std::abs(q.at(3))});
    if (!(m > 0.0)) throw py::value_error(name + " quaternion must not be zero");
    return Pose::fromQuaternion(q.at(0) / m, q.at(1) / m, q.at(2) / m, q.at(3) / m, t);
  }
  const DoubleArray a = DoubleArray::ensure(pose);
  if (!a || a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4)
    throw py::value_error(name + " must be None, (position, quaternion x y z w) or a 4x4 matrix");
  Pose p;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      if (!std::isfinite(a.at(i, j)))
        throw py::value_error(name + "[" + std::to_string(i) + ", " + std::to_string(j) + "] is not finite");
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) p.R(i, j) = a.at(i, j);
    p.t[i] = a.at(i, 3);
  }
  if (a.at(3, 0) != 0.0 || a.at(3, 1) != 0.0 || a.at(3, 2) != 0.0 || a.at(3, 3) != 1.0)
    throw py::value_error(name + " must have the last row [0, 0, 0, 1]");
  // The test of the query files' "R": orthonormal within 1e-9 in every entry of RᵀR − I, det > 0.
  const double off = (p.R.transpose() * p.R - Mat3::Identity()).cwiseAbs().maxCoeff();
  char buf[64];
  constexpr double kOrthonormal = 1e-9;
  if (!(off <= kOrthonormal)) {
    std::snprintf(buf, sizeof buf, "%.3g", off);
    throw py::value_error(name + " is not a rotation: max |R^T R - I| = " + buf + " exceeds 1e-9");
  }
  if (!(p.R.determinant() > 0.0)) throw py::value_error(name + " is not a rotation: det < 0 (a reflection)");
  return p;
}

py::array_t<double> poseMatrix(const Pose& pose) {
  py::array_t<double> m({4, 4});
  auto w = m.mutable_unchecked<2>();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) w(i, j) = pose.R(i, j);
    w(i, 3) = pose.t[i];
    w(3, i) = 0.0;
  }
  w(3, 3) = 1.0;
  return m;
}

py::array_t<double> toArray(const Vec3& v) {
  py::array_t<double> a(3);
  auto w = a.mutable_unchecked<1>();
  for (int i = 0; i < 3; ++i) w(i) = v[i];
  return a;
}

}  // namespace clearway::python
