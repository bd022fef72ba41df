// Environment's link queries: a link against the obstacles and voxels near it (the store is environment.cpp).
//
// The map's voxels are met as their blocks (voxel_blocks.h): boxes of exactly their union, a few hundred
// where a scanned shelf has ten thousand voxels. Every query walks the blocks, so that they all see the
// same geometry (a free state stays leavable by a motion); only a report goes back to the voxels, to name
// one the link touches.
//
// A link is first reduced to its world box (the box of its hull's box placed by the pose), which picks
// the candidates from each tree. Candidates then meet tests from cheapest to dearest: for blocks the
// link's box as an oriented box (6 face axes), then GJK against the link's hull (one warm-started
// cache for all blocks of a query: every block is axis-aligned, so the last separating axis is a good
// start for the next), and only in Mesh mode, when the hull touches blocks, the triangles. When more
// than a few blocks pass the hull, the block tree and the link's triangle tree are descended together
// (world frame against link frame), which tests each block only against the triangles near it.
//
// Slack: boxes are grown by padding + band, band = 4·max(gjk_absolute, 64 ulps)·scale with scale
// bounding every coordinate of the query, so box culling never drops a pair that GJK (whose own band
// is gjk_absolute times the pair's size) would call touching.
#include <clearway/environment/environment.h>
#include <clearway/environment/voxel_blocks.h>

#include <clearway/detail/margins.h>
#include <clearway/narrowphase/epa.h>
#include <clearway/narrowphase/ray_cast.h>
#include <clearway/shape/support.h>
#include <clearway/tree/oriented_box_test.h>

#include "environment_boxes.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <type_traits>
#include <utility>

namespace clearway {
namespace {

using environment_detail::maxAbs;
using environment_detail::obstacleBox;
using environment_detail::shapeWorldBox;

Pose poseAt(const Obstacle& o, double t) noexcept {
  Pose p = o.pose;
  if (o.moving()) p.t += t * o.velocity;
  return p;
}

// The radius of the link's bounding ball placed by `pose` (centre pose · sphereCenter()), grown by the
// rounding of that product (R·c + t rounds by a few ulps of |c| + |t|).
double ballReach(const LinkGeometry& link, const Pose& pose) noexcept {
  return link.sphereRadius() * (1.0 + margins::kRounding) + margins::placedRounding(link.sphereCenter().norm(), pose.t.norm());
}

// True when voxel v and block b share more than a face (a coarse voxel's cells may lie in several blocks).
bool shares(const Aabb& block, const Aabb& voxel) noexcept {
  return (block.min.cwiseMax(voxel.min).array() < block.max.cwiseMin(voxel.max).array()).all();
}

// What a hit on the map's voxel v reports.
EnvironmentHit voxelHit(const std::vector<Aabb>& voxels, int v) noexcept {
  EnvironmentHit h;
  h.kind = EnvironmentHit::Kind::Voxel;
  h.index = v;
  h.voxel = voxels[static_cast<std::size_t>(v)];
  return h;
}

// Blocks passing the hull test that the Mesh mode checks one by one (each against the triangles near
// it); beyond this many, descending the two trees together is cheaper than a triangle-tree query each.
constexpr int kFewBlocks = 4;

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

}  // namespace

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

// One item near the link: an obstacle where it is at the query's time, a voxel made by withPoints (as a box
// obstacle), or a block of the map's voxels (voxel_blocks.h: every query sees the map as its blocks, the
// same union, so that they agree with each other; only a report names a voxel).
struct Environment::Item {
  EnvironmentHit::Kind kind;
  int block;                   // a map block's index, else −1
  const Obstacle* obstacle;    // null for a voxel or block
  const Aabb* voxel;           // a point voxel's cell or a block, else null
  Pose pose;                   // the obstacle's at the query's time, or the box's centre
  int warm;                    // a static obstacle's warm-start slot, else −1

  Aabb box() const noexcept { return obstacle ? obstacleBox(*obstacle, pose) : *voxel; }
  // f applied to the link's BodyPair with the item (a voxel as a box: a Shape holding a Box allocates nothing),
  // its hulls' warm start `warm` when given.
  template <class F>
  decltype(auto) pairWith(const LinkGeometry& link, SimplexCache* warm, F&& f) const {
    if (obstacle && obstacle->mesh) return f(BodyPair(link, *obstacle->mesh, warm));
    if (obstacle) return f(BodyPair(link, obstacle->shape, warm));  // (its own shape: a copied hull would allocate)
    const Shape box = Box(voxel->halfExtents());
    return f(BodyPair(link, box, warm));
  }
  // What a hit on it reports (a block names none of its voxels: the query that found it looks one up).
  EnvironmentHit hit() const noexcept {
    EnvironmentHit h;
    h.kind = kind;
    if (kind == EnvironmentHit::Kind::Obstacle) h.obstacle = obstacle;
    else h.voxel = box();
    return h;
  }
};

template <class F>
Environment::Walk Environment::forEachItem(const Reach& reach, double t, F&& visit) const {
  const auto on_static = [&](const Static& s, const Aabb& box) {
    if (s.voxel) return visit(Item{EnvironmentHit::Kind::Voxel, -1, nullptr, &box, Pose::translation(box.center()), -1});
    const Obstacle& o = *s.obstacle;
    return visit(Item{EnvironmentHit::Kind::Obstacle, -1, &o, nullptr, o.pose, s.slot});
  };
  if (reach.box ? static_.query(*reach.box, on_static) : static_.forEachWithin(*reach.local, *reach.pose, *reach.limit, on_static))
    return Walk::Stopped;
  // Moving obstacles are few by nature: each box is placed at t and tested on its own.
  const Aabb link_box = reach.box ? Aabb() : transformed(*reach.local, *reach.pose);
  for (const auto& o : moving_) {
    const Item item{EnvironmentHit::Kind::Obstacle, -1, o.get(), nullptr, poseAt(*o, t), -1};
    if (!item.pose.isFinite()) return Walk::Invalid;
    const Aabb box = item.box();
    if (reach.box ? !overlaps(box, *reach.box) : !(boxDistance(box, link_box) <= *reach.limit)) continue;
    if (visit(item)) return Walk::Stopped;
  }
  if (!blocks_) return Walk::Done;
  const std::vector<Aabb>& boxes = blocks_->boxes();
  const auto on_block = [&](std::int32_t b) {
    return visit(Item{EnvironmentHit::Kind::Voxel, b, nullptr, &boxes[b], Pose::translation(boxes[b].center()), -1});
  };
  const AabbTree& tree = blocks_->tree();
  return (reach.box ? tree.query(*reach.box, on_block)
                    : tree.forEachWithin(*reach.local, *reach.pose, *reach.limit, on_block))
             ? Walk::Stopped
             : Walk::Done;
}

bool Environment::ballClearByTrees(const Vec3& center, double radius, double slack) const noexcept {
  if (!moving_.empty()) return false;
  const double reach = (radius + slack) * (1.0 + margins::kRounding);
  if (!center.allFinite() || !(reach >= 0.0) || !(reach < INFINITY)) return false;
  // A box within reach: the squared distance from the centre to it (each axis's gap, rounded by a few ulps
  // of the coordinates, which the band in `slack` exceeds many times over) at most reach².
  const auto near = [&](const Aabb& b) {
    const Vec3 gap = (b.min - center).cwiseMax(center - b.max).cwiseMax(0.0);
    return !(gap.squaredNorm() > reach * reach);
  };
  const Aabb box = Aabb::fromCenterHalf(center, Vec3::Constant(reach));
  if (static_.query(box, [&](const Static&, const Aabb& b) { return near(b); })) return false;
  if (!blocks_) return true;
  const std::vector<Aabb>& blocks = blocks_->boxes();
  return !blocks_->tree().query(box, [&](std::int32_t b) { return near(blocks[static_cast<std::size_t>(b)]); });
}

EnvironmentHit Environment::invalidMovingHit(double t) const noexcept {
  EnvironmentHit h;
  h.kind = EnvironmentHit::Kind::Obstacle;
  for (const auto& o : moving_)
    if (!poseAt(*o, t).isFinite()) {
      h.obstacle = o.get();
      break;
    }
  return h;
}

bool Environment::linkIntersects(const LinkGeometry& link, const Pose& pose, const Tolerances& tol,
                                 const IntersectQuery& q, const EnvironmentQuery& at) const noexcept {
  const double padding = q.padding, t = at.t;
  const GeometryMode mode = q.mode;
  EnvironmentHit* const hit = at.hit;
  EnvironmentCounters* const counters = at.counters;
  if (hit) *hit = EnvironmentHit{};
  if (!pose.isFinite() || !(padding >= 0.0) || !std::isfinite(padding) || !std::isfinite(t)) return true;
  const auto report = [&](const EnvironmentHit& h) {
    if (hit) *hit = h;
    return true;
  };
  // The box of the link's bounding ball: a dozen operations where placing its box costs ten times more,
  // and as tight for most links (R·c + t rounds by a few ulps of |c| + |t|).
  const Vec3 centre = pose * link.sphereCenter();
  const double reach = ballReach(link, pose);
  const Aabb link_box = Aabb::fromCenterHalf(centre, Vec3::Constant(reach));
  // (max |centre_i| + reach is the box's largest coordinate: rounding to nearest is monotone and symmetric.)
  const double extent = std::max({std::abs(centre.x()), std::abs(centre.y()), std::abs(centre.z())}) + reach;
  const double slack = linkSlack(padding, extent, tol);
  const Aabb query = link_box.inflated(slack);
  // Most links of a state overlap no item's box at all: the trees alone say so, before the culls and hull
  // tests below are set up (which cost more than the walk). Moving obstacles take the full path.
  if (moving_.empty()) {
    countQuery();  // (Scene::isFree reads the grid, once built, before it calls here)
    const auto any = [](const auto&...) { return true; };
    if (!static_.query(query, any) && !(blocks_ && blocks_->tree().query(query, any))) return false;
  }
  // A block touched: the report names the first of its voxels the same test finds touching (only when asked).
  const auto blockHit = [&](int b) {
    if (!hit) return true;
    const Aabb& box = blocks_->boxes()[static_cast<std::size_t>(b)];
    int found = blocks_->voxelOf(b);
    voxel_tree_->query(query, [&](std::int32_t v) {
      const Aabb& c = map_->occupied[static_cast<std::size_t>(v)];
      if (!shares(box, c) ||
          !shapeIntersectsLink(Box(c.halfExtents()), Pose::translation(c.center()), link, pose, tol, mode, padding))
        return false;
      found = v;
      return true;
    });
    return report(voxelHit(map_->occupied, found));
  };

  // The link's box as an oriented box in the world (A = world, B = the link frame): the blocks' first cull,
  // set up at the first block (most links near obstacles meet none).
  std::optional<detail::OrientedBoxTest> obb;
  detail::OrientedBoxTest::PlacedB placed_link;
  SimplexCache cache;  // one for all blocks: they are axis-aligned, so the last separating axis starts the next well
  int passed[kFewBlocks];
  int n_passed = 0;
  bool many = false;
  int found = -1;
  EnvironmentHit found_obstacle;  // an obstacle (or a point voxel) touched
  const Walk walk = forEachItem(Reach::overlapping(query), t, [&](const Item& item) {
    if (item.block < 0) {  // an obstacle, or a voxel made by withPoints: on its own
      if (counters) ++counters->obstacle_tests;
      if (!item.pairWith(link, nullptr, [&](BodyPair pair) { return pair.intersects(pose, item.pose, tol, q); }))
        return false;
      found_obstacle = item.hit();
      return true;
    }
    double c[3], h[3];
    detail::OrientedBoxTest::centerHalf(*item.voxel, c, h);
    if (!obb) {
      obb.emplace(pose, slack, scale_ + extent);
      placed_link = obb->place(link.bounds());
    }
    if (obb->separated<false>(c, h, placed_link)) return false;
    if (counters) ++counters->voxel_tests;
    if (!shapeIntersectsLink(Box(Vec3(h[0], h[1], h[2])), Pose::translation(Vec3(c[0], c[1], c[2])), link, pose, tol,
                             GeometryMode::Hull, padding, &cache))
      return false;
    if (mode == GeometryMode::Hull || n_passed == kFewBlocks) {
      found = item.block;
      many = mode == GeometryMode::Mesh;
      return true;
    }
    passed[n_passed++] = item.block;
    return false;
  });
  if (walk == Walk::Invalid) return report(invalidMovingHit(t));  // out of reach of the doubles: touching
  if (found_obstacle.kind != EnvironmentHit::Kind::None) return report(found_obstacle);
  if (!blocks_) return false;
  const AabbTree& block_tree = blocks_->tree();
  const std::vector<Aabb>& blocks = blocks_->boxes();
  if (mode == GeometryMode::Hull) return found >= 0 ? blockHit(found) : false;

  if (!many) {
    for (int k = 0; k < n_passed; ++k) {
      const Aabb& b = blocks[passed[k]];
      if (counters) ++counters->voxel_tests;
      if (shapeIntersectsLink(Box(b.halfExtents()), Pose::translation(b.center()), link, pose, tol, GeometryMode::Mesh,
                              padding, &cache))
        return blockHit(passed[k]);
    }
    return false;
  }

  // Many blocks inside the hull: block tree (world) against triangle tree (link frame), then box–triangle
  // GJK; then the link's primitives against the blocks near them.
  found = -1;
  // A core of the link meeting a block settles it without the triangle search.
  const double core_margin = margins::kSlack * (1.0 + scale_ + extent);
  // (A block within r of c.)
  const auto blockWithin = [&](const Vec3& c, double r) {
    int at = -1;
    block_tree.query(Aabb::fromCenterHalf(c, Vec3::Constant(r)), [&](std::int32_t v) {
      const Aabb& b = blocks[v];
      if (!(((c - b.center()).cwiseAbs() - b.halfExtents()).cwiseMax(0.0).norm() < r)) return false;
      at = v;
      return true;
    });
    return at;
  };
  for (const LinkGeometry::CoreGroup& g : link.coreGroups()) {
    if (blockWithin(pose * g.center, g.radius) < 0) continue;  // (a filter: no block near any of its cores)
    for (int k = g.first; k < g.first + g.count; ++k) {
      const LinkGeometry::Ball& core = link.cores()[k];
      const double r = core.radius - core_margin;
      if (!(r > 0.0)) continue;
      found = blockWithin(pose * core.center, r);
      if (found >= 0) return blockHit(found);
    }
  }
  const std::vector<Triangle>& tris = link.triangles();
  forEachOverlap(
      block_tree, link.tree(), pose,
      [&](std::int32_t v, std::int32_t j) {
        if (counters) ++counters->voxel_tests;
        const Aabb& b = blocks[v];
        const Box box(b.halfExtents());
        SimplexCache pair_cache;
        if (!gjkIntersect(Margin<Box>{box, padding}, Pose::translation(b.center()), tris[j], pose, tol, pair_cache)
                 .intersecting)
          return false;
        found = v;
        return true;
      },
      slack);
  if (found >= 0) return blockHit(found);
  for (const LinkGeometry::Primitive& p : link.primitives()) {
    const Pose pose_p = pose * p.pose;
    block_tree.query(shapeWorldBox(p.shape, pose_p).inflated(slack), [&](std::int32_t v) {
      if (counters) ++counters->voxel_tests;
      const Aabb& b = blocks[v];
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
    if (found >= 0) return blockHit(found);
  }
  // No surface touches a block: one may still lie inside a closed mesh of the link (a block the surface does
  // not cross lies wholly inside the solid or wholly outside it: its centre says which).
  if (link.solidCount() > 0) {
    const Pose to_link = pose.inverse();
    block_tree.query(query, [&](std::int32_t v) {
      if (!link.containsPoint(to_link * blocks[v].center())) return false;
      found = v;
      return true;
    });
    if (found >= 0) return blockHit(found);
  }
  return false;
}

DistanceResult Environment::linkDistance(const LinkGeometry& link, const Pose& pose, const Tolerances& tol,
                                         const DistanceQuery& q, const EnvironmentQuery& at) const noexcept {
  const double cutoff = q.cutoff, t = at.t, relative_error = q.relative;
  const GeometryMode mode = q.mode;
  EnvironmentCounters* const counters = at.counters;
  if (!pose.isFinite() || !std::isfinite(t) || !(cutoff >= 0.0) || !(relative_error >= 0.0) ||
      !std::isfinite(relative_error)) {
    DistanceResult r;
    r.status = Status::InvalidInput;
    return r;
  }
  NearestSearch search(cutoff, relative_error);

  // One item: the hulls' distance first (one GJK), the exact geometry only when it may be nearer. The
  // link's box as an oriented box sees items much nearer than its world box admits. (The exact distance is
  // asked with no cutoff: a cut-off answer carries no witness points, and could still become the best.)
  DistanceQuery hulls;
  hulls.mode = GeometryMode::Hull;
  DistanceQuery exact;
  exact.relative = relative_error;
  const Walk walk = forEachItem(Reach::within(link.bounds(), pose, search.limit), t, [&](const Item& item) {
    return item.pairWith(link, nullptr, [&](BodyPair pair) {
      const DistanceResult hull = pair.distance(pose, item.pose, tol, hulls);
      if (!isFailure(hull.status) && hull.lower_bound >= search.limit) return false;
      if (mode == GeometryMode::Hull) return search.add(hull);
      if (counters) ++counters->distance_tests;
      return search.add(pair.distance(pose, item.pose, tol, exact));
    });
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

double Environment::lowerBound(const LinkGeometry& link, const Pose& pose, const Tolerances& tol, const BoundQuery& q,
                               const EnvironmentQuery& at) const noexcept {
  const double t = at.t;
  SimplexCache* const warm = at.warm;
  EnvironmentHit* const hit = at.hit;
  EnvironmentCounters* const counters = at.counters;
  if (hit) *hit = EnvironmentHit{};
  if (!pose.isFinite() || !std::isfinite(t) || !(q.enough >= 0.0) || !(q.relative >= 0.0) || !std::isfinite(q.relative))
    return 0.0;
  // (No clearance grid here: it exists only once enough queries were asked, and a bound it settled could
  // differ from the GJKs' within their relative error, so a segment's verdict would depend on history.)
  // The obstacles' boxes exist from the start: a link whose bounding ball they clear by q.enough (and the
  // band) is that far from every item, which is all that is asked; no walk, no GJK. (Not ballClear's walk
  // where there are none: the walk below starts the same way.)
  if (const ObstacleBoxes* boxes = obstacleBoxes(); boxes && std::isfinite(q.enough)) {
    const Vec3 centre = pose * link.sphereCenter();
    const double reach = ballReach(link, pose);
    const double extent = centre.cwiseAbs().maxCoeff() + reach;
    if (boxes->ballClear(centre, reach, linkSlack(q.enough, extent, tol))) return q.enough;
  }
  // One walk: each item near the link climbs its own ladder, asked only to prove the least bound so far
  // (items certainly beyond it cannot lower it, and are not visited). The map's voxels are walked as their
  // blocks: the same union (voxel_blocks.h), so the same bound, from a few boxes instead of many voxels.
  double lower = q.enough;
  BoundQuery item_q = q;
  std::optional<Item> nearest;
  const Walk walk = forEachItem(Reach::within(link.bounds(), pose, lower), t, [&](const Item& item) {
    if (!item.obstacle && counters) ++counters->voxel_tests;  // (as linkDistance counts: voxel hull tests)
    SimplexCache* cache = warm && item.warm >= 0 ? warm + item.warm : nullptr;
    item_q.enough = lower;
    double d = 0.0;
    item.pairWith(link, cache, [&](BodyPair pair) {
      d = pair.lowerBound(pose, item.pose, tol, item_q);
      if (counters && pair.lastRung() == Rung::Exact) ++counters->distance_tests;
    });
    if (!(d < lower)) return false;  // (NaN: a failure, which BodyPair answers 0 for, never comes here)
    lower = d;
    nearest = item;
    return !(lower > 0.0);
  });
  if (walk == Walk::Invalid) {  // a moving obstacle out of reach of the doubles: touching, never free
    if (hit) *hit = invalidMovingHit(t);
    return 0.0;
  }
  if (hit && nearest)
    *hit = nearest->block < 0 ? nearest->hit() : nearestVoxel(link, pose, tol, q, nearest->block, lower);
  return lower >= 0.0 ? lower : 0.0;  // (NaN: 0)
}

EnvironmentHit Environment::nearestVoxel(const LinkGeometry& link, const Pose& pose, const Tolerances& tol,
                                         const BoundQuery& q, int block, double bound) const noexcept {
  const std::vector<Aabb>& voxels = map_->occupied;
  const Aabb& box = blocks_->boxes()[static_cast<std::size_t>(block)];
  int found = blocks_->voxelOf(block);
  // Only a bound within the climbing distance is a contact a caller reports: there the block's voxels
  // near the link (few, that near) are measured and the nearest named. Elsewhere any voxel of it will do.
  if (q.climb < 0.0 ? bound < q.enough : bound <= q.climb) {
    // (The block's nearest voxel is as near as the block: within its bound's relative error, which the
    // doubling holds with room to spare; the walk then meets only the voxels that near.)
    double best = std::min(q.enough, 2.0 * bound * (1.0 + q.relative) + margins::kRounding * (1.0 + scale_));
    BoundQuery voxel_q = q;
    voxel_tree_->forEachWithin(link.bounds(), pose, best, [&](std::int32_t v) {
      const Aabb& b = voxels[v];
      if (!shares(box, b)) return false;
      voxel_q.enough = best;
      const Shape cell = Box(b.halfExtents());
      const double d = BodyPair(link, cell).lowerBound(pose, Pose::translation(b.center()), tol, voxel_q);
      if (!(d < best)) return false;
      best = d;
      found = v;
      return !(best > 0.0);
    });
  }
  return voxelHit(voxels, found);
}

double Environment::linkCast(const LinkGeometry& link, const Pose& pose, const Tolerances& tol, const CastQuery& q,
                             const EnvironmentQuery& at) const noexcept {
  const Vec3& velocity = q.velocity;
  const double margin = q.margin, max_s = q.max_s, t = at.t;
  EnvironmentCounters* const counters = at.counters;
  constexpr double kNone = std::numeric_limits<double>::infinity();
  if (!pose.isFinite() || !velocity.allFinite() || !(margin >= 0.0) || !std::isfinite(margin) || !std::isfinite(t) ||
      !(max_s >= 0.0) || !std::isfinite(max_s))
    return 0.0;
  const Aabb start = transformed(link.bounds(), pose).inflated(margin);
  Aabb swept = start;
  swept.min += (max_s * velocity).cwiseMin(Vec3::Zero());
  swept.max += (max_s * velocity).cwiseMax(Vec3::Zero());
  const double band = cullBand(scale_ + maxAbs(swept), tol);
  swept = swept.inflated(band);
  double first = kNone;
  // One candidate: the slab test of the moving box against its box first (the s interval where they
  // overlap), then the pair's cast, only as far as the earliest hit so far.
  const Walk walk = forEachItem(Reach::overlapping(swept), t, [&](const Item& item) {
    const Aabb box = item.box();
    const double limit = std::min(first, max_s);
    double enter = 0.0, leave = limit;
    for (int i = 0; i < 3 && enter <= leave; ++i) {
      const double lo = box.min[i] - band - start.max[i], hi = box.max[i] + band - start.min[i];  // overlap: lo ≤ s·v ≤ hi
      const double v = velocity[i];
      if (v == 0.0) {
        if (lo > 0.0 || hi < 0.0) return false;
      } else {
        const double a = lo / v, b = hi / v;
        enter = std::max(enter, std::min(a, b));
        leave = std::min(leave, std::max(a, b));
      }
    }
    if (!(enter <= leave)) return false;
    if (counters) ++counters->cast_tests;
    const CastQuery item_q{velocity, margin, limit};
    const CastResult c =
        item.pairWith(link, nullptr, [&](const BodyPair& pair) { return pair.cast(pose, item.pose, tol, item_q); });
    if (c.hit) first = std::min(first, std::max(0.0, c.t));
    return false;
  });
  if (walk == Walk::Invalid) return 0.0;
  return first <= max_s ? first : kNone;
}

double Environment::linkPenetration(const LinkGeometry& link, const Pose& pose, const Tolerances& tol, double padding,
                                    const EnvironmentQuery& at) const noexcept {
  const double t = at.t;
  EnvironmentCounters* const counters = at.counters;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (!pose.isFinite() || !(padding >= 0.0) || !std::isfinite(padding) || !std::isfinite(t)) return nan;
  const Aabb link_box = transformed(link.bounds(), pose).inflated(padding);
  double deepest = 0.0;
  bool failed = false;
  // Each touching item: the hulls' depth (EPA runs only there).
  const IntersectQuery q{padding, GeometryMode::Mesh};
  const Walk walk = forEachItem(Reach::overlapping(link_box), t, [&](const Item& item) {
    item.pairWith(link, nullptr, [&](BodyPair pair) {
      if (!pair.intersects(pose, item.pose, tol, q)) return;
      if (counters) ++counters->penetration_tests;
      const double d = pair.penetration(pose, item.pose, tol, padding);
      if (std::isnan(d)) failed = true;
      else deepest = std::max(deepest, d);
    });
    return false;
  });
  if (walk == Walk::Invalid) return nan;
  return failed ? nan : deepest;
}

}  // namespace clearway
