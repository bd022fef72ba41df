// The sphere tree (sphere_tree.h): built from the top levels of a body's triangle tree and from cells of its
// primitives; queried by distance comparisons, descending the larger ball first.
#include <clearway/body/sphere_tree.h>

#include <clearway/body/link_geometry.h>  // placedBox

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>
#include <variant>

namespace clearway {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

// A radius computed as the norm of differences is within a few ulps of the true one; 8 ulps more holds it.
double roundOut(double r) noexcept { return r * (1.0 + 8.0 * kEps); }

// At most this many balls cover one primitive (cells of its box).
constexpr int kMaxCells = 8;

class Builder {
 public:
  Builder(const std::vector<Triangle>& triangles, const AabbTree& tree, std::vector<SphereTree::Node>& nodes)
      : triangles_(triangles), tree_(tree), nodes_(nodes) {}

  // Node `at` becomes the ball of triangle-tree node n (at `level`) and, above kLevels, its children's parent.
  void mesh(std::size_t at, int n, int level) {
    const AabbTree::Node& tn = tree_.nodes()[n];
    const Vec3 c = tn.box.center();
    double r2 = 0.0;
    forEachTriangle(n, [&](const Triangle& t) {
      for (const Vec3& v : t.v) r2 = std::max(r2, (v - c).squaredNorm());
    });
    nodes_[at].center = c;
    nodes_[at].radius = roundOut(std::sqrt(r2));
    if (tn.isLeaf() || level == SphereTree::kLevels) return;
    const std::size_t first = nodes_.size();
    nodes_.resize(first + 2);
    nodes_[at].first = static_cast<std::int32_t>(first);
    nodes_[at].count = 2;
    mesh(first, tn.first, level + 1);
    mesh(first + 1, tn.first + 1, level + 1);
  }

  // Node `at` becomes the balls covering one primitive.
  void primitive(std::size_t at, const Shape& shape, const Pose& pose) {
    if (const auto* s = std::get_if<Sphere>(&shape)) {
      leaf(at, pose.t, s->r);
    } else if (const auto* s = std::get_if<Capsule>(&shape)) {
      // n pieces of the axis, each a capsule of half length h/n inside the ball of radius r + h/n.
      const int n = std::clamp(static_cast<int>(std::ceil(s->h / s->r)), 1, kMaxCells);
      leaf(at, pose.t, s->r + s->h);
      if (n == 1) return;
      const std::size_t first = children(at, n);
      for (int k = 0; k < n; ++k)
        leaf(first + k, pose * Vec3(0.0, 0.0, -s->h + (2 * k + 1) * s->h / n), s->r + s->h / n);
    } else {
      // The shape's box in its own frame, cut into up to kMaxCells cells along its longest sides.
      const Aabb box = placedBox(shape, Pose());
      const Vec3 e = box.max - box.min;
      int n[3] = {1, 1, 1};
      while (n[0] * n[1] * n[2] * 2 <= kMaxCells) {
        int i = 0;
        for (int k = 1; k < 3; ++k)
          if (e[k] / n[k] > e[i] / n[i]) i = k;
        double shortest = std::numeric_limits<double>::infinity();
        for (int k = 0; k < 3; ++k) shortest = std::min(shortest, e[k] / n[k]);
        if (!(e[i] / n[i] > 1.5 * shortest)) break;  // cells already about cubes
        n[i] *= 2;
      }
      leaf(at, pose * box.center(), 0.5 * e.norm());
      const int cells = n[0] * n[1] * n[2];
      if (cells == 1) return;
      const Vec3 step(e[0] / n[0], e[1] / n[1], e[2] / n[2]);
      const std::size_t first = children(at, cells);
      int k = 0;
      for (int x = 0; x < n[0]; ++x)
        for (int y = 0; y < n[1]; ++y)
          for (int z = 0; z < n[2]; ++z) {
            const Vec3 lo = box.min + Vec3(x * step[0], y * step[1], z * step[2]);
            const Vec3 hi(x + 1 == n[0] ? box.max[0] : lo[0] + step[0], y + 1 == n[1] ? box.max[1] : lo[1] + step[1],
                          z + 1 == n[2] ? box.max[2] : lo[2] + step[2]);
            leaf(first + k++, pose * (0.5 * (lo + hi)), 0.5 * (hi - lo).norm());
          }
    }
  }

  void leaf(std::size_t at, const Vec3& c, double r) {
    nodes_[at].center = c;
    nodes_[at].radius = roundOut(r);
  }

  // Makes n children of node `at`; returns the first.
  std::size_t children(std::size_t at, int n) {
    const std::size_t first = nodes_.size();
    nodes_.resize(first + n);
    nodes_[at].first = static_cast<std::int32_t>(first);
    nodes_[at].count = n;
    return first;
  }

 private:
  template <class F>
  void forEachTriangle(int n, F&& f) const {
    int stack[AabbTree::kMaxDepth + 1];
    int top = 0;
    stack[top++] = n;
    while (top > 0) {
      const AabbTree::Node& node = tree_.nodes()[stack[--top]];
      if (node.isLeaf()) {
        for (int s = node.first; s < node.first + node.count; ++s) f(triangles_[tree_.items()[s]]);
      } else {
        stack[top++] = node.first;
        stack[top++] = node.first + 1;
      }
    }
  }

  const std::vector<Triangle>& triangles_;
  const AabbTree& tree_;
  std::vector<SphereTree::Node>& nodes_;
};

// Enough for any descent that does not overflow it; one that would answers "not apart" (proves nothing).
constexpr int kStack = 256;

}  // namespace

SphereTree::SphereTree(const std::vector<Triangle>& triangles, const AabbTree& tree,
                       const std::vector<Placed>& primitives) {
  const bool mesh = !tree.empty();
  const int top = static_cast<int>(primitives.size()) + (mesh ? 1 : 0);
  if (top == 0) return;
  Builder build(triangles, tree, nodes_);
  // The top-level balls (the triangles', each primitive's) at `first`…; under a root of their own when several.
  std::size_t first = 0;
  nodes_.resize(1);
  if (top > 1) first = build.children(0, top);
  std::size_t at = first;
  if (mesh) build.mesh(at++, 0, 0);
  for (const Placed& p : primitives) build.primitive(at++, *p.shape, p.pose);
  if (top > 1) {
    Aabb box;
    for (int k = 0; k < top; ++k) {
      const Node& c = nodes_[first + k];
      box.grow(c.center - Vec3::Constant(c.radius));
      box.grow(c.center + Vec3::Constant(c.radius));
    }
    const Vec3 c = box.center();
    double r = 0.0;
    for (int k = 0; k < top; ++k) r = std::max(r, (nodes_[first + k].center - c).norm() + nodes_[first + k].radius);
    nodes_[0].center = c;
    nodes_[0].radius = roundOut(r);
  }
  for (const Node& n : nodes_) leaves_ += n.isLeaf();
}

bool sphereTreesApart(const SphereTree& a, const SphereTree& b, const Pose& b_in_a, double gap) noexcept {
  if (a.empty() || b.empty() || !(gap >= 0.0)) return false;
  const auto& na = a.nodes();
  const auto& nb = b.nodes();
  std::int32_t stack[kStack][2];
  int top = 0;
  stack[top][0] = 0;
  stack[top++][1] = 0;
  while (top > 0) {
    --top;
    const SphereTree::Node& x = na[stack[top][0]];
    const SphereTree::Node& y = nb[stack[top][1]];
    const double reach = x.radius + y.radius + gap;
    if ((x.center - b_in_a * y.center).squaredNorm() > reach * reach) continue;  // (a NaN goes on, to a leaf)
    if (x.isLeaf() && y.isLeaf()) return false;
    const bool split_a = !x.isLeaf() && (y.isLeaf() || x.radius >= y.radius);
    const SphereTree::Node& s = split_a ? x : y;
    if (top + s.count > kStack) return false;
    const std::int32_t keep = split_a ? stack[top][1] : stack[top][0];
    for (std::int32_t c = s.first; c < s.first + s.count; ++c) {
      stack[top][split_a ? 0 : 1] = c;
      stack[top++][split_a ? 1 : 0] = keep;
    }
  }
  return true;
}

double sphereTreesLowerBound(const SphereTree& a, const SphereTree& b, const Pose& b_in_a, double enough) noexcept {
  if (a.empty() || b.empty() || !(enough > 0.0)) return 0.0;
  const auto& na = a.nodes();
  const auto& nb = b.nodes();
  double best = enough;  // branch and bound: a pair of balls at least this far apart cannot lower it
  std::int32_t stack[kStack][2];
  int top = 0;
  stack[top][0] = 0;
  stack[top++][1] = 0;
  while (top > 0) {
    --top;
    const SphereTree::Node& x = na[stack[top][0]];
    const SphereTree::Node& y = nb[stack[top][1]];
    const Vec3 cy = b_in_a * y.center;
    // The rounding of the placement and the norm, a few ulps of the coordinates, taken off.
    const double slop = 16.0 * kEps * (x.center.lpNorm<Eigen::Infinity>() + cy.lpNorm<Eigen::Infinity>() + x.radius + y.radius);
    const double gap = (x.center - cy).norm() - x.radius - y.radius - slop;
    if (gap >= best) continue;
    if (!(gap > 0.0)) {
      if (x.isLeaf() && y.isLeaf()) return 0.0;  // (a NaN too)
    } else if (x.isLeaf() && y.isLeaf()) {
      best = gap;
      continue;
    }
    const bool split_a = !x.isLeaf() && (y.isLeaf() || x.radius >= y.radius);
    const SphereTree::Node& s = split_a ? x : y;
    if (top + s.count > kStack) return 0.0;
    const std::int32_t keep = split_a ? stack[top][1] : stack[top][0];
    for (std::int32_t c = s.first; c < s.first + s.count; ++c) {
      stack[top][split_a ? 0 : 1] = c;
      stack[top++][split_a ? 1 : 0] = keep;
    }
  }
  return best;
}

double sphereTreeLowerBoundTo(const SphereTree& tree, const Shape& shape, const Pose& shape_in_tree,
                              double enough) noexcept {
  if (tree.empty() || !(enough > 0.0) || std::holds_alternative<Triangle>(shape) ||
      std::holds_alternative<ConvexHull>(shape))
    return 0.0;
  const Pose tree_in_shape = shape_in_tree.inverse();
  const auto& nodes = tree.nodes();
  double best = enough;
  std::int32_t stack[kStack];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const SphereTree::Node& x = nodes[stack[--top]];
    const Vec3 p = tree_in_shape * x.center;
    const double slop = 16.0 * kEps * (p.lpNorm<Eigen::Infinity>() + shape_in_tree.t.lpNorm<Eigen::Infinity>() + x.radius);
    const double gap = pointShapeLowerBound(shape, p) - x.radius - slop;
    if (gap >= best) continue;
    if (x.isLeaf()) {
      if (!(gap > 0.0)) return 0.0;  // (a NaN too)
      best = gap;
      continue;
    }
    if (top + x.count > kStack) return 0.0;
    for (std::int32_t c = x.first; c < x.first + x.count; ++c) stack[top++] = c;
  }
  return best;
}

double pointShapeLowerBound(const Shape& shape, const Vec3& p) noexcept {
  return std::visit(
      [&](const auto& s) -> double {
        using S = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<S, Point>) {
          return (p - s.p).norm();
        } else if constexpr (std::is_same_v<S, Segment>) {
          const Vec3 d = s.p1 - s.p0;
          const double dd = d.squaredNorm();
          const double u = dd > 0.0 ? std::clamp((p - s.p0).dot(d) / dd, 0.0, 1.0) : 0.0;
          return (p - (s.p0 + u * d)).norm();
        } else if constexpr (std::is_same_v<S, Sphere>) {
          return std::max(0.0, p.norm() - s.r);
        } else if constexpr (std::is_same_v<S, Capsule>) {
          const double z = std::clamp(p.z(), -s.h, s.h);
          return std::max(0.0, Vec3(p.x(), p.y(), p.z() - z).norm() - s.r);
        } else if constexpr (std::is_same_v<S, Box>) {
          return (p.cwiseAbs() - s.half).cwiseMax(0.0).norm();
        } else if constexpr (std::is_same_v<S, Cylinder> || std::is_same_v<S, Cone>) {
          // (A cone lies in the cylinder of its base radius and height.)
          const double radial = std::max(0.0, std::hypot(p.x(), p.y()) - s.r);
          const double axial = std::max(0.0, std::abs(p.z()) - s.h);
          return std::hypot(radial, axial);
        } else {
          return p.allFinite() ? 0.0 : std::numeric_limits<double>::quiet_NaN();
        }
      },
      shape);
}

bool sphereTreeApartFrom(const SphereTree& tree, const Shape& shape, const Pose& shape_in_tree, double gap) noexcept {
  if (tree.empty() || !(gap >= 0.0) || std::holds_alternative<Triangle>(shape) ||
      std::holds_alternative<ConvexHull>(shape))
    return false;
  const Pose tree_in_shape = shape_in_tree.inverse();
  const auto& nodes = tree.nodes();
  std::int32_t stack[kStack];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const SphereTree::Node& x = nodes[stack[--top]];
    // The rounding of the point's placement and of the distance is the caller's band (within `gap`).
    if (pointShapeLowerBound(shape, tree_in_shape * x.center) > x.radius + gap) continue;  // (NaN goes on)
    if (x.isLeaf() || top + x.count > kStack) return false;
    for (std::int32_t c = x.first; c < x.first + x.count; ++c) stack[top++] = c;
  }
  return true;
}

}  // namespace clearway
