// BodyPair: the proximity ladder of two bodies, written once.
#include <clearway/body/proximity.h>

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

double BodyPair::lowerBound(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol,
                            const BoundQuery& q) noexcept {
  if (!pose_a.isFinite() || !pose_b.isFinite()) return 0.0;
  const LinkGeometry& a = *a_;
  const LinkGeometry& b = *b_;
  const double climb = q.climb >= 0.0 ? q.climb : q.enough;
  // (In every max() below the bound so far comes second: a NaN rung leaves it, and a NaN first bound
  // gives way to the rung's number.)
  rung_ = Rung::Balls;
  double lower = (pose_a * a.sphereCenter() - pose_b * b.sphereCenter()).norm() - a.sphereRadius() - b.sphereRadius();
  if (!(lower >= q.enough)) {
    rung_ = Rung::Hulls;
    lower = std::max(gjkLowerBound(a.hull(), pose_a, b.hull(), pose_b, tol, hull_, q.enough, q.relative), lower);
  }
  if (!(lower <= climb) || q.mode == GeometryMode::Hull) return lower >= 0.0 ? lower : 0.0;
  if (parts_stale_ || parts_.empty()) {  // (allocated when first needed: most pairs never get this far)
    parts_.assign(a.parts().size() * b.parts().size(), SimplexCache{});
    parts_stale_ = false;
  }
  rung_ = Rung::Parts;
  lower = std::max(partsLowerBound(a, pose_a, b, pose_b, tol, q.enough, q.relative, parts_.data()), lower);
  if (!(lower <= climb)) return lower;
  rung_ = Rung::Exact;
  // The convex pieces are near, so the triangles are (and a fine mesh has many near): whether they lie
  // within `within` is a search that stops at the first pair; only if not, how far they are.
  if (q.within >= 0.0 && meshesIntersect(a, pose_a, b, pose_b, tol, GeometryMode::Mesh, q.within)) return 0.0;
  const DistanceResult m = meshDistance(a, pose_a, b, pose_b, tol, q.relative, std::min(q.enough, q.near));
  if (isFailure(m.status)) return 0.0;
  return q.within >= 0.0 ? std::max(m.lower_bound, q.within * (1.0 + 1e-9)) : m.lower_bound;
}

double BodyPair::penetration(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol,
                              double padding) const noexcept {
  if (!(padding >= 0.0) || !std::isfinite(padding)) return std::numeric_limits<double>::quiet_NaN();
  const PenetrationResult r = epaPenetration(a_->hull(), pose_a, b_->hull(), pose_b, tol);
  if (isFailure(r.status)) return std::numeric_limits<double>::quiet_NaN();
  return std::max(0.0, padding - r.signed_distance);  // padded bodies may overlap with their hulls apart
}

DistanceResult BodyPair::distance(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol,
                                  const DistanceQuery& q) const noexcept {
  return meshDistance(*a_, pose_a, *b_, pose_b, tol, q.relative, q.cutoff);
}

}  // namespace clearway
