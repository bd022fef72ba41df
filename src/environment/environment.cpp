// Environment: obstacles and voxels in world-frame AABB trees, and the link queries against them.
//
// A link is first reduced to its world box (the box of its hull's box placed by the pose), which picks
// the candidates from each tree. Candidates then meet tests from cheapest to dearest: for voxels the
// link's box as an oriented box (6 face axes), then GJK against the link's hull (one warm-started
// cache for all voxels of a query: every voxel is axis-aligned, so the last separating axis is a good
// start for the next), and only in Mesh mode, when the hull touches voxels, the triangles. When more
// than a few voxels pass the hull, the voxel tree and the link's triangle tree are descended together
// (world frame against link frame), which tests each voxel only against the triangles near it.
//
// Slack: boxes are grown by padding + band, band = 4·max(gjk_absolute, 64 ulps)·scale with scale
// bounding every coordinate of the query, so box culling never drops a pair that GJK (whose own band
// is gjk_absolute times the pair's size) would call touching.
#include <clearway/environment/environment.h>

#include <clearway/narrowphase/epa.h>
#include <clearway/narrowphase/ray_cast.h>
#include <clearway/shape/support.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace clearway {
namespace {

// The world box of a shape placed by `pose`, widened by a few roundings of its coordinates: the trees
// must never drop what the box only just reaches.
Aabb shapeWorldBox(const Shape& shape, const Pose& pose) noexcept {
  const Aabb box = placedBox(shape, pose);
  const double scale = box.min.cwiseAbs().cwiseMax(box.max.cwiseAbs()).maxCoeff();
  return box.inflated(16.0 * std::numeric_limits<double>::epsilon() * scale);
}

Aabb obstacleBox(const Obstacle& o, const Pose& pose) noexcept {
  return o.mesh ? transformed(o.mesh->bounds(), pose) : shapeWorldBox(o.shape, pose);
}

// f applied to the obstacle as a convex shape: a mesh obstacle's hull, or its primitive.
template <class F>
decltype(auto) onConvex(const Obstacle& o, F&& f) {
  return o.mesh ? f(o.mesh->hull()) : std::visit(f, o.shape);
}

Pose poseAt(const Obstacle& o, double t) noexcept {
  Pose p = o.pose;
  if (o.moving()) p.t += t * o.velocity;
  return p;
}

double maxAbs(const Aabb& b) noexcept {
  return b.isEmpty() ? 0.0 : b.min.cwiseAbs().cwiseMax(b.max.cwiseAbs()).maxCoeff();
}

// The culls' band: four times the narrow phase's, for the roundings of placing boxes in the world.
double bandOf(double scale, const Tolerances& tol) noexcept { return 4.0 * narrowBand(scale, tol); }

bool obstacleIntersects(const Obstacle& o, const Pose& pose_o, const LinkGeometry& link, const Pose& pose,
                        const Tolerances& tol, GeometryMode mode, double padding) noexcept {
  return o.mesh ? meshesIntersect(*o.mesh, pose_o, link, pose, tol, mode, padding)
                : shapeIntersectsLink(o.shape, pose_o, link, pose, tol, mode, padding);
}

// Voxels passing the hull test that the Mesh mode checks one by one (each against the triangles near
// it); beyond this many, descending the two trees together is cheaper than a triangle-tree query each.
constexpr int kFewVoxels = 4;

// The running minimum of Environment::linkDistance, with the link as A.
struct NearestSearch {
  DistanceResult best;
  double lower = std::numeric_limits<double>::infinity();  // min of the evaluated items' lower bounds
  double limit;   // items certainly farther than this are skipped: min(cutoff, best / (1 + e))
  double shrink;
  bool failed = false;

  NearestSearch(double cutoff, double relative_error) : limit(cutoff), shrink(1.0 / (1.0 + relative_error)) {
    best.distance = cutoff;
    best.lower_bound = cutoff;
    best.status = Status::Separated;
  }
  // Returns true when the search can stop (contact, or a failure).
  bool add(const DistanceResult& r) {
    best.iterations += r.iterations;
    if (isFailure(r.status)) {
      failed = true;
      return true;
    }
    lower = std::min(lower, r.lower_bound);
    if (r.distance < best.distance) {
      const int iterations = best.iterations;
      best = r;
      best.iterations = iterations;
      limit = std::min(limit, r.distance * shrink);
    }
    return best.distance <= 0.0;
  }
};

// A distance with A and B exchanged.
DistanceResult swapped(DistanceResult r) noexcept {
  std::swap(r.point_a, r.point_b);
  r.normal = -r.normal;
  return r;
}

}  // namespace

Environment::Environment(std::vector<Obstacle> obstacles, std::shared_ptr<const OccupancyMap> map)
    : obstacles_(std::move(obstacles)), map_(std::move(map)) {
  std::vector<Aabb> boxes;
  for (std::size_t i = 0; i < obstacles_.size(); ++i) {
    const Obstacle& o = obstacles_[i];
    if (!o.pose.isFinite()) throw std::invalid_argument("environment: obstacle '" + o.name + "' has a non-finite pose");
    if (!o.velocity.allFinite())
      throw std::invalid_argument("environment: obstacle '" + o.name + "' has a non-finite velocity");
    if (o.moving()) {
      moving_.push_back(static_cast<int>(i));
      continue;
    }
    static_.push_back(static_cast<int>(i));
    boxes.push_back(obstacleBox(o, o.pose));
  }
  has_moving_ = !moving_.empty();
  static_tree_ = AabbTree(boxes);  // throws std::invalid_argument for a non-finite box
  // Voxels lie on a grid: the median split is as good as the SAH there and builds several times faster.
  if (map_ && !map_->occupied.empty()) voxel_tree_ = AabbTree(map_->occupied, {TreeSplit::Median, 2});
  scale_ = std::max(maxAbs(static_tree_.bounds()), maxAbs(voxel_tree_.bounds()));
}

// Which items a query visits: those whose boxes overlap a world box, or those within `limit` of the link's
// box as an oriented box (the limit is read again before each item: a nearest search lowers it).
struct Environment::Reach {
  const Aabb* box = nullptr;    // overlap
  const Aabb* local = nullptr;  // within: the link's box in its frame, placed by *pose
  const Pose* pose = nullptr;
  double* limit = nullptr;

  static Reach overlapping(const Aabb& world_box) noexcept {
    Reach r;
    r.box = &world_box;
    return r;
  }
  static Reach within(const Aabb& local_box, const Pose& pose, double& limit) noexcept {
    Reach r;
    r.local = &local_box;
    r.pose = &pose;
    r.limit = &limit;
    return r;
  }
};

// One item near the link: an obstacle where it is at the query's time, or a voxel.
struct Environment::Item {
  EnvironmentHit::Kind kind;
  int index;                   // obstacle index, or voxel index
  const Obstacle* obstacle;    // null for a voxel
  const Aabb* voxel;           // null for an obstacle
  Pose pose;                   // the obstacle's at the query's time, or the voxel's centre
  int warm;                    // a static obstacle's index among the static ones (its warm start), else −1

  Aabb box() const noexcept { return obstacle ? obstacleBox(*obstacle, pose) : *voxel; }
  // f applied to the item as a convex shape: a mesh obstacle's hull, a primitive, a voxel's box.
  template <class F>
  decltype(auto) convex(F&& f) const {
    return obstacle ? onConvex(*obstacle, f) : f(Box(voxel->halfExtents()));
  }
};

template <class F>
Environment::Walk Environment::forEachItem(const Reach& reach, double t, F&& visit) const {
  const auto tree = [&](const AabbTree& items, auto&& on_item) {
    return reach.box ? items.query(*reach.box, on_item) : items.forEachWithin(*reach.local, *reach.pose, *reach.limit, on_item);
  };
  if (tree(static_tree_, [&](std::int32_t k) {
        const int i = static_[k];
        return visit(Item{EnvironmentHit::Kind::Obstacle, i, &obstacles_[i], nullptr, obstacles_[i].pose, k});
      }))
    return Walk::Stopped;
  // Moving obstacles are few by nature: each box is placed at t and tested on its own.
  const Aabb link_box = reach.box ? Aabb() : transformed(*reach.local, *reach.pose);
  for (const int i : moving_) {
    const Item item{EnvironmentHit::Kind::Obstacle, i, &obstacles_[i], nullptr, poseAt(obstacles_[i], t), -1};
    if (!item.pose.isFinite()) return Walk::Invalid;
    const Aabb box = item.box();
    if (reach.box ? !overlaps(box, *reach.box) : !(boxDistance(box, link_box) <= *reach.limit)) continue;
    if (visit(item)) return Walk::Stopped;
  }
  if (voxel_tree_.empty()) return Walk::Done;
  const std::vector<Aabb>& voxels = map_->occupied;
  return tree(voxel_tree_, [&](std::int32_t v) {
           return visit(Item{EnvironmentHit::Kind::Voxel, v, nullptr, &voxels[v], Pose::translation(voxels[v].center()), -1});
         })
             ? Walk::Stopped
             : Walk::Done;
}

bool Environment::linkIntersects(const LinkGeometry& link, const Pose& pose, const Tolerances& tol, GeometryMode mode,
                                 double padding, double t, EnvironmentHit* hit,
                                 EnvironmentCounters* counters) const noexcept {
  if (hit) *hit = EnvironmentHit{};
  if (!pose.isFinite() || !(padding >= 0.0) || !std::isfinite(padding) || !std::isfinite(t)) return true;
  const auto report = [&](EnvironmentHit::Kind kind, int index) {
    if (hit) {
      hit->kind = kind;
      hit->index = index;
    }
    return true;
  };
  const Aabb link_box = transformed(link.bounds(), pose);
  const double slack = padding + bandOf(scale_ + maxAbs(link_box) + padding, tol);
  const Aabb query = link_box.inflated(slack);

  // The link's box as an oriented box in the world (A = world, B = the link frame): the voxels' first cull.
  const detail::OrientedBoxTest obb(pose, slack, scale_ + maxAbs(link_box));
  const detail::OrientedBoxTest::PlacedB placed_link = obb.place(link.bounds());
  SimplexCache cache;  // one for all voxels: they are axis-aligned, so the last separating axis starts the next well
  int passed[kFewVoxels];
  int n_passed = 0;
  bool many = false;
  int found = -1;
  EnvironmentHit::Kind found_kind = EnvironmentHit::Kind::None;
  const Walk walk = forEachItem(Reach::overlapping(query), t, [&](const Item& item) {
    found_kind = item.kind;
    if (item.obstacle) {
      if (counters) ++counters->obstacle_tests;
      if (!obstacleIntersects(*item.obstacle, item.pose, link, pose, tol, mode, padding)) return false;
      found = item.index;
      return true;
    }
    double c[3], h[3];
    detail::OrientedBoxTest::centerHalf(*item.voxel, c, h);
    if (obb.separated<false>(c, h, placed_link)) return false;
    if (counters) ++counters->voxel_tests;
    if (!shapeIntersectsLink(Box(Vec3(h[0], h[1], h[2])), Pose::translation(Vec3(c[0], c[1], c[2])), link, pose, tol,
                             GeometryMode::Hull, padding, &cache))
      return false;
    if (mode == GeometryMode::Hull || n_passed == kFewVoxels) {
      found = item.index;
      many = mode == GeometryMode::Mesh;
      return true;
    }
    passed[n_passed++] = item.index;
    return false;
  });
  if (walk == Walk::Invalid) {  // a moving obstacle out of reach of the doubles: touching, never free
    for (const int i : moving_)
      if (!poseAt(obstacles_[i], t).isFinite()) return report(EnvironmentHit::Kind::Obstacle, i);
  }
  if (found >= 0 && found_kind == EnvironmentHit::Kind::Obstacle) return report(found_kind, found);
  if (voxel_tree_.empty()) return false;
  const std::vector<Aabb>& voxels = map_->occupied;
  if (mode == GeometryMode::Hull) return found >= 0 ? report(EnvironmentHit::Kind::Voxel, found) : false;

  if (!many) {
    for (int k = 0; k < n_passed; ++k) {
      const Aabb& b = voxels[passed[k]];
      if (counters) ++counters->voxel_tests;
      if (shapeIntersectsLink(Box(b.halfExtents()), Pose::translation(b.center()), link, pose, tol, GeometryMode::Mesh,
                              padding, &cache))
        return report(EnvironmentHit::Kind::Voxel, passed[k]);
    }
    return false;
  }

  // Many voxels inside the hull: voxel tree (world) against triangle tree (link frame), then box–triangle
  // GJK; then the link's primitives against the voxels near them.
  found = -1;
  // A core of the link meeting an occupied voxel settles it without the triangle search.
  const double core_margin = 1e-9 * (1.0 + scale_ + maxAbs(link_box));
  for (const LinkGeometry::Ball& core : link.cores()) {
    const Vec3 c = pose * core.center;
    const double r = core.radius - core_margin;
    if (!(r > 0.0)) continue;
    voxel_tree_.query(Aabb::fromCenterHalf(c, Vec3::Constant(r)), [&](std::int32_t v) {
      const Aabb& b = voxels[v];
      if (((c - b.center()).cwiseAbs() - b.halfExtents()).cwiseMax(0.0).norm() >= r) return false;
      found = v;
      return true;
    });
    if (found >= 0) return report(EnvironmentHit::Kind::Voxel, found);
  }
  const std::vector<Triangle>& tris = link.triangles();
  forEachOverlap(
      voxel_tree_, link.tree(), pose,
      [&](std::int32_t v, std::int32_t j) {
        if (counters) ++counters->voxel_tests;
        const Aabb& b = voxels[v];
        const Box box(b.halfExtents());
        SimplexCache pair_cache;
        if (!gjkIntersect(Margin<Box>{box, padding}, Pose::translation(b.center()), tris[j], pose, tol, pair_cache)
                 .intersecting)
          return false;
        found = v;
        return true;
      },
      slack);
  if (found >= 0) return report(EnvironmentHit::Kind::Voxel, found);
  for (const LinkGeometry::Primitive& p : link.primitives()) {
    const Pose pose_p = pose * p.pose;
    voxel_tree_.query(shapeWorldBox(p.shape, pose_p).inflated(slack), [&](std::int32_t v) {
      if (counters) ++counters->voxel_tests;
      const Aabb& b = voxels[v];
      const Box box(b.halfExtents());
      SimplexCache pair_cache;
      const bool touching = std::visit(
          [&](const auto& s) {
            return gjkIntersect(Margin<Box>{box, padding}, Pose::translation(b.center()), s, pose_p, tol, pair_cache)
                .intersecting;
          },
          p.shape);
      if (touching) found = v;
      return touching;
    });
    if (found >= 0) return report(EnvironmentHit::Kind::Voxel, found);
  }
  // No surface touches a voxel: one may still lie inside a closed mesh of the link.
  if (link.solidCount() > 0) {
    const Pose to_link = pose.inverse();
    voxel_tree_.query(query, [&](std::int32_t v) {
      if (!link.containsPoint(to_link * voxels[v].center())) return false;
      found = v;
      return true;
    });
    if (found >= 0) return report(EnvironmentHit::Kind::Voxel, found);
  }
  return false;
}

DistanceResult Environment::linkDistance(const LinkGeometry& link, const Pose& pose, const Tolerances& tol,
                                         double cutoff, double t, double relative_error,
                                         EnvironmentCounters* counters, GeometryMode mode) const noexcept {
  if (!pose.isFinite() || !std::isfinite(t) || !(cutoff >= 0.0) || !(relative_error >= 0.0) ||
      !std::isfinite(relative_error)) {
    DistanceResult r;
    r.status = Status::InvalidInput;
    return r;
  }
  NearestSearch search(cutoff, relative_error);

  // One item: the hull's lower bound first (one GJK), the exact geometry only when it may be nearer. The
  // link's box as an oriented box sees items much nearer than its world box admits.
  const Walk walk = forEachItem(Reach::within(link.bounds(), pose, search.limit), t, [&](const Item& item) {
    const DistanceResult hull = item.convex([&](const auto& s) { return gjkDistance(link.hull(), pose, s, item.pose, tol); });
    if (!isFailure(hull.status) && hull.lower_bound >= search.limit) return false;
    if (mode == GeometryMode::Hull) return search.add(hull);
    if (counters) ++counters->distance_tests;
    if (item.obstacle && item.obstacle->mesh)
      return search.add(meshDistance(link, pose, *item.obstacle->mesh, item.pose, tol, relative_error));
    // (The obstacle's own shape by reference: a copy of a hull would allocate per item.)
    if (item.obstacle)
      return search.add(swapped(shapeLinkDistance(item.obstacle->shape, item.pose, link, pose, tol, relative_error)));
    return search.add(swapped(shapeLinkDistance(Box(item.voxel->halfExtents()), item.pose, link, pose, tol, relative_error)));
  });
  if (walk == Walk::Invalid) search.failed = true;

  DistanceResult r = search.best;
  if (search.failed) {
    r.status = Status::NotConverged;
    r.distance = 0.0;
    r.lower_bound = 0.0;
    return r;
  }
  // Every item not evaluated was at least the final limit away.
  r.lower_bound = std::min({search.lower, search.limit, r.distance});
  return r;
}

double Environment::hullLowerBound(const LinkGeometry& link, const Pose& pose, const Tolerances& tol, double enough,
                                   double relative, double t, EnvironmentCounters* counters,
                                   SimplexCache* warm, bool by_parts) const noexcept {
  if (!pose.isFinite() || !std::isfinite(t) || !(enough >= 0.0) || !(relative >= 0.0) || !std::isfinite(relative))
    return 0.0;
  double lower = enough;  // the least bound so far: items certainly beyond it cannot lower it
  const auto measure = [&](const auto& shape, const Pose& pose_o, SimplexCache* cache) {
    SimplexCache cold;
    if (by_parts) {  // (cold starts: callers ask only when the hull has come within contact)
      for (const LinkGeometry::Part& part : link.parts()) {
        cold = SimplexCache{};
        lower = std::min(lower, gjkLowerBound(part.hull, pose, shape, pose_o, tol, cold, lower, relative));
        if (!(lower > 0.0)) return true;
      }
      // The parts cover the link's surfaces, not a closed mesh's inside, where the item may lie.
      // (The core's support point is a point of the item.)
      if (link.solidCount() > 0 && link.containsPoint(relativePose(pose, pose_o) * shape.support(Vec3::UnitX()))) {
        lower = 0.0;
        return true;
      }
      return false;
    }
    lower = std::min(lower, gjkLowerBound(link.hull(), pose, shape, pose_o, tol, cache ? *cache : cold, lower, relative));
    return !(lower > 0.0);
  };
  const Walk walk = forEachItem(Reach::within(link.bounds(), pose, lower), t, [&](const Item& item) {
    if (!item.obstacle && counters) ++counters->voxel_tests;  // (as linkDistance counts: voxel hull tests)
    SimplexCache* cache = warm && item.warm >= 0 ? warm + item.warm : nullptr;
    return item.convex([&](const auto& s) { return measure(s, item.pose, cache); });
  });
  if (walk == Walk::Invalid) return 0.0;
  return lower >= 0.0 ? lower : 0.0;  // (NaN: 0)
}

double Environment::lowerBound(const LinkGeometry& link, const Pose& pose, const Tolerances& tol, const BoundQuery& q,
                               double t, SimplexCache* warm, EnvironmentHit* hit,
                               EnvironmentCounters* counters) const noexcept {
  if (hit) *hit = EnvironmentHit{};
  const double climb = q.climb >= 0.0 ? q.climb : q.enough;
  double lower = hullLowerBound(link, pose, tol, q.enough, q.relative, t, counters, warm);
  if (!(lower <= climb) || q.mode == GeometryMode::Hull) return lower;
  // (The bound so far second in max(): a NaN leaves it.)
  lower = std::max(hullLowerBound(link, pose, tol, q.enough, q.relative, t, counters, nullptr, true), lower);
  if (!(lower <= climb)) return lower;
  if (q.within >= 0.0 && linkIntersects(link, pose, tol, GeometryMode::Mesh, q.within, t, hit, counters)) return 0.0;
  const DistanceResult m = linkDistance(link, pose, tol, std::min(q.enough, q.near), t, q.relative, counters);
  if (isFailure(m.status)) return 0.0;
  return q.within >= 0.0 ? std::max(m.lower_bound, q.within * (1.0 + 1e-9)) : m.lower_bound;
}

double Environment::linkCast(const LinkGeometry& link, const Pose& pose, const Vec3& velocity, double margin,
                             const Tolerances& tol, double max_s, double t,
                             EnvironmentCounters* counters) const noexcept {
  constexpr double kNone = std::numeric_limits<double>::infinity();
  if (!pose.isFinite() || !velocity.allFinite() || !(margin >= 0.0) || !std::isfinite(margin) || !std::isfinite(t) ||
      !(max_s >= 0.0) || !std::isfinite(max_s))
    return 0.0;
  const Aabb start = transformed(link.bounds(), pose).inflated(margin);
  Aabb swept = start;
  swept.min += (max_s * velocity).cwiseMin(Vec3::Zero());
  swept.max += (max_s * velocity).cwiseMax(Vec3::Zero());
  const double band = bandOf(scale_ + maxAbs(swept), tol);
  swept = swept.inflated(band);
  const Margin<ConvexHull> grown{link.hull(), margin};
  double first = kNone;
  // One candidate: the slab test of the moving box against its box first (the s interval where they
  // overlap), then the cast, only as far as the earliest hit so far.
  const auto visit = [&](const Aabb& box, const auto& shape, const Pose& pose_o) {
    const double limit = std::min(first, max_s);
    double enter = 0.0, leave = limit;
    for (int i = 0; i < 3 && enter <= leave; ++i) {
      const double lo = box.min[i] - band - start.max[i], hi = box.max[i] + band - start.min[i];  // overlap: lo ≤ s·v ≤ hi
      const double v = velocity[i];
      if (v == 0.0) {
        if (lo > 0.0 || hi < 0.0) return;
      } else {
        const double a = lo / v, b = hi / v;
        enter = std::max(enter, std::min(a, b));
        leave = std::min(leave, std::max(a, b));
      }
    }
    if (!(enter <= leave)) return;
    if (counters) ++counters->cast_tests;
    const CastResult c = gjkShapeCast(grown, pose, velocity, shape, pose_o, limit, tol);
    if (c.hit) first = std::min(first, std::max(0.0, c.t));
  };
  const Walk walk = forEachItem(Reach::overlapping(swept), t, [&](const Item& item) {
    item.convex([&](const auto& shape) { visit(item.box(), shape, item.pose); });
    return false;
  });
  if (walk == Walk::Invalid) return 0.0;
  return first <= max_s ? first : kNone;
}

double Environment::linkPenetration(const LinkGeometry& link, const Pose& pose, const Tolerances& tol, double padding,
                                    double t, EnvironmentCounters* counters) const noexcept {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (!pose.isFinite() || !(padding >= 0.0) || !std::isfinite(padding) || !std::isfinite(t)) return nan;
  const Aabb link_box = transformed(link.bounds(), pose).inflated(padding);
  double deepest = 0.0;
  bool failed = false;
  // One touching item: the hull's depth into it (EPA runs only here).
  const auto depth = [&](const auto& shape, const Pose& pose_s) {
    if (counters) ++counters->penetration_tests;
    const PenetrationResult r = epaPenetration(link.hull(), pose, shape, pose_s, tol);
    if (isFailure(r.status)) failed = true;
    deepest = std::max(deepest, padding - r.signed_distance);  // padded links may touch with the hull apart
  };
  const Walk walk = forEachItem(Reach::overlapping(link_box), t, [&](const Item& item) {
    const Obstacle* o = item.obstacle;
    if (o && o->mesh) {
      if (meshesIntersect(link, pose, *o->mesh, item.pose, tol, GeometryMode::Mesh, padding)) depth(o->mesh->hull(), item.pose);
      return false;
    }
    const auto visit = [&](const Shape& shape) {  // (by reference: a copied hull would allocate)
      if (shapeIntersectsLink(shape, item.pose, link, pose, tol, GeometryMode::Mesh, padding))
        std::visit([&](const auto& s) { depth(s, item.pose); }, shape);
    };
    if (o) visit(o->shape);
    else visit(Box(item.voxel->halfExtents()));
    return false;
  });
  if (walk == Walk::Invalid) return nan;
  return failed ? nan : deepest;
}

}  // namespace clearway
