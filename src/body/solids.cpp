// Closed meshes as solids: which triangles of a link form closed shells, and whether a point lies inside
// them (ray crossings). Vertices are welded by exact coordinates. A shell is the triangles joined across
// edges that exactly two of them share, so shells touching at a corner or along an edge stay apart (one
// piece of both would count a nested shell's inside as outside by parity). A shell is closed when every
// edge of it is shared by an even number of its triangles: the surface is then a cycle mod 2, and a ray
// from a point not on it crosses it an odd number of times exactly when the point is inside
// (Jordan–Brouwer). Shells open on their own that close together (through edges of four triangles) are
// joined by shared vertices and tested again. A closed shell whose every edge runs as often one way as
// the other is wound: its crossings, signed, sum to its winding number (+1 inside an outward shell, −1
// inside an inward one).
//
// When wound shells of both windings nest as one solid (an outer surface, cavities within its material,
// solids within the cavities), the winding numbers summed over them decide, so a cavity is empty. The
// nesting is checked at each triangle's centre, where the other shells' winding number must be 0 for a
// shell wound as the whole (it bounds material from outside) and the whole's for a shell wound against
// it (a cavity lies in material). Otherwise (a turned part crossing another, say) a point is inside when
// it is inside any shell on its own: never free by accident.
//
// A ray that passes within rounding of an edge, a vertex or a triangle's plane could count a crossing
// twice or not at all: such a ray is dropped and the next of a fixed set of directions is tried; when all
// are dropped, the point counts as inside (never "outside" by accident).
#include <clearway/body/link_geometry.h>
#include <clearway/detail/margins.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <utility>

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
constexpr double kEdgeMargin = margins::kSlack;
constexpr double kParallelMargin = margins::kSlack;
// A shell's signed volume below this fraction of the sum of its tetrahedra's absolute volumes gives it no
// winding (a sheet seen from both sides); far above the rounding of the sum.
constexpr double kFlatVolume = 1e-6;

struct Dsu {
  std::vector<std::int32_t> parent;
  explicit Dsu(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  std::int32_t find(std::int32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void join(std::int32_t a, std::int32_t b) { parent[find(a)] = find(b); }
};

// One use of a welded edge (lower id in the high half) by a triangle, +1 when it runs from the lower id.
struct EdgeUse {
  std::uint64_t key;
  std::int32_t triangle;
  std::int32_t dir;
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
  // Probes: one vertex per piece of triangles joined by shared vertices (each lies wholly inside or
  // outside another body's solids while the surfaces do not meet).
  {
    Dsu pieces(static_cast<std::size_t>(ids));
    for (std::size_t t = 0; t < n; ++t) {
      pieces.join(id[3 * t], id[3 * t + 1]);
      pieces.join(id[3 * t], id[3 * t + 2]);
    }
    std::vector<char> probed(static_cast<std::size_t>(ids), 0);
    for (std::size_t t = 0; t < n; ++t) {
      const std::int32_t root = pieces.find(id[3 * t]);
      if (!probed[root]) {
        probed[root] = 1;
        probes_.push_back(triangles_[t].v[0]);
      }
    }
  }
  // Edge uses. A triangle with two welded corners equal has no area and its edges cancel in pairs: it
  // belongs to no shell (and stays a surface).
  std::vector<char> flat(n, 0);
  std::vector<EdgeUse> uses;
  uses.reserve(3 * n);
  for (std::size_t t = 0; t < n; ++t) {
    const std::int32_t* c = &id[3 * t];
    if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) {
      flat[t] = 1;
      continue;
    }
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = static_cast<std::uint32_t>(c[e]), b = static_cast<std::uint32_t>(c[(e + 1) % 3]);
      uses.push_back({(static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b),
                      static_cast<std::int32_t>(t), a < b ? 1 : -1});
    }
  }
  std::sort(uses.begin(), uses.end(),
            [](const EdgeUse& x, const EdgeUse& y) { return x.key < y.key || (x.key == y.key && x.triangle < y.triangle); });
  const auto forEachEdge = [&](auto&& f) {
    for (std::size_t i = 0; i < uses.size();) {
      std::size_t j = i;
      while (j < uses.size() && uses[j].key == uses[i].key) ++j;
      f(i, j);
      i = j;
    }
  };
  // Shells: triangles joined across edges that exactly two of them use.
  Dsu shells(n);
  forEachEdge([&](std::size_t i, std::size_t j) {
    if (j - i == 2) shells.join(uses[i].triangle, uses[i + 1].triangle);
  });
  // Per shell (its root): open when an edge is used an odd number of times in it, unwound when an edge's
  // uses in it do not run once each way as often.
  std::vector<char> open(n), unwound(n);
  const auto classify = [&] {
    std::fill(open.begin(), open.end(), 0);
    std::fill(unwound.begin(), unwound.end(), 0);
    std::vector<std::pair<std::int32_t, std::int32_t>> mine;  // (shell, direction) of one edge's uses
    forEachEdge([&](std::size_t i, std::size_t j) {
      mine.clear();
      for (std::size_t k = i; k < j; ++k) mine.emplace_back(shells.find(uses[k].triangle), uses[k].dir);
      std::sort(mine.begin(), mine.end());
      for (std::size_t a = 0; a < mine.size();) {
        std::size_t b = a;
        int sum = 0;
        for (; b < mine.size() && mine[b].first == mine[a].first; ++b) sum += mine[b].second;
        if ((b - a) % 2 != 0) open[mine[a].first] = 1;
        if (sum != 0) unwound[mine[a].first] = 1;
        a = b;
      }
    });
  };
  classify();
  // Shells open on their own may close together (pieces meeting along edges of four triangles): join
  // their triangles by shared vertices, as pieces, and classify again. Every closed piece of triangles
  // joined by vertices thus stays closed, split into closed shells where it can be.
  {
    std::vector<char> was_open(n, 0);
    bool any = false;
    for (std::size_t t = 0; t < n; ++t)
      if (!flat[t] && open[shells.find(static_cast<std::int32_t>(t))]) was_open[t] = 1, any = true;
    if (any) {
      std::vector<std::int32_t> first(static_cast<std::size_t>(ids), -1);
      for (std::size_t t = 0; t < n; ++t) {
        if (!was_open[t]) continue;
        for (int k = 0; k < 3; ++k) {
          std::int32_t& f = first[id[3 * t + k]];
          if (f < 0) f = static_cast<std::int32_t>(t);
          else shells.join(static_cast<std::int32_t>(t), f);
        }
      }
      classify();
    }
  }
  // Number the closed shells.
  std::vector<std::int32_t> number(n, -1);
  for (std::size_t t = 0; t < n; ++t) {
    if (flat[t]) continue;
    const std::int32_t root = shells.find(static_cast<std::int32_t>(t));
    if (open[root]) continue;
    if (number[root] < 0) {
      number[root] = static_cast<std::int32_t>(solid_boxes_.size());
      solid_boxes_.emplace_back();
      solid_sign_.push_back(unwound[root] ? 0 : 1);
    }
    solid_of_[t] = number[root];
    for (const Vec3& v : triangles_[t].v) solid_boxes_[number[root]].grow(v);
  }
  // A primitive's core point lies in it (spheres and capsules: the centre or the axis).
  for (const Primitive& p : primitives_)
    probes_.push_back(std::visit([&](const auto& s) { return p.pose * s.support(Vec3::UnitX()); }, p.shape));
  if (solid_boxes_.empty()) {
    solid_of_.clear();
    return;
  }
  // Windings: the sign of each wound shell's volume (about its box's centre, for rounding).
  const std::size_t shell_count = solid_boxes_.size();
  std::vector<double> volume(shell_count, 0.0), scale(shell_count, 0.0);
  for (std::size_t t = 0; t < n; ++t) {
    const std::int32_t s = solid_of_[t];
    if (s < 0 || solid_sign_[s] == 0) continue;
    const Vec3 o = solid_boxes_[s].center();
    const Vec3 a = triangles_[t].v[0] - o, b = triangles_[t].v[1] - o, c = triangles_[t].v[2] - o;
    const double v = a.dot(b.cross(c));
    volume[s] += v;
    scale[s] += std::abs(v);
  }
  bool outward = false, inward = false;
  double total = 0.0, total_scale = 0.0;
  for (std::size_t s = 0; s < shell_count; ++s) {
    if (solid_sign_[s] == 0) continue;
    solid_sign_[s] = volume[s] > kFlatVolume * scale[s] ? 1 : volume[s] < -kFlatVolume * scale[s] ? -1 : 0;
    outward |= solid_sign_[s] > 0;
    inward |= solid_sign_[s] < 0;
    if (solid_sign_[s] != 0) total += volume[s], total_scale += scale[s];
  }
  // Shells of one winding only never cancel: "inside any shell" is their winding number's answer too.
  if (!outward || !inward) return;
  const int solid = total > kFlatVolume * total_scale ? 1 : total < -kFlatVolume * total_scale ? -1 : 0;
  if (solid == 0) return;
  // Nesting: in front of each triangle lies the outside (winding 0), behind it the material (winding
  // `solid`); a shell wound as the solid adds its 1 behind, one wound against it its −1 in front.
  for (std::size_t t = 0; t < n; ++t) {
    const std::int32_t s = solid_of_[t];
    if (s < 0 || solid_sign_[s] == 0) continue;
    const Triangle& tri = triangles_[t];
    if (!((tri.v[1] - tri.v[0]).cross(tri.v[2] - tri.v[0]).norm() > 1e-300)) continue;  // no area, no side
    const Vec3 centre = (tri.v[0] + tri.v[1] + tri.v[2]) / 3.0;
    const int expected = solid_sign_[s] == solid ? 0 : solid;
    int winding = 0;
    bool decided = false;
    for (int r = 0; r < kRays && !decided; ++r) decided = rayCrossings(kWound, s, centre, rayDirection(r), winding);
    if (!decided || winding != expected) return;
  }
  nested_ = true;
}

bool LinkGeometry::rayCrossings(int s, int skip, const Vec3& p, const Vec3& dir, int& winding) const noexcept {
  const Vec3 inv(1.0 / dir.x(), 1.0 / dir.y(), 1.0 / dir.z());
  const double grow = margins::kSlack * (1.0 + p.cwiseAbs().maxCoeff() + bounding_radius_);  // (boxes' rounding)
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
  winding = 0;
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
      const std::int32_t piece = solid_of_[t];
      if (s >= 0 ? piece != s : (piece < 0 || piece == skip || solid_sign_[piece] == 0)) continue;
      if (!reaches(tree_.slotBoxes()[slot])) continue;
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
        if (std::abs(normal.dot(a)) <= kParallelMargin * nn * (reach + 1e-300)) return false;
        continue;
      }
      const double la = wa / sum, lb = wb / sum, lc = wc / sum;
      if (la < -kEdgeMargin || lb < -kEdgeMargin || lc < -kEdgeMargin) continue;  // the line misses it
      const double along = normal.dot(a) / sum;  // the ray parameter of the plane
      const double near = margins::kRounding * (a.norm() + b.norm() + c.norm());
      if (along < -near) continue;  // behind p
      if (along <= near) return false;  // p on the triangle (touching) or next to it
      if (la <= kEdgeMargin || lb <= kEdgeMargin || lc <= kEdgeMargin) return false;  // at an edge or vertex
      winding += sum > 0.0 ? 1 : -1;  // leaving through the front, or entering
    }
  }
  return true;
}

int LinkGeometry::insideAlong(const Vec3& p, int r) const noexcept {
  const Vec3& dir = rayDirection(r);
  const double grow = margins::kSlack * (1.0 + bounding_radius_);
  bool undecided = false, wound = false;
  for (int s = 0; s < solidCount(); ++s) {
    const Aabb& box = solid_boxes_[s];
    if ((p.array() < box.min.array() - grow).any() || (p.array() > box.max.array() + grow).any()) continue;
    if (nested_ && solid_sign_[s] != 0) {
      wound = true;  // summed over every wound shell below
      continue;
    }
    int w = 0;
    if (!rayCrossings(s, kWound, p, dir, w)) {
      undecided = true;
    } else if (solid_sign_[s] != 0 ? w != 0 : (w & 1) != 0) {
      return 1;
    }
  }
  if (wound) {
    int w = 0;
    if (!rayCrossings(kWound, kWound, p, dir, w)) return -1;
    if (w != 0) return 1;
  }
  return undecided ? -1 : 0;
}

bool LinkGeometry::containsPoint(const Vec3& p) const noexcept {
  if (!p.allFinite()) return !solid_boxes_.empty();
  if (solid_boxes_.empty()) return false;
  for (int r = 0; r < kRays; ++r) {
    const int inside = insideAlong(p, r);
    if (inside >= 0) return inside == 1;
  }
  return true;  // inside, or undecided
}

bool LinkGeometry::surelyInside(const Vec3& p) const noexcept {
  for (int r = 0; r < 3; ++r)
    if (insideAlong(p, r) != 1) return false;
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
