#pragma once
// Convex primitives in their local frames, each known to the narrow phase only through
//   support(d): a point of the *core* that is farthest along d (local frame), and
//   radius():   the core is swept by a sphere of this radius (0 for polytopes).
// Keeping spheres and capsules as point and segment cores swept by a radius lets GJK answer
// them exactly in one or two iterations instead of crawling over a curved surface.
#include <clearway/math.h>

#include <stdexcept>
#include <string>

namespace clearway {

/// Thrown when a shape is built from invalid numbers (NaN, infinity, negative or zero radius, no points).
class ShapeError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

namespace detail {
inline void requireFinite(const Vec3& p, const char* shape, const char* what) {
  if (!p.allFinite()) throw ShapeError(std::string(shape) + ": " + what + " is not finite");
}
inline void requirePositive(double x, const char* shape, const char* what) {
  if (!(x > 0.0) || !std::isfinite(x))
    throw ShapeError(std::string(shape) + ": " + what + " must be finite and > 0, got " + std::to_string(x));
}
inline void requireNonNegative(double x, const char* shape, const char* what) {
  if (!(x >= 0.0) || !std::isfinite(x))
    throw ShapeError(std::string(shape) + ": " + what + " must be finite and >= 0, got " + std::to_string(x));
}
// sign with sign(0) = +1, so a support point is always a vertex.
inline double nonNegativeSign(double x) { return x < 0.0 ? -1.0 : 1.0; }
}  // namespace detail

/// A single point (local origin unless given).
struct Point {
  Vec3 p = Vec3::Zero();  ///< the point (local frame)
  /// The local origin.
  Point() = default;
  /// The point p; throws ShapeError if not finite.
  explicit Point(const Vec3& at) : p(at) { detail::requireFinite(p, "point", "position"); }
  /// p, whatever the direction.
  Vec3 support(const Vec3&) const noexcept { return p; }
  /// 0: the core is the shape.
  double radius() const noexcept { return 0.0; }
  /// p.
  Vec3 center() const noexcept { return p; }
};

/// The segment between p0 and p1.
struct Segment {
  ///@{
  Vec3 p0, p1;  ///< the endpoints (local frame)
  ///@}
  /// Throws ShapeError on a non-finite endpoint; a zero-length segment is a point and allowed.
  Segment(const Vec3& a, const Vec3& b) : p0(a), p1(b) {
    detail::requireFinite(p0, "segment", "p0");
    detail::requireFinite(p1, "segment", "p1");
  }
  /// The endpoint farthest along d (p0 on a tie).
  Vec3 support(const Vec3& d) const noexcept { return d.dot(p1 - p0) > 0.0 ? p1 : p0; }
  /// 0: the core is the shape.
  double radius() const noexcept { return 0.0; }
  /// The midpoint.
  Vec3 center() const noexcept { return 0.5 * (p0 + p1); }
};

/// The closed triangle with vertices v[0], v[1], v[2] (needle and sliver triangles allowed).
struct Triangle {
  Vec3 v[3];  ///< the vertices (local frame)
  /// Throws ShapeError on a non-finite vertex.
  Triangle(const Vec3& a, const Vec3& b, const Vec3& c) : v{a, b, c} {
    for (const Vec3& p : v) detail::requireFinite(p, "triangle", "vertex");
  }
  /// The vertex farthest along d (the lowest index on a tie).
  Vec3 support(const Vec3& d) const noexcept {
    const double d0 = d.dot(v[0]), d1 = d.dot(v[1]), d2 = d.dot(v[2]);
    if (d0 >= d1) return d0 >= d2 ? v[0] : v[2];
    return d1 >= d2 ? v[1] : v[2];
  }
  /// 0: the core is the shape.
  double radius() const noexcept { return 0.0; }
  /// The centroid.
  Vec3 center() const noexcept { return (v[0] + v[1] + v[2]) / 3.0; }
};

/// An axis-aligned box centred at the local origin.
struct Box {
  Vec3 half;  ///< half extents along local x, y, z (metres, ≥ 0)
  /// Half extents must be finite and ≥ 0 (a zero extent is a flat box); throws ShapeError otherwise.
  explicit Box(const Vec3& half_extents) : half(half_extents) {
    for (int i = 0; i < 3; ++i) detail::requireNonNegative(half[i], "box", "half extent");
  }
  /// The corner farthest along d (a zero component of d picks the + side: always a vertex).
  Vec3 support(const Vec3& d) const noexcept {
    return {detail::nonNegativeSign(d.x()) * half.x(), detail::nonNegativeSign(d.y()) * half.y(),
            detail::nonNegativeSign(d.z()) * half.z()};
  }
  /// 0: the core is the shape.
  double radius() const noexcept { return 0.0; }
  /// The local origin.
  Vec3 center() const noexcept { return Vec3::Zero(); }
};

/// A sphere centred at the local origin: a point core swept by the radius.
struct Sphere {
  double r;  ///< radius (metres, > 0)
  /// Throws ShapeError unless radius is finite and > 0.
  explicit Sphere(double radius) : r(radius) { detail::requirePositive(r, "sphere", "radius"); }
  /// The local origin (the core), whatever the direction.
  Vec3 support(const Vec3&) const noexcept { return Vec3::Zero(); }
  /// r: the core is swept by it.
  double radius() const noexcept { return r; }
  /// The local origin.
  Vec3 center() const noexcept { return Vec3::Zero(); }
};

/// A capsule along local z: the segment z ∈ [−half_length, half_length] swept by the radius.
struct Capsule {
  ///@{
  double r, h;  ///< radius (metres, > 0) and half length of the core segment (metres, ≥ 0)
  ///@}
  /// Throws ShapeError unless radius > 0 and half_length ≥ 0, both finite.
  Capsule(double radius, double half_length) : r(radius), h(half_length) {
    detail::requirePositive(r, "capsule", "radius");
    detail::requireNonNegative(h, "capsule", "half_length");
  }
  /// The core segment's end farthest along d (+h when d.z() is 0).
  Vec3 support(const Vec3& d) const noexcept { return {0.0, 0.0, detail::nonNegativeSign(d.z()) * h}; }
  /// r: the core segment is swept by it.
  double radius() const noexcept { return r; }
  /// The local origin.
  Vec3 center() const noexcept { return Vec3::Zero(); }
};

/// A solid cylinder along local z, z ∈ [−half_length, half_length].
struct Cylinder {
  ///@{
  double r, h;  ///< radius (metres, > 0) and half length (metres, ≥ 0)
  ///@}
  /// Throws ShapeError unless radius > 0 and half_length ≥ 0, both finite.
  Cylinder(double radius, double half_length) : r(radius), h(half_length) {
    detail::requirePositive(r, "cylinder", "radius");
    detail::requireNonNegative(h, "cylinder", "half_length");
  }
  /// A rim point farthest along d (on the +z rim when d.z() is 0).
  Vec3 support(const Vec3& d) const noexcept {
    const double s = std::sqrt(d.x() * d.x() + d.y() * d.y());
    const double z = detail::nonNegativeSign(d.z()) * h;
    if (s > 0.0) return {r * d.x() / s, r * d.y() / s, z};
    return {r, 0.0, z};  // d along the axis: any rim point is a support point
  }
  /// 0: the core is the shape.
  double radius() const noexcept { return 0.0; }
  /// The local origin.
  Vec3 center() const noexcept { return Vec3::Zero(); }
};

/// A solid cone along local z: base disc of the radius at z = −half_length, apex at z = +half_length.
struct Cone {
  ///@{
  double r, h;  ///< base radius (metres, > 0) and half height (metres, > 0)
  ///@}
  /// Throws ShapeError unless radius > 0 and half_length > 0, both finite.
  Cone(double radius, double half_length) : r(radius), h(half_length) {
    detail::requirePositive(r, "cone", "radius");
    detail::requirePositive(h, "cone", "half_length");
  }
  /// The apex or the base rim's point farthest along d, whichever is farther (the apex on a tie).
  Vec3 support(const Vec3& d) const noexcept {
    const double s = std::sqrt(d.x() * d.x() + d.y() * d.y());
    const Vec3 rim = s > 0.0 ? Vec3(r * d.x() / s, r * d.y() / s, -h) : Vec3(r, 0.0, -h);
    return h * d.z() >= d.dot(rim) ? Vec3(0.0, 0.0, h) : rim;
  }
  /// 0: the core is the shape.
  double radius() const noexcept { return 0.0; }
  /// A point on the axis inside the cone (z = −half_length / 2).
  Vec3 center() const noexcept { return {0.0, 0.0, -0.5 * h}; }
};

}  // namespace clearway
