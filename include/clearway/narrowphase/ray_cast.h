#pragma once
// The GJK ray cast and shape cast.
// Based on: G. van den Bergen, "Ray Casting against General Convex Objects with Application to
// Continuous Collision Detection" (2004). GJK runs from a point x on the ray; whenever a support
// plane separates x from the shape, the ray is clipped to that plane, x advances to the clip point
// and the plane's normal becomes the hit normal. λ only grows and is always a certified lower
// bound on the time of impact, which is why a capped run may still answer "hit at λ" safely.
// A shape cast of A (translating) against B (still) is a ray cast from the origin along −velocity
// against A − B; swept radii shift the support planes outward (the cores stay exact).
// The GJK cast converges linearly on curved shapes and stops at cast_relative; conservative
// advancement on exact distances (refineCast, Newton's method on the distance along the ray) then
// takes t to GJK's rounding band, or proves a miss for a ray that only passes close.
#include <clearway/narrowphase/gjk.h>

#include <limits>

namespace clearway {

/// Result of a ray or shape cast. Normal and point are in the world frame.
struct CastResult {
  bool hit = true;          ///< also true on failure: the caller assumes contact at t
  double t = 0.0;           ///< time of impact (ray parameter); 0 when starting in contact
  Vec3 normal = Vec3::Zero();  ///< unit outward normal of the still shape at the contact; zero when starting inside
  Vec3 point = Vec3::Zero();   ///< contact point on the still shape
  Status status = Status::NotConverged;  ///< why it stopped; isFailure(status): hit is true
  int iterations = 0;          ///< cast and advancement steps run (≤ Tolerances::cast_max_iterations)
};

/// A ray in the world frame: the points origin + t·direction, 0 ≤ t ≤ max_t.
struct Ray {
  Vec3 origin = Vec3::Zero();      ///< the point at t = 0 (world)
  Vec3 direction = Vec3::UnitX();  ///< any length: t counts multiples of it
  double max_t = 1.0;              ///< the last t considered
};

namespace detail {

// Ray from the origin along r against the swept set core(D) ⊕ ball(D.radius()), in A's frame.
template <class MD>
CastResult castCore(const MD& md, const Vec3& r, double max_t, const Tolerances& tol, Vec3& hit_b_core,
                    Vec3& normal_d, bool& exact) noexcept {
  CastResult out;
  const double rsum = md.radius();
  double lambda = 0.0;
  Vec3 x = Vec3::Zero();
  Vec3 n = Vec3::Zero();
  Simplex s;  // points of core(D) with their witnesses; the working simplex is {x − p}
  Vec3 v = x - md.center();
  if (!(v.squaredNorm() > 0.0)) v = r.squaredNorm() > 0.0 ? Vec3(-r) : Vec3(Vec3::UnitX());
  exact = false;
  double lw[4] = {1.0, 0.0, 0.0, 0.0};
  for (int it = 1; it <= tol.cast_max_iterations; ++it) {
    out.iterations = it;
    const double vlen = v.norm();
    if (!std::isfinite(vlen)) { out.status = Status::NotConverged; break; }
    const SupportPoint p = md.support(v);
    const double vw = v.dot(x - p.w);
    bool clipped = false;
    // x within rounding of the support plane counts as touching: only a plane beyond that band may clip
    // or prove a miss. Without it, a ray starting on a rotated box's vertex (2e-16 outside after
    // rounding) and pointing away was a certified miss. The band is the rounding band of GJK
    // (gjk_absolute relative to the size), not the cast tolerance: a band of cast_relative stopped clips
    // early at loose tolerances and left x short of the stopping test (capped runs on cylinders). The size
    // includes ‖x − centre‖: with x on a vertex the yᵢ alone are ~1e-16 long. Clips still go to the plane
    // itself, so λ stays a lower bound.
    double reach = std::max((x - md.center()).squaredNorm(), (x - p.w).squaredNorm());
    for (int i = 0; i < s.n; ++i) reach = std::max(reach, (x - s.p[i].w).squaredNorm());
    const double margin = tol.gjk_absolute * (std::sqrt(reach) + rsum);
    if (vw > (rsum + margin) * vlen) {
      // The support plane (pushed out by the skin) separates x from the shape: clip the ray to it.
      const double vr = v.dot(r);
      if (!(vr < 0.0)) { out.hit = false; out.status = Status::Separated; return out; }
      lambda -= (vw - rsum * vlen) / vr;
      if (!(lambda <= max_t)) { out.hit = false; out.status = Status::Separated; return out; }
      x = lambda * r;
      n = v;
      clipped = true;
    }
    if (inSimplex(s, p.w)) {
      // Only rounding can repeat a point without a clip (exactly, ‖v‖ ≤ rsum would have ended the loop).
      if (!clipped) { out.status = Status::RepeatedSupport; break; }
    } else {
      s.p[s.n++] = p;
    }
    Simplex y = s;
    for (int i = 0; i < y.n; ++i) y.p[i].w = x - s.p[i].w;
    closestWeights(y, lw);
    compactSimplex(s, lw);
    compactSimplex(y, lw);
    v.setZero();
    double scale = 0.0;
    for (int i = 0; i < y.n; ++i) {
      v += y.lambda[i] * y.p[i].w;
      scale = std::max(scale, y.p[i].w.squaredNorm());
    }
    if (s.n == 4) { out.status = Status::Overlapping; break; }
    const double gap = v.norm() - rsum;
    exact = gap <= tol.gjk_absolute * (std::sqrt(scale) + rsum);  // x on D to rounding: nothing to refine
    if (gap <= tol.cast_relative * (std::sqrt(scale) + rsum)) { out.status = Status::Converged; break; }
  }
  out.hit = true;
  out.t = lambda;
  Vec3 a_core, b_core;
  simplexWitnesses(s, a_core, b_core);
  hit_b_core = b_core;
  // With a skin the direction from the core to x is the exact normal; without, the last clip plane is.
  const double vn = v.norm();
  normal_d = rsum > 0.0 && vn > 0.0 ? Vec3(v / vn) : (n.squaredNorm() > 0.0 ? Vec3(n.normalized()) : Vec3::Zero());
  return out;
}

// The difference D seen from the ray point x: core(D) − x, so GJK's distance from the origin is x's distance to D.
template <class MD>
struct ShiftedDifference {
  const MD& md;
  Vec3 x;
  SupportPoint support(const Vec3& d) const noexcept {
    SupportPoint p = md.support(d);
    p.w -= x;
    return p;
  }
  double radius() const noexcept { return md.radius(); }
  Vec3 center() const noexcept { return md.center() - x; }
};

// Conservative advancement to the last digits, after castCore. The GJK cast stops once x is within
// cast_relative of D, which leaves t short by that over the incidence (2e-7 of the size on cylinders
// and cones), calls rays passing 1e-6 outside a sphere hits, and on two curved cores may not get there
// within the cap. Here each step measures x's distance to D with a full GJK distance and clips the ray
// to the plane through D's support point along the measured normal: any plane bounding D is a lower
// bound on the entry (as in castCore), and the closest one makes this Newton's method on the distance
// along the ray, so a transversal hit converges in two or three steps and a ray that passes D is
// carried past its closest approach, where the plane proves the miss. It stops when x is within GJK's
// rounding band of D, and takes at most the cast's remaining iterations; a failed distance query keeps
// castCore's answer, which is already a certified lower bound. Clips stop a rounding margin short of
// the plane, so t never passes the true entry through rounding.
template <class MD>
void refineCast(const MD& md, const Vec3& r, double max_t, const Tolerances& tol, CastResult& out, Vec3& hit_b_core,
                Vec3& normal_d) noexcept {
  constexpr double kRounding = 64 * std::numeric_limits<double>::epsilon();
  const double rsum = md.radius();
  double lambda = out.t;
  for (int it = out.iterations + 1; it <= tol.cast_max_iterations; ++it) {
    const Vec3 x = lambda * r;
    Simplex s;
    const GjkCoreResult c = gjkCoreDistance(ShiftedDifference<MD>{md, x}, tol, &s);
    if (isFailure(c.status)) return;  // castCore's certified λ stands
    out.iterations = it;
    out.t = lambda;
    hit_b_core = c.b;
    if (c.dist == 0.0) { out.status = Status::Converged; return; }  // x on or in the core, to rounding
    // Any plane bounding D gives a lower bound, so try two normals and keep the higher plane: the
    // direction from the closest point, and the simplex's own normal. Once ‖v‖ ≪ the simplex, the
    // former is off by ~2⁻⁵³·size/‖v‖ rad and far more on a sliver (gjkIntersect has the same fix); a
    // plane tilted by α sits ~α²·(D's size) low, which stopped this loop 4e-8 short on a cylinder.
    Vec3 dirs[2] = {x - (c.a - c.b), Vec3::Zero()};  // (from D's core towards x)
    if (s.n == 3) {
      const Vec3 n = (s.p[1].w - s.p[0].w).cross(s.p[2].w - s.p[0].w);
      dirs[1] = -n * n.dot(s.p[0].w);
    } else if (s.n == 2) {
      const Vec3 e = s.p[1].w - s.p[0].w;
      const double ee = e.squaredNorm();
      if (ee > 0.0) dirs[1] = dirs[0] - e * (dirs[0].dot(e) / ee);
    }
    double gap = -INFINITY, reach = 0.0;
    Vec3 v = Vec3::Zero();
    for (const Vec3& d : dirs) {
      const double dlen = d.norm();
      if (!(dlen > 0.0) || !std::isfinite(dlen)) continue;
      const SupportPoint p = md.support(d);
      const double g = d.dot(x - p.w) / dlen - rsum;  // x's height over D's support plane along d
      if (g > gap) {
        gap = g;
        v = d / dlen;
        reach = std::max((x - md.center()).norm(), (x - p.w).norm()) + rsum;
      }
    }
    if (!(gap > -INFINITY)) return;
    normal_d = v;
    if (!(gap > tol.gjk_absolute * reach)) { out.status = Status::Converged; return; }  // within the band: a hit at λ
    // Only comparisons that hold prove a miss; a NaN falls through to "λ stands".
    const double vr = v.dot(r);
    if (vr >= 0.0) { out.hit = false; out.status = Status::Separated; return; }  // moving away from the plane
    const double next = lambda + (gap - kRounding * reach) / -vr;
    if (next > max_t) { out.hit = false; out.status = Status::Separated; return; }
    if (!(next > lambda)) { out.status = Status::NoProgress; return; }  // rounding floor (or a NaN): λ stands
    lambda = next;
  }
  // Iterations used up: λ is certified; the status stays castCore's.
  out.t = lambda;
}

}  // namespace detail

/// Shape cast: A translates by t·velocity_a (world), B stays; the first t in [0, max_t] at which they touch.
template <class A, class B>
CastResult gjkShapeCast(const A& a, const Pose& pose_a, const Vec3& velocity_a, const B& b, const Pose& pose_b,
                        double max_t, const Tolerances& tol = {}) noexcept {
  const MinkowskiDifference<A, B> md{a, b, relativePose(pose_a, pose_b)};
  const Vec3 r = -(pose_a.R.transpose() * velocity_a);
  Vec3 b_core, n_d;
  // The GJK cast converges linearly on curved cores (a cone against a cylinder did not finish in 128
  // iterations) and the refinement quadratically, so past half the cap the rest goes to the refinement.
  Tolerances core_tol = tol;
  if (tol.cast_max_iterations > 8) core_tol.cast_max_iterations = tol.cast_max_iterations / 2;
  bool exact = false;
  CastResult out = detail::castCore(md, r, max_t, core_tol, b_core, n_d, exact);
  if (!out.hit) return out;
  if (!exact && out.status != Status::Overlapping) detail::refineCast(md, r, max_t, tol, out, b_core, n_d);
  if (!out.hit) return out;
  // D = A − B, so D's outward normal at the hit is B's inward one.
  const Vec3 n_b = -n_d;
  out.normal = pose_a.R * n_b;
  out.point = pose_a * (b_core + b.radius() * n_b);
  return out;
}

/// Ray cast against a posed shape: the smallest t in [0, ray.max_t] with origin + t·direction in the solid.
CastResult gjkRayCast(const Shape& shape, const Pose& pose, const Ray& ray, const Tolerances& tol = {}) noexcept;

/// Shape cast of two posed shapes (see the template above); non-finite input yields Status::InvalidInput.
CastResult gjkShapeCast(const Shape& a, const Pose& pose_a, const Vec3& velocity_a, const Shape& b,
                        const Pose& pose_b, double max_t, const Tolerances& tol = {}) noexcept;

}  // namespace clearway
