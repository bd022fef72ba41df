#pragma once
// What the binding's files share: numpy views of caller arrays, poses from Python, and the check that
// a state batch has the shape a scene or robot expects. Every check raises ValueError naming the
// argument, so that bad input never reaches a query (which would call it a collision, or worse).
#include <clearway/math.h>
#include <clearway/shape/shape.h>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>

namespace clearway::python {

namespace py = pybind11;

/// A shape held by Python (clearway.Box, Sphere, ...: narrowphase.cpp); obstacles and attached bodies take them too.
struct PyShape {
  Shape shape = Point();
};

/// A C-contiguous float64 array: a view of the caller's array when it already is one, else a copy.
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// Throws ValueError "NAME must have shape (N, cols), got (...)" unless `a` is two-dimensional with
/// `cols` columns.
void requireRows(const DoubleArray& a, const char* name, py::ssize_t cols);

/// Throws ValueError unless `a` is one-dimensional with `n` entries.
void requireVector(const DoubleArray& a, const char* name, py::ssize_t n);

/// The shape of an array as Python prints it: "(3, 7)".
std::string shapeText(const py::array& a);

/// A finite 3-vector from a sequence of three numbers; ValueError naming `name` otherwise.
Vec3 toVec3(const py::handle& v, const std::string& name);

/// A pose from None (identity), (position, quaternion x y z w) or a 4×4 homogeneous matrix whose
/// rotation is orthonormal within 1e-9 and right-handed. Read exactly as the query files read them, so
/// that the same numbers give the same bits. ValueError naming `name` otherwise.
Pose toPose(const py::handle& pose, const std::string& name);

/// A pose as a 4×4 numpy array.
py::array_t<double> poseMatrix(const Pose& pose);

/// A 3-vector as a numpy array of 3 (a copy: results outlive nothing).
py::array_t<double> toArray(const Vec3& v);

}  // namespace clearway::python
