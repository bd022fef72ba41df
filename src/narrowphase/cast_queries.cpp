// Shape-level entry points: validate the numbers once, visit both variants once, and hand the
// concrete pair to the templated algorithm. The 9×9 pair instantiations are split over three files
// (GJK, EPA, casts) so they compile in parallel.
#include <clearway/narrowphase/ray_cast.h>

namespace clearway {

CastResult gjkShapeCast(const Shape& a, const Pose& pose_a, const Vec3& velocity_a, const Shape& b,
                        const Pose& pose_b, double max_t, const Tolerances& tol) noexcept {
  if (!pose_a.isFinite() || !pose_b.isFinite() || !velocity_a.allFinite() || std::isnan(max_t) || max_t < 0.0) {
    CastResult r;
    r.status = Status::InvalidInput;
    return r;
  }
  return std::visit(
      [&](const auto& sa, const auto& sb) { return gjkShapeCast(sa, pose_a, velocity_a, sb, pose_b, max_t, tol); }, a,
      b);
}

CastResult gjkRayCast(const Shape& shape, const Pose& pose, const Ray& ray, const Tolerances& tol) noexcept {
  if (!pose.isFinite() || !ray.origin.allFinite() || !ray.direction.allFinite() || std::isnan(ray.max_t) ||
      ray.max_t < 0.0) {
    CastResult r;
    r.status = Status::InvalidInput;
    return r;
  }
  // A ray is a point translating along the direction.
  const Point origin;
  return std::visit(
      [&](const auto& s) { return gjkShapeCast(origin, Pose::translation(ray.origin), ray.direction, s, pose, ray.max_t, tol); },
      shape);
}

}  // namespace clearway
