#pragma once
// The closest point of a simplex (≤ 4 points) to the origin, by the signed-volume method of
// Montanari, Petrinic and Barbieri, "Improving the GJK algorithm for faster and more reliable
// distance queries between convex objects" (ACM TOG 2017). Instead of Johnson's sub-algorithm it
// decides the Voronoi region from signed volumes (determinant cofactors) projected onto the
// best-conditioned axis or plane, so degenerate simplices (coplanar tetrahedra, collinear
// triangles, repeated points) fall back to their faces instead of dividing by ~0.
#include <clearway/shape/support.h>

#include <algorithm>
#include <cmath>

namespace clearway::detail {

struct Simplex {
  SupportPoint p[4];
  double lambda[4];  // barycentric weights of p[0..n) for the closest point
  int n = 0;
};

/// Weights of the closest point of the simplex's hull to the origin; a zero weight drops a point.
/// Compiled once (simplex.cpp): it is the same for every shape pair.
void closestWeights(const Simplex& s, double l[4]) noexcept;

/// Keeps the points with positive weight (in order) and stores their weights.
inline void compactSimplex(Simplex& s, const double l[4]) noexcept {
  int m = 0;
  for (int i = 0; i < s.n; ++i) {
    if (l[i] > 0.0) {
      s.p[m] = s.p[i];
      s.lambda[m] = l[i];
      ++m;
    }
  }
  s.n = m;
}

/// Replaces the simplex by the smallest subset supporting its closest point to the origin and
/// returns that point v. Afterwards n == 4 means the origin is enclosed. (Always inlined: it is the step of
/// every GJK loop, and a call there cost about 2% of a state check when the inliner chose otherwise.)
[[gnu::always_inline]] inline Vec3 reduceSimplex(Simplex& s) noexcept {
  double l[4];
  closestWeights(s, l);
  compactSimplex(s, l);
  Vec3 v = Vec3::Zero();
  for (int i = 0; i < s.n; ++i) v += s.lambda[i] * s.p[i].w;
  return v;
}

/// The witnesses of the simplex's closest point on the cores of A and B (A's frame).
inline void simplexWitnesses(const Simplex& s, Vec3& a, Vec3& b) noexcept {
  a.setZero();
  b.setZero();
  for (int i = 0; i < s.n; ++i) {
    a += s.lambda[i] * s.p[i].a;
    b += s.lambda[i] * s.p[i].b;
  }
}

}  // namespace clearway::detail
