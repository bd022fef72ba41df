#pragma once
// One link's collision geometry, as the self-collision and environment checks see it: the exact
// triangles of its meshes in an AabbTree, its primitives, and the convex hull of all of it. The hull
// contains the link, so "hulls apart" proves "links apart" in one GJK call; only when the hulls
// overlap do the triangles decide (seeds/000: oriented AABB trees descended together, then
// primitive–primitive tests through the narrow phase).
//
// A closed (watertight) mesh is a solid: every edge of its triangles is shared by an even number of
// them, so a ray from a point crosses it an odd number of times exactly when the point is inside. Closed
// pieces are shells (triangles joined across edges that exactly two of them share), so shells that touch
// at a corner or an edge stay apart. Shells wound consistently, nested as one solid's outer surface and
// cavities (opposite windings, each inner shell within the material of the ones around it), bound the
// points of non-zero winding number: a cavity is empty. Otherwise a point is inside when it is inside one
// shell on its own. When no surfaces meet, one point of each connected piece of a body (probes())
// decides whether it lies inside a closed mesh of the other. An open mesh stays a surface (as in FCL's BVHModel): a body wholly inside it
// does not touch it, though its hull does. Primitives (boxes, spheres, ...) are solids. Closed sets
// throughout: touching counts as intersecting.
//
// Every query answers in the frames of the poses given; a LinkGeometry itself is in the link frame.
#include <clearway/detail/margins.h>
#include <clearway/kinematics/robot_model.h>
#include <clearway/shape/triangle_mesh.h>
#include <clearway/narrowphase/gjk.h>
#include <clearway/shape/convex_hull.h>
#include <clearway/shape/shape.h>
#include <clearway/tolerances.h>
#include <clearway/tree/aabb_tree.h>

#include <atomic>
#include <cstdint>
#include <limits>
#include <vector>

namespace clearway {

/// How two link geometries are compared.
enum class GeometryMode {
  Hull,  ///< convex hulls only: conservative (may report a collision the triangles do not have, never the reverse)
  Mesh,  ///< hulls first; when they overlap, the exact triangles and primitives decide
};

/// A link's triangles (in an AabbTree), primitives and convex hull, all in the link frame. Immutable.
class LinkGeometry {
 public:
  /// A primitive collision element placed in the link frame.
  struct Primitive {
    Shape shape;  ///< in its own local frame
    Pose pose;    ///< the shape's frame in the link frame
  };

  /// The triangles of one mesh (already in the link frame). Throws ShapeError for a mesh without
  /// triangles, a triangle index out of range or a non-finite vertex.
  explicit LinkGeometry(const TriangleMesh& mesh, const TreeBuildOptions& options = {});
  /// All collision elements of a link (RobotModel::link(i).collisions): meshes index `meshes`
  /// (RobotModel::meshes()) and are placed by each element's origin, as are primitives.
  /// Throws ShapeError when there is no element, an element is neither mesh nor primitive, or a mesh
  /// index, triangle index or coordinate is invalid.
  LinkGeometry(const std::vector<CollisionElement>& elements, const std::vector<TriangleMesh>& meshes,
               const TreeBuildOptions& options = {});

  /// Every mesh triangle, link frame; tree() indexes this list.
  const std::vector<Triangle>& triangles() const noexcept { return triangles_; }
  /// The AabbTree over triangles() (empty when the link has primitives only).
  const AabbTree& tree() const noexcept { return tree_; }
  /// The primitive elements (empty for a mesh-only link).
  const std::vector<Primitive>& primitives() const noexcept { return primitives_; }
  /// The link's one element when it is a single primitive without triangles (else null): then the
  /// primitive is the link, and its own GJK is exact where the hull, a circumscribed polytope, is not.
  const Primitive* solePrimitive() const noexcept { return sole_primitive_ ? primitives_.data() : nullptr; }
  /// A convex hull containing every triangle and primitive (curved primitives enter as circumscribed
  /// polytopes, so the hull is slightly larger than their hull).
  const ConvexHull& hull() const noexcept { return hull_; }
  /// The box of hull() in the link frame.
  const Aabb& bounds() const noexcept { return bounds_; }
  /// The largest distance of a hull vertex from the link frame's origin.
  double boundingRadius() const noexcept { return bounding_radius_; }
  /// Convex pieces whose union contains the link's triangles and primitives (not the inside of its closed
  /// meshes: see partBallMargin): the hulls of the triangles under the tree's top nodes (up to kMaxParts),
  /// and one per primitive; each with a ball that contains it (link frame). Tighter than hull() where the
  /// link is concave, and far cheaper than the triangles.
  struct Part {
    ConvexHull hull;  ///< the piece (link frame)
    Vec3 center;      ///< centre of a ball containing hull (link frame)
    double radius;    ///< that ball's radius (metres)
  };
  /// At most this many parts come from the triangles (each primitive adds one more). Four: a pair of
  /// links may cost parts² GJKs, and on the shared UR5 motions 8 and 16 parts cost more than their
  /// tighter bound saved, while 2 were too loose (mesh searches made motions 5 times slower).
  static constexpr int kMaxParts = 4;
  /// The parts: at most kMaxParts from the triangles, plus one per primitive.
  const std::vector<Part>& parts() const noexcept { return parts_; }
  ///@{
  /// A ball containing the hull (the first, cheapest test): centre in the link frame, and radius.
  const Vec3& sphereCenter() const noexcept { return sphere_center_; }
  double sphereRadius() const noexcept { return sphere_radius_; }
  ///@}

  /// How many closed shells of triangles the link has (edge-connected, however they touch); the other
  /// triangles are open surfaces.
  int solidCount() const noexcept { return static_cast<int>(solid_boxes_.size()); }
  /// True when the point (link frame) lies inside the link's closed meshes (outside their cavities), or on
  /// them, or so near that no ray decides (never "outside" by accident). False for a link without solids.
  bool containsPoint(const Vec3& p) const noexcept;
  /// One point of each connected piece of the link (triangles joined by shared vertices; each primitive),
  /// link frame: while the surfaces of two bodies do not meet, each piece lies wholly inside or wholly
  /// outside the other's solids.
  const std::vector<Vec3>& probes() const noexcept { return probes_; }

  /// A ball, link frame.
  struct Ball {
    Vec3 center;    ///< link frame
    double radius;  ///< metres
  };
  /// At most this many cores per link: the largest few, then balls hugging the surface (a pair compares
  /// those of one that reach the other's box with all of the other's, after the hull test).
  static constexpr int kMaxCores = 32;
  /// Balls wholly inside the link's solids (closed meshes and primitives), by group (coreGroups()): two
  /// bodies whose cores overlap share interior points, so they collide at any padding. Empty when the link
  /// has no solid.
  const std::vector<Ball>& cores() const noexcept { return cores_; }
  /// Neighbouring cores, [first, first + count) of cores(), and a ball holding them all (link frame): a test
  /// that the ball cannot pass skips the group.
  struct CoreGroup {
    Vec3 center;       ///< link frame
    double radius;     ///< metres: every core of the group lies within it
    int first;         ///< the group's first core in cores()
    int count;         ///< how many cores it has, in order from first
  };
  /// The cores' groups, at most eight cores each, covering cores() in order.
  const std::vector<CoreGroup>& coreGroups() const noexcept { return core_groups_; }
  /// How far every part's ball must grow for their union to hold the whole link, the inside of its closed
  /// meshes included (the parts hold only their surfaces): 0 for a link without closed meshes or with one
  /// part, a proven small margin for one with them, +∞ where no proof was found (then only the bounding
  /// ball holds it). Proven at the first call (thread-safe): only the enclosing layer asks, for robot links.
  double partBallMargin() const;
  /// True when the balls (link frame), each grown by `margin`, provably hold every point inside the
  /// link's closed meshes (true without closed meshes). False proves nothing: the proof gives up after a
  /// bounded amount of work.
  bool ballsHoldSolids(const std::vector<Ball>& balls, double margin) const;

 private:
  LinkGeometry(std::vector<Triangle> triangles, std::vector<Primitive> primitives, const TreeBuildOptions& options);
  void buildParts();
  void findSolids();
  void findCores();
  // True when p may centre a core: inside the solids in every reading (the rays', the winding number's).
  bool coreCentre(const Vec3& p) const noexcept;
  void addSurfaceCores(double margin);
  void groupCores();
  double coverSolids() const;
  // The distance from p to the nearest triangle, or `cutoff` when none is nearer.
  double surfaceDistance(const Vec3& p, double cutoff) const noexcept;
  // The crossings of the ray from p along `dir` with shell s (s ≥ 0), or with every wound shell but
  // `skip` (s = kWound), each +1 leaving through a triangle's front and −1 entering: false when the ray
  // passes too near an edge, a vertex or a plane to tell.
  static constexpr int kWound = -1;
  bool rayCrossings(int s, int skip, const Vec3& p, const Vec3& dir, int& winding) const noexcept;
  // Whether p lies inside the solids along ray direction r: 1 inside, 0 outside, −1 undecided.
  int insideAlong(const Vec3& p, int r) const noexcept;
  // True only when three ray directions all decide that p lies inside.
  bool surelyInside(const Vec3& p) const noexcept;

  std::vector<Triangle> triangles_;
  std::vector<Primitive> primitives_;
  AabbTree tree_;
  ConvexHull hull_;
  std::vector<Part> parts_;
  Aabb bounds_;
  double bounding_radius_ = 0.0;
  bool sole_primitive_ = false;  // one primitive, no triangles (solePrimitive)
  Vec3 sphere_center_ = Vec3::Zero();
  double sphere_radius_ = 0.0;
  std::vector<std::int32_t> solid_of_;  // per triangle: its closed piece, −1 for an open one
  std::vector<Aabb> solid_boxes_;       // per closed piece
  std::vector<std::int8_t> solid_sign_;  // per closed piece: its winding (+1 outward, −1 inward), 0 unwound
  bool nested_ = false;                  // the wound shells nest as one solid: the winding number decides
  std::vector<Vec3> probes_;
  std::vector<Ball> cores_;
  std::vector<CoreGroup> core_groups_;
  // partBallMargin once proven (NaN before). Copies keep it; two threads asking at once both prove it, to the
  // same value.
  struct Proven {
    mutable std::atomic<double> value{std::numeric_limits<double>::quiet_NaN()};
    Proven() = default;
    Proven(const Proven& o) noexcept : value(o.value.load(std::memory_order_relaxed)) {}
    Proven& operator=(const Proven& o) noexcept {
      value.store(o.value.load(std::memory_order_relaxed), std::memory_order_relaxed);
      return *this;
    }
  };
  Proven part_ball_margin_;
};

/// The box, in the frame `pose` is given in, of a convex shape placed by it: 6 support queries plus its
/// sweep radius. Tight: callers add the rounding and padding their culls must keep.
template <class S>
Aabb placedBox(const S& s, const Pose& pose) noexcept {
  Aabb box;
  const double r = s.radius();
  for (int i = 0; i < 3; ++i) {
    const Vec3 d = pose.R.row(i).transpose();  // the parent's axis i in the shape's frame
    box.max[i] = (pose * s.support(d))[i] + r;
    box.min[i] = (pose * s.support(-d))[i] - r;
  }
  return box;
}
/// placedBox of any Shape (the variant visited once).
Aabb placedBox(const Shape& shape, const Pose& pose) noexcept;

/// The narrow phase's band for a query whose coordinates and sizes are at most `scale` metres: GJK calls
/// bodies this near touching (tol.gjk_absolute of their size, never below 64 ulps), so a cull by boxes or
/// axes must keep at least this much.
inline double narrowBand(double scale, const Tolerances& tol) noexcept {
  return margins::narrowBand(tol.gjk_absolute) * scale;
}

/// True when a piece of one link lies inside a closed mesh of the other (b placed in a's frame by b_in_a).
/// Meaningful once their surfaces are known not to meet: then it decides whether the solids overlap.
bool linkContained(const LinkGeometry& a, const LinkGeometry& b, const Pose& b_in_a) noexcept;
/// True when the convex shape (placed in the link's frame) lies inside one of the link's closed meshes,
/// given that it meets none of the link's triangles.
bool shapeInsideLink(const Shape& shape, const Pose& shape_in_link, const LinkGeometry& link) noexcept;

/// True when a core of `a` and a core of `b` overlap (b placed in a's frame by b_in_a): the links collide.
/// False proves nothing. The comparison keeps a margin far above the rounding of placing the centres.
bool coresOverlap(const LinkGeometry& a, const LinkGeometry& b, const Pose& b_in_a) noexcept;
/// True when a core of the link reaches into the convex shape (placed in the link's frame) by more than
/// `depth` (metres, ≥ 0): they collide, and still do with the core moved up to `depth` from there.
/// Decided for boxes, spheres and capsules (exact point distances); other shapes answer false.
bool coreMeetsShape(const Shape& shape, const Pose& shape_in_link, const LinkGeometry& link,
                    double depth = 0.0) noexcept;

}  // namespace clearway
