#pragma once
// The robot's world: primitive and mesh obstacles with poses (some moving at constant velocity), and
// OctoMap occupancy (occupied leaves at any depth become boxes; unknown space counts as free or as
// occupied, by choice). Everything sits in AABB trees in the world frame, so a link is tested only
// against the obstacles and voxels its bounds can touch, then exactly (body/link_geometry.h).
//
// An environment never changes; an edit (an obstacle added, moved or removed, points inserted) makes a
// new one that shares every untouched part with the old: static obstacles and inserted voxels sit in a
// versioned tree (tree/versioned_tree.h), so an edit costs O(log n), and a query running on the old
// environment meanwhile sees it whole.
#include <clearway/load/load_error.h>
#include <clearway/shape/triangle_mesh.h>
#include <clearway/math.h>
#include <clearway/narrowphase/gjk.h>
#include <clearway/body/link_geometry.h>
#include <clearway/body/proximity.h>
#include <clearway/shape/shape.h>
#include <clearway/tolerances.h>
#include <clearway/detail/persistent_map.h>
#include <clearway/environment/clearance_grid.h>
#include <clearway/environment/obstacle_boxes.h>
#include <clearway/tree/aabb_tree.h>
#include <clearway/tree/versioned_tree.h>

#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace clearway {

class VoxelBlocks;

/// How OctoMap cells that were never observed count.
enum class UnknownSpace {
  Free,      ///< only occupied leaves are obstacles
  Occupied,  ///< unobserved cells inside the map's observed bounds are obstacles too (never outside them)
};

/// Occupancy from an OctoMap file, as axis-aligned boxes in the world (the map's) frame.
struct OccupancyMap {
  double resolution = 0.0;           ///< the finest voxel edge, metres
  std::vector<Aabb> occupied;        ///< one box per occupied leaf (any depth), plus unknown cells when counted
  Aabb known_bounds;                 ///< the box of all observed (free or occupied) leaves
  int occupied_leaves = 0;           ///< occupied leaves in the file
  int unknown_boxes = 0;             ///< boxes added for unknown space (0 under UnknownSpace::Free)
};

/// Reads a .bt (binary) or .ot (full) OctoMap. Throws LoadError naming the file and the reason for a
/// missing file, an unknown extension, a foreign or truncated file, or a map that is not an OcTree
/// (a .ot names its tree type, and only OcTree is read; a .bt holds plain occupancy whatever tree wrote it).
OccupancyMap loadOctomap(const std::string& path, UnknownSpace unknown = UnknownSpace::Free);

/// One obstacle: a convex shape or a triangle mesh, placed in the world, optionally moving.
struct Obstacle {
  std::string name;                    ///< for Environment::obstacle(name) and messages; need not be unique
  Shape shape;                         ///< used when mesh is null
  std::shared_ptr<const LinkGeometry> mesh;  ///< a mesh obstacle's triangles, tree and hull (null for a shape)
  Pose pose;                           ///< at time 0
  Vec3 velocity = Vec3::Zero();        ///< m/s, world frame: the pose at time t is translated by t·velocity
  /// True when velocity is not zero.
  bool moving() const noexcept { return velocity != Vec3::Zero(); }
};

/// Which part of the environment a link touched.
struct EnvironmentHit {
  ///@{
  /// What was touched: nothing, an obstacle, or a voxel (a map's or a point's).
  enum class Kind { None, Obstacle, Voxel } kind = Kind::None;
  ///@}
  int index = -1;  ///< a voxel of the map: its index into OccupancyMap::occupied (−1 for other hits)
  const Obstacle* obstacle = nullptr;  ///< the obstacle touched (valid while its environment lives)
  Aabb voxel;  ///< the voxel touched (a map's, or one made by withPoints)
};

/// Work a query did, for tests and benchmarks ("compute nothing the scene did not ask for").
struct EnvironmentCounters {
  long long obstacle_tests = 0;  ///< exact obstacle-vs-link tests
  long long voxel_tests = 0;     ///< voxel-vs-link GJK tests (hull tests, and voxel–triangle pairs in Mesh mode)
  long long distance_tests = 0;  ///< distance computations
  long long penetration_tests = 0;  ///< EPA runs (only for the signed clearance of a colliding link)
  long long cast_tests = 0;      ///< GJK shape casts (translating links)
  long long grid_clears = 0;     ///< links the clearance grid cleared with no tree walk (Scene::isFree)
  long long box_clears = 0;      ///< links the obstacles' oriented boxes cleared with no tree walk (Scene::isFree)
};

/// Where and when an Environment link query runs, beside what it asks (BodyPair's IntersectQuery,
/// DistanceQuery, BoundQuery, CastQuery: one vocabulary for a pair and for the world): the time, the warm
/// starts, and where it reports what it touched and the work it did.
struct EnvironmentQuery {
  double t = 0.0;                 ///< seconds: moving obstacles are displaced by t·velocity (static ones ignore it)
  SimplexCache* warm = nullptr;   ///< lowerBound: staticCount() hull warm starts for the link, or null (cold)
  EnvironmentHit* hit = nullptr;  ///< if given: what linkIntersects touched, or the item lowerBound's bound came from
  EnvironmentCounters* counters = nullptr;  ///< if given: the query's work is added to it
};

/// Obstacles and occupancy, immutable once built; queries are const and thread-safe. Copies are cheap
/// (they share everything).
class Environment {
 public:
  /// A world of these obstacles and this map. Throws std::invalid_argument for a non-finite pose or
  /// velocity.
  Environment(std::vector<Obstacle> obstacles = {}, std::shared_ptr<const OccupancyMap> map = nullptr);

  /// Every obstacle (static ones in tree order, then moving ones): O(n), for tools, not for queries.
  std::vector<std::shared_ptr<const Obstacle>> obstacles() const;
  /// The obstacles (not counting voxels made by withPoints).
  std::size_t obstacleCount() const noexcept { return named_count_; }
  /// The obstacle of that name, or null (also when several share it).
  const Obstacle* obstacle(const std::string& name) const noexcept;
  /// The obstacles that move.
  const std::vector<std::shared_ptr<const Obstacle>>& movingObstacles() const noexcept { return moving_; }
  /// The occupancy map, or null when there is none (valid while this environment or a copy lives).
  const OccupancyMap* map() const noexcept { return map_.get(); }
  /// The map's voxels merged into blocks, as every query here walks them (voxel_blocks.h); null without voxels.
  const VoxelBlocks* voxelBlocks() const noexcept { return blocks_.get(); }
  /// Voxels made occupied by withPoints (beyond the map's own).
  int pointVoxelCount() const noexcept { return point_voxels_; }
  /// True when nothing can be hit: no obstacle, no voxel of the map or of withPoints.
  bool empty() const noexcept {
    return static_.empty() && moving_.empty() && (!map_ || map_->occupied.empty());
  }
  /// True when some obstacle moves (then the clearance grid is not consulted).
  bool hasMovingObstacles() const noexcept { return !moving_.empty(); }
  /// The static obstacles' and voxels' clearance grid (clearance_grid.h), once built, else null. While no
  /// obstacle moves, Scene::isFree reads it before the trees: a link inside balls it clears is free of
  /// all of them. A version builds its own once kClearanceAfter link queries have been asked of it (copies
  /// that keep the static items share it), so a world edited between every few queries never pays for one.
  const ClearanceGrid* clearanceGrid() const noexcept;
  /// The slack linkIntersects grows a link's box by: `padding`, and the narrow phase's band for a link
  /// whose coordinates lie within `extent` of the origin. While no obstacle moves, a link inside a ball
  /// (or inside balls) whose clearanceGrid()->lowerBound() at the centre exceeds its radius plus this
  /// makes linkIntersects answer false.
  double linkSlack(double padding, double extent, const Tolerances& tol) const noexcept {
    return padding + cullBand(scale_ + extent + padding, tol);
  }
  /// The link queries a version answers before it builds its clearance grid.
  /// (About 4 ms of link queries on the shared problems, as long as a grid takes to build there.)
  static constexpr int kClearanceAfter = 16384;
  /// Builds the clearance grid now, if this version has none (thread-safe; a failed allocation leaves none).
  void prepareClearanceGrid() const noexcept;
  /// This world, never with a clearance grid, nor any world edited from it: every query walks the trees
  /// (for comparing verdicts and cost).
  Environment withoutClearanceGrid() const;
  /// The static obstacles as oriented boxes (obstacle_boxes.h) while they are all there is to hit (no
  /// obstacle moves, the map has no voxel) and few (ObstacleBoxes::kMaxBoxes), else null. Scene::isFree
  /// asks them before the grid and the trees: a link whose bounding ball, grown by linkSlack, they clear is
  /// free of this world.
  const ObstacleBoxes* obstacleBoxes() const noexcept {
    return moving_.empty() && !voxel_tree_ ? boxes_.get() : nullptr;
  }
  /// This world, never with the obstacles' boxes, nor any world edited from it (for comparing verdicts and
  /// cost).
  Environment withoutObstacleBoxes() const;
  /// True when the ball (world frame) is more than `slack` (beyond rounding) from every obstacle and voxel,
  /// by their boxes: the obstacleBoxes() when there are, else the trees' boxes near the ball (an obstacle's
  /// world box, the map's blocks). False proves nothing; so for a NaN or infinite input, and while an
  /// obstacle moves. As for linkIntersects' culls, `slack` should hold the narrow phase's band (linkSlack).
  bool ballClear(const Vec3& center, double radius, double slack) const noexcept {
    if (const ObstacleBoxes* boxes = obstacleBoxes()) return boxes->ballClear(center, radius, slack);
    return ballClearByTrees(center, radius, slack);
  }
  /// This world with its map's voxels never merged into blocks (each voxel a block of its own: voxel_blocks.h),
  /// nor in any world edited from it (for comparing verdicts and cost).
  Environment withoutVoxelBlocks() const;

  /// This world with one obstacle more: O(log n). Throws std::invalid_argument for an empty name or one
  /// in use, or a non-finite pose or velocity.
  Environment withObstacle(Obstacle obstacle) const;
  /// This world without the named obstacle: O(log n). Throws std::invalid_argument when no obstacle, or
  /// more than one, has that name.
  Environment withoutObstacle(const std::string& name) const;
  /// This world with the named obstacle at `pose` (at time 0): O(log n). Throws as withoutObstacle does,
  /// and for a non-finite pose.
  Environment withObstacleMoved(const std::string& name, const Pose& pose) const;
  /// This world with the voxel holding each point occupied: voxels of edge `resolution` on OctoMap's grid
  /// (cell k spans [k·res, (k+1)·res) per axis), the map's resolution when 0. Points in voxels already
  /// occupied (by the map or earlier points) add nothing; O(m log m) for m points, plus O(log n) per new
  /// voxel or one O(n) rebuild when that is less. Refused with std::invalid_argument naming the first: a
  /// non-finite point or one whose voxel reaches beyond kMaxInputLength; likewise a resolution below
  /// kMinInputLength or not finite (or 0 without a map).
  Environment withPoints(const std::vector<Vec3>& points, double resolution = 0.0) const;
  /// This world with another occupancy map (a changed .bt); the obstacles and point voxels are shared.
  Environment withMap(std::shared_ptr<const OccupancyMap> map) const;

  /// True when the link (placed by pose) is within q.padding of an obstacle or an occupied voxel at time
  /// at.t (moving obstacles displaced by t·velocity; static ones ignore t); q.mode Hull: the link's hull
  /// instead (conservative). Never "free" by accident: non-finite input counts as a hit. at.hit (optional)
  /// says what was touched first.
  bool linkIntersects(const LinkGeometry& link, const Pose& pose, const Tolerances& tol, const IntersectQuery& q = {},
                      const EnvironmentQuery& at = {}) const noexcept;

  /// Distance from the link's exact geometry to the nearest obstacle or voxel (0 when touching;
  /// lower_bound certified). Only obstacles within q.cutoff are examined: beyond it the result is
  /// {distance = lower_bound = cutoff, status Separated}. q.relative as meshDistance's relative_error. The
  /// link is A: point_a on the link, point_b on the obstacle or voxel, normal from the link towards it
  /// (world frame). q.mode Hull measures from the link's convex hull (and a mesh obstacle's hull) instead:
  /// one GJK call per item, a lower bound on the exact distance.
  DistanceResult linkDistance(const LinkGeometry& link, const Pose& pose, const Tolerances& tol,
                              const DistanceQuery& q = {}, const EnvironmentQuery& at = {}) const noexcept;

  /// A certified lower bound on the distance from the link to the nearest obstacle or voxel at time at.t,
  /// computed only as far as q.enough (the answer is at least q.enough when nothing is nearer): one walk,
  /// each item within reach of the link's oriented box climbing BodyPair::lowerBound's ladder (the balls,
  /// the hulls, the link's convex parts, the exact geometry; q as there), asked to prove only the least
  /// bound so far. at.warm, if given, holds staticCount() hull warm starts for this link, one per static
  /// obstacle. The map's voxels are walked merged into blocks (voxel_blocks.h: the same union). at.hit
  /// (optional) names the item the bound came from when one came below q.enough; for the map, the block's
  /// voxel nearest the link where the bound is within q.climb (q.climb < 0: below q.enough), elsewhere a
  /// voxel of that block. 0 for non-finite input or a failed query.
  double lowerBound(const LinkGeometry& link, const Pose& pose, const Tolerances& tol, const BoundQuery& q,
                    const EnvironmentQuery& at = {}) const noexcept;
  /// How many warm starts lowerBound takes: one slot per static obstacle (slots of removed obstacles
  /// are reused by those added later).
  std::size_t staticCount() const noexcept { return static_cast<std::size_t>(slot_count_); }

  /// For a link translating by s·q.velocity (world frame), s ∈ [0, q.max_s], with its convex hull grown by
  /// q.margin: a certified lower bound on the first s at which it touches an obstacle (its hull, for a mesh
  /// obstacle) or an occupied voxel, obstacles held where they are at time at.t; +∞ when nothing is
  /// touched up to max_s. Each candidate the swept box reaches costs one GJK shape cast. 0 for non-finite
  /// input.
  double linkCast(const LinkGeometry& link, const Pose& pose, const Tolerances& tol, const CastQuery& q,
                  const EnvironmentQuery& at = {}) const noexcept;

  /// How deep the link penetrates the environment: over the obstacles and voxels its exact geometry
  /// (grown by padding) touches, the largest EPA depth of its convex hull into them, plus padding. The
  /// hull contains the link, so this is an upper bound on the exact depth. 0 when nothing touches; NaN
  /// when a query failed or the input is not finite.
  double linkPenetration(const LinkGeometry& link, const Pose& pose, const Tolerances& tol, double padding = 0.0,
                         const EnvironmentQuery& at = {}) const noexcept;

 private:
  // The one walk over what lies near a link (environment.cpp): static obstacles from their tree, moving
  // ones where they are at the query's time, then voxels; every query above is a visit of it.
  struct Reach;
  struct Item;
  enum class Walk { Done, Stopped, Invalid };
  template <class F>
  Walk forEachItem(const Reach& reach, double t, F&& visit) const;
  // What a walk stopped by a moving obstacle out of reach of the doubles at time t reports: that obstacle.
  EnvironmentHit invalidMovingHit(double t) const noexcept;
  // ballClear without the obstacles' boxes (out of line: the boxes' callers pay nothing for it).
  bool ballClearByTrees(const Vec3& center, double radius, double slack) const noexcept;
  // What lowerBound reports for a bound `bound` from map block `block`: the block's voxel nearest the link
  // where the bound is within q.climb (a contact), else one of its voxels.
  EnvironmentHit nearestVoxel(const LinkGeometry& link, const Pose& pose, const Tolerances& tol, const BoundQuery& q,
                              int block, double bound) const noexcept;

  // A static obstacle in the tree, with its warm-start slot; or a voxel made by withPoints: no obstacle,
  // slot −1, the item's box its cell (a cloud's million voxels, each a small node and nothing more).
  struct Static {
    std::shared_ptr<const Obstacle> obstacle;  // null for a voxel
    int slot = -1;
    bool voxel = false;
  };
  using StaticTree = VersionedAabbTree<Static>;
  // Where a name is: its static obstacle's key, or moving; and how many obstacles carry it.
  struct Named {
    StaticTree::Key key{};
    bool moving = false;
    int count = 1;
  };
  // Warm-start slots freed by removals, reused first (a shared list: each version keeps its own head).
  struct FreeSlot {
    int slot;
    std::shared_ptr<const FreeSlot> next;
  };
  Environment withStatic(std::shared_ptr<const Obstacle> o) const;  // adds (name checked by the caller)
  void rescale();  // after the static items changed: their scale, their boxes, a new (unbuilt) clearance grid
  // The culls' band: four times the narrow phase's, for the roundings of placing boxes in the world.
  static double cullBand(double scale, const Tolerances& tol) noexcept { return 4.0 * narrowBand(scale, tol); }
  // The clearance grid of one version of the static items, built at most once.
  struct Clearance;
  void countQuery() const noexcept;  // one link query toward the grid: the one that reaches the count builds it

  std::shared_ptr<const OccupancyMap> map_;
  StaticTree static_;                  // static obstacles and point voxels, world frame
  detail::PersistentMap<std::string, Named> names_;
  std::vector<std::shared_ptr<const Obstacle>> moving_;  // checked one by one: few by nature
  std::shared_ptr<const AabbTree> voxel_tree_;  // map_->occupied (null without voxels)
  std::shared_ptr<const VoxelBlocks> blocks_;   // map_->occupied merged: every query walks these (null without voxels)
  std::shared_ptr<const FreeSlot> free_slots_;
  int slot_count_ = 0;
  std::size_t named_count_ = 0;
  int point_voxels_ = 0;
  std::shared_ptr<Clearance> clearance_;  // null: never a grid (withoutClearanceGrid), in edits too
  double scale_ = 0.0;            // the largest |coordinate| of the trees' bounds (sizes the rounding band)
  std::shared_ptr<const ObstacleBoxes> boxes_;  // of this version's static items (null: too many, or none)
  bool without_boxes_ = false;                  // withoutObstacleBoxes, in edits too
  bool without_blocks_ = false;                 // withoutVoxelBlocks, in edits too
};

}  // namespace clearway
