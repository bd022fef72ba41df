// The signed-volume sub-algorithm (see simplex.h for the reference).
#include <clearway/narrowphase/simplex.h>

namespace clearway::detail {

namespace {

bool sameSign(double a, double b) noexcept { return (a > 0.0 && b > 0.0) || (a < 0.0 && b < 0.0); }

// Closest point of segment [a, b] to the origin: weights (la, lb), and which points support it.
void closestOnSegment(const Vec3& a, const Vec3& b, double& la, double& lb) noexcept {
  const Vec3 t = b - a;
  const double tt = t.squaredNorm();
  // Degenerate segment: either endpoint is the answer. The test "s in (0,1)" below is written so that
  // a NaN lands in a vertex region and cannot produce NaN weights.
  const double s = tt > 0.0 ? -a.dot(t) / tt : 0.0;
  if (!(s > 0.0)) { la = 1.0; lb = 0.0; return; }
  if (!(s < 1.0)) { la = 0.0; lb = 1.0; return; }
  la = 1.0 - s;
  lb = s;
}

// Signed-volume test for a triangle; writes weights for (a, b, c), zero for unused vertices.
void closestOnTriangle(const Vec3& a, const Vec3& b, const Vec3& c, double l[3]) noexcept {
  const Vec3 n = (b - a).cross(c - a);
  const double nn = n.squaredNorm();
  const double scale = (b - a).squaredNorm() * (c - a).squaredNorm();
  if (nn > 1e-28 * scale && nn > 0.0) {
    // Project the origin onto the plane, then compare signed areas in the coordinate plane where
    // the triangle's projection is largest (the best-conditioned 2D problem).
    const Vec3 p0 = n * (a.dot(n) / nn);
    int k = 0;
    if (std::abs(n[1]) > std::abs(n[k])) k = 1;
    if (std::abs(n[2]) > std::abs(n[k])) k = 2;
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    auto cross2 = [&](const Vec3& u, const Vec3& w) {
      return (u[i] - p0[i]) * (w[j] - p0[j]) - (u[j] - p0[j]) * (w[i] - p0[i]);
    };
    const double mu = n[k];
    const double c0 = cross2(b, c), c1 = cross2(c, a), c2 = cross2(a, b);
    if (sameSign(mu, c0) && sameSign(mu, c1) && sameSign(mu, c2)) {
      l[0] = c0 / mu; l[1] = c1 / mu; l[2] = c2 / mu;
      return;
    }
  }
  // The origin projects outside the triangle (or the triangle is degenerate): the closest point is on
  // an edge. Testing all three edges costs a few flops and never misses a vertex region.
  const Vec3* v[3] = {&a, &b, &c};
  double best = INFINITY;
  l[0] = 1.0; l[1] = 0.0; l[2] = 0.0;
  for (int e = 0; e < 3; ++e) {
    const int p = e, q = (e + 1) % 3;
    double lp, lq;
    closestOnSegment(*v[p], *v[q], lp, lq);
    const double d = (lp * *v[p] + lq * *v[q]).squaredNorm();
    if (d < best) {
      best = d;
      l[0] = l[1] = l[2] = 0.0;
      l[p] = lp; l[q] = lq;
    }
  }
}

// Signed-volume test for a tetrahedron; weights for its four points.
void closestOnTetrahedron(const Vec3 s[4], double l[4]) noexcept {
  // Cofactors of the last row of M = [s0 s1 s2 s3; 1 1 1 1]: λⱼ = Cⱼ / det M when the origin is inside.
  const double c0 = -s[1].dot(s[2].cross(s[3]));
  const double c1 = s[0].dot(s[2].cross(s[3]));
  const double c2 = -s[0].dot(s[1].cross(s[3]));
  const double c3 = s[0].dot(s[1].cross(s[2]));
  const double det = c0 + c1 + c2 + c3;
  const double c[4] = {c0, c1, c2, c3};
  if (sameSign(det, c0) && sameSign(det, c1) && sameSign(det, c2) && sameSign(det, c3)) {
    for (int j = 0; j < 4; ++j) l[j] = c[j] / det;
    return;
  }
  // Only facets whose cofactor disagrees in sign face the origin; with det = 0 (flat tetrahedron)
  // none agrees and all four are tried.
  double best = INFINITY;
  l[0] = 1.0; l[1] = l[2] = l[3] = 0.0;
  for (int j = 0; j < 4; ++j) {
    if (sameSign(det, c[j])) continue;
    int f[3], m = 0;
    for (int q = 0; q < 4; ++q)
      if (q != j) f[m++] = q;
    double lf[3];
    closestOnTriangle(s[f[0]], s[f[1]], s[f[2]], lf);
    const double d = (lf[0] * s[f[0]] + lf[1] * s[f[1]] + lf[2] * s[f[2]]).squaredNorm();
    if (d < best) {
      best = d;
      l[0] = l[1] = l[2] = l[3] = 0.0;
      for (int q = 0; q < 3; ++q) l[f[q]] = lf[q];
    }
  }
}

}  // namespace

/// Weights of the closest point of the simplex's hull to the origin; a zero weight drops a point.
void closestWeights(const Simplex& s, double l[4]) noexcept {
  l[0] = 1.0; l[1] = l[2] = l[3] = 0.0;
  switch (s.n) {
    case 2: closestOnSegment(s.p[0].w, s.p[1].w, l[0], l[1]); break;
    case 3: closestOnTriangle(s.p[0].w, s.p[1].w, s.p[2].w, l); break;
    case 4: {
      const Vec3 w[4] = {s.p[0].w, s.p[1].w, s.p[2].w, s.p[3].w};
      closestOnTetrahedron(w, l);
      break;
    }
    default: break;
  }
}

}  // namespace clearway::detail
