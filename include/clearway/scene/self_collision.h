#pragma once
// Self-collision of a robot: every checked link pair (scene/collision_filter.h) tested with the link
// geometries of body/robot_geometry.h at the link poses of one configuration. The checker is
// immutable and shared by all threads; what changes from query to query (the separating axis of each
// pair's hulls, the pair that collided last) lives in a SelfCollisionContext, one per thread.
#include <clearway/kinematics/robot_model.h>
#include <clearway/scene/collision_filter.h>
#include <clearway/body/enclosing.h>
#include <clearway/body/proximity.h>
#include <clearway/body/robot_geometry.h>
#include <clearway/scene/pair_table.h>
#include <clearway/tolerances.h>

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

namespace clearway {

/// Two links of one robot, a < b.
struct LinkPair {
  ///@{
  int a = -1, b = -1;  ///< link indices
  ///@}
  /// True when both links are the same.
  bool operator==(const LinkPair& o) const noexcept { return a == o.a && b == o.b; }
};

/// How self-collision is checked.
struct SelfCollisionOptions {
  GeometryMode mode = GeometryMode::Mesh;  ///< hulls only, or hulls then triangles (exact)
  Tolerances tolerances;                   ///< the narrow phase's
  /// Metres added around each link (indexed by link; empty: none). A pair collides when its links are
  /// within padding[a] + padding[b]. Must be finite and ≥ 0.
  std::vector<double> link_padding;
  /// Tabulate the verdicts of pairs whose relative pose depends on one or two joint variables
  /// (scene/pair_table.h), for queries that pass the configuration. Same verdicts, built at construction.
  bool pair_tables = true;
  /// held[v], when finite: variable v never leaves this value in queries that pass the configuration (a
  /// joint the scene holds), so the tables treat its joint as fixed. Empty: every variable may move.
  std::vector<double> held;
  PairTableOptions table_options;  ///< how finely each table is cut, and its work bounds
  /// Seconds all the tables may take to build (measured from the first); cells past it stay Unsure. None
  /// by default (table_options bounds their work by counts, the same on every machine).
  double table_seconds = std::numeric_limits<double>::infinity();
};

/// Per-thread state of self-collision queries: one hull cache per pair and the pair that last collided.
struct SelfCollisionContext {
  std::vector<BodyPair> bodies;  ///< per checked pair: its two links' geometry and warm starts
  EnclosingBalls balls;          ///< the links' enclosing balls at the current query's poses
  std::vector<int> unsure;       ///< pairs the cheap rungs left to the triangles (scratch of one query)
  std::vector<std::uint8_t> table_free;  ///< per pair: its table called it Free at this query's q (scratch)
  std::vector<std::uint8_t> bounds_apart;  ///< per pair: its bounding balls apart at this query's poses (scratch)
  int last_hit = -1;  ///< the pair (index into pairs()) that last collided, tried first; -1: none
  long long pair_tests = 0;  ///< pairs that reached the narrow phase (bounding spheres not apart), cumulative
};

/// Self-collision checker of one robot with one filter. Immutable; queries are thread-safe given one
/// context per thread.
class SelfCollision {
 public:
  /// Throws std::invalid_argument when padding has the wrong length or a negative or non-finite entry.
  SelfCollision(std::shared_ptr<const RobotGeometry> geometry, const CollisionFilter& filter,
                SelfCollisionOptions options = {});

  /// The robot's geometry (shared with the caller).
  const RobotGeometry& geometry() const noexcept { return *geometry_; }
  /// The pairs checked, sorted.
  const std::vector<LinkPair>& pairs() const noexcept { return pairs_; }
  /// The options the checker was built with.
  const SelfCollisionOptions& options() const noexcept { return options_; }
  /// The padding of pair k (the sum of its links' paddings).
  double pairPadding(int k) const noexcept { return pair_padding_[k]; }
  /// Pair k's table, or null when it has none.
  const PairTable* pairTable(int k) const noexcept { return tables_.empty() ? nullptr : tables_[k].get(); }
  /// A fresh context for this checker (allocates; make one per thread and reuse it).
  SelfCollisionContext makeContext() const;

  /// The first colliding pair at these world link poses (one per link), or nullptr when none collides.
  /// The pair that collided in the previous query of this context is tried first (frame coherence).
  /// Never "free" by accident: a non-finite pose collides. q (optional): the configuration the poses were
  /// computed from (every variable of the robot, held ones at their held values), which lets the pair
  /// tables answer; the verdict is the same with or without it. balls_placed: placeBalls() was last
  /// called with these very poses (and its answer was true), so they are not placed again.
  const LinkPair* firstCollision(const Pose* link_poses, SelfCollisionContext& context, const double* q = nullptr,
                                 bool balls_placed = false) const noexcept;
  /// Places the context's enclosing balls (body/enclosing.h) at these poses when it has them (a context
  /// made by makeContext); false otherwise.
  bool placeBalls(const Pose* link_poses, SelfCollisionContext& context) const noexcept;
  /// Every colliding pair at these poses, appended to `out` in pair order.
  void allCollisions(const Pose* link_poses, SelfCollisionContext& context, std::vector<LinkPair>& out) const;
  /// True when pair index k collides at these poses.
  bool pairCollides(int k, const Pose* link_poses, SelfCollisionContext& context) const noexcept;
  /// The clearance of the closest checked pair (distance between exact geometries, minus padding; 0 when
  /// touching); `pair` (optional) receives it. relative_error as in meshDistance. Infinity with no pairs.
  DistanceResult minimumDistance(const Pose* link_poses, LinkPair* pair = nullptr, double relative_error = 0.0) const;
  /// How deep the robot penetrates itself: over the colliding pairs, the largest EPA depth between the
  /// two links' convex hulls (an upper bound on the meshes' depth), plus the pair's padding; `pair`
  /// (optional) receives that pair. 0 when no pair collides; NaN when a query failed.
  double penetration(const Pose* link_poses, SelfCollisionContext& context, LinkPair* pair = nullptr) const;

 private:
  // pairCollides, first asking the context's enclosing balls (placed for these poses by the caller).
  bool pairHits(int k, const Pose* link_poses, SelfCollisionContext& context, bool balls_placed) const noexcept;
  // pairHits in two halves: the enclosing balls and the pair's cheap rungs, then (for Unsure) the triangles.
  Screen pairScreen(int k, const Pose* link_poses, SelfCollisionContext& context, bool balls_placed) const noexcept;
  bool pairExactly(int k, const Pose* link_poses) const noexcept;
  // Pair k's table verdict at q (Unsure without a table or q).
  PairTable::Verdict tabled(int k, const double* q) const noexcept {
    return q && !tables_.empty() && tables_[k] ? tables_[k]->lookup(q) : PairTable::Verdict::Unsure;
  }
  // Records pair k as the last hit and returns it.
  const LinkPair* hit(int k, SelfCollisionContext& context) const noexcept;

  std::shared_ptr<const RobotGeometry> geometry_;
  std::vector<LinkPair> pairs_;
  std::vector<double> pair_padding_;
  std::vector<std::int64_t> pair_a_, pair_b_;  // pairs_' links, as the enclosing layer's lanes read them
  std::vector<std::shared_ptr<const PairTable>> tables_;  // per pair when options_.pair_tables
  std::vector<int> with_table_;                          // the pairs that have one
  SelfCollisionOptions options_;
};

}  // namespace clearway
