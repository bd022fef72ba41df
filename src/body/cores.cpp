// Cores: balls certainly inside a link's solids. Two bodies whose cores overlap share interior points, so
// they collide at any padding: one distance comparison decides what the exact triangles would spend many
// box and triangle tests on (interpenetrating links, a link in an obstacle). A mesh core's centre is inside
// the solids (not in a cavity) along three ray directions that all decide, and its radius stays below the
// centre's distance to every triangle of the link, so the ball crosses no surface: being connected, it
// lies inside. Primitives are solids, and their cores are inscribed balls.
//
// Which balls: first the largest few (a hill climb from a coarse grid), which settle deep contacts and let
// a pair table call whole cells colliding; then balls that hug the surface, chosen greedily from a finer
// grid so that as many points of the surface as possible lie within a small reach of one: a shallow
// contact is settled once a core of each body reaches into the other. Which balls are chosen changes how
// many contacts they settle, never whether a settled one is real.
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
// The largest cores are at most this many; the surface's fill the rest, up to kMaxCores.
constexpr int kLargest = 8;
// The surface's: candidate centres per link (a grid over its closed pieces' boxes), points of the surface
// that the choice tries to reach (spaced kSampleSpacing of the link's bounding ball apart, at most
// kMaxSamples of them), and how near a core must come to a point to reach it (a share of the bounding ball).
constexpr double kSurfaceCandidates = 1000;
constexpr double kSampleSpacing = 0.05;
constexpr std::size_t kMaxSamples = 2000;
constexpr double kReach = 0.03;
// A surface core is chosen only while it reaches at least this many points no chosen core reaches.
constexpr int kMinGain = 2;

// ceil(x) within [1, most] (NaN: 1), cast only once in range.
int cellsFor(double x, int most) noexcept {
  const double c = std::ceil(x);
  return !(c >= 1.0) ? 1 : c >= most ? most : static_cast<int>(c);
}

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

bool LinkGeometry::coreCentre(const Vec3& p) const noexcept {
  if (!surelyInside(p)) return false;
  if (nested_) return true;  // (the winding number decides, as the rays read it)
  // Otherwise the rays read p inside one shell on its own. In shells wound outward only, that is a winding
  // number of at least 1 too; an inward-wound or unwound shell can part the readings (on the shared UR5's
  // inner_finger_fine.STL, inward-wound shells hold points of winding number 0), and a core must hold in
  // every reading: no centre within such a shell's box.
  for (std::size_t s = 0; s < solid_boxes_.size(); ++s)
    if (solid_sign_[s] <= 0 && solid_boxes_[s].contains(p)) return false;
  return true;
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
    const auto inside = [&](const Vec3& p) { return coreCentre(p); };
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
    const std::size_t climbers = std::clamp(static_cast<int>(2 * kLargest * share) + 1, 1, 2 * kLargest);
    if (mine.size() > climbers) mine.resize(climbers);
    // Climb: move each centre along the axes while its clearance grows (a bounded number of halvings).
    for (Ball& b : mine) {
      double step = 0.5 * box.extents().maxCoeff() / grid;
      for (int h = 0; h < kClimbSteps; ++h, step *= 0.5)
        for (int d = 0; d < 6; ++d) {
          Vec3 p = b.center;
          p[d / 2] += d % 2 ? -step : step;
          // (The distance to the surface moves by at most the step: a search cut off just beyond b's radius
          // plus the step answers the distance itself, and far sooner.)
          const double r = surfaceDistance(p, 2.0 * (b.radius + step));
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
    if (static_cast<int>(cores_.size()) == kLargest) break;
    if (!cores_.empty() && c.radius < kSmallest * cores_.front().radius) break;
    const bool adds = std::all_of(cores_.begin(), cores_.end(), [&](const Ball& k) {
      return (c.center - k.center).norm() + kNewReach * c.radius > k.radius;
    });
    if (adds) cores_.push_back(c);
  }
  addSurfaceCores(m);
  groupCores();
}

void LinkGeometry::groupCores() {
  // Halved at the median of the longest side of their centres' box until at most 8 remain: neighbours
  // share a group, so a test of the group's ball skips the cores far from where two bodies meet.
  constexpr int kGroup = 8;
  std::vector<std::pair<int, int>> todo{{0, static_cast<int>(cores_.size())}};
  while (!todo.empty()) {
    const auto [first, count] = todo.back();
    todo.pop_back();
    if (count == 0) continue;
    Aabb box;
    for (int i = first; i < first + count; ++i) box.grow(cores_[i].center);
    if (count > kGroup) {
      int axis = 0;
      box.extents().maxCoeff(&axis);
      const auto begin = cores_.begin() + first;
      std::nth_element(begin, begin + count / 2, begin + count,
                       [axis](const Ball& x, const Ball& y) { return x.center[axis] < y.center[axis]; });
      todo.emplace_back(first, count / 2);
      todo.emplace_back(first + count / 2, count - count / 2);
      continue;
    }
    // (The group's ball only skips tests: its rounding can cost a proof, never make one.)
    CoreGroup g{box.center(), 0.0, first, count};
    for (int i = first; i < first + count; ++i)
      g.radius = std::max(g.radius, (cores_[i].center - g.center).norm() + cores_[i].radius);
    core_groups_.push_back(g);
  }
  std::sort(core_groups_.begin(), core_groups_.end(),
            [](const CoreGroup& x, const CoreGroup& y) { return x.first < y.first; });
}

void LinkGeometry::addSurfaceCores(double m) {
  if (solid_boxes_.empty() || triangles_.empty()) return;
  // The candidates: a grid over each closed piece's box, as fine as its share of the link's volume allows.
  double volume = 0.0;
  for (const Aabb& box : solid_boxes_) volume += box.extents().prod();
  std::vector<Ball> candidates;
  for (const Aabb& box : solid_boxes_) {
    const Vec3 e = box.extents();
    const double share = volume > 0.0 ? e.prod() / volume : 1.0;
    const double spacing = std::cbrt(std::max(e.prod(), 1e-300) / std::max(1.0, kSurfaceCandidates * share));
    int n[3];
    for (int a = 0; a < 3; ++a) n[a] = cellsFor(e[a] / spacing, 64);
    // (A flat or tiny piece's grid is cut back to its share: many small shells must not cost many points each.)
    const double limit = 2.0 * kSurfaceCandidates * share + 1.0;
    while (static_cast<double>(n[0]) * n[1] * n[2] > limit) *std::max_element(n, n + 3) -= 1;
    if (kSurfaceCandidates * share < 1.0) continue;  // (under a thousandth of the volume: too small to matter)
    for (int i = 0; i < n[0]; ++i)
      for (int j = 0; j < n[1]; ++j)
        for (int k = 0; k < n[2]; ++k) {
          const Vec3 f((i + 0.5) / n[0], (j + 0.5) / n[1], (k + 0.5) / n[2]);
          const Vec3 p = box.min + f.cwiseProduct(e);
          if (!coreCentre(p)) continue;
          // (The cutoff caps deep centres' balls, which stay inside: the distance answered is at most the true one.)
          const double r = surfaceDistance(p, 4.0 * spacing) - m;
          if (r > 0.0 && p.allFinite()) candidates.push_back({p, r});
        }
  }
  // The points to reach: on every triangle, a grid of about kSampleSpacing, every stride-th kept so that at
  // most about kMaxSamples are (counted first: a million long triangles must not make a hundred million).
  const double spacing = kSampleSpacing * sphere_radius_;
  const auto steps = [&](const Triangle& t) {
    const double edge = std::max({(t.v[1] - t.v[0]).norm(), (t.v[2] - t.v[1]).norm(), (t.v[0] - t.v[2]).norm()});
    return cellsFor(edge / spacing, 16);
  };
  std::size_t total = 0;
  for (const Triangle& t : triangles_) {
    const int n = steps(t);
    total += static_cast<std::size_t>((n + 1) * (n + 2) / 2);
  }
  const std::size_t stride = std::max<std::size_t>(1, (total + kMaxSamples - 1) / kMaxSamples);
  std::vector<Vec3> samples;
  std::size_t at = 0;
  for (const Triangle& t : triangles_) {
    const int n = steps(t);
    for (int a = 0; a <= n; ++a)
      for (int b = 0; a + b <= n; ++b, ++at)
        if (at % stride == 0)
          samples.push_back(t.v[0] + (t.v[1] - t.v[0]) * (double(a) / n) + (t.v[2] - t.v[0]) * (double(b) / n));
  }
  const double reach = kReach * sphere_radius_;
  const auto reaches = [&](const Ball& b, const Vec3& p) { return (p - b.center).norm() <= b.radius + reach; };
  std::vector<char> reached(samples.size(), 0);
  const auto markReached = [&](const Ball& b) {
    for (std::size_t i = 0; i < samples.size(); ++i) reached[i] |= reaches(b, samples[i]);
  };
  for (const Ball& c : cores_) markReached(c);
  const auto gain = [&](const Ball& b) {
    int g = 0;
    for (std::size_t i = 0; i < samples.size(); ++i) g += !reached[i] && reaches(b, samples[i]);
    return g;
  };
  // Greedy, lazily: a candidate's gain only falls as cores are chosen, so one whose recomputed gain still
  // tops the others' last known gains is the best.
  std::vector<std::pair<int, int>> heap;  // (gain when last computed, candidate)
  for (std::size_t c = 0; c < candidates.size(); ++c) heap.emplace_back(gain(candidates[c]), static_cast<int>(c));
  std::make_heap(heap.begin(), heap.end());
  while (static_cast<int>(cores_.size()) < kMaxCores && !heap.empty() && heap.front().first >= kMinGain) {
    std::pop_heap(heap.begin(), heap.end());
    const int c = heap.back().second;
    heap.pop_back();
    const int now = gain(candidates[c]);
    if (!heap.empty() && now < heap.front().first) {
      heap.emplace_back(now, c);
      std::push_heap(heap.begin(), heap.end());
      continue;
    }
    if (now < kMinGain) break;
    cores_.push_back(candidates[c]);
    markReached(candidates[c]);
  }
}

bool coresOverlap(const LinkGeometry& a, const LinkGeometry& b, const Pose& b_in_a) noexcept {
  if (a.cores().empty() || b.cores().empty()) return false;
  const double m = margin(a.boundingRadius() + b.boundingRadius() + b_in_a.t.norm());
  // a's cores lie in its solids, so in its hull's box: a core of b that does not reach the box meets none.
  const Vec3 box_center = a.bounds().center(), box_half = a.bounds().halfExtents();
  const auto reachesBox = [&](const Vec3& c, double r) {
    return ((c - box_center).cwiseAbs() - box_half).cwiseMax(0.0).squaredNorm() < r * r;
  };
  for (const LinkGeometry::CoreGroup& g : b.coreGroups()) {
    if (!reachesBox(b_in_a * g.center, g.radius)) continue;
    for (int k = g.first; k < g.first + g.count; ++k) {
      const LinkGeometry::Ball& cb = b.cores()[k];
      const Vec3 c = b_in_a * cb.center;
      if (!reachesBox(c, cb.radius)) continue;
      for (const LinkGeometry::CoreGroup& h : a.coreGroups()) {
        const double near = h.radius + cb.radius;
        if (!((c - h.center).squaredNorm() < near * near)) continue;
        for (int i = h.first; i < h.first + h.count; ++i) {
          const LinkGeometry::Ball& ca = a.cores()[i];
          const double reach = ca.radius + cb.radius - m;
          if (reach > 0.0 && (c - ca.center).squaredNorm() < reach * reach) return true;
        }
      }
    }
  }
  return false;
}

bool coreMeetsShape(const Shape& shape, const Pose& shape_in_link, const LinkGeometry& link, double depth) noexcept {
  if (link.cores().empty()) return false;
  const Pose link_in_shape = shape_in_link.inverse();
  const double m = margin(link.boundingRadius() + shape_in_link.t.norm() + boundingRadius(shape));
  for (const LinkGeometry::CoreGroup& g : link.coreGroups()) {
    const Vec3 gp = link_in_shape * g.center;
    if (std::visit(PointDistance{gp}, shape) >= g.radius) continue;  // (NaN: the group is tested)
    for (int k = g.first; k < g.first + g.count; ++k) {
      const LinkGeometry::Ball& c = link.cores()[k];
      const Vec3 p = link_in_shape * c.center;
      const double d = std::visit(PointDistance{p}, shape);
      if (d < c.radius - m - depth) return true;  // (a NaN distance, or depth, decides nothing)
    }
  }
  return false;
}

}  // namespace clearway
