#pragma once
// Penetration depth by the Expanding Polytope Algorithm, run only when the cores overlap.
// Based on: G. van den Bergen, "Proximity Queries and Penetration Depth Computation on 3D Game
// Objects" (GDC 2001), and the hybrid approach of the seeds (002): while only the skins overlap,
// GJK's closest points of the cores already give depth and normal; EPA is for deep overlaps.
// The polytope lives in fixed arrays (no allocation); every loop is bounded by the capacity.
#include <clearway/detail/margins.h>
#include <clearway/narrowphase/gjk.h>

namespace clearway {

/// Result of a penetration query. Points and normal are in the world frame.
struct PenetrationResult {
  double depth = 0.0;            ///< > 0 when overlapping (≥ the true depth − tolerance), 0 when separated
  double signed_distance = 0.0;  ///< distance when separated, −depth when overlapping
  Vec3 normal = Vec3::Zero();    ///< unit: B moves along it to separate (points from A towards B)
  Vec3 point_a = Vec3::Zero();   ///< deepest (or closest) point of A (world)
  Vec3 point_b = Vec3::Zero();   ///< deepest (or closest) point of B (world)
  Status status = Status::NotConverged;  ///< why it stopped; isFailure(status): treat as a collision
  int iterations = 0;            ///< GJK's iterations plus EPA's (0 for invalid input)
};

namespace detail {

struct EpaCoreResult {
  double depth;  // penetration depth of the cores
  Vec3 normal;   // unit, A's frame: B moves along it to separate
  Vec3 a, b;     // witnesses on the cores, A's frame
  Status status;
  int iterations;
};

constexpr int kEpaMaxVertices = 128;
constexpr int kEpaMaxFaces = 2 * kEpaMaxVertices;

struct EpaFace {
  int v[3];
  Vec3 n;    // unit outward normal
  double d;  // signed distance of the face's plane from the origin
  bool alive;
};

// The expanding polytope: fixed arrays, no allocation. Its bookkeeping does not depend on the
// shapes, so it is compiled once (epa.cpp) and the per-pair template only calls support.
class EpaPolytope {
 public:
  /// Starts from a tetrahedron (any orientation); false when it has no volume.
  bool init(const SupportPoint tet[4]) noexcept;
  /// The live face nearest the origin (−1 if none).
  int closestFace() const noexcept;
  const EpaFace& face(int f) const noexcept { return faces_[f]; }
  bool hasVertex(const Vec3& w) const noexcept;
  bool full() const noexcept { return nv_ >= kEpaMaxVertices; }
  /// Adds w: removes the faces that see it and closes the horizon; false on a degenerate face or overflow.
  bool expand(const SupportPoint& w, double eps) noexcept;
  /// Witnesses on both cores of the origin's projection onto face f.
  void witnesses(int f, Vec3& a, Vec3& b) const noexcept;

 private:
  bool makeFace(int i, int j, int k, EpaFace& f) const noexcept;
  SupportPoint vs_[kEpaMaxVertices];
  EpaFace faces_[kEpaMaxFaces];
  int nv_ = 0, nf_ = 0;
};

// Core depth for a Minkowski difference without volume: moving B along the flat direction by an
// infinitesimal amount separates the cores, so their depth is 0 and the normal is that direction.
inline EpaCoreResult flatResult(const Vec3& normal, const Simplex& s, int iterations) noexcept {
  EpaCoreResult r{0.0, normal, Vec3::Zero(), Vec3::Zero(), Status::Touching, iterations};
  Simplex t = s;
  reduceSimplex(t);
  simplexWitnesses(t, r.a, r.b);
  return r;
}

inline Vec3 anyPerpendicular(const Vec3& e) noexcept {
  const Vec3 axis = std::abs(e.x()) < std::abs(e.y()) ? (std::abs(e.x()) < std::abs(e.z()) ? Vec3::UnitX() : Vec3::UnitZ())
                                                      : (std::abs(e.y()) < std::abs(e.z()) ? Vec3::UnitY() : Vec3::UnitZ());
  return e.cross(axis).normalized();
}

}  // namespace detail

/// EPA on the cores of md, starting from GJK's final simplex (which must contain or touch the origin).
template <class MD>
detail::EpaCoreResult epaCore(const MD& md, detail::Simplex s, const Tolerances& tol) noexcept {
  using namespace detail;
  double scale = simplexScale(s);
  for (int i = 0; i < s.n; ++i) scale = std::max(scale, s.p[i].w.squaredNorm());
  const double eps = margins::kRounding * std::sqrt(std::max(scale, md.center().squaredNorm()) + 1e-300);
  // Prefer directions pointing from A's centre to B's, so flat cases get a sensible normal.
  const Vec3 toward_b = -md.center();
  auto oriented = [&](Vec3 n) { return n.dot(toward_b) < 0.0 ? Vec3(-n) : n; };

  // Grow GJK's simplex to a tetrahedron; failure means core(A) − core(B) is flat.
  if (s.n == 1) {
    const Vec3 dirs[6] = {Vec3::UnitX(), -Vec3::UnitX(), Vec3::UnitY(), -Vec3::UnitY(), Vec3::UnitZ(), -Vec3::UnitZ()};
    for (const Vec3& d : dirs) {
      const SupportPoint p = md.support(d);
      if ((p.w - s.p[0].w).norm() > eps) { s.p[s.n++] = p; break; }
    }
    if (s.n == 1) return flatResult(oriented(toward_b.squaredNorm() > 0.0 ? toward_b.normalized() : Vec3(Vec3::UnitZ())), s, 0);
  }
  if (s.n == 2) {
    const Vec3 e = s.p[1].w - s.p[0].w;
    const Vec3 u = anyPerpendicular(e);
    const Vec3 u2 = e.normalized().cross(u);
    for (int k = 0; k < 6 && s.n == 2; ++k) {
      const double ang = k * (M_PI / 3.0);
      const SupportPoint p = md.support(std::cos(ang) * u + std::sin(ang) * u2);
      if (e.cross(p.w - s.p[0].w).norm() > eps * e.norm()) s.p[s.n++] = p;
    }
    if (s.n == 2) {
      Vec3 n = toward_b - toward_b.dot(e) / e.squaredNorm() * e;  // perpendicular to the flat direction
      return flatResult(oriented(n.squaredNorm() > 0.0 ? Vec3(n.normalized()) : u), s, 0);
    }
  }
  if (s.n == 3) {
    const Vec3 n = (s.p[1].w - s.p[0].w).cross(s.p[2].w - s.p[0].w).normalized();
    SupportPoint p = md.support(n);
    if (n.dot(p.w - s.p[0].w) <= eps) {
      p = md.support(-n);
      if (-n.dot(p.w - s.p[0].w) <= eps) return flatResult(oriented(n), s, 0);
    }
    s.p[s.n++] = p;
  }

  EpaPolytope poly;
  if (!poly.init(s.p)) return flatResult(oriented(Vec3::UnitZ()), s, 0);
  EpaCoreResult r{0.0, Vec3::Zero(), Vec3::Zero(), Vec3::Zero(), Status::NotConverged, 0};
  double upper = INFINITY;
  int best = -1;
  for (int it = 1;; ++it) {
    r.iterations = it;
    best = poly.closestFace();
    if (best < 0) return r;  // cannot happen for a closed polytope; kept as a proven exit
    const EpaFace& f = poly.face(best);
    const SupportPoint w = md.support(f.n);
    // f.d is a lower bound on the depth, the support plane's offset f.n·w an upper bound.
    upper = std::min(upper, f.n.dot(w.w));
    if (upper - f.d <= tol.epa_relative * std::abs(upper) || !(upper - f.d > eps)) { r.status = Status::Converged; break; }
    if (it >= tol.epa_max_iterations || poly.full()) { r.status = Status::NotConverged; break; }
    if (poly.hasVertex(w.w)) { r.status = Status::RepeatedSupport; break; }
    if (!poly.expand(w, eps)) { r.status = Status::NoProgress; break; }
  }
  poly.witnesses(best, r.a, r.b);
  r.depth = std::max(0.0, poly.face(best).d);
  r.normal = poly.face(best).n;
  return r;
}

/// Penetration depth, normal and witnesses for two posed shapes given as concrete types; when they
/// are apart, the signed distance is their distance (no EPA is run).
template <class A, class B>
PenetrationResult epaPenetration(const A& a, const Pose& pose_a, const B& b, const Pose& pose_b,
                                 const Tolerances& tol = {}) noexcept {
  const MinkowskiDifference<A, B> md{a, b, relativePose(pose_a, pose_b)};
  PenetrationResult r;
  detail::Simplex simplex;
  const detail::GjkCoreResult g = gjkCoreDistance(md, tol, &simplex);
  r.status = g.status;
  r.iterations = g.iterations;
  if (isFailure(g.status)) return r;
  const double ra = a.radius(), rb = b.radius();
  Vec3 ca = g.a, cb = g.b, n;
  double core_signed;
  // The normal is normalised by the witnesses' own gap: ‖v‖ differs from ‖b − a‖ by rounding of order
  // 2⁻⁵³·max‖y‖, which at a distance of 1e-9·max‖y‖ left the "unit" normal 1e-8 off unit length.
  const double gap = (cb - ca).norm();
  if (g.status != Status::Overlapping && g.status != Status::Touching && g.dist > 0.0 && gap > 0.0) {
    // Hybrid: the cores are apart, so their closest points give the contact even if the skins overlap.
    n = (cb - ca) / gap;
    core_signed = g.dist;
  } else {
    const detail::EpaCoreResult e = epaCore(md, simplex, tol);
    r.iterations += e.iterations;
    r.status = e.status;
    if (isFailure(e.status)) return r;
    n = e.normal;
    ca = e.a;
    cb = e.b;
    core_signed = -e.depth;
  }
  r.signed_distance = core_signed - ra - rb;
  r.depth = std::max(0.0, -r.signed_distance);
  r.normal = pose_a.R * n;
  r.point_a = pose_a * (ca + ra * n);
  r.point_b = pose_a * (cb - rb * n);
  return r;
}

/// Penetration query on two posed shapes (see the template above); non-finite poses yield InvalidInput.
PenetrationResult epaPenetration(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                                 const Tolerances& tol = {}) noexcept;

}  // namespace clearway
