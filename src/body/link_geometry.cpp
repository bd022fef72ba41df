// LinkGeometry: construction (triangles, tree, hull, convex parts, solids, cores). The proximity
// ladder is in proximity.cpp, the triangle–triangle separating-axis test in triangle_sat.cpp.
#include <clearway/body/link_geometry.h>
#include <clearway/detail/margins.h>
#include <clearway/tree/oriented_box_test.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>

namespace clearway {
namespace {


// ---- Construction -----------------------------------------------------------------------------------

std::vector<Triangle> meshTriangles(const TriangleMesh& mesh, const Pose& origin, std::vector<Triangle> out = {}) {
  const auto nv = static_cast<std::int64_t>(mesh.vertices.size());
  for (const auto& t : mesh.triangles) {
    for (const std::int32_t i : t)
      if (i < 0 || i >= nv)
        throw ShapeError("link geometry: triangle index " + std::to_string(i) + " out of range (" +
                         std::to_string(nv) + " vertices)");
    out.emplace_back(origin * mesh.vertices[t[0]], origin * mesh.vertices[t[1]], origin * mesh.vertices[t[2]]);
  }
  return out;
}

// Unit directions whose hull circumscribes the unit ball once scaled by kBallScale: a Fibonacci sphere.
constexpr double kPi = 3.14159265358979323846;
constexpr int kBallPoints = 64;
constexpr int kCirclePoints = 16;

struct UnitBall {
  std::vector<Vec3> points;  // scaled so that their hull contains the unit ball
};

const UnitBall& circumscribedUnitBall() {
  static const UnitBall ball = [] {
    UnitBall b;
    const double golden = kPi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < kBallPoints; ++i) {
      const double z = 1.0 - (2.0 * i + 1.0) / kBallPoints;
      const double r = std::sqrt(1.0 - z * z);
      b.points.emplace_back(r * std::cos(golden * i), r * std::sin(golden * i), z);
    }
    // The hull's nearest face plane to the centre: scaling by its inverse pushes every face out to
    // distance ≥ 1, and the factor kBeyond covers the rounding of the planes.
    const ConvexHull hull(b.points);
    double nearest = std::numeric_limits<double>::infinity();
    for (const auto& t : hull.triangles()) {
      const Vec3& p0 = hull.vertices()[t[0]];
      const Vec3 n = (hull.vertices()[t[1]] - p0).cross(hull.vertices()[t[2]] - p0).normalized();
      nearest = std::min(nearest, std::abs(n.dot(p0)));
    }
    const double scale = margins::kBeyond / nearest;
    for (Vec3& p : b.points) p *= scale;
    return b;
  }();
  return ball;
}

// Points whose hull contains the primitive placed by `pose`: its vertices when it has any, otherwise a
// circumscribed polytope (a regular polygon outside each circle, the scaled Fibonacci sphere around
// each sphere-swept core).
struct HullPoints {
  const Pose& pose;
  std::vector<Vec3>& out;

  void ball(const Vec3& c, double r) const {
    for (const Vec3& u : circumscribedUnitBall().points) out.push_back(pose * (c + r * u));
  }
  void circle(double z, double r) const {
    const double R = r / std::cos(kPi / kCirclePoints) * (1.0 + margins::kRounding);
    for (int i = 0; i < kCirclePoints; ++i) {
      const double phi = 2.0 * kPi * i / kCirclePoints;
      out.push_back(pose * Vec3(R * std::cos(phi), R * std::sin(phi), z));
    }
  }
  void operator()(const Point& s) const { out.push_back(pose * s.p); }
  void operator()(const Segment& s) const { out.push_back(pose * s.p0); out.push_back(pose * s.p1); }
  void operator()(const Triangle& s) const { for (const Vec3& v : s.v) out.push_back(pose * v); }
  void operator()(const Box& s) const {
    for (int i = 0; i < 8; ++i)
      out.push_back(pose * Vec3((i & 1 ? 1 : -1) * s.half.x(), (i & 2 ? 1 : -1) * s.half.y(), (i & 4 ? 1 : -1) * s.half.z()));
  }
  void operator()(const Sphere& s) const { ball(Vec3::Zero(), s.r); }
  void operator()(const Capsule& s) const { ball(Vec3(0, 0, -s.h), s.r); ball(Vec3(0, 0, s.h), s.r); }
  void operator()(const Cylinder& s) const { circle(-s.h, s.r); circle(s.h, s.r); }
  void operator()(const Cone& s) const { circle(-s.h, s.r); out.push_back(pose * Vec3(0, 0, s.h)); }
  void operator()(const ConvexHull& s) const { for (const Vec3& v : s.vertices()) out.push_back(pose * v); }
};

std::vector<Vec3> hullPoints(const std::vector<Triangle>& triangles, const std::vector<LinkGeometry::Primitive>& prims) {
  std::vector<Vec3> points;
  points.reserve(3 * triangles.size());
  for (const Triangle& t : triangles)
    for (const Vec3& v : t.v) points.push_back(v);
  // Each mesh vertex is a corner of about six triangles: quickhull runs twice as fast without the copies.
  const auto less = [](const Vec3& p, const Vec3& q) {
    return p.x() < q.x() || (p.x() == q.x() && (p.y() < q.y() || (p.y() == q.y() && p.z() < q.z())));
  };
  std::sort(points.begin(), points.end(), less);
  points.erase(std::unique(points.begin(), points.end()), points.end());
  for (const auto& p : prims) std::visit(HullPoints{p.pose, points}, p.shape);
  if (points.empty()) throw ShapeError("link geometry: no triangles and no primitives");
  return points;
}

std::vector<Aabb> triangleBoxes(const std::vector<Triangle>& triangles) {
  std::vector<Aabb> boxes(triangles.size());
  for (std::size_t i = 0; i < triangles.size(); ++i)
    for (const Vec3& v : triangles[i].v) boxes[i].grow(v);
  return boxes;
}

}  // namespace

// ---- LinkGeometry -------------------------------------------------------------------------------------

LinkGeometry::LinkGeometry(std::vector<Triangle> triangles, std::vector<Primitive> primitives,
                           const TreeBuildOptions& options)
    : triangles_(std::move(triangles)),
      primitives_(std::move(primitives)),
      tree_(triangleBoxes(triangles_), options),
      hull_(hullPoints(triangles_, primitives_)) {
  for (const Vec3& v : hull_.vertices()) {
    bounds_.grow(v);
    bounding_radius_ = std::max(bounding_radius_, v.norm());
  }
  sphere_center_ = bounds_.center();
  for (const Vec3& v : hull_.vertices()) sphere_radius_ = std::max(sphere_radius_, (v - sphere_center_).norm());
  // Rounding of the norms (relative) and of the centre (relative to the coordinates).
  sphere_radius_ = margins::roundedUp(sphere_radius_, bounding_radius_);
  sole_primitive_ = triangles_.empty() && primitives_.size() == 1;
  buildParts();
  findSolids();
  findCores();
}

void LinkGeometry::buildParts() {
  const auto add = [&](std::vector<Vec3> points) {
    ConvexHull hull(points);
    Aabb box;
    for (const Vec3& v : hull.vertices()) box.grow(v);
    double radius = 0.0;
    for (const Vec3& v : hull.vertices()) radius = std::max(radius, (v - box.center()).norm());
    parts_.push_back({std::move(hull), box.center(), margins::roundedUp(radius, bounding_radius_)});
  };
  // The tree's top nodes split the triangles spatially; descending level by level keeps the parts even.
  if (!tree_.empty()) {
    const auto& nodes = tree_.nodes();
    std::vector<std::int32_t> frontier{0};
    while (static_cast<int>(frontier.size()) * 2 <= kMaxParts - static_cast<int>(primitives_.size())) {
      std::vector<std::int32_t> next;
      for (std::int32_t n : frontier) {
        if (nodes[n].isLeaf()) next.push_back(n);
        else next.insert(next.end(), {nodes[n].first, nodes[n].first + 1});
      }
      if (next.size() == frontier.size()) break;  // all leaves
      frontier = std::move(next);
    }
    for (std::int32_t top : frontier) {
      std::vector<Vec3> points;
      std::vector<std::int32_t> stack{top};
      while (!stack.empty()) {
        const AabbTree::Node& node = nodes[stack.back()];
        stack.pop_back();
        if (!node.isLeaf()) {
          stack.push_back(node.first);
          stack.push_back(node.first + 1);
          continue;
        }
        for (std::int32_t k = node.first; k < node.first + node.count; ++k)
          for (const Vec3& v : triangles_[tree_.items()[k]].v) points.push_back(v);
      }
      add(std::move(points));
    }
  }
  for (const Primitive& p : primitives_) {
    std::vector<Vec3> points;
    std::visit(HullPoints{p.pose, points}, p.shape);
    add(std::move(points));
  }
}

LinkGeometry::LinkGeometry(const TriangleMesh& mesh, const TreeBuildOptions& options)
    : LinkGeometry(meshTriangles(mesh, Pose::identity()), {}, options) {}  // no triangles: hullPoints throws

namespace {
std::vector<Triangle> elementTriangles(const std::vector<CollisionElement>& elements,
                                       const std::vector<TriangleMesh>& meshes) {
  if (elements.empty()) throw ShapeError("link geometry: no collision elements");
  std::vector<Triangle> out;
  for (const CollisionElement& e : elements) {
    if (e.primitive) continue;
    if (e.mesh < 0 || e.mesh >= static_cast<int>(meshes.size()))
      throw ShapeError("link geometry: mesh index " + std::to_string(e.mesh) + " out of range (" +
                       std::to_string(meshes.size()) + " meshes)");
    if (!e.origin.isFinite()) throw ShapeError("link geometry: an element origin is not finite");
    out = meshTriangles(meshes[e.mesh], e.origin, std::move(out));
  }
  return out;
}

std::vector<LinkGeometry::Primitive> elementPrimitives(const std::vector<CollisionElement>& elements) {
  std::vector<LinkGeometry::Primitive> out;
  for (const CollisionElement& e : elements) {
    if (!e.primitive) continue;
    if (!e.origin.isFinite()) throw ShapeError("link geometry: an element origin is not finite");
    out.push_back({*e.primitive, e.origin});
  }
  return out;
}
}  // namespace

LinkGeometry::LinkGeometry(const std::vector<CollisionElement>& elements, const std::vector<TriangleMesh>& meshes,
                           const TreeBuildOptions& options)
    : LinkGeometry(elementTriangles(elements, meshes), elementPrimitives(elements), options) {}

Aabb placedBox(const Shape& shape, const Pose& pose) noexcept {
  return std::visit([&](const auto& s) { return placedBox(s, pose); }, shape);
}

}  // namespace clearway
