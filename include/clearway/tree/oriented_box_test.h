#pragma once
// The separating-axis test of two boxes in different frames, the inner loop of every tree descent
// (AabbTree, VersionedAabbTree) and the first cull of a link against obstacles and voxels (body/,
// environment/): S. Gottschalk, M. Lin, D. Manocha, "OBBTree" (SIGGRAPH 1996), with the face normals
// first ("SAT lite", van den Bergen 1997) and the 9 edge-pair axes on demand.
#include <clearway/math.h>
#include <clearway/tree/aabb.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace clearway::detail {

/// The separating-axis test of box A (in frame A) against box B (in frame B, placed in A by b_in_a).
/// Boxes closer than `margin` count as overlapping, and so do boxes within rounding of touching: the
/// margin is widened by 32 ulps of `scale`, an upper bound on every coordinate and extent involved.
class OrientedBoxTest {
 public:
  OrientedBoxTest(const Pose& b_in_a, double margin, double scale) noexcept
      : R_(b_in_a.R), t_(b_in_a.t), margin_(margin + 32.0 * std::numeric_limits<double>::epsilon() * scale) {
    // The ulp added to |R| keeps the edge-pair axes of nearly parallel edges (cross product ≈ 0) from
    // separating boxes on rounding noise (Gottschalk's fix); it also widens the face tests harmlessly.
    abs_R_ = R_.cwiseAbs().array() + 4.0 * std::numeric_limits<double>::epsilon();
  }

  /// B's box as A sees it: its centre in A's frame and its half widths along A's axes (|R|·h).
  struct PlacedB {
    double center[3], reach[3], half[3];
  };
  // Written out in scalars: this is the inner loop of every tree descent, and the compiler would not
  // inline Eigen's fixed-size products here.
  PlacedB place(const Aabb& b) const noexcept {
    PlacedB p;
    double c[3];
    for (int k = 0; k < 3; ++k) {
      c[k] = 0.5 * (b.min[k] + b.max[k]);
      p.half[k] = 0.5 * (b.max[k] - b.min[k]);
    }
    for (int i = 0; i < 3; ++i) {
      p.center[i] = R_(i, 0) * c[0] + R_(i, 1) * c[1] + R_(i, 2) * c[2] + t_[i];
      p.reach[i] = abs_R_(i, 0) * p.half[0] + abs_R_(i, 1) * p.half[1] + abs_R_(i, 2) * p.half[2];
    }
    return p;
  }

  /// True when the boxes are farther apart than the margin along one of A's or B's 3 face normals
  /// (SAT lite) or, when kFull, along one of the 9 cross products of their edge directions.
  template <bool kFull>
  bool separated(const Aabb& a, const Aabb& b) const noexcept {
    double ca[3], ha[3];
    centerHalf(a, ca, ha);
    return separated<kFull>(ca, ha, place(b));
  }

  /// A box as centre and half extents.
  static void centerHalf(const Aabb& a, double c[3], double h[3]) noexcept {
    for (int k = 0; k < 3; ++k) {
      c[k] = 0.5 * (a.min[k] + a.max[k]);
      h[k] = 0.5 * (a.max[k] - a.min[k]);
    }
  }

  /// The same with A's box as centre and half extents and B's box placed (a descent unfolding one box
  /// places the other once for both children).
  template <bool kFull>
  bool separated(const double ca[3], const double ha[3], const PlacedB& b) const noexcept {
    double T[3];  // B's centre relative to A's, in A's frame
    for (int i = 0; i < 3; ++i) {
      T[i] = b.center[i] - ca[i];
      if (std::abs(T[i]) - ha[i] - b.reach[i] > margin_) return true;
    }
    // B's face normals: T in B's frame against A's half widths along B's axes.
    for (int j = 0; j < 3; ++j) {
      const double tb = R_(0, j) * T[0] + R_(1, j) * T[1] + R_(2, j) * T[2];
      const double ra = abs_R_(0, j) * ha[0] + abs_R_(1, j) * ha[1] + abs_R_(2, j) * ha[2];
      if (std::abs(tb) - b.half[j] - ra > margin_) return true;
    }
    if constexpr (kFull) {
      // Axis e_i × (B's axis j) in A's frame: its length is sin∠ ≤ 1, so comparing against the
      // unscaled margin is conservative.
      const double* hb = b.half;
      for (int i = 0; i < 3; ++i) {
        const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
        for (int j = 0; j < 3; ++j) {
          const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
          const double dist = std::abs(T[i2] * R_(i1, j) - T[i1] * R_(i2, j));
          const double reach = ha[i1] * abs_R_(i2, j) + ha[i2] * abs_R_(i1, j) + hb[j1] * abs_R_(i, j2) +
                               hb[j2] * abs_R_(i, j1);
          if (dist - reach > margin_) return true;
        }
      }
    }
    return false;
  }

  /// A lower bound on the distance between the boxes beyond the margin: the largest gap along the
  /// 6 face normals and the line through the centres, minus the margin, at least 0 (a gap along any
  /// unit axis never exceeds the distance; the centre line makes the bound tight for distant boxes,
  /// where the face normals see only about 1/√3 of a diagonal offset).
  double gap(const Aabb& a, const Aabb& b) const noexcept { return gap(a, place(b)); }
  /// The same with B's box placed once (a query against many boxes A).
  double gap(const Aabb& a, const PlacedB& p) const noexcept {
    double ca[3], ha[3];
    centerHalf(a, ca, ha);
    double T[3], Ta[3], Tba[3];
    double g = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < 3; ++i) {
      T[i] = p.center[i] - ca[i];
      Ta[i] = std::abs(T[i]);
      g = std::max(g, Ta[i] - ha[i] - p.reach[i]);
    }
    for (int j = 0; j < 3; ++j) {
      Tba[j] = std::abs(R_(0, j) * T[0] + R_(1, j) * T[1] + R_(2, j) * T[2]);
      const double ra = abs_R_(0, j) * ha[0] + abs_R_(1, j) * ha[1] + abs_R_(2, j) * ha[2];
      g = std::max(g, Tba[j] - p.half[j] - ra);
    }
    // Along u = T/|T|: A reaches |u|·ha, B reaches |Rᵀu|·hb = |Tb|·hb/|T|.
    const double len2 = T[0] * T[0] + T[1] * T[1] + T[2] * T[2];
    if (len2 > 0.0) {
      const double len = std::sqrt(len2);
      const double reach = Ta[0] * ha[0] + Ta[1] * ha[1] + Ta[2] * ha[2] + Tba[0] * p.half[0] + Tba[1] * p.half[1] +
                           Tba[2] * p.half[2];
      g = std::max(g, len - reach / len);
    }
    return std::max(0.0, g - margin_);
  }

 private:
  Mat3 R_, abs_R_;
  Vec3 t_;
  double margin_;
};

// An upper bound on |coordinate| and extent of every node box of a and b (B's in A's frame).
inline double treePairScale(const Aabb& a, const Aabb& b, const Pose& b_in_a) noexcept {
  const double na = a.min.cwiseAbs().cwiseMax(a.max.cwiseAbs()).norm();
  const double nb = b.min.cwiseAbs().cwiseMax(b.max.cwiseAbs()).norm();
  return na + nb + b_in_a.t.norm();
}

}  // namespace clearway::detail
