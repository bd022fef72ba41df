// Closed meshes as solids: which pieces of a link's triangles are closed, and whether a point lies inside
// one (ray parity). A piece is closed when every edge of it, its vertices welded by exact coordinates, is
// shared by an even number of its triangles: the surface is then a cycle mod 2, and a ray from a point not
// on it crosses it an odd number of times exactly when the point is inside (Jordan–Brouwer). A ray that
// passes within rounding of an edge, a vertex or a triangle's plane could count a crossing twice or not at
// all: such a ray is dropped and the next of a fixed set of directions is tried; when all are dropped, the
// point counts as inside (never "outside" by accident).
#include <clearway/body/link_geometry.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>

namespace clearway {
namespace {

// Directions with no simple relation to mesh axes (no zero component: the slab test divides by each).
constexpr int kRays = 8;
const Vec3& rayDirection(int i) noexcept {
  static const Vec3 dirs[kRays] = {
      Vec3(0.5377, 0.8263, -0.1686).normalized(),  Vec3(-0.3259, 0.2391, 0.9147).normalized(),
      Vec3(0.7413, -0.5821, 0.3347).normalized(),  Vec3(-0.6125, -0.4479, -0.6513).normalized(),
      Vec3(0.1873, -0.9512, -0.2451).normalized(), Vec3(-0.8834, 0.3127, -0.3489).normalized(),
      Vec3(0.4021, 0.3569, -0.8431).normalized(),  Vec3(-0.2219, -0.7317, 0.6443).normalized(),
  };
  return dirs[i];
}

// Relative margins (of the barycentric weights, and of a plane's tilt to the ray) below which a crossing
// is not decided by rounding; far above double's rounding of the triple products involved.
constexpr double kEdgeMargin = 1e-9;
constexpr double kParallelMargin = 1e-9;

struct Dsu {
  std::vector<std::int32_t> parent;
  explicit Dsu(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  std::int32_t find(std::int32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void join(std::int32_t a, std::int32_t b) { parent[find(a)] = find(b); }
};

}  // namespace

void LinkGeometry::findSolids() {
  const std::size_t n = triangles_.size();
  solid_of_.assign(n, -1);
  // Weld: one id per distinct vertex coordinate.
  std::vector<std::int32_t> order(3 * n);
  std::iota(order.begin(), order.end(), 0);
  const auto at = [&](std::int32_t k) -> const Vec3& { return triangles_[k / 3].v[k % 3]; };
  const auto less = [&](std::int32_t i, std::int32_t j) {
    const Vec3 &p = at(i), &q = at(j);
    return p.x() < q.x() || (p.x() == q.x() && (p.y() < q.y() || (p.y() == q.y() && p.z() < q.z())));
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<std::int32_t> id(3 * n);
  std::int32_t ids = 0;
  for (std::size_t k = 0; k < order.size(); ++k) {
    if (k > 0 && at(order[k]) != at(order[k - 1])) ++ids;
    id[order[k]] = ids;
  }
  if (n > 0) ++ids;
  // Pieces: vertices joined by triangles.
  Dsu pieces(static_cast<std::size_t>(ids));
  for (std::size_t t = 0; t < n; ++t) {
    pieces.join(id[3 * t], id[3 * t + 1]);
    pieces.join(id[3 * t], id[3 * t + 2]);
  }
  // Edges (welded, unordered) and how many triangles share each; a piece with an odd count is open.
  std::vector<std::uint64_t> edges;
  edges.reserve(3 * n);
  for (std::size_t t = 0; t < n; ++t)
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = static_cast<std::uint32_t>(id[3 * t + e]);
      const std::uint32_t b = static_cast<std::uint32_t>(id[3 * t + (e + 1) % 3]);
      if (a != b) edges.push_back((static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b));
    }
  std::sort(edges.begin(), edges.end());
  std::vector<char> open(static_cast<std::size_t>(ids), 0);
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if ((j - i) % 2 != 0) open[pieces.find(static_cast<std::int32_t>(edges[i] >> 32))] = 1;
    i = j;
  }
  // Number the closed pieces; one probe (a vertex) per piece, closed or not.
  std::vector<std::int32_t> number(static_cast<std::size_t>(ids), -1);
  std::vector<char> probed(static_cast<std::size_t>(ids), 0);
  for (std::size_t t = 0; t < n; ++t) {
    const std::int32_t root = pieces.find(id[3 * t]);
    if (!probed[root]) {
      probed[root] = 1;
      probes_.push_back(triangles_[t].v[0]);
    }
    if (open[root]) continue;
    if (number[root] < 0) {
      number[root] = static_cast<std::int32_t>(solid_boxes_.size());
      solid_boxes_.emplace_back();
    }
    solid_of_[t] = number[root];
    for (const Vec3& v : triangles_[t].v) solid_boxes_[number[root]].grow(v);
  }
  if (solid_boxes_.empty()) solid_of_.clear();
  // A primitive's core point lies in it (spheres and capsules: the centre or the axis).
  for (const Primitive& p : primitives_)
    probes_.push_back(std::visit([&](const auto& s) { return p.pose * s.support(Vec3::UnitX()); }, p.shape));
}

int LinkGeometry::rayParity(int s, const Vec3& p, const Vec3& dir) const noexcept {
  const Vec3 inv(1.0 / dir.x(), 1.0 / dir.y(), 1.0 / dir.z());
  const double grow = 1e-9 * (1.0 + p.cwiseAbs().maxCoeff() + bounding_radius_);  // (boxes' rounding)
  const auto reaches = [&](const Aabb& box) {
    double lo = 0.0, hi = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 3; ++i) {
      double a = (box.min[i] - grow - p[i]) * inv[i], b = (box.max[i] + grow - p[i]) * inv[i];
      if (a > b) std::swap(a, b);
      lo = std::max(lo, a);
      hi = std::min(hi, b);
    }
    return !(lo > hi);  // (a NaN keeps the node)
  };
  int crossings = 0;
  const auto& nodes = tree_.nodes();
  std::int32_t stack[AabbTree::kMaxDepth + 1];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const AabbTree::Node& node = nodes[stack[--top]];
    if (!reaches(node.box)) continue;
    if (!node.isLeaf()) {
      stack[top++] = node.first;
      stack[top++] = node.first + 1;
      continue;
    }
    for (std::int32_t slot = node.first; slot < node.first + node.count; ++slot) {
      const std::int32_t t = tree_.items()[slot];
      if (solid_of_[t] != s || !reaches(tree_.slotBoxes()[slot])) continue;
      const Vec3 a = triangles_[t].v[0] - p, b = triangles_[t].v[1] - p, c = triangles_[t].v[2] - p;
      const Vec3 normal = (b - a).cross(c - a);
      const double nn = normal.norm();
      // A triangle of no area is part of no crossing a ray of these directions can make on its own: a
      // ray through it passes through its neighbours' edges, which drop the ray.
      if (!(nn > 1e-300)) continue;
      // Signed volumes of the ray with each edge: all of one sign when the ray's line passes inside.
      const double wa = dir.dot(b.cross(c)), wb = dir.dot(c.cross(a)), wc = dir.dot(a.cross(b));
      const double sum = wa + wb + wc;  // = dir · normal
      if (std::abs(sum) <= kParallelMargin * nn) {  // the ray runs along the plane: in it, or beside it?
        // Beside it, the plane is crossed at t = |n·a| / |d·n| > max(|a|, |b|, |c|): past every vertex, so off
        // the triangle.
        const double reach = std::max({a.norm(), b.norm(), c.norm()});
        if (std::abs(normal.dot(a)) <= kParallelMargin * nn * (reach + 1e-300)) return -1;
        continue;
      }
      const double la = wa / sum, lb = wb / sum, lc = wc / sum;
      if (la < -kEdgeMargin || lb < -kEdgeMargin || lc < -kEdgeMargin) continue;  // the line misses it
      const double along = normal.dot(a) / sum;  // the ray parameter of the plane
      const double near = 1e-12 * (a.norm() + b.norm() + c.norm());
      if (along < -near) continue;  // behind p
      if (along <= near) return -1;  // p on the triangle (touching) or next to it
      if (la <= kEdgeMargin || lb <= kEdgeMargin || lc <= kEdgeMargin) return -1;  // at an edge or vertex
      ++crossings;
    }
  }
  return crossings & 1;
}

bool LinkGeometry::containsPoint(const Vec3& p) const noexcept {
  if (!p.allFinite()) return !solid_boxes_.empty();
  for (int s = 0; s < solidCount(); ++s) {
    const Aabb& box = solid_boxes_[s];
    const double grow = 1e-9 * (1.0 + bounding_radius_);
    if ((p.array() < box.min.array() - grow).any() || (p.array() > box.max.array() + grow).any()) continue;
    int parity = -1;
    for (int r = 0; r < kRays && parity < 0; ++r) parity = rayParity(s, p, rayDirection(r));
    if (parity != 0) return true;  // inside, or undecided
  }
  return false;
}

bool LinkGeometry::surelyInside(int s, const Vec3& p) const noexcept {
  for (int r = 0; r < 3; ++r)
    if (rayParity(s, p, rayDirection(r)) != 1) return false;
  return true;
}

bool linkContained(const LinkGeometry& a, const LinkGeometry& b, const Pose& b_in_a) noexcept {
  if (b.solidCount() > 0) {
    const Pose a_in_b = b_in_a.inverse();
    for (const Vec3& p : a.probes())
      if (b.containsPoint(a_in_b * p)) return true;
  }
  if (a.solidCount() > 0)
    for (const Vec3& p : b.probes())
      if (a.containsPoint(b_in_a * p)) return true;
  return false;
}

bool shapeInsideLink(const Shape& shape, const Pose& shape_in_link, const LinkGeometry& link) noexcept {
  if (link.solidCount() == 0) return false;
  // The core's support point is a point of the shape (the radius only grows it).
  const Vec3 p = std::visit([](const auto& s) { return s.support(Vec3::UnitX()); }, shape);
  return link.containsPoint(shape_in_link * p);
}

}  // namespace clearway
