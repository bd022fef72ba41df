#include <clearway/scene/pair_table.h>

#include <clearway/body/proximity.h>
#include <clearway/detail/margins.h>
#include <clearway/detail/parallel_for.h>
#include <clearway/detail/weak_memo.h>
#include <clearway/shape/convex_hull.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <tuple>

namespace clearway {

PairTableOptions PairTableOptions::within(double seconds) const {
  PairTableOptions o = *this;
  const auto budget = std::chrono::duration<double>(std::max(0.0, std::min(seconds, 1e6)));  // (NaN: 0)
  o.deadline = std::min(deadline, std::chrono::steady_clock::now() +
                                      std::chrono::duration_cast<std::chrono::steady_clock::duration>(budget));
  return o;
}

namespace {

constexpr double kPi = 3.14159265358979323846;
// Added to every cell's half-width (radians or metres): far above the rounding of a value's cell
// coordinate and of reducing a turn to [−π, π] with the double 2π (below 1e-13 for values up to
// kMaxTurn, beyond which a turn is not looked up).
constexpr double kValueSlack = margins::kSlack;
constexpr double kMaxTurn = 1e3;

// One axis of a walk through unit cells (Amanatides–Woo) along u + s·d, s ∈ [0, 1], from the cell `start`
// (the integer part of u, or a cell it was clamped into): the step to the next cell, the parameter s of the
// first crossing and the parameter between crossings (∞ for an axis the segment does not move along).
struct WalkAxis {
  int step = 0;
  double next = std::numeric_limits<double>::infinity(), delta = std::numeric_limits<double>::infinity();
  WalkAxis(double u, double d, double start) noexcept {
    if (d > 0.0) {
      step = 1;
      next = (start + 1.0 - u) / d;
      delta = 1.0 / d;
    } else if (d < 0.0) {
      step = -1;
      next = (u - start) / -d;
      delta = -1.0 / d;
    }
  }
};

// A joint of the chain that the table's variables move.
struct Moved {
  const Joint* joint;
  int var;
  bool periodic;
  double lo, hi;
};

Pose jointMotion(const Joint& j, double x) {
  Pose m;
  if (j.type == JointType::Prismatic) m.t = x * j.axis;
  else m.R = Eigen::AngleAxisd(x, j.axis).toRotationMatrix();
  return m;
}

double axisDistance(const Vec3& p, const Vec3& u) { return (p - p.dot(u) * u).norm(); }

// A body holding every turn of `points` about the axis u through the origin. A point's turn is a circle, and
// the profile of the turn (height along u, ± distance from it) lies in the convex hull of the points'
// profiles, mirrored across the axis; so the body of that polygon's circles holds them all. The polygon is
// cut across the axis into kSlabs slabs, one convex piece each (a part of its own: near a joint, the slab
// near the axes moves less than the far one); each piece is the hull of the regular kSides-gons whose sides
// touch its corners' circles (corners at radius r / cos(π/kSides), grown for rounding). Primitives, not a
// mesh: they need no cores or triangles, which cost a mesh ten times as long to build. Nothing when a
// piece is flat (a profile without area).
std::optional<LinkGeometry> revolvedHull(const std::vector<Vec3>& points, const Vec3& u) {
  constexpr int kSides = 16, kSlabs = 4;
  const double grow = margins::kBeyond / std::cos(kPi / kSides);
  struct Profile {
    double z, r;
  };
  std::vector<Profile> profile;
  for (const Vec3& p : points) {
    const double z = p.dot(u), r = (p - z * u).norm();
    profile.push_back({z, r});
    profile.push_back({z, -r});
  }
  std::sort(profile.begin(), profile.end(),
            [](const Profile& a, const Profile& b) { return a.z < b.z || (a.z == b.z && a.r < b.r); });
  // Andrew's monotone chain, counter-clockwise; a corner kept in doubt (a turn rounded to zero) only adds
  // a circle.
  const auto cross = [](const Profile& o, const Profile& a, const Profile& b) {
    return (a.z - o.z) * (b.r - o.r) - (a.r - o.r) * (b.z - o.z);
  };
  std::vector<Profile> polygon(2 * profile.size());
  std::size_t k = 0;
  for (const Profile& p : profile) {
    while (k >= 2 && cross(polygon[k - 2], polygon[k - 1], p) < 0.0) --k;
    polygon[k++] = p;
  }
  for (std::size_t i = profile.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(polygon[k - 2], polygon[k - 1], profile[i]) < 0.0) --k;
    polygon[k++] = profile[i];
  }
  polygon.resize(k > 0 ? k - 1 : 0);  // (the chain ends where it began)
  if (polygon.size() < 3) return std::nullopt;
  // The slabs' cuts: each edge crossing a cut is cut at the same point for the slabs on both sides.
  const auto clip = [](const std::vector<Profile>& in, double c, bool keep_above) {
    std::vector<Profile> out;
    for (std::size_t i = 0; i < in.size(); ++i) {
      const Profile& p = in[i];
      const Profile& q = in[(i + 1) % in.size()];
      const bool p_in = keep_above ? p.z >= c : p.z <= c, q_in = keep_above ? q.z >= c : q.z <= c;
      if (p_in) out.push_back(p);
      if (p_in != q_in) {
        const Profile& lo = p.z < q.z ? p : q;  // (from the same end on both sides of the cut)
        const Profile& hi = p.z < q.z ? q : p;
        out.push_back({c, lo.r + (hi.r - lo.r) * ((c - lo.z) / (hi.z - lo.z))});
      }
    }
    return out;
  };
  const Vec3 e1 = u.unitOrthogonal(), e2 = u.cross(e1);
  const double z0 = profile.front().z, z1 = profile.back().z;
  std::vector<CollisionElement> pieces;
  for (int slab = 0; slab < kSlabs; ++slab) {
    std::vector<Profile> piece = polygon;
    if (slab > 0) piece = clip(piece, z0 + (z1 - z0) * slab / kSlabs, true);
    if (slab + 1 < kSlabs) piece = clip(piece, z0 + (z1 - z0) * (slab + 1) / kSlabs, false);
    // The piece is mirrored across the axis (so are its cuts, negation being exact): a corner and its
    // mirror give one circle, and one on the axis a point.
    for (Profile& p : piece) p.r = std::abs(p.r);
    std::sort(piece.begin(), piece.end(),
              [](const Profile& a, const Profile& b) { return std::tie(a.z, a.r) < std::tie(b.z, b.r); });
    piece.erase(std::unique(piece.begin(), piece.end(),
                            [](const Profile& a, const Profile& b) { return a.z == b.z && a.r == b.r; }),
                piece.end());
    std::vector<Vec3> corners;
    for (const Profile& p : piece)
      for (int j = 0; j < (p.r > 0.0 ? kSides : 1); ++j) {
        const double angle = 2.0 * kPi * j / kSides;
        corners.push_back(p.z * u + (grow * p.r) * (std::cos(angle) * e1 + std::sin(angle) * e2));
      }
    if (corners.empty()) return std::nullopt;
    ConvexHull hull(corners);
    if (hull.triangles().empty()) return std::nullopt;
    CollisionElement solid;
    solid.primitive = Shape{std::move(hull)};
    pieces.push_back(std::move(solid));
  }
  return LinkGeometry(pieces, std::vector<TriangleMesh>{});
}

// revolvedHull's body, shared by every call with the same points and axis (compared exactly, so a body is
// never another's): a wrist's turning link is the lower body of a table for each link above it, and
// building the body took a quarter of loading the dual arm. Null: revolvedHull gave none. At most 64 kept.
std::shared_ptr<const LinkGeometry> revolvedBody(const std::vector<Vec3>& points, const Vec3& u) {
  static std::mutex mutex;
  static std::map<std::vector<double>, std::shared_ptr<const LinkGeometry>> bodies;
  std::vector<double> key = {u.x(), u.y(), u.z()};
  for (const Vec3& p : points) key.insert(key.end(), {p.x(), p.y(), p.z()});
  {
    const std::lock_guard<std::mutex> lock(mutex);
    if (const auto it = bodies.find(key); it != bodies.end()) return it->second;
  }
  std::optional<LinkGeometry> body = revolvedHull(points, u);
  auto shared = body ? std::make_shared<const LinkGeometry>(std::move(*body)) : nullptr;
  const std::lock_guard<std::mutex> lock(mutex);
  if (bodies.size() >= 64) bodies.clear();
  bodies.emplace(std::move(key), shared);
  return shared;
}

bool isAncestor(const RobotModel& model, int ancestor, int link) {
  for (int l = link; l >= 0; l = model.parentLink(l))
    if (l == ancestor) return true;
  return false;
}

// The joints from the upper of links a and b down to the other, root side first, and the upper link; −1
// when neither is the other's ancestor (no chain: no table).
int chainBetween(const RobotModel& model, int a, int b, std::vector<int>& chain) {
  int up = a, down = b;
  if (!isAncestor(model, a, b)) {
    if (!isAncestor(model, b, a)) return -1;
    std::swap(up, down);
  }
  chain.clear();
  for (int l = down; l != up; l = model.parentLink(l)) chain.push_back(model.links()[l].parent_joint);
  std::reverse(chain.begin(), chain.end());
  return up;
}

// Builds one table: the chain up → down as fixed[0]·M₀(x₀)·fixed[1]·(M₁(x₁)·fixed[2]).
struct Builder {
  const LinkGeometry& up;
  const LinkGeometry& down;
  std::vector<Moved> moved;
  std::vector<Pose> fixed;
  double padding;
  GeometryMode mode;
  const Tolerances& tol;
  BodyPair pair;
  double reach_last = 0.0;  // ρ of the lowest moved joint (configuration-independent)
  // The lower body holds more than the lower link (its solid of revolution, revolvedHull): a cell it keeps
  // apart is Free, but its cores prove nothing, and its triangles are not the link's.
  bool free_only = false;

  Builder(const LinkGeometry& u, const LinkGeometry& d, double pad, GeometryMode m, const Tolerances& t)
      : up(u), down(d), padding(pad), mode(m), tol(t), pair(u, d) {}

  Pose relative(const double* x) const {
    Pose p = fixed[0];
    for (std::size_t k = 0; k < moved.size(); ++k) p = p * jointMotion(*moved[k].joint, x[k]) * fixed[k + 1];
    return p;
  }

  // The largest distance of the points of `hull` (the lower link's, or a part's) from joint k's axis, with
  // the joints below k at x.
  double reach(std::size_t k, const double* x, const ConvexHull& hull) const {
    if (moved[k].joint->type == JointType::Prismatic) return 1.0;
    Pose below = fixed[k + 1];
    for (std::size_t i = k + 1; i < moved.size(); ++i) below = below * jointMotion(*moved[i].joint, x[i]) * fixed[i + 1];
    double r = 0.0;
    for (const Vec3& v : hull.vertices()) r = std::max(r, axisDistance(below * v, moved[k].joint->axis));
    return r * margins::kBeyond + margins::kRounding;
  }
  // The upper joint's ρ (of two), for the whole lower link and then for each part: it depends on the lower
  // joint's value alone, so it is computed once per value the cells' centres take (a few hundred), not
  // once per cell (which, over every vertex of every part, was 40% of a UR5 table's cost).
  std::map<double, std::vector<double>> upper_reach;
  const std::vector<double>& upperReach(double lower_value) {
    const auto it = upper_reach.find(lower_value);
    if (it != upper_reach.end()) return it->second;
    const double x[2] = {0.0, lower_value};
    std::vector<double> r = {reach(0, x, down.hull())};
    for (const LinkGeometry::Part& part : down.parts()) r.push_back(reach(0, x, part.hull));
    return upper_reach.emplace(lower_value, std::move(r)).first->second;
  }

  // True when every part of the lower link, moved by its own δ over the cell (a part near the axes moves
  // far less than the link's farthest point), stays beyond the padding: then the pair is apart in the
  // cell. Only in Mesh mode: the parts hold the triangles, not the hull that Hull mode checks.
  std::vector<double> part_reach_last;  // ρ of the lowest moved joint, per part of the lower link
  std::vector<double> part_need;        // scratch
  int near_parts = -1;                  // the part pair too near in the last cell, tested first in the next
  bool partsFree(const double* x, const double* h, const Pose& t, double margin) {
    const std::vector<LinkGeometry::Part>& parts = down.parts();
    if (mode != GeometryMode::Mesh || parts.size() < 2 || up.parts().empty()) return false;
    part_need.assign(parts.size(), padding + margin);
    for (std::size_t j = 0; j < parts.size(); ++j) {
      for (std::size_t k = 0; k < moved.size(); ++k) {
        const double r = k + 1 == moved.size() ? part_reach_last[j] : upperReach(x[1])[1 + j];
        part_need[j] += (h[k] * margins::kBeyond + kValueSlack) * r;
      }
    }
    return partsApart(up, Pose::identity(), down, t, tol, part_need.data(), &near_parts);
  }

  // The verdict for the cell centred at x with half-widths h; for an Unsure one, when `witness` is given,
  // the two triangles that touch at x (invalid when none do). Only the finest cells (`finest`) climb to
  // the triangles (while the table's count of such checks lasts): a larger cell's wide margin would send
  // a search through most of them, and its halves are cheaper to settle.
  long exact_left = 0;  // cells that may still climb to the triangles

  PairTable::Verdict cell(const double* x, const double* h, bool finest, TrianglePair* witness) {
    finest = finest && exact_left > 0;
    if (finest) --exact_left;
    if (!finest) witness = nullptr;
    double delta = 0.0;
    for (std::size_t k = 0; k < moved.size(); ++k) {
      const double r = k + 1 == moved.size() ? reach_last : upperReach(x[1])[0];
      delta += (h[k] * margins::kBeyond + kValueSlack) * r;
    }
    const Pose t = relative(x);
    if (!t.isFinite() || !std::isfinite(delta)) return PairTable::Verdict::Unsure;
    // The rounding of this pose against the one forward kinematics computes, and of the bounds below.
    const double scale = up.boundingRadius() + down.boundingRadius() + t.t.norm();
    const double margin = margins::kSlack + 1e-7 * scale;
    if (!free_only)  // (the swept body's cores are not the link's)
      for (const LinkGeometry::CoreGroup& gb : down.coreGroups()) {
        const Vec3 gc = t * gb.center;
        for (const LinkGeometry::CoreGroup& ga : up.coreGroups()) {
          if (!((ga.center - gc).norm() < ga.radius + gb.radius)) continue;  // (a filter: it decides nothing)
          for (int j = gb.first; j < gb.first + gb.count; ++j) {
            const LinkGeometry::Ball& b = down.cores()[j];
            const Vec3 c = t * b.center;
            for (int i = ga.first; i < ga.first + ga.count; ++i) {
              const LinkGeometry::Ball& a = up.cores()[i];
              if ((a.center - c).norm() + delta + margin < a.radius + b.radius) return PairTable::Verdict::Colliding;
            }
          }
        }
      }
    // So does a core of the lower link that reaches into a primitive of the upper one by more than δ: its
    // centre moves at most δ over the cell (the box a UR5 stands on, whose cores against the upper arm's
    // leave half the pair's colliding cells Unsure).
    if (!free_only && !down.cores().empty() && !up.primitives().empty()) {
      const Pose up_in_down = t.inverse();
      for (const LinkGeometry::Primitive& p : up.primitives())
        if (coreMeetsShape(p.shape, up_in_down * p.pose, down, delta + margin)) return PairTable::Verdict::Colliding;
    }
    const double need = padding + delta + margin;
    BoundQuery q;
    q.enough = need;
    q.mode = GeometryMode::Hull;
    q.within = need;  // the triangles' question is whether they lie within it: no distance is measured
    q.near = 0.0;
    // (At least `need`, not beyond it: a rung that proves enough answers enough itself, e.g. the parts' when
    // every part is that far, and need holds the margin that makes "at least" certain.) The hulls, then
    // each part with its own δ, and only then, in the finest cells, the parts and triangles with the
    // link's δ: most cells near contact settle before the triangle search.
    if (pair.lowerBound(Pose::identity(), t, tol, q) >= need) return PairTable::Verdict::Free;
    if (partsFree(x, h, t, margin)) return PairTable::Verdict::Free;
    if (!finest || mode == GeometryMode::Hull) return PairTable::Verdict::Unsure;
    // The centre's triangles within the padding first: a pair touching there is Unsure whatever the
    // search within `need` would say (11% fewer instructions for the shared Panda's tables), and its
    // witness is kept for the lookups.
    if (witness && meshesIntersectExactly(up, Pose::identity(), down, t, tol, padding, witness))
      return PairTable::Verdict::Unsure;
    // Then the triangles within the cell's margin (the parts, whose needs were at most this one, already
    // failed: climbing the ladder again would only repeat them).
    return meshesIntersectExactly(up, Pose::identity(), down, t, tol, need) ? PairTable::Verdict::Unsure
                                                                            : PairTable::Verdict::Free;
  }
};

// Tables already built, for checkers of the same two link geometries joined by the same chain with the
// same settings (scenes that share a loaded robot, one after another or at once; a scene and its edits,
// a body attached or detached elsewhere on the robot included): a table depends on nothing else. An entry
// lives as long as both geometries (the addresses are then theirs alone).
struct TableKey {
  const LinkGeometry* ga;
  const LinkGeometry* gb;
  int a, b;
  std::vector<double> settings;  // padding, mode, tolerances, grid, held values, the chain's joints
  bool operator<(const TableKey& o) const {
    return std::tie(ga, gb, a, b, settings) < std::tie(o.ga, o.gb, o.a, o.b, o.settings);
  }
};
// A null table: the pair gets none.
using TableCache = detail::WeakMemo<TableKey, std::shared_ptr<const PairTable>, LinkGeometry>;

TableCache& tableCache() {
  static TableCache cache;
  return cache;
}

std::vector<double> tableSettings(double padding, GeometryMode mode, const Tolerances& t,
                                  const std::vector<double>& held, const PairTableOptions& p) {
  std::vector<double> s = {padding, static_cast<double>(mode)};
  appendTolerances(t, s);
  s.insert(s.end(),
           {static_cast<double>(p.coarse_one), static_cast<double>(p.fine_one), static_cast<double>(p.coarse_two),
            static_cast<double>(p.fine_two), static_cast<double>(p.max_checks), p.min_probe_share,
            static_cast<double>(p.max_exact_checks), static_cast<double>(p.max_exact_triangles)});
  for (double h : held) s.push_back(std::isfinite(h) ? h : -std::numeric_limits<double>::infinity());
  return s;
}

// What PairTable::build reads of the model for links a and b, appended to s: the joints between them, in
// order (type, origin, axis, variable, mimic and the moving variable's limits); −1 when neither link is
// the other's ancestor. Robots that agree on it give the same two link geometries the same table.
void appendChain(const RobotModel& model, int a, int b, std::vector<double>& s) {
  std::vector<int> chain;
  const int up = chainBetween(model, a, b, chain);
  if (up < 0) {
    s.push_back(-1.0);
    return;
  }
  s.push_back(up == a ? 0.0 : 1.0);
  for (int ji : chain) {
    const Joint& j = model.joints()[ji];
    s.push_back(static_cast<double>(j.type));
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) s.push_back(j.origin.R(r, c));
    s.insert(s.end(), {j.origin.t.x(), j.origin.t.y(), j.origin.t.z(), j.axis.x(), j.axis.y(), j.axis.z()});
    const int leader = j.isMimic() ? model.joint(j.mimic.joint).first_variable : j.first_variable;
    s.insert(s.end(),
             {static_cast<double>(j.first_variable), static_cast<double>(leader), j.mimic.multiplier, j.mimic.offset});
    if (leader >= 0 && leader < static_cast<int>(model.variables().size()))
      s.insert(s.end(), {model.variables()[leader].lower, model.variables()[leader].upper});
  }
}

}  // namespace

std::shared_ptr<const PairTable> PairTable::shared(const std::shared_ptr<const RobotGeometry>& geometry, int a, int b,
                                                   double padding, GeometryMode mode, const Tolerances& tol,
                                                   const std::vector<double>& held, const PairTableOptions& options) {
  if (!geometry || !geometry->link(a) || !geometry->link(b)) return nullptr;
  TableCache& cache = tableCache();
  TableKey key{geometry->link(a), geometry->link(b), a, b, tableSettings(padding, mode, tol, held, options)};
  appendChain(geometry->model(), a, b, key.settings);
  if (std::optional<std::shared_ptr<const PairTable>> known = cache.find(key)) return *known;
  std::shared_ptr<const PairTable> t =
      build(geometry->model(), a, *geometry->link(a), b, *geometry->link(b), padding, mode, tol, held, options);
  cache.store(std::move(key), geometry->linkPtr(a), geometry->linkPtr(b), t);
  return t;
}

std::vector<std::shared_ptr<const PairTable>> PairTable::sharedMany(
    const std::shared_ptr<const RobotGeometry>& geometry, const std::vector<Request>& requests, GeometryMode mode,
    const Tolerances& tol, const std::vector<double>& held, const PairTableOptions& options) {
  std::vector<std::shared_ptr<const PairTable>> out(requests.size());
  detail::parallelFor(requests.size(), detail::loadThreads(options.threads), [&](std::size_t i) {
    const Request& r = requests[i];
    out[i] = shared(geometry, r.a, r.b, r.padding, mode, tol, held, options);
  });
  return out;
}

PairTable::CacheStats PairTable::cacheStats() {
  const TableCache::Stats m = tableCache().stats();
  CacheStats s;
  s.entries = m.entries;
  s.built = m.stored;
  s.swept = m.swept;
  return s;
}

std::unique_ptr<const PairTable> PairTable::build(const RobotModel& model, int a, const LinkGeometry& ga, int b,
                                                  const LinkGeometry& gb, double padding, GeometryMode mode,
                                                  const Tolerances& tol, const std::vector<double>& held,
                                                  const PairTableOptions& options) {
  std::vector<int> chain;
  const int up = chainBetween(model, a, b, chain);
  if (up < 0) return nullptr;

  const auto heldValue = [&](int var) {
    return var >= 0 && var < static_cast<int>(held.size()) && std::isfinite(held[var]) ? held[var] : NAN;
  };
  const auto leaderOf = [&](const Joint& j) {
    return j.isMimic() ? model.joint(j.mimic.joint).first_variable : j.first_variable;
  };
  const auto moves = [&](const Joint& j) {
    return j.type != JointType::Fixed && !std::isfinite(heldValue(leaderOf(j)));
  };
  // A third moving joint, the lowest, that turns the lower link about its own axis (a wrist's last joint,
  // below it only fixed or held ones): the lower body becomes the solid the link sweeps about that axis,
  // fixed to the joint's parent, and the table is over the other two variables (Free cells only).
  const LinkGeometry& lower = up == a ? gb : ga;
  std::shared_ptr<const LinkGeometry> revolved;
  std::size_t end = chain.size();  // the chain's joints walked below (the revolved joint's origin after them)
  if (std::count_if(chain.begin(), chain.end(), [&](int ji) { return moves(model.joints()[ji]); }) == 3) {
    std::size_t last = chain.size();
    while (!moves(model.joints()[chain[last - 1]])) --last;
    const Joint& turn = model.joints()[chain[last - 1]];
    Pose below = Pose::identity();  // the lower link in the turning joint's frame
    bool rigid = true;
    for (std::size_t k = last; k < chain.size() && rigid; ++k) {
      const Joint& j = model.joints()[chain[k]];
      below = below * j.origin;
      if (j.type == JointType::Fixed) continue;
      rigid = j.type == JointType::Revolute || j.type == JointType::Continuous || j.type == JointType::Prismatic;
      const double value = heldValue(leaderOf(j));
      if (rigid) below = below * jointMotion(j, j.isMimic() ? j.mimic.multiplier * value + j.mimic.offset : value);
    }
    const bool turns = turn.type == JointType::Revolute || turn.type == JointType::Continuous;
    if (rigid && turns && !turn.isMimic() && std::abs(turn.axis.norm() - 1.0) <= margins::kSlack && below.isFinite()) {
      std::vector<Vec3> points;
      for (const Vec3& v : lower.hull().vertices()) points.push_back(below * v);
      revolved = revolvedBody(points, turn.axis);
      if (!revolved) return nullptr;
      end = last - 1;
    }
  }
  Builder bld(up == a ? ga : gb, revolved ? *revolved : lower, padding, mode, tol);
  bld.free_only = revolved != nullptr;
  const auto small = [&](const LinkGeometry& g) {
    return g.triangles().size() <= static_cast<std::size_t>(std::max(0, options.max_exact_triangles));
  };
  bld.exact_left = small(ga) && small(gb) && !revolved ? options.max_exact_checks : 0;
  Pose cur = Pose::identity();
  for (std::size_t k = 0; k < end; ++k) {
    const Joint& j = model.joints()[chain[k]];
    cur = cur * j.origin;
    if (j.type == JointType::Fixed) continue;
    const bool turns = j.type == JointType::Revolute || j.type == JointType::Continuous;
    if (!turns && j.type != JointType::Prismatic) {  // planar, floating: only when held
      return nullptr;
    }
    const int leader = j.isMimic() ? model.joint(j.mimic.joint).first_variable : j.first_variable;
    const double value = heldValue(leader);
    if (std::isfinite(value)) {
      cur = cur * jointMotion(j, j.isMimic() ? j.mimic.multiplier * value + j.mimic.offset : value);
      continue;
    }
    if (j.isMimic() || leader < 0 || bld.moved.size() == 2 || std::abs(j.axis.norm() - 1.0) > margins::kSlack) return nullptr;
    const JointVariable& v = model.variables()[leader];
    Moved m{&j, leader, false, v.lower, v.upper};
    if (turns && !(v.upper - v.lower < 2.0 * kPi)) m = {&j, leader, true, -kPi, kPi};
    if (!(m.hi - m.lo > margins::kSlack) || !std::isfinite(m.hi - m.lo)) return nullptr;
    bld.fixed.push_back(cur);
    bld.moved.push_back(m);
    cur = Pose::identity();
  }
  if (bld.moved.empty()) return nullptr;  // a rigid pair: decided once by the scene
  if (revolved) cur = cur * model.joints()[chain[end]].origin;  // (the body turns about the origin's axis)
  bld.fixed.push_back(cur);

  std::unique_ptr<PairTable> t(new PairTable());
  t->free_only_ = bld.free_only;
  const int dims = static_cast<int>(bld.moved.size());
  const int coarse = dims == 1 ? options.coarse_one : options.coarse_two;
  // Fine cells per coarse one: a power of two, for the halving below.
  t->fine_ = 1;
  while (t->fine_ * 2 <= (dims == 1 ? options.fine_one : options.fine_two)) t->fine_ *= 2;
  for (const Moved& m : bld.moved) {
    t->var_.push_back(m.var);
    t->periodic_.push_back(m.periodic);
    t->lo_.push_back(m.lo);
    t->n_.push_back(std::max(1, coarse));
    t->inv_.push_back(t->n_.back() / (m.hi - m.lo));
  }
  {
    const double x[2] = {0.0, 0.0};
    bld.reach_last = bld.reach(dims - 1, x, bld.down.hull());
    for (const LinkGeometry::Part& part : bld.down.parts())
      bld.part_reach_last.push_back(bld.reach(dims - 1, x, part.hull));
  }
  const auto width = [&](int k) { return (bld.moved[k].hi - bld.moved[k].lo) / t->n_[k]; };
  const int n0 = t->n_[0], n1 = dims == 2 ? t->n_[1] : 1;
  const int f = t->fine_, f1 = dims == 2 ? f : 1;
  long budget = options.max_checks;
  // A region of coarse cell `coarse`: fine cells [j, j + size) per dimension.
  struct Region {
    int coarse, j0, j1, size;
  };
  std::vector<TrianglePair> witnesses(static_cast<std::size_t>(n0) * n1 * f * f1);
  const auto check = [&](const Region& r) {
    const int i[2] = {r.coarse % n0, r.coarse / n0}, j[2] = {r.j0, r.j1};
    double x[2], h[2];
    for (int k = 0; k < dims; ++k) {
      x[k] = bld.moved[k].lo + (i[k] + (j[k] + 0.5 * r.size) / f) * width(k);
      h[k] = 0.5 * r.size * width(k) / f;
    }
    ++t->checked_;
    --budget;
    TrianglePair w;
    const Verdict v = bld.cell(x, h, r.size == 1, r.size == 1 ? &w : nullptr);
    // In the pair's order (a, b), as lookup gives it.
    if (w.valid()) witnesses[(static_cast<std::size_t>(r.coarse) * f1 + r.j1) * f + r.j0] = up == a ? w : TrianglePair{w.b, w.a};
    return v;
  };
  // Level by level, halving the regions still unsure: those far from contact settle after a split or
  // two, only those near it reach the finest size, and a budget that runs out leaves the whole table
  // equally fine rather than one end of it. The lower joint varies slowest: neighbours share warm starts.
  std::vector<Verdict> cells(static_cast<std::size_t>(n0) * n1 * f * f1, Verdict::Unsure);
  const auto fill = [&](const Region& r, Verdict v) {
    const std::size_t base = static_cast<std::size_t>(r.coarse) * f * f1;
    for (int y = r.j1; y < r.j1 + (dims == 2 ? r.size : 1); ++y)
      for (int x = r.j0; x < r.j0 + r.size; ++x) cells[base + static_cast<std::size_t>(y) * f + x] = v;
  };
  const auto split = [&](const Region& r, std::vector<Region>& out) {
    const int half = r.size / 2;
    for (int b1 = 0; b1 < (dims == 2 ? 2 : 1); ++b1)
      for (int b0 = 0; b0 < 2; ++b0) out.push_back({r.coarse, r.j0 + b0 * half, r.j1 + b1 * half, half});
  };
  const auto refine = [&](std::vector<Region> level) {
    std::vector<Region> next;
    while (!level.empty() && budget >= static_cast<long>(level.size())) {
      next.clear();
      for (const Region& r : level) {
        if (std::chrono::steady_clock::now() > options.deadline) return;
        const Verdict v = check(r);
        if (v != Verdict::Unsure) fill(r, v);
        else if (r.size > 1) split(r, next);
      }
      level.swap(next);
    }
  };
  const auto share = [&](const std::vector<int>& coarse_cells) {
    const std::size_t per = static_cast<std::size_t>(f) * f1;
    double settled = 0.0;
    for (int c : coarse_cells)
      for (std::size_t k = c * per; k < (c + 1) * per; ++k) settled += cells[k] != Verdict::Unsure;
    return coarse_cells.empty() ? 1.0 : settled / (per * coarse_cells.size());
  };
  // A probe first, every kProbe-th coarse cell per dimension refined in full: a pair that stays near
  // contact over its whole range (a link turning about an axis through its neighbour) settles too little
  // to pay for the rest.
  constexpr int kProbe = 4;
  std::vector<int> probe;
  std::vector<Region> probe_cells, rest;
  for (int c = 0; c < n0 * n1; ++c) {
    const bool probed = c % n0 % kProbe == 0 && c / n0 % kProbe == 0;
    (probed ? probe_cells : rest).push_back({c, 0, 0, f});
    if (probed) probe.push_back(c);
  }
  refine(probe_cells);
  // (A free-only table, asked only where the balls meet, must settle twice the share to pay its build.)
  if (share(probe) < (bld.free_only ? 2.0 : 1.0) * options.min_probe_share) return nullptr;
  refine(rest);
  // Blocks all of one verdict fold into their coarse cell.
  const std::size_t per = static_cast<std::size_t>(f) * f1;
  double certified = 0.0;
  for (int c = 0; c < n0 * n1; ++c) {
    const auto first = cells.begin() + static_cast<std::ptrdiff_t>(c * per), last = first + static_cast<std::ptrdiff_t>(per);
    certified += static_cast<double>(std::count_if(first, last, [](Verdict w) { return w != Verdict::Unsure; })) / per;
    const auto wfirst = witnesses.begin() + static_cast<std::ptrdiff_t>(c * per), wlast = wfirst + static_cast<std::ptrdiff_t>(per);
    if (std::all_of(first, last, [&](Verdict w) { return w == *first; }) &&
        std::none_of(wfirst, wlast, [](const TrianglePair& w) { return w.valid(); })) {
      t->coarse_.push_back(-1 - static_cast<std::int32_t>(*first));
    } else {
      t->coarse_.push_back(static_cast<std::int32_t>(t->fine_cells_.size()));
      t->fine_cells_.insert(t->fine_cells_.end(), first, last);
      t->witness_.insert(t->witness_.end(), wfirst, wlast);
    }
  }
  t->certified_ = certified / (static_cast<double>(n0) * n1);
  return t;
}

double PairTable::coordinate(int k, double x) const noexcept {
  if (periodic_[k]) {
    if (!(std::abs(x) <= kMaxTurn)) return -1.0;
    x = std::remainder(x, 2.0 * kPi);
  }
  const double u = (x - lo_[k]) * inv_[k];
  return u >= 0.0 && u <= n_[k] ? u : -1.0;  // (NaN fails)
}

PairTable::Verdict PairTable::lookup(const double* q, TrianglePair* witness) const noexcept {
  if (witness) *witness = {};
  const int dims = static_cast<int>(var_.size());
  double u[2];
  int i[2];
  int cell = 0, stride = 1;
  for (int k = 0; k < dims; ++k) {
    u[k] = coordinate(k, q[var_[k]]);
    if (u[k] < 0.0) return Verdict::Unsure;
    i[k] = std::min(static_cast<int>(u[k]), n_[k] - 1);
    cell += i[k] * stride;
    stride *= n_[k];
  }
  const std::int32_t e = coarse_[cell];
  if (e < 0) return static_cast<Verdict>(-1 - e);
  int at = 0;
  stride = 1;
  for (int k = 0; k < dims; ++k) {
    at += std::min(static_cast<int>((u[k] - i[k]) * fine_), fine_ - 1) * stride;
    stride *= fine_;
  }
  if (witness) *witness = witness_[e + at];
  return fine_cells_[e + at];
}

bool PairTable::freeAlong(const double* q0, const double* q1) const noexcept {
  // A walk through the coarse cells the segment crosses (Amanatides–Woo), in coarse-cell units, and through
  // the fine cells it crosses within each refined one; a turn is walked unrolled, its cells taken modulo the
  // turn. A crossing misordered by rounding near a corner visits a neighbour of the cell it skips, within
  // far less than the slack every cell's check added.
  const int dims = static_cast<int>(var_.size());
  double u[2] = {0.0, 0.0}, d[2] = {0.0, 0.0}, next[2], delta[2];
  int c[2] = {0, 0}, step[2] = {0, 0};
  long budget = 2;  // coarse cells the walk may visit: those between its ends, plus its first
  for (int k = 0; k < dims; ++k) {
    double a = q0[var_[k]], b = q1[var_[k]];
    if (periodic_[k]) {
      if (!(std::abs(a) <= kMaxTurn && std::abs(b) <= kMaxTurn)) return false;
      const double r = std::remainder(a, 2.0 * kPi);
      b = r + (b - a);
      a = r;
    } else if (!(a >= lo_[k] && a <= lo_[k] + n_[k] / inv_[k] && b >= lo_[k] && b <= lo_[k] + n_[k] / inv_[k])) {
      return false;  // (the segment lies within the range when its ends do)
    }
    u[k] = (a - lo_[k]) * inv_[k];
    d[k] = (b - a) * inv_[k];
    if (!std::isfinite(u[k]) || !std::isfinite(d[k])) return false;
    const double start = std::floor(u[k]);
    c[k] = static_cast<int>(start);
    const WalkAxis axis(u[k], d[k], start);
    step[k] = axis.step, next[k] = axis.next, delta[k] = axis.delta;
    budget += static_cast<long>(std::abs(std::floor(u[k] + d[k]) - start)) + 1;
  }
  if (budget > 64L * (n_[0] + (dims == 2 ? n_[1] : 0))) return false;  // many turns: not worth the walk
  double t_in = 0.0;                                                   // where the segment enters the coarse cell c
  for (; budget > 0; --budget) {
    int cell = 0, stride = 1;
    int walked[2] = {0, 0};  // c, but a range's end on its far border in the last cell
    for (int k = 0; k < dims; ++k) {
      int at = c[k] % n_[k];
      if (at < 0) at += n_[k];
      walked[k] = c[k];
      if (!periodic_[k]) at = walked[k] = std::clamp(c[k], 0, n_[k] - 1);
      cell += at * stride;
      stride *= n_[k];
    }
    const int k = dims == 2 && next[1] < next[0] ? 1 : 0;
    const double t_out = std::min(next[k], 1.0);
    const std::int32_t e = coarse_[cell];
    if (e < 0 ? static_cast<Verdict>(-1 - e) != Verdict::Free : !fineFreeAlong(e, walked, u, d, t_in, t_out))
      return false;
    if (!(next[k] <= 1.0)) return true;  // the walk reached q1's cell
    c[k] += step[k];
    t_in = next[k];
    next[k] += delta[k];
  }
  return false;  // (rounding took more steps than the cells between the ends: not proved)
}

bool PairTable::fineFreeAlong(std::int32_t e, const int* c, const double* u, const double* d, double t_in,
                              double t_out) const noexcept {
  // The same walk in fine-cell units, from where the segment enters coarse cell c (unrolled) until it leaves
  // it, its fine cells clamped into c's.
  const int dims = static_cast<int>(var_.size());
  double uf[2], next[2] = {INFINITY, INFINITY}, delta[2] = {INFINITY, INFINITY};
  int f[2] = {0, 0}, step[2] = {0, 0}, first[2] = {0, 0};
  for (int k = 0; k < dims; ++k) {
    uf[k] = u[k] * fine_;
    const double df = d[k] * fine_;
    first[k] = c[k] * fine_;
    f[k] = std::clamp(static_cast<int>(std::floor(uf[k] + df * t_in)), first[k], first[k] + fine_ - 1);
    const WalkAxis axis(uf[k], df, f[k]);
    step[k] = axis.step, next[k] = axis.next, delta[k] = axis.delta;
  }
  for (int left = 2 * fine_ + 2; left > 0; --left) {  // (a walk within one coarse cell crosses 2·fine_ at most)
    int at = 0, stride = 1;
    for (int k = 0; k < dims; ++k) {
      at += (f[k] - first[k]) * stride;
      stride *= fine_;
    }
    if (fine_cells_[e + at] != Verdict::Free) return false;
    const int k = dims == 2 && next[1] < next[0] ? 1 : 0;
    if (!(next[k] < t_out)) return true;  // it leaves the coarse cell first
    f[k] += step[k];
    if (f[k] < first[k] || f[k] >= first[k] + fine_) return true;
    next[k] += delta[k];
  }
  return false;
}

}  // namespace clearway
