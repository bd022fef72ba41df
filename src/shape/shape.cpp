#include <clearway/shape/shape.h>

#include <algorithm>

namespace clearway {

namespace {
struct TypeName {
  const char* operator()(const Point&) const { return "point"; }
  const char* operator()(const Segment&) const { return "segment"; }
  const char* operator()(const Triangle&) const { return "triangle"; }
  const char* operator()(const Box&) const { return "box"; }
  const char* operator()(const Sphere&) const { return "sphere"; }
  const char* operator()(const Capsule&) const { return "capsule"; }
  const char* operator()(const Cylinder&) const { return "cylinder"; }
  const char* operator()(const Cone&) const { return "cone"; }
  const char* operator()(const ConvexHull&) const { return "convex"; }
};

struct BoundingRadius {
  double operator()(const Point& s) const { return s.p.norm(); }
  double operator()(const Segment& s) const { return std::max(s.p0.norm(), s.p1.norm()); }
  double operator()(const Triangle& s) const { return std::max({s.v[0].norm(), s.v[1].norm(), s.v[2].norm()}); }
  double operator()(const Box& s) const { return s.half.norm(); }
  double operator()(const Sphere& s) const { return s.r; }
  double operator()(const Capsule& s) const { return s.h + s.r; }
  double operator()(const Cylinder& s) const { return std::hypot(s.r, s.h); }
  double operator()(const Cone& s) const { return std::hypot(s.r, s.h); }
  double operator()(const ConvexHull& s) const {
    double m = 0.0;
    for (const Vec3& v : s.vertices()) m = std::max(m, v.norm());
    return m;
  }
};
}  // namespace

const char* shapeTypeName(const Shape& shape) noexcept { return std::visit(TypeName{}, shape); }

double boundingRadius(const Shape& shape) noexcept { return std::visit(BoundingRadius{}, shape); }

}  // namespace clearway
