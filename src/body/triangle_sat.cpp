// The triangle–triangle separating-axis test (17 axes: 2 normals, 9 edge–edge cross products, 6 in-plane
// edge normals), the cheap rejection before GJK on a triangle pair (proximity.cpp).
#include <clearway/body/proximity.h>

#include <algorithm>
#include <cmath>

namespace clearway::detail {

bool trianglesSeparated(const Vec3 a[3], const Vec3 b[3], double slack) noexcept {
  // Axes shorter than this are (near-)parallel cross products: skipping them only keeps a pair.
  constexpr double kMinAxis2 = 1e-200;
  const auto apart = [&](const Vec3& L) {
    const double a0 = L.dot(a[0]), a1 = L.dot(a[1]), a2 = L.dot(a[2]);
    const double b0 = L.dot(b[0]), b1 = L.dot(b[1]), b2 = L.dot(b[2]);
    const double gap = std::max(std::min({b0, b1, b2}) - std::max({a0, a1, a2}),
                                std::min({a0, a1, a2}) - std::max({b0, b1, b2}));
    if (!(gap > 0.0)) return false;
    const double ll = L.squaredNorm();
    return ll > kMinAxis2 && gap * gap > slack * slack * ll;
  };
  const Vec3 ea[3] = {a[1] - a[0], a[2] - a[1], a[0] - a[2]};
  const Vec3 eb[3] = {b[1] - b[0], b[2] - b[1], b[0] - b[2]};
  const Vec3 na = ea[0].cross(ea[1]);
  const Vec3 nb = eb[0].cross(eb[1]);
  if (apart(na) || apart(nb)) return true;
  for (const Vec3& e : ea)
    for (const Vec3& f : eb)
      if (apart(e.cross(f))) return true;
  // Parallel planes: the Minkowski difference is flat, and its in-plane edge normals are the axes.
  for (int i = 0; i < 3; ++i)
    if (apart(na.cross(ea[i])) || apart(nb.cross(eb[i]))) return true;
  return false;
}

}  // namespace clearway::detail
