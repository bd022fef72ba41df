// Shape-level entry points: validate the numbers once, visit both variants once, and hand the
// concrete pair to the templated algorithm. The 9×9 pair instantiations are split over three files
// (GJK, EPA, casts) so they compile in parallel.
#include <clearway/narrowphase/gjk.h>

#include <type_traits>

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

double gjkLowerBound(const Shape& a, const Pose& pose_a, const Shape& b, const Pose& pose_b, const Tolerances& tol,
                     SimplexCache& cache, double enough, double relative) noexcept {
  if (!pose_a.isFinite() || !pose_b.isFinite()) return 0.0;
  // A hull goes in as a hull with a skin of 0 (the same support and radius): gjkLowerBound<ConvexHull, ...>
  // is the body ladder's hot rung, instantiated in its own files, and a copy of it from here, where 81 of
  // them grow one file, is inlined less and may be the one the linker keeps (+0.5% instructions per motion).
  const auto seen = [](const auto& s) -> decltype(auto) {
    if constexpr (std::is_same_v<std::decay_t<decltype(s)>, ConvexHull>)
      return Margin<ConvexHull>{s, 0.0};
    else
      return s;
  };
  return std::visit(
      [&](const auto& sa, const auto& sb) {
        return gjkLowerBound(seen(sa), pose_a, seen(sb), pose_b, tol, cache, enough, relative);
      },
      a, b);
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
