// Shape-level entry points: validate the numbers once, visit both variants once, and hand the
// concrete pair to the templated algorithm. The 9×9 pair instantiations are split over three files
// (GJK, EPA, casts) so they compile in parallel.
#include <clearway/narrowphase/gjk.h>

namespace clearway {

DistanceResult gjkDistance(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                           const Tolerances& tol) noexcept {
  if (!pose_a.isFinite() || !pose_b.isFinite()) {
    DistanceResult r;
    r.status = Status::InvalidInput;
    return r;
  }
  return std::visit([&](const auto& sa, const auto& sb) { return gjkDistance(sa, pose_a, sb, pose_b, tol); }, a, b);
}

IntersectResult gjkIntersect(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b,
                             const Tolerances& tol, SimplexCache& cache) noexcept {
  if (!pose_a.isFinite() || !pose_b.isFinite()) {
    IntersectResult r;
    r.status = Status::InvalidInput;
    return r;
  }
  return std::visit([&](const auto& sa, const auto& sb) { return gjkIntersect(sa, pose_a, sb, pose_b, tol, cache); },
                    a, b);
}

}  // namespace clearway
