#pragma once
// Axis-aligned bounding boxes: the bounding volume of the mid phase (seeds/000: "a fair trade-off
// between storage space and fit; overlap tests are fast; fast construction and update").
// Boxes are closed: boxes that touch overlap.
#include <clearway/math.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace clearway {

/// A closed axis-aligned box [min, max] in some frame; empty when min > max on an axis (the default).
struct Aabb {
  Vec3 min = Vec3::Constant(std::numeric_limits<double>::infinity());   ///< lowest corner (+∞ when empty)
  Vec3 max = Vec3::Constant(-std::numeric_limits<double>::infinity());  ///< highest corner (−∞ when empty)

  /// The empty box: grow() and merge() turn it into the box of what they are given.
  static Aabb empty() noexcept { return {}; }
  /// The box [lo, hi].
  static Aabb fromMinMax(const Vec3& lo, const Vec3& hi) noexcept { return {lo, hi}; }
  /// The box centred at c with half extents h (h ≥ 0).
  static Aabb fromCenterHalf(const Vec3& c, const Vec3& h) noexcept { return {c - h, c + h}; }
  /// The box of a single point.
  static Aabb ofPoint(const Vec3& p) noexcept { return {p, p}; }

  /// True when the box holds no point (also for the default box).
  bool isEmpty() const noexcept { return !(min.x() <= max.x() && min.y() <= max.y() && min.z() <= max.z()); }
  /// Extends the box to contain p.
  void grow(const Vec3& p) noexcept { min = min.cwiseMin(p); max = max.cwiseMax(p); }
  /// Extends the box to contain b (an empty b changes nothing).
  void merge(const Aabb& b) noexcept { min = min.cwiseMin(b.min); max = max.cwiseMax(b.max); }

  ///@{
  /// The centre, half extents and extents (max − min) of a non-empty box.
  Vec3 center() const noexcept { return 0.5 * (min + max); }
  Vec3 halfExtents() const noexcept { return 0.5 * (max - min); }
  Vec3 extents() const noexcept { return max - min; }
  ///@}
  /// Surface area (the SAH cost of a node); 0 for an empty box.
  double surfaceArea() const noexcept {
    if (isEmpty()) return 0.0;
    const Vec3 e = extents();
    return 2.0 * (e.x() * e.y() + e.y() * e.z() + e.z() * e.x());
  }
  /// The box grown by `margin` metres on every side.
  Aabb inflated(double margin) const noexcept { return {min.array() - margin, max.array() + margin}; }
  /// True when p lies in the closed box.
  bool contains(const Vec3& p) const noexcept {
    return (min.array() <= p.array()).all() && (p.array() <= max.array()).all();
  }
  /// True when b lies in the closed box (an empty b is contained in anything).
  bool contains(const Aabb& b) const noexcept {
    return b.isEmpty() || ((min.array() <= b.min.array()).all() && (b.max.array() <= max.array()).all());
  }
};

/// The smallest box containing a and b.
inline Aabb merged(const Aabb& a, const Aabb& b) noexcept {
  Aabb r = a;
  r.merge(b);
  return r;
}

/// True when the closed boxes share a point (touching boxes overlap; an empty box overlaps nothing).
inline bool overlaps(const Aabb& a, const Aabb& b) noexcept {
  return (a.min.array() <= b.max.array()).all() && (b.min.array() <= a.max.array()).all();
}

/// Euclidean distance between two boxes (0 when they overlap).
inline double boxDistance(const Aabb& a, const Aabb& b) noexcept {
  const Vec3 gap = (a.min - b.max).cwiseMax(b.min - a.max).cwiseMax(0.0);
  return gap.norm();
}

/// The box, in the pose's parent frame, of `box` placed by `pose`: centre R·c + t, half extents |R|·h.
/// It contains the rotated box exactly (tight for the rotated box, not for what the box bounds), and is
/// widened by a few roundings so that the containment survives floating point.
inline Aabb transformed(const Aabb& box, const Pose& pose) noexcept {
  if (box.isEmpty()) return box;
  // Written out in scalars: Eigen's fixed-size products here cost three times as much (every link of
  // every state check places its box).
  double c[3], h[3], ac[3];
  for (int k = 0; k < 3; ++k) {
    c[k] = 0.5 * (box.min[k] + box.max[k]);
    h[k] = 0.5 * (box.max[k] - box.min[k]);
    ac[k] = std::abs(c[k]);
  }
  Aabb out;
  double size = 0.0;
  double wc[3], wh[3];
  for (int i = 0; i < 3; ++i) {
    const double a0 = std::abs(pose.R(i, 0)), a1 = std::abs(pose.R(i, 1)), a2 = std::abs(pose.R(i, 2));
    wc[i] = pose.R(i, 0) * c[0] + pose.R(i, 1) * c[1] + pose.R(i, 2) * c[2] + pose.t[i];
    wh[i] = a0 * h[0] + a1 * h[1] + a2 * h[2];
    size = std::max(size, a0 * ac[0] + a1 * ac[1] + a2 * ac[2] + std::abs(pose.t[i]) + wh[i]);
  }
  // R·c + t and |R|·h each carry a relative rounding of a few ulps of |R||c| + |t| and |R|h (a NaN stays).
  const double slack = 8.0 * std::numeric_limits<double>::epsilon() * size;
  for (int i = 0; i < 3; ++i) {
    out.min[i] = wc[i] - (wh[i] + slack);
    out.max[i] = wc[i] + (wh[i] + slack);
  }
  return out;
}

}  // namespace clearway
