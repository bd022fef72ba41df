// Cores: balls certainly inside a link's solids. Two bodies whose cores overlap share interior points, so
// they collide at any padding: one distance comparison decides what the exact triangles would spend many
// box and triangle tests on (deeply interpenetrating links, a link deep in an obstacle). A mesh core's
// centre is inside the solids (not in a cavity) along three ray directions that all decide, and its radius
// stays below the centre's distance to every triangle of the link, so the ball crosses no surface: being
// connected, it lies inside. Primitives are solids, and their cores are inscribed balls.
#include <clearway/body/link_geometry.h>

#include <clearway/detail/margins.h>
#include <clearway/narrowphase/simplex.h>

#include <algorithm>
#include <cmath>

namespace clearway {
namespace {

// Candidate centres per link, shared among its closed pieces by the volume of their boxes (at least 2 per
// axis in each), and the hill climb's halvings of its step.
constexpr double kCandidates = 216;
constexpr int kClimbSteps = 6;
// A candidate is kept only when at least this fraction of its radius reaches beyond every kept core, and
// only while it is at least kSmallest of the largest core: tiny balls cost a comparison and decide little.
constexpr double kNewReach = 0.5;
constexpr double kSmallest = 0.1;

// The distance from p to segment ab, given a − p and b − p (a point-sized segment: the distance to a).
double segmentDistance(const Vec3& a, const Vec3& b) noexcept {
  const Vec3 e = b - a;
  const double ee = e.squaredNorm();
  const double t = ee > 0.0 ? std::clamp(-a.dot(e) / ee, 0.0, 1.0) : 0.0;
  return (a + t * e).norm();
}

// Never above the distance but for rounding: the closest point of the triangle's plane (signed volumes)
// is inside the triangle, but a sliver's plane is known only roughly, and that point can lie farther than
// the nearest; the nearest point of a sliver is on an edge, whose distance each edge's own test gives.
double triangleDistance(const Triangle& t, const Vec3& p) noexcept {
  detail::Simplex s;
  s.n = 3;
  for (int i = 0; i < 3; ++i) s.p[i].w = t.v[i] - p;
  double l[4];
  detail::closestWeights(s, l);
  const double face = (l[0] * s.p[0].w + l[1] * s.p[1].w + l[2] * s.p[2].w).norm();
  const Vec3 &a = s.p[0].w, &b = s.p[1].w, &c = s.p[2].w;
  return std::min({face, segmentDistance(a, b), segmentDistance(b, c), segmentDistance(c, a)});
}

// A ball's margin: far above the rounding of the distances (a few ulps of the link's size).
double margin(double size) noexcept { return margins::kSlack * (1.0 + size); }

// Point-to-shape distance for the shapes coreMeetsShape decides (p in the shape's frame); NaN otherwise.
struct PointDistance {
  const Vec3& p;
  double operator()(const Box& b) const noexcept { return (p.cwiseAbs() - b.half).cwiseMax(0.0).norm(); }
  double operator()(const Sphere& s) const noexcept { return p.norm() - s.r; }
  double operator()(const Capsule& c) const noexcept {
    return Vec3(p.x(), p.y(), p.z() - std::clamp(p.z(), -c.h, c.h)).norm() - c.r;
  }
  template <class S>
  double operator()(const S&) const noexcept { return std::nan(""); }
};

// Inscribed balls of a primitive along its longest axis (shape frame); none for shapes without one here.
struct InscribedBalls {
  const Pose& pose;
  std::vector<LinkGeometry::Ball>& out;
  void along(int axis, double half_length, double radius) const {
    if (!(radius > 0.0)) return;  // a flat box or a disc holds no ball
    const double reach = std::max(0.0, half_length - radius);
    // Counted in double: reach / radius reaches 1e15 within the input limits (a 1 nm plate 1000 km long).
    const int n = reach > 0.0 ? static_cast<int>(std::min(4.0, 1.0 + std::ceil(reach / radius))) : 1;
    for (int i = 0; i < n; ++i) {
      Vec3 c = Vec3::Zero();
      c[axis] = n == 1 ? 0.0 : -reach + 2.0 * reach * i / (n - 1);
      out.push_back({pose * c, radius});
    }
  }
  void operator()(const Box& b) const {
    int longest = 0;
    for (int i = 1; i < 3; ++i)
      if (b.half[i] > b.half[longest]) longest = i;
    along(longest, b.half[longest], b.half.minCoeff());
  }
  void operator()(const Sphere& s) const { out.push_back({pose.t, s.r}); }
  void operator()(const Capsule& c) const { along(2, c.h + c.r, c.r); }
  void operator()(const Cylinder& c) const { along(2, c.h, std::min(c.r, c.h)); }
  template <class S>
  void operator()(const S&) const {}
};

}  // namespace

double LinkGeometry::surfaceDistance(const Vec3& p, double cutoff) const noexcept {
  tree_.forEachWithin(Aabb::ofPoint(p), cutoff, [&](std::int32_t t) {
    cutoff = std::min(cutoff, triangleDistance(triangles_[t], p));
    return false;
  });
  return cutoff;
}

void LinkGeometry::findCores() {
  const double m = margin(bounding_radius_);
  std::vector<Ball> candidates;
  // The distance from p to the nearest triangle of the link (any piece: more than the ball needs).
  const auto clearance = [&](const Vec3& p) { return surfaceDistance(p, std::numeric_limits<double>::infinity()); };
  double volume = 0.0;
  for (const Aabb& box : solid_boxes_) volume += box.extents().prod();
  for (int s = 0; s < solidCount(); ++s) {
    const Aabb& box = solid_boxes_[s];
    const double share = volume > 0.0 ? box.extents().prod() / volume : 1.0;
    const int grid = std::clamp(static_cast<int>(std::cbrt(kCandidates * share)), 2, 6);
    const auto inside = [&](const Vec3& p) { return surelyInside(p); };
    std::vector<Ball> mine;
    for (int i = 0; i < grid; ++i)
      for (int j = 0; j < grid; ++j)
        for (int k = 0; k < grid; ++k) {
          const Vec3 f((i + 0.5) / grid, (j + 0.5) / grid, (k + 0.5) / grid);
          const Vec3 p = box.min + f.cwiseProduct(box.extents());
          if (inside(p)) mine.push_back({p, clearance(p)});
        }
    std::sort(mine.begin(), mine.end(), [](const Ball& x, const Ball& y) { return x.radius > y.radius; });
    // The best few climb (as many as the piece's share of the link allows, up to twice the cores kept).
    const std::size_t climbers = std::clamp(static_cast<int>(2 * kMaxCores * share) + 1, 1, 2 * kMaxCores);
    if (mine.size() > climbers) mine.resize(climbers);
    // Climb: move each centre along the axes while its clearance grows (a bounded number of halvings).
    for (Ball& b : mine) {
      double step = 0.5 * box.extents().maxCoeff() / grid;
      for (int h = 0; h < kClimbSteps; ++h, step *= 0.5)
        for (int d = 0; d < 6; ++d) {
          Vec3 p = b.center;
          p[d / 2] += d % 2 ? -step : step;
          const double r = clearance(p);
          if (r > b.radius && inside(p)) b = {p, r};
        }
    }
    candidates.insert(candidates.end(), mine.begin(), mine.end());
  }
  for (Ball& b : candidates) b.radius -= m;
  for (const Primitive& p : primitives_) {
    std::vector<Ball> balls;
    std::visit(InscribedBalls{p.pose, balls}, p.shape);
    for (Ball& b : balls) candidates.push_back({b.center, b.radius * (1.0 - margins::kRounding) - m});
  }
  std::sort(candidates.begin(), candidates.end(), [](const Ball& x, const Ball& y) { return x.radius > y.radius; });
  for (const Ball& c : candidates) {
    if (!(c.radius > 0.0) || !c.center.allFinite()) continue;
    if (static_cast<int>(cores_.size()) == kMaxCores) break;
    if (!cores_.empty() && c.radius < kSmallest * cores_.front().radius) break;
    const bool adds = std::all_of(cores_.begin(), cores_.end(), [&](const Ball& k) {
      return (c.center - k.center).norm() + kNewReach * c.radius > k.radius;
    });
    if (adds) cores_.push_back(c);
  }
}

bool coresOverlap(const LinkGeometry& a, const LinkGeometry& b, const Pose& b_in_a) noexcept {
  if (a.cores().empty() || b.cores().empty()) return false;
  const double m = margin(a.boundingRadius() + b.boundingRadius() + b_in_a.t.norm());
  for (const LinkGeometry::Ball& cb : b.cores()) {
    const Vec3 c = b_in_a * cb.center;
    for (const LinkGeometry::Ball& ca : a.cores()) {
      const double reach = ca.radius + cb.radius - m;
      if (reach > 0.0 && (c - ca.center).squaredNorm() < reach * reach) return true;
    }
  }
  return false;
}

bool coreMeetsShape(const Shape& shape, const Pose& shape_in_link, const LinkGeometry& link) noexcept {
  if (link.cores().empty()) return false;
  const Pose link_in_shape = shape_in_link.inverse();
  const double m = margin(link.boundingRadius() + shape_in_link.t.norm() + boundingRadius(shape));
  for (const LinkGeometry::Ball& c : link.cores()) {
    const Vec3 p = link_in_shape * c.center;
    const double d = std::visit(PointDistance{p}, shape);
    if (d < c.radius - m) return true;  // (a NaN distance decides nothing)
  }
  return false;
}

}  // namespace clearway
