#pragma once
// GJK distance and intersection on support mappings.
// Based on: G. van den Bergen, "A Fast and Robust GJK Implementation for Collision Detection of
// Convex Objects" (JGT 1999) and "Collision Detection in Interactive 3D Environments" (2003):
// termination on the gap between upper bound ‖v‖ and lower bound v·w/‖v‖, on ‖v‖ under an absolute
// tolerance scaled by the simplex, on a repeated support point, on no progress, or at the cap.
// Sub-algorithm: signed volumes (simplex.h). Shapes are swept cores (primitives.h): GJK runs on the
// cores and the radii are subtracted at the end, the "hybrid" approach that makes sphere and
// capsule queries exact in one or two iterations.
#include <clearway/narrowphase/simplex.h>
#include <clearway/narrowphase/status.h>
#include <clearway/shape/shape.h>
#include <clearway/tolerances.h>

#include <limits>

namespace clearway {

/// Result of a distance query. Points and normal are in the world frame (the frame of the poses).
struct DistanceResult {
  double distance = 0.0;     ///< upper bound on the distance, 0 when the shapes overlap
  double lower_bound = 0.0;  ///< certified lower bound on the distance (GJK's v·w/‖v‖ minus the radii)
  Vec3 point_a = Vec3::Zero();  ///< closest point on A (world)
  Vec3 point_b = Vec3::Zero();  ///< closest point on B (world)
  Vec3 normal = Vec3::Zero();   ///< unit, from A towards B; zero when the cores overlap
  Status status = Status::NotConverged;  ///< why it stopped; isFailure(status): mayCollide() is true
  int iterations = 0;           ///< GJK iterations run (≤ Tolerances::gjk_max_iterations)
  /// True when the shapes may touch: overlap, touching, or a query that failed (never "free" by accident).
  bool mayCollide() const noexcept { return isFailure(status) || distance <= 0.0; }
};

/// The separating axis found by the last intersection query of a pair, kept by the caller for the next one.
struct SimplexCache {
  Vec3 axis = Vec3::Zero();  ///< in A's local frame, so it survives when both shapes move together
  bool valid = false;        ///< false until a query found an axis: then the next one starts from it
  ///@{
  std::int32_t hint_a = -1, hint_b = -1;  ///< where the support searches of A and B ended (hulls resume there)
  ///@}
};

/// Result of an intersection query.
struct IntersectResult {
  bool intersecting = true;  ///< true also when status is a failure: callers assume a collision
  Status status = Status::NotConverged;  ///< why it stopped (Separated: a separating axis was proven)
  int iterations = 0;        ///< GJK iterations run (≤ Tolerances::gjk_max_iterations)
};

namespace detail {

// The absolute tolerance of GJK: below ‖v‖ ≤ tol·max‖yᵢ‖ the rounding in v exceeds v itself.
inline double simplexScale(const Simplex& s) noexcept {
  double m = 0.0;
  for (int i = 0; i < s.n; ++i) m = std::max(m, s.p[i].w.squaredNorm());
  return m;
}

inline bool inSimplex(const Simplex& s, const Vec3& w) noexcept {
  for (int i = 0; i < s.n; ++i)
    if (s.p[i].w == w) return true;
  return false;
}

// The closest point v of a reduced simplex, made true to rounding at any ‖v‖ (see gjkIntersect): three
// points give it as the origin's projection on their plane, two as v orthogonal to their edge.
inline void refineClosest(const Simplex& s, Vec3& v) noexcept {
  if (s.n == 3) {
    const Vec3 n = (s.p[1].w - s.p[0].w).cross(s.p[2].w - s.p[0].w);
    const double nn = n.squaredNorm();
    if (nn > 0.0) v = n * (n.dot(s.p[0].w) / nn);
  } else if (s.n == 2) {
    const Vec3 e = s.p[1].w - s.p[0].w;
    const double ee = e.squaredNorm();
    if (ee > 0.0) v -= e * (v.dot(e) / ee);
  }
}

struct GjkCoreResult {
  Vec3 a, b;          // witnesses on the cores, A's frame
  double dist;        // ‖v‖: upper bound on the core distance
  double lower;       // lower bound on the core distance
  Status status;
  int iterations;
};

}  // namespace detail

/// How far below GJK's absolute band a distance query goes.
struct CoreBand {
  /// False: cores within tol.gjk_absolute of the simplex's size are Touching (distance 0). True: such a
  /// query goes on with the rounding of its own computation as the band, as gjkIntersect does, and its
  /// lower bound is certified to that rounding: what the intersection test calls apart, the distance
  /// proves apart, so a state the validity checker accepts has a clearance a motion can start from.
  bool to_rounding = false;
  /// The L1 norm of the lengths whose rounding every step carries: the world translations the relative
  /// pose was computed from, its translation and the radii (as gjkIntersect counts them).
  double world = 0.0;
  Vec3 b_origin = Vec3::Zero();  ///< B's origin in A's frame (B's support points are measured from it)
};

/// The rounding of one GJK step of a Minkowski difference: 32 ulps of the L1 lengths involved (the
/// world translations, the support points and the relative pose's translation; a plane's height carries a
/// few). Shared by gjkIntersect, which calls shapes apart beyond twice it, and the distance's rounding
/// band, which subtracts it once: so both draw the line in one place, with room between them.
inline double gjkRounding(double world, const Vec3& a, const Vec3& b_minus_t) noexcept {
  constexpr double kUlps = 32 * std::numeric_limits<double>::epsilon();
  return kUlps * (world + a.cwiseAbs().sum() + b_minus_t.cwiseAbs().sum());
}

/// Distance between the cores of a Minkowski difference, in A's frame (the building block of every query).
/// When `final_simplex` is given it receives the last simplex (EPA starts from it).
template <class MD>
detail::GjkCoreResult gjkCoreDistance(const MD& md, const Tolerances& tol, detail::Simplex* final_simplex = nullptr,
                                      CoreBand precision = {}) noexcept {
  using namespace detail;
  Simplex s;
  Vec3 dir = md.center();
  if (!(dir.squaredNorm() > 0.0)) dir = Vec3::UnitX();
  s.p[0] = md.support(-dir);
  s.lambda[0] = 1.0;
  s.n = 1;
  Vec3 v = s.p[0].w;
  double vv = v.squaredNorm();
  double lower = 0.0;
  const double world = precision.world;
  double rounding = precision.to_rounding ? gjkRounding(world, s.p[0].a, s.p[0].b - precision.b_origin) : 0.0;
  bool in_band = false;  // (to_rounding) below gjk_absolute: the rounding is the band
  GjkCoreResult r{s.p[0].a, s.p[0].b, std::sqrt(vv), 0.0, Status::NotConverged, 0};
  for (int it = 1; it <= tol.gjk_max_iterations; ++it) {
    r.iterations = it;
    if (!(vv >= 0.0) || !std::isfinite(vv)) { r.status = Status::NotConverged; return r; }
    if (!in_band && vv <= tol.gjk_absolute * tol.gjk_absolute * simplexScale(s)) {
      if (!precision.to_rounding) { r.status = Status::Touching; break; }
      in_band = true;
    }
    if (in_band && vv <= rounding * rounding) { r.status = Status::Touching; break; }
    const SupportPoint p = md.support(-v);
    if (precision.to_rounding) rounding = std::max(rounding, gjkRounding(world, p.a, p.b - precision.b_origin));
    const double vw = v.dot(p.w);
    if (vw > 0.0) lower = std::max(lower, vw / std::sqrt(vv));
    // ‖v‖ − v·w/‖v‖ ≤ ε‖v‖, multiplied through by ‖v‖ to avoid a square root.
    if (vv - vw <= tol.gjk_relative * vv) { r.status = Status::Converged; break; }
    if (inSimplex(s, p.w)) { r.status = Status::RepeatedSupport; break; }
    s.p[s.n++] = p;
    const Simplex before = s;
    Vec3 v_next = reduceSimplex(s);
    // Far below the simplex's size, v's direction is off by ~2⁻⁵³·size/‖v‖ (gjkIntersect explains the
    // fix): the plane's normal, or v made orthogonal to the edge, keeps the lower bound true to rounding
    // (from the step that reaches the band on: that step's v is the next one's direction).
    if (precision.to_rounding) refineClosest(s, v_next);
    const double vv_next = v_next.squaredNorm();
    if (s.n == 4) { v = v_next; vv = 0.0; r.status = Status::Overlapping; break; }
    // ‖v‖ must strictly decrease in exact arithmetic; when rounding stops that, the previous simplex is
    // the best answer there is.
    if (!(vv_next < vv)) { s = before; s.n = before.n - 1; r.status = Status::NoProgress; break; }
    v = v_next;
    vv = vv_next;
  }
  if (r.status == Status::NotConverged) return r;  // cap reached: no certificate
  // Within the rounding band, a pair whose certified bound is not above the rounding is touching (its ‖v‖
  // may sit a hair above 0 while the cores overlap).
  if (in_band && r.status != Status::Overlapping && !(std::min(lower, std::sqrt(vv)) > rounding))
    r.status = Status::Touching;
  if (final_simplex) *final_simplex = s;
  simplexWitnesses(s, r.a, r.b);
  // Touching means ‖v‖ is below rounding: the distance is 0 (tolerances.h). Reporting ‖v‖ instead made
  // mayCollide() false for pairs whose simplex merely passed near the origin while they overlapped deeply
  // (a 1e-3 box overlapping a 1e3 box's corner by 1e-4 came out "free" at 1.6e-13).
  r.dist = r.status == Status::Overlapping || r.status == Status::Touching ? 0.0 : std::sqrt(vv);
  // A plane's height is computed with the step's rounding: to_rounding subtracts it, so the bound is certified.
  r.lower = r.status == Status::Overlapping || r.status == Status::Touching ? 0.0
                                                                          : std::max(0.0, std::min(lower, r.dist) - rounding);
  return r;
}

/// Distance between two posed convex shapes given as concrete types (the fast path for hot loops).
template <class A, class B>
DistanceResult gjkDistance(const A& a, const Pose& pose_a, const B& b, const Pose& pose_b,
                           const Tolerances& tol = {}) noexcept {
  const MinkowskiDifference<A, B> md{a, b, relativePose(pose_a, pose_b)};
  const double world = pose_a.t.cwiseAbs().sum() + pose_b.t.cwiseAbs().sum() + md.b_in_a.t.cwiseAbs().sum() + md.radius();
  const detail::GjkCoreResult c = gjkCoreDistance(md, tol, nullptr, {true, world, md.b_in_a.t});
  DistanceResult r;
  r.status = c.status;
  r.iterations = c.iterations;
  if (isFailure(c.status)) return r;
  const double ra = a.radius(), rb = b.radius();
  Vec3 n = c.b - c.a;
  const double len = n.norm();
  n = len > 0.0 ? Vec3(n / len) : Vec3::Zero();
  // The witnesses move out of the cores by each radius along the normal; inside the skins they cross.
  r.point_a = pose_a * (c.a + ra * n);
  r.point_b = pose_a * (c.b - rb * n);
  r.normal = pose_a.R * n;
  r.distance = std::max(0.0, c.dist - ra - rb);
  r.lower_bound = std::max(0.0, c.lower - ra - rb);
  if (c.dist < ra + rb && c.status != Status::Overlapping) r.status = Status::Overlapping;
  return r;
}

/// Boolean intersection that stops at the first separating axis; the axis goes back into `cache`
/// and starts the next query of the same pair, so smoothly moving pairs take about one iteration.
/// Shapes within the rounding of the computation (a few ulps of every length involved) of touching count
/// as intersecting; so do pairs GJK cannot tell apart within the cap.
template <class A, class B>
IntersectResult gjkIntersect(const A& a, const Pose& pose_a, const B& b, const Pose& pose_b,
                             const Tolerances& tol, SimplexCache& cache) noexcept {
  using namespace detail;
  const MinkowskiDifference<A, B> md{a, b, relativePose(pose_a, pose_b), cache.hint_a, cache.hint_b};
  // The support searches' end points go back into the cache however the query ends.
  struct SaveHints {
    const MinkowskiDifference<A, B>& md;
    SimplexCache& cache;
    ~SaveHints() { cache.hint_a = md.hint_a; cache.hint_b = md.hint_b; }
  } save_hints{md, cache};
  const double rsum = md.radius();
  Vec3 v = cache.valid ? cache.axis : md.center();
  if (!(v.squaredNorm() > 0.0)) v = Vec3::UnitX();
  Simplex s;
  double vv = v.squaredNorm();
  double lower = -INFINITY;
  IntersectResult r;
  // The band of gjk_absolute is 1e-10 of the size of A − B, which for a 1e-3 box on a 1e3 one is 2e-7,
  // a million times the rounding of coordinates near 1e3 (~1e-13). It ends GJK near contact; what decides
  // is the rounding of the whole computation relative to the shapes as given (the relative pose, the
  // support points, the dot products): a few ulps of every length involved, world translations
  // included, and 64 ulps of their sum (L1 norms: no square roots, never smaller; twice gjkRounding) is
  // generous. A plane
  // clearing A − B by more than that separates them, and a pair that reaches the band goes on with the
  // rounding as its band (to the cap at most, where it counts as intersecting), so pairs 1e-10 apart
  // are told from touching ones at any size ratio. Apart means clear by twice gjkRounding: a distance
  // query certifies its bound with one subtracted (CoreBand), so what this test calls apart, a motion
  // starting there can measure as apart (one notion of contact for states and motions).
  const double world = pose_a.t.cwiseAbs().sum() + pose_b.t.cwiseAbs().sum() + md.b_in_a.t.cwiseAbs().sum() + rsum;
  double rounding = 0.0;
  bool in_band = false;
  for (int it = 1; it <= tol.gjk_max_iterations; ++it) {
    r.iterations = it;
    const SupportPoint p = md.support(-v);
    const double vlen = std::sqrt(vv);
    rounding = std::max(rounding, gjkRounding(world, p.a, p.b - md.b_in_a.t));
    // The band keeps exactly touching shapes (rounding either way) on the colliding side.
    const double band = in_band ? 2.0 * rounding
                                : std::max(2.0 * rounding, tol.gjk_absolute * (std::sqrt(std::max(simplexScale(s), p.w.squaredNorm())) + rsum));
    const double vw = v.dot(p.w);
    if (vw > (rsum + band) * vlen) {
      cache.axis = v;
      cache.valid = true;
      r.intersecting = false;
      r.status = Status::Separated;
      return r;
    }
    lower = std::max(lower, vw / vlen);
    if (s.n > 0 && (inSimplex(s, p.w) || vv - vw <= tol.gjk_relative * vv)) {
      // The distance is known to rounding (or to the tolerance): decide by the certified lower bound,
      // colliding when in doubt.
      r.intersecting = !(lower > rsum + 2.0 * rounding);
      r.status = inSimplex(s, p.w) ? Status::RepeatedSupport : Status::Converged;
      if (!r.intersecting) { cache.axis = v; cache.valid = true; }
      return r;
    }
    s.p[s.n++] = p;
    Vec3 v_next = reduceSimplex(s);
    // v is a weighted sum of points ~max‖y‖ long, so once ‖v‖ ≪ max‖y‖ its direction is off by
    // ~2⁻⁵³·max‖y‖/‖v‖ rad and v·w/‖v‖ misses the distance by that times max‖y‖: boxes 1e-8 apart
    // (size 1) got a negative lower bound and were called intersecting (via RepeatedSupport or
    // NoProgress). Three points left: the closest point is the origin's projection on the triangle's
    // plane, which its normal gives to rounding at any ‖v‖. Two: v must be orthogonal to the edge;
    // removing the along-edge error keeps support(−v) from swinging to a far endpoint (an error across
    // the edge only turns v inside the edge's normal cone, which leaves v·w unchanged).
    refineClosest(s, v_next);
    const double vv_next = v_next.squaredNorm();
    if (s.n == 4) { r.status = Status::Overlapping; return r; }
    if (vv_next <= (rsum + band) * (rsum + band)) {
      r.status = Status::Touching;
      if (in_band || !(vv_next > (rsum + 2.0 * rounding) * (rsum + 2.0 * rounding))) return r;
      in_band = true;  // within gjk_absolute: go on with the rounding as the band
    }
    if (!(vv_next < vv) && it > 1) { r.status = Status::NoProgress; return r; }  // intersecting, conservatively
    if (!std::isfinite(vv_next)) { r.status = Status::NotConverged; return r; }
    v = v_next;
    vv = vv_next;
  }
  r.status = Status::NotConverged;
  return r;
}

/// A certified lower bound on the distance between two posed convex shapes (0 when they may touch),
/// for conservative advancement, where a bound that is large enough beats an exact distance: GJK starts
/// from the pair's cached axis and stops once the bound reaches `enough` metres or is within `relative`
/// (a fraction of the distance) of it. Any direction v gives the bound v·w/‖v‖ (w the support point
/// along −v), so the answer is certified however the loop ends, and a failed query only weakens it.
template <class A, class B>
double gjkLowerBound(const A& a, const Pose& pose_a, const B& b, const Pose& pose_b, const Tolerances& tol,
                     SimplexCache& cache, double enough, double relative) noexcept {
  using namespace detail;
  const MinkowskiDifference<A, B> md{a, b, relativePose(pose_a, pose_b), cache.hint_a, cache.hint_b};
  const double rsum = md.radius();
  Vec3 v = cache.valid ? cache.axis : md.center();
  if (!(v.squaredNorm() > 0.0) || !v.allFinite()) v = Vec3::UnitX();
  double vv = v.squaredNorm();
  double lower = 0.0;  // on the cores' distance
  Simplex s;
  for (int it = 1; it <= tol.gjk_max_iterations; ++it) {
    const SupportPoint p = md.support(-v);
    const double vw = v.dot(p.w);
    if (vw > 0.0) lower = std::max(lower, vw / std::sqrt(vv));
    if (!(lower - rsum < enough)) break;
    // Until the simplex holds a point, v is only a direction: the relative test needs v in the difference.
    // Relative to the distance of the shapes, skins included (‖v‖ − rsum bounds it from above): cores far
    // apart under thick skins (two capsules) would otherwise stop with a bound far short of it. Skins that
    // overlap (‖v‖ ≤ rsum): the distance is 0, which the bound already is.
    const double skin = rsum > 0.0 ? rsum * std::sqrt(vv) : 0.0;  // rsum·‖v‖
    if (s.n > 0 && (vv - vw <= relative * (vv - skin) || skin >= vv || inSimplex(s, p.w))) break;
    s.p[s.n++] = p;
    const Vec3 v_next = reduceSimplex(s);
    const double vv_next = v_next.squaredNorm();
    if (s.n == 4) { lower = 0.0; break; }             // the origin is inside: overlapping
    if (it > 1 && !(vv_next < vv)) break;            // rounding stalls progress: keep what is proven
    if (!std::isfinite(vv_next) || !(vv_next > 0.0)) { lower = 0.0; break; }
    v = v_next;
    vv = vv_next;
  }
  cache.hint_a = md.hint_a;
  cache.hint_b = md.hint_b;
  if (std::isfinite(vv) && vv > 0.0) {
    cache.axis = v;
    cache.valid = true;
  }
  const double d = lower - rsum;
  return std::isfinite(d) && d > 0.0 ? d : 0.0;
}

/// Distance between two posed shapes: witness points and normal in the world frame.
/// A non-finite pose yields Status::InvalidInput.
DistanceResult gjkDistance(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                           const Tolerances& tol = {}) noexcept;

/// gjkLowerBound of two posed shapes (the template above, for each pair of shape types).
double gjkLowerBound(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b, const Tolerances& tol,
                     SimplexCache& cache, double enough, double relative) noexcept;

/// Intersection of two posed shapes with separating-axis caching (see the template above).
IntersectResult gjkIntersect(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                             const Tolerances& tol, SimplexCache& cache) noexcept;

}  // namespace clearway
