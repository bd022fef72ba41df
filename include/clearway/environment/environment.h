#pragma once
// The robot's world: primitive and mesh obstacles with poses (some moving at constant velocity), and
// OctoMap occupancy (occupied leaves at any depth become boxes; unknown space counts as free or as
// occupied, by choice). Everything sits in AABB trees in the world frame, so a link is tested only
// against the obstacles and voxels its bounds can touch, then exactly (body/link_geometry.h).
#include <clearway/load/load_error.h>
#include <clearway/shape/triangle_mesh.h>
#include <clearway/math.h>
#include <clearway/narrowphase/gjk.h>
#include <clearway/body/link_geometry.h>
#include <clearway/body/proximity.h>
#include <clearway/shape/shape.h>
#include <clearway/tolerances.h>
#include <clearway/tree/aabb_tree.h>

#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace clearway {

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
  std::string name;
  Shape shape;                         ///< used when mesh is null
  std::shared_ptr<const LinkGeometry> mesh;  ///< a mesh obstacle's triangles, tree and hull (null for a shape)
  Pose pose;                           ///< at time 0
  Vec3 velocity = Vec3::Zero();        ///< m/s, world frame: the pose at time t is translated by t·velocity
  bool moving() const noexcept { return velocity != Vec3::Zero(); }
};

/// Which part of the environment a link touched.
struct EnvironmentHit {
  enum class Kind { None, Obstacle, Voxel } kind = Kind::None;
  int index = -1;  ///< obstacle index, or index into OccupancyMap::occupied
};

/// Work a query did, for tests and benchmarks ("compute nothing the scene did not ask for").
struct EnvironmentCounters {
  long long obstacle_tests = 0;  ///< exact obstacle-vs-link tests
  long long voxel_tests = 0;     ///< voxel-vs-link GJK tests (hull tests, and voxel–triangle pairs in Mesh mode)
  long long distance_tests = 0;  ///< distance computations
  long long penetration_tests = 0;  ///< EPA runs (only for the signed clearance of a colliding link)
  long long cast_tests = 0;      ///< GJK shape casts (translating links)
};

/// Obstacles and occupancy, immutable once built; queries are const and thread-safe.
class Environment {
 public:
  /// An empty world. Throws std::invalid_argument for a non-finite pose or velocity.
  Environment(std::vector<Obstacle> obstacles = {}, std::shared_ptr<const OccupancyMap> map = nullptr);

  const std::vector<Obstacle>& obstacles() const noexcept { return obstacles_; }
  const OccupancyMap* map() const noexcept { return map_.get(); }
  bool empty() const noexcept { return obstacles_.empty() && (!map_ || map_->occupied.empty()); }
  bool hasMovingObstacles() const noexcept { return has_moving_; }

  /// True when the link (placed by pose) is within `padding` of an obstacle or an occupied voxel at
  /// time t (moving obstacles displaced by t·velocity; static ones ignore t). Never "free" by
  /// accident: a non-finite pose counts as a hit. `hit` (optional) says what was touched first.
  bool linkIntersects(const LinkGeometry& link, const Pose& pose, const Tolerances& tol, GeometryMode mode,
                      double padding = 0.0, double t = 0.0, EnvironmentHit* hit = nullptr,
                      EnvironmentCounters* counters = nullptr) const noexcept;

  /// Distance from the link's exact geometry to the nearest obstacle or voxel (0 when touching;
  /// lower_bound certified). Only obstacles within `cutoff` are examined: beyond it the result is
  /// {distance = lower_bound = cutoff, status Separated}. relative_error as in meshDistance. The link is A:
  /// point_a on the link, point_b on the obstacle or voxel, normal from the link towards it (world frame).
  /// GeometryMode::Hull measures from the link's convex hull (and a mesh obstacle's hull) instead: one
  /// GJK call per item, a lower bound on the exact distance.
  DistanceResult linkDistance(const LinkGeometry& link, const Pose& pose, const Tolerances& tol,
                              double cutoff = std::numeric_limits<double>::infinity(), double t = 0.0,
                              double relative_error = 0.0, EnvironmentCounters* counters = nullptr,
                              GeometryMode mode = GeometryMode::Mesh) const noexcept;

  /// A certified lower bound on the distance from the link's convex hull to the nearest obstacle (a mesh
  /// obstacle's hull) or voxel, computed only as far as `enough`: the answer is at least `enough` when
  /// nothing is nearer. One GJK per item within reach of the link's oriented box, each stopping once it
  /// proves the item beyond the nearest so far, or within `relative` of its distance. Conservative
  /// advancement needs no more. 0 for non-finite input or when the hull touches. `warm`, if given, holds
  /// staticCount() GJK warm starts for this link, one per non-moving obstacle in the order given.
  /// by_parts: the least over the link's convex parts instead of its hull (tighter where the link is
  /// concave, up to kMaxParts GJKs per item; `warm` is then not used).
  double hullLowerBound(const LinkGeometry& link, const Pose& pose, const Tolerances& tol, double enough,
                        double relative, double t = 0.0, EnvironmentCounters* counters = nullptr,
                        SimplexCache* warm = nullptr, bool by_parts = false) const noexcept;
  /// BodyPair::lowerBound's ladder against everything near the link, at time t: the hull's bound (with the
  /// warm starts `warm`, as hullLowerBound takes them), the convex parts' (Mesh mode), then the exact
  /// geometry (q.within, q.near as there); `hit` (optional) names what lies within q.within when that
  /// settles it. 0 for non-finite input or a failed query.
  double lowerBound(const LinkGeometry& link, const Pose& pose, const Tolerances& tol, const BoundQuery& q,
                    double t = 0.0, SimplexCache* warm = nullptr, EnvironmentHit* hit = nullptr,
                    EnvironmentCounters* counters = nullptr) const noexcept;
  /// How many obstacles do not move (the warm starts hullLowerBound takes).
  std::size_t staticCount() const noexcept { return static_.size(); }

  /// For a link translating by s·velocity (world frame), s ∈ [0, max_s], with its convex hull grown by
  /// `margin`: a certified lower bound on the first s at which it touches an obstacle (its hull, for a mesh
  /// obstacle) or an occupied voxel, obstacles held where they are at time t; +∞ when nothing is touched
  /// up to max_s. Each candidate the swept box reaches costs one GJK shape cast. 0 for non-finite input.
  double linkCast(const LinkGeometry& link, const Pose& pose, const Vec3& velocity, double margin,
                  const Tolerances& tol, double max_s = 1.0, double t = 0.0,
                  EnvironmentCounters* counters = nullptr) const noexcept;

  /// How deep the link penetrates the environment: over the obstacles and voxels its exact geometry
  /// (grown by padding) touches, the largest EPA depth of its convex hull into them, plus padding. The
  /// hull contains the link, so this is an upper bound on the exact depth. 0 when nothing touches; NaN
  /// when a query failed or the input is not finite.
  double linkPenetration(const LinkGeometry& link, const Pose& pose, const Tolerances& tol, double padding = 0.0,
                         double t = 0.0, EnvironmentCounters* counters = nullptr) const noexcept;

 private:
  // The one walk over what lies near a link (environment.cpp): static obstacles from their tree, moving
  // ones where they are at the query's time, then voxels; every query above is a visit of it.
  struct Reach;
  struct Item;
  enum class Walk { Done, Stopped, Invalid };
  template <class F>
  Walk forEachItem(const Reach& reach, double t, F&& visit) const;

  std::vector<Obstacle> obstacles_;
  std::shared_ptr<const OccupancyMap> map_;
  AabbTree static_tree_;          // static obstacles, world frame
  std::vector<int> static_;       // static_tree_ item → obstacle index
  std::vector<int> moving_;       // indices of moving obstacles (checked one by one: few by nature)
  AabbTree voxel_tree_;           // map_->occupied
  bool has_moving_ = false;
  double scale_ = 0.0;            // the largest |coordinate| of the trees' bounds (sizes the rounding band)
};

}  // namespace clearway
