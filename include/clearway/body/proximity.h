#pragma once
// How near two rigid bodies are, asked three ways, each climbing the same ladder of ever tighter and dearer
// bounds once: the bounding balls, the convex hulls (warm-started GJK), the convex parts, and last the
// exact triangles and primitives (closed meshes as solids). A query stops at the first rung that settles
// it. A BodyPair keeps the pair's GJK warm starts from one query to the next.
#include <clearway/body/link_geometry.h>

#include <limits>
#include <vector>

namespace clearway {

/// What BodyPair::intersects asks.
struct IntersectQuery {
  double padding = 0.0;                    ///< bodies within this many metres count as touching (≥ 0)
  GeometryMode mode = GeometryMode::Mesh;  ///< Hull: the balls and hulls only (conservative)
};

/// What BodyPair::lowerBound asks: a certified lower bound on the distance, as cheap as it may be.
struct BoundQuery {
  /// A bound of at least this is all that is asked: each GJK stops once it proves it.
  double enough = std::numeric_limits<double>::infinity();
  /// Each GJK may stop once within this relative error of its distance (any value is safe: only lower
  /// bounds are used; looser ends each GJK sooner and sends more pairs down the ladder).
  double relative = 0.0;
  GeometryMode mode = GeometryMode::Mesh;  ///< Hull: stop at the hulls
  /// A dearer rung is climbed only while the bound is at most this (below 0: while it is short of enough).
  double climb = -1.0;
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
};

/// The rungs of the ladder, cheapest first.
enum class Rung : char { Balls, Hulls, Parts, Exact };

/// Two bodies (two links, or a link and a mesh obstacle) and the warm starts of their convex bounds. Made
/// without allocating; the geometries must outlive it. Not thread-safe: one per pair and thread.
class BodyPair {
 public:
  /// The pair of a and b (borrowed), with cold warm starts; allocates nothing.
  BodyPair(const LinkGeometry& a, const LinkGeometry& b);

  /// The first body, as given.
  const LinkGeometry& a() const noexcept { return *a_; }
  /// The second body, as given.
  const LinkGeometry& b() const noexcept { return *b_; }

  /// True when the bodies (placed by the poses) are within q.padding of each other: meshesIntersect, warm.
  /// Never "free" by accident (non-finite input, a narrow-phase failure: true).
  bool intersects(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol, const IntersectQuery& q) noexcept;
  /// intersects() split in two: its rungs short of the triangles (screenMeshes, warm), then, for an Unsure
  /// pair, the triangles (meshesIntersectExactly). Together they answer as intersects() does.
  Screen screen(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol, const IntersectQuery& q) noexcept;
  /// The triangles' rung alone: meshesIntersectExactly on the two bodies (no warm start used or kept).
  bool intersectsExactly(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol, double padding) const noexcept;
  /// A certified lower bound on the distance between the bodies (see BoundQuery); 0 for non-finite input or
  /// a narrow-phase failure.
  double lowerBound(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol, const BoundQuery& q) noexcept;
  /// An upper bound on how deep the bodies overlap, counting `padding` as overlap (0 when they are farther
  /// apart than padding): the hulls' EPA depth plus padding, the hulls containing the bodies. NaN when EPA
  /// fails or the input is not finite (never a depth of 0 by accident).
  double penetration(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol, double padding = 0.0) const noexcept;
  /// The distance between the exact geometries: meshDistance's answer, but with a finite q.cutoff the balls,
  /// hulls and parts (warm) are asked first, and bodies they prove that far apart answer the cutoff at once.
  DistanceResult distance(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol,
                          const DistanceQuery& q) noexcept;

  /// Drops the warm starts (O(1): the parts' are emptied when next used), so that the next answers
  /// depend on nothing asked before.
  void forget() noexcept;
  /// The hulls' last GJK axis (valid once a query has reached the hulls).
  const SimplexCache& hullAxis() const noexcept { return hull_; }
  /// The rung the last lowerBound() or distance() stopped at.
  Rung lastRung() const noexcept { return rung_; }

 private:
  // The balls, the hulls, then (in Mesh mode, while the bound is at most `climb`) the convex parts; sets rung_.
  double convexBound(const Pose& pose_a, const Pose& pose_b, const Tolerances& tol, double enough, double relative,
                     double climb, GeometryMode mode) noexcept;

  const LinkGeometry* a_;
  const LinkGeometry* b_;
  SimplexCache hull_;
  std::vector<SimplexCache> parts_;  // a's part i against b's part j at i·nb + j
  bool parts_stale_ = false;
  Rung rung_ = Rung::Balls;
};

}  // namespace clearway
