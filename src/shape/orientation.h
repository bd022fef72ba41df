#pragma once
// Exact orientation predicates for the hull builder: a floating-point evaluation with a proven error
// bound, then (x87) extended precision, then expansion arithmetic when the bound cannot decide
// (J. R. Shewchuk, "Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric Predicates",
// Discrete & Computational Geometry 18, 1997; the code is our own).
//
// Coordinates reaching these functions are scaled by a power of two (exactly) so that |x| < 1: products
// of three coordinates cannot overflow, and do not underflow unless a coordinate is below ~2^-300 of
// the largest, which keeps the error-free transformations exact.
#include <clearway/math.h>

#include <cmath>

namespace clearway::orientation {

constexpr double kUnitRoundoff = 0x1p-53;
// A permanent below this may hide underflowed products, for which the relative error bound fails.
constexpr double kMinPermanent = 0x1p-900;

// vol(a, b, c, q) = ((b − a) × (c − a)) · (q − a), evaluated as (a − q) · ((c − q) × (b − q)): positive
// when q lies on the side that the counter-clockwise normal of triangle (a, b, c) points to.
struct FilteredSign {
  double vol;    // the floating-point value
  bool certain;  // its sign is the exact sign
};

inline FilteredSign orientFiltered(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& q) {
  const double ax = a.x() - q.x(), ay = a.y() - q.y(), az = a.z() - q.z();
  const double bx = b.x() - q.x(), by = b.y() - q.y(), bz = b.z() - q.z();
  const double cx = c.x() - q.x(), cy = c.y() - q.y(), cz = c.z() - q.z();
  const double p0 = cy * bz, p1 = cz * by, p2 = cz * bx, p3 = cx * bz, p4 = cx * by, p5 = cy * bx;
  const double det = ax * (p0 - p1) + ay * (p2 - p3) + az * (p4 - p5);
  const double perm = std::abs(ax) * (std::abs(p0) + std::abs(p1)) + std::abs(ay) * (std::abs(p2) + std::abs(p3)) +
                      std::abs(az) * (std::abs(p4) + std::abs(p5));
  // Rounding of the differences perturbs the determinant by ≤ 3u·perm, its evaluation adds ≤ 5u·perm
  // (u = 2^-53, second-order terms ignored); 12u covers both and the rounding of perm itself.
  return {det, perm >= kMinPermanent && std::abs(det) > 12.0 * kUnitRoundoff * perm};
}

// The exact sign of vol(a, b, c, q) where the filter above could not settle it.
int orientUncertain(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& q);

// The exact sign of vol(a, b, c, q).
inline int orientSign(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& q) {
  const FilteredSign f = orientFiltered(a, b, c, q);
  if (f.certain) return f.vol > 0.0 ? 1 : -1;
  return orientUncertain(a, b, c, q);
}

// The exact sign of (a − c) × (b − c) in the plane: positive when a, b, c turn counter-clockwise.
int orient2dSign(double ax, double ay, double bx, double by, double cx, double cy);

// True when a, b, c lie on one line (exactly): every axis-aligned projection is degenerate.
bool collinear(const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace clearway::orientation
