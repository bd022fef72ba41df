#pragma once
// How near two rigid bodies are, asked three ways, each climbing the same ladder of ever tighter and dearer
// bounds once: the bounding balls, the convex hulls (warm-started GJK), the convex parts, and last the
// exact triangles and primitives (closed meshes as solids). A query stops at the first rung that settles
// it. A BodyPair keeps the pair's GJK warm starts from one query to the next.
#include <clearway/body/link_geometry.h>
#include <clearway/narrowphase/ray_cast.h>
#include <clearway/tree/oriented_box_test.h>

#include <limits>
#include <vector>

namespace clearway {

// ---- The rungs: one question each, of two links or of a convex shape and a link ----------------------

/// True when the two links are within `padding` metres of each other (padding ≥ 0; 0: touching counts).
/// Hull: the bounding spheres, then one GJK test of the hulls. Mesh: the same, then the two triangle trees descended together
/// (oriented boxes, SAT lite), then triangle pairs (a separating-axis test, confirmed by GJK), and
/// primitives against triangles and primitives. `hull_cache`, if given, carries the hulls' separating
/// axis to the next query of the same pair (keep one per link pair and thread).
/// Pairs within the narrow phase's band (tol.gjk_absolute times the pair's size) of touching count as
/// intersecting. Never "free" by accident: a non-finite pose or padding, or a narrow-phase query that
/// does not converge, answers true.
bool meshesIntersect(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                     const Tolerances& tol, GeometryMode mode, double padding = 0.0,
                     SimplexCache* hull_cache = nullptr) noexcept;

/// What the cheap rungs of meshesIntersect (bounding balls, boxes, cores, hulls; convex parts where a link
/// has more than 512 triangles) tell of a pair.
enum class Screen : char { Apart, Touching, Unsure };
/// meshesIntersect's rungs short of the triangles: Apart or Touching where they settle it (the answer
/// meshesIntersect gives), Unsure where only meshesIntersectExactly can. Hull mode is never Unsure.
Screen screenMeshes(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                    const Tolerances& tol, GeometryMode mode, double padding = 0.0,
                    SimplexCache* hull_cache = nullptr) noexcept;
/// screenMeshes' second rung, which the enclosing layer asks too: the links' hull boxes (bounds()) as
/// oriented boxes are farther apart than `padding` and the band on one of their face axes. b_in_a: b's pose
/// in a's frame, finite. (Inline: both ask it for most pairs they see.)
inline bool boxesApart(const LinkGeometry& a, const LinkGeometry& b, const Pose& b_in_a, const Tolerances& tol,
                       double padding) noexcept {
  const double scale = a.boundingRadius() + b.boundingRadius() + b_in_a.t.norm();
  const double slack = padding + narrowBand(scale + padding, tol);
  return detail::OrientedBoxTest(b_in_a, slack, scale).separated<false>(a.bounds(), b.bounds());
}
/// The exact rung of meshesIntersect in Mesh mode (triangles, primitives, closed meshes as solids), for a pair
/// the screen left Unsure; meshesIntersect's answer there.
bool meshesIntersectExactly(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                            const Tolerances& tol, double padding = 0.0) noexcept;
/// Two triangles, one of each link (indices into triangles()), that touch: a witness that the links do.
struct TrianglePair {
  ///@{
  std::int32_t a = -1, b = -1;  ///< index into the first / the second link's triangles(); -1: none
  ///@}
  /// True when both indices are set (a pair was found).
  bool valid() const noexcept { return a >= 0 && b >= 0; }
};
/// meshesIntersectExactly, also giving (when the answer is true because two triangles touch) the pair found.
bool meshesIntersectExactly(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                            const Tolerances& tol, double padding, TrianglePair* witness) noexcept;
/// True when the witness's triangles touch at these poses, tested as meshesIntersectExactly tests a pair:
/// then the links intersect. False proves nothing (a witness out of range is false).
bool trianglesTouch(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                    TrianglePair witness, const Tolerances& tol, double padding = 0.0) noexcept;

/// A certified lower bound on the distance between two links from their convex parts (0 when parts
/// touch): the least over part pairs, each pair's GJK stopping once it reaches `enough` metres or is
/// within `relative` of its distance. Between the hulls' bound and meshDistance in cost and tightness.
/// `caches`, if given, holds a.parts().size()·b.parts().size() warm starts (pair i, j at i·nb + j).
double partsLowerBound(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                       const Tolerances& tol, double enough, double relative, SimplexCache* caches = nullptr) noexcept;

/// True when each convex part j of b is certified at least need_b[j] metres from every part of a (part
/// balls, then GJK lower bounds) and neither link lies inside the other's closed meshes: every point of b's
/// part j may then move by need_b[j] without b's triangles and primitives reaching a's, whatever the other
/// parts do. False proves nothing (nor does a NaN or negative need, or a non-finite pose). `first`
/// (optional): the part pair to test first (i·nb + j), set to the one that was too near when false: a
/// query at a neighbouring pose then usually ends at once.
bool partsApart(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                const Tolerances& tol, const double* need_b, int* first = nullptr) noexcept;

/// The same for a convex shape (an obstacle, a primitive) against a link: hull first, then (Mesh mode)
/// the shape's box in the link frame against the triangle tree, and the link's primitives.
bool shapeIntersectsLink(const Shape& shape, const Pose& pose_shape, const LinkGeometry& link, const Pose& pose_link,
                         const Tolerances& tol, GeometryMode mode, double padding = 0.0,
                         SimplexCache* hull_cache = nullptr) noexcept;

/// The distance between the exact geometries of two links (triangles and primitives): the minimum over
/// element pairs of GJK's distance, pairs pruned by their boxes' separation. `distance` is an upper
/// bound and `lower_bound` a certified lower bound, both 0 when the links intersect; points and normal
/// (from A to B) in the world frame (the poses' frame). With relative_error = 0 the two agree within
/// tol.gjk_relative; a relative_error e > 0 lets the search skip pairs that cannot be closer than
/// distance / (1 + e), so lower_bound ≥ distance / (1 + e) only (much faster: conservative advancement
/// needs a lower bound, not the exact distance). Element pairs farther apart than `cutoff` are not
/// examined: when none is nearer, distance = lower_bound = cutoff. A narrow-phase failure, a non-finite
/// pose, a negative relative_error or cutoff gives distance 0 and a failure status.
DistanceResult meshDistance(const LinkGeometry& a, const Pose& pose_a, const LinkGeometry& b, const Pose& pose_b,
                            const Tolerances& tol = {}, double relative_error = 0.0,
                            double cutoff = std::numeric_limits<double>::infinity()) noexcept;

/// The distance between a convex shape (A, an obstacle or a voxel) and a link's exact geometry (B):
/// the minimum over the link's triangles and primitives, with the same bounds, frames and relative_error
/// as meshDistance (normal from the shape towards the link). The link's hull is not consulted: callers
/// that want a cheap lower bound first ask GJK for the shape-to-hull distance.
DistanceResult shapeLinkDistance(const Shape& shape, const Pose& pose_shape, const LinkGeometry& link,
                                 const Pose& pose_link, const Tolerances& tol = {}, double relative_error = 0.0) noexcept;

namespace detail {

/// The separating-axis test of two closed triangles given in one frame: true when one of the 17 axes
/// (2 normals, 9 edge–edge cross products, 6 in-plane edge normals) separates them by more than `slack`
/// metres (slack > 0 must exceed the rounding of the coordinates: then "true" is certain). Complete
/// for non-degenerate triangles in exact arithmetic; a false "false" can come only from rounding.
bool trianglesSeparated(const Vec3 a[3], const Vec3 b[3], double slack) noexcept;

}  // namespace detail

// ---- BodyPair: the rungs climbed in order, warm --------------------------------------------------------

/// What BodyPair::intersects asks.
struct IntersectQuery {
  double padding = 0.0;                    ///< bodies within this many metres count as touching (≥ 0)
  GeometryMode mode = GeometryMode::Mesh;  ///< Hull: the balls and hulls only (conservative)
};

/// The rungs of the ladder, cheapest first.
enum class Rung : char { Balls, Hulls, Parts, Exact };

/// What BodyPair::lowerBound asks: a certified lower bound on the distance, as cheap as it may be.
struct BoundQuery {
  /// A bound of at least this is all that is asked: each GJK stops once it proves it, and no dearer rung
  /// is climbed once the bound reaches it.
  double enough = std::numeric_limits<double>::infinity();
  /// Each GJK may stop once within this relative error of its distance (any value is safe: only lower
  /// bounds are used; looser ends each GJK sooner and sends more pairs down the ladder).
  double relative = 0.0;
  GeometryMode mode = GeometryMode::Mesh;  ///< Hull: stop at the hulls
  /// A dearer rung is climbed only while the bound is at most this (below 0: while it is short of enough).
  double climb = -1.0;
  /// The dearest rung climbed (a cheap bound: Hulls, Parts); Hull mode stops at the hulls whatever this says.
  Rung top = Rung::Exact;
  /// ≥ 0: at the exact rung, first ask whether the bodies lie within this distance (a search that stops at
  /// the first touching pair, far cheaper near fine meshes than a distance): if so, the bound is 0; if not,
  /// it is above `within` (by a relative 1e-9, so that callers comparing with ≤ see it beyond).
  double within = -1.0;
  /// The exact rung measures no farther than this: beyond it, the answer is the rungs' bound or `near`.
  double near = std::numeric_limits<double>::infinity();
};

/// What BodyPair::distance asks.
struct DistanceQuery {
  double cutoff = std::numeric_limits<double>::infinity();  ///< bodies farther apart answer `cutoff`
  double relative = 0.0;  ///< as meshDistance's relative_error
  /// Hull: the distance between the convex hulls (a shape: itself), one GJK, a lower bound on the exact one.
  GeometryMode mode = GeometryMode::Mesh;
};

/// What BodyPair::cast asks: A's hull, grown by `margin`, translating by s·velocity (the poses' frame),
/// s ∈ [0, max_s], B held.
struct CastQuery {
  Vec3 velocity = Vec3::Zero();  ///< A's translation per unit of s
  double margin = 0.0;           ///< metres A's hull is grown by (≥ 0)
  double max_s = 1.0;            ///< the sweep ends at s = max_s
};

/// Two bodies and the warm starts of their convex bounds: a link (A) and either another link or a mesh
/// obstacle (B, a LinkGeometry), or a convex shape (B: an obstacle's primitive, a voxel's box), which has
/// one convex piece, itself, for hull, part and exact geometry alike. Made without allocating; the
/// geometries must outlive it. Not thread-safe: one per pair and thread.
class BodyPair {
 public:
  /// The pair of a and b (borrowed), with cold warm starts; allocates nothing. `hull_warm`, when given, is
  /// where the hulls' warm start lives (the caller's, so that it outlives a pair made for one query); such
  /// a pair keeps no warm starts of its own (its parts start cold).
  BodyPair(const LinkGeometry& a, const LinkGeometry& b, SimplexCache* hull_warm = nullptr)
      : a_(&a), b_(&b), warm_(hull_warm) {}
  /// The link a against the convex shape b (placed by pose_b in every query), both borrowed; `hull_warm`
  /// as above.
  BodyPair(const LinkGeometry& a, const Shape& b, SimplexCache* hull_warm = nullptr)
      : a_(&a), shape_(&b), warm_(hull_warm) {}

  /// The first body, as given.
  const LinkGeometry& a() const noexcept { return *a_; }
  /// The second body of a pair of links (null for a convex shape).
  const LinkGeometry* b() const noexcept { return b_; }
  /// The second body of a link and a convex shape (null for a pair of links).
  const Shape* shape() const noexcept { return shape_; }

  /// True when the bodies (placed by the poses) are within q.padding of each other: meshesIntersect (or
  /// shapeIntersectsLink), warm. Never "free" by accident (non-finite input, a narrow-phase failure: true).
  /// (Inline: the environment makes a pair per obstacle and query, and most ask this alone.)
  bool intersects(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol, const IntersectQuery& q) noexcept {
    if (shape_) return shapeIntersectsLink(*shape_, pose_b, *a_, pose_a, tol, q.mode, q.padding, &hullCache());
    return meshesIntersect(*a_, pose_a, *b_, pose_b, tol, q.mode, q.padding, &hullCache());
  }
  /// intersects() split in two: its cheap rungs (screenMeshes' short of the convex parts, warm), then, for
  /// an Unsure pair, intersectsExactly(). Together they answer as intersects() does.
  Screen screen(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol, const IntersectQuery& q) noexcept;
  ///@{
  /// screen() in two halves, for a caller that screens many pairs and stops at the first contact: the rungs
  /// of a few operations each (bounding spheres, the hulls' boxes, the cores), then, for a pair they leave
  /// Unsure, the hulls' (or the primitives') GJK. A contact the cores prove in any pair then costs no GJK of
  /// the pairs before it. Together they answer as screen() does.
  Screen screenCheap(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol, const IntersectQuery& q) noexcept;
  Screen screenDear(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol, const IntersectQuery& q) noexcept;
  ///@}
  /// The dear rungs: the convex parts (warm: the part pair too near last time is tried first), then the
  /// triangles (meshesIntersectExactly). Left for the pairs screen() leaves Unsure, so that a query that
  /// ends on another pair's contact never pays them.
  bool intersectsExactly(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol, double padding) noexcept;
  /// A certified lower bound on the distance between the bodies (see BoundQuery); 0 for non-finite input or
  /// a narrow-phase failure.
  double lowerBound(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol, const BoundQuery& q) noexcept;
  /// An upper bound on how deep the bodies overlap, counting `padding` as overlap (0 when they are farther
  /// apart than padding): the hulls' EPA depth plus padding, the hulls containing the bodies. NaN when EPA
  /// fails or the input is not finite (never a depth of 0 by accident).
  double penetration(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol, double padding = 0.0) const noexcept;
  /// The distance between the exact geometries (normal from A towards B): meshDistance's answer (or
  /// shapeLinkDistance's), but with a finite q.cutoff the balls, hulls and parts (warm) are asked first,
  /// and bodies they prove that far apart answer the cutoff at once. q.mode Hull: the hulls' distance.
  DistanceResult distance(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol,
                          const DistanceQuery& q) noexcept;

  /// The first s at which A's hull (grown by q.margin), moving by s·q.velocity, touches B's hull (a shape:
  /// itself): gjkShapeCast's answer, a certified lower bound on when the bodies meet. Hit at 0 on a failure
  /// or non-finite input (never "clear" by accident).
  CastResult cast(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol, const CastQuery& q) const noexcept;

  /// Drops the warm starts (O(1): the parts' are emptied when next used), so that the next answers
  /// depend on nothing asked before.
  void forget() noexcept;
  /// The hulls' last GJK axis (valid once a query has reached the hulls).
  const SimplexCache& hullAxis() const noexcept { return warm_ ? *warm_ : hull_; }
  /// The rung the last lowerBound() or distance() stopped at.
  Rung lastRung() const noexcept { return rung_; }

 private:
  // The balls, the hulls, then (in Mesh mode, while the bound is at most `climb`) the convex parts; sets rung_.
  // Two links of one primitive each, in Mesh mode and unless `primitives` is false: the balls, then the
  // primitives themselves (rung_ Exact).
  double convexBound(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol, double enough, double relative,
                     double climb, GeometryMode mode, bool primitives = true) noexcept;
  SimplexCache& hullCache() noexcept { return warm_ ? *warm_ : hull_; }

  const LinkGeometry* a_;
  const LinkGeometry* b_ = nullptr;
  const Shape* shape_ = nullptr;
  SimplexCache* warm_ = nullptr;
  SimplexCache hull_;
  SimplexCache sole_;                // two links of one primitive each: the primitives' GJK axis
  std::vector<SimplexCache> parts_;  // a's part i against b's part j at i·nb + j
  bool parts_stale_ = false;
  int parts_first_ = -1;  // the part pair intersectsExactly() tries first: the one too near last time
  Rung rung_ = Rung::Balls;
};

}  // namespace clearway
