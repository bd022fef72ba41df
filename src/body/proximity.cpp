// BodyPair: the proximity ladder of two bodies, written once.
#include <clearway/body/proximity.h>

#include <clearway/detail/margins.h>
#include <clearway/narrowphase/epa.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace clearway {

BodyPair::BodyPair(const LinkGeometry& a, const LinkGeometry& b) : a_(&a), b_(&b) {}

void BodyPair::forget() noexcept {
  hull_ = SimplexCache{};
  parts_stale_ = true;
}

bool BodyPair::intersects(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol,
                          const IntersectQuery& q) noexcept {
  return meshesIntersect(*a_, pose_a, *b_, pose_b, tol, q.mode, q.padding, &hull_);
}

Screen BodyPair::screen(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol, const IntersectQuery& q) noexcept {
  return screenMeshes(*a_, pose_a, *b_, pose_b, tol, q.mode, q.padding, &hull_);
}

bool BodyPair::intersectsExactly(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol,
                                 double padding) const noexcept {
  return meshesIntersectExactly(*a_, pose_a, *b_, pose_b, tol, padding);
}

double BodyPair::convexBound(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol, double enough,
                             double relative, double climb, GeometryMode mode) noexcept {
  const LinkGeometry& a = *a_;
  const LinkGeometry& b = *b_;
  // (In every max() below the bound so far comes second: a NaN rung leaves it, and a NaN first bound
  // gives way to the rung's number.)
  rung_ = Rung::Balls;
  double lower = (pose_a * a.sphereCenter() - pose_b * b.sphereCenter()).norm() - a.sphereRadius() - b.sphereRadius();
  if (!(lower >= enough)) {
    rung_ = Rung::Hulls;
    lower = std::max(gjkLowerBound(a.hull(), pose_a, b.hull(), pose_b, tol, hull_, enough, relative), lower);
  }
  if (!(lower <= climb) || mode == GeometryMode::Hull) return lower >= 0.0 ? lower : 0.0;
  if (parts_stale_ || parts_.empty()) {  // (allocated when first needed: most pairs never get this far)
    parts_.assign(a.parts().size() * b.parts().size(), SimplexCache{});
    parts_stale_ = false;
  }
  rung_ = Rung::Parts;
  return std::max(partsLowerBound(a, pose_a, b, pose_b, tol, enough, relative, parts_.data()), lower);
}

double BodyPair::lowerBound(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol,
                            const BoundQuery& q) noexcept {
  if (!pose_a.isFinite() || !pose_b.isFinite()) return 0.0;
  const double climb = q.climb >= 0.0 ? q.climb : q.enough;
  const double lower = convexBound(pose_a, pose_b, tol, q.enough, q.relative, climb, q.mode);
  if (rung_ != Rung::Parts || !(lower <= climb)) return lower;
  rung_ = Rung::Exact;
  const LinkGeometry& a = *a_;
  const LinkGeometry& b = *b_;
  // The convex pieces are near, so the triangles are (and a fine mesh has many near): whether they lie
  // within `within` is a search that stops at the first pair; only if not, how far they are.
  if (q.within >= 0.0 && meshesIntersect(a, pose_a, b, pose_b, tol, GeometryMode::Mesh, q.within)) return 0.0;
  const DistanceResult m = meshDistance(a, pose_a, b, pose_b, tol, q.relative, std::min(q.enough, q.near));
  if (isFailure(m.status)) return 0.0;
  return q.within >= 0.0 ? std::max(m.lower_bound, q.within * margins::kBeyond) : m.lower_bound;
}

double BodyPair::penetration(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol,
                              double padding) const noexcept {
  if (!(padding >= 0.0) || !std::isfinite(padding)) return std::numeric_limits<double>::quiet_NaN();
  const PenetrationResult r = epaPenetration(a_->hull(), pose_a, b_->hull(), pose_b, tol);
  if (isFailure(r.status)) return std::numeric_limits<double>::quiet_NaN();
  return std::max(0.0, padding - r.signed_distance);  // padded bodies may overlap with their hulls apart
}

DistanceResult BodyPair::distance(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol,
                                  const DistanceQuery& q) noexcept {
  // A finite cutoff lets the convex rungs answer first: bodies they prove at least the cutoff apart get
  // what meshDistance gives when no element pair is nearer (cutoff, points at A's origin), no triangle
  // touched. meshDistance's distance is at least any certified lower bound, so nothing else changes.
  if (q.cutoff < std::numeric_limits<double>::infinity() && q.cutoff > 0.0 && q.relative >= 0.0 &&
      std::isfinite(q.relative) && pose_a.isFinite() && pose_b.isFinite() &&
      convexBound(pose_a, pose_b, tol, q.cutoff, 0.0, q.cutoff, GeometryMode::Mesh) >= q.cutoff) {
    DistanceResult r;
    r.distance = r.lower_bound = q.cutoff;
    r.point_a = r.point_b = pose_a.t;
    r.status = Status::Separated;
    return r;
  }
  rung_ = Rung::Exact;
  return meshDistance(*a_, pose_a, *b_, pose_b, tol, q.relative, q.cutoff);
}

}  // namespace clearway
