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
  /// Tabulate the verdicts of pairs whose relative pose depends on one or two joint variables, or three
  /// whose lowest turns the lower link (scene/pair_table.h), for queries that pass the configuration. Same
  /// verdicts, built at construction.
  bool pair_tables = true;
  /// held[v], when finite: variable v never leaves this value in queries that pass the configuration (a
  /// joint the scene holds), so the tables treat its joint as fixed. Empty: every variable may move.
  std::vector<double> held;
  PairTableOptions table_options;  ///< how finely each table is cut, and its work bounds
  /// Seconds all the tables may take to build (measured from the first); cells past it stay Unsure. None
  /// by default (table_options bounds their work by counts, the same on every machine).
  double table_seconds = std::numeric_limits<double>::infinity();
};

namespace scene_detail {
struct SelfScratch;  // self_collision.cpp
}  // namespace scene_detail

/// One thread's scratch for SelfCollision's queries (each pair's warm starts, the links' enclosing balls,
/// the pair that collided last): made by the checker's makeContext(), then reused. Movable, not copyable;
/// a default-made one holds nothing (queries given it answer the same, without warm starts).
class SelfCollisionContext {
 public:
  SelfCollisionContext() noexcept;
  ///@{
  /// Takes the other context's scratch, leaving that one empty.
  SelfCollisionContext(SelfCollisionContext&&) noexcept;
  SelfCollisionContext& operator=(SelfCollisionContext&&) noexcept;
  ///@}
  ~SelfCollisionContext();
  /// Pairs that reached the narrow phase through this context (their bounding balls not apart), cumulative.
  long long pairTests() const noexcept;

 private:
  friend class SelfCollision;
  explicit SelfCollisionContext(std::unique_ptr<scene_detail::SelfScratch> scratch) noexcept;
  std::unique_ptr<scene_detail::SelfScratch> scratch_;
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
  /// True when some pair has a table that may prove it colliding (tabledCollision can then answer).
  bool hasTables() const noexcept { return !with_table_.empty(); }
  /// Pair k's table, or null when it has none.
  const PairTable* pairTable(int k) const noexcept { return tables_.empty() ? nullptr : tables_[k].get(); }
  /// A fresh context for this checker (allocates; make one per thread and reuse it).
  SelfCollisionContext makeContext() const;

  /// The first colliding pair at these world link poses (one per link), or nullptr when none collides.
  /// The pair that collided in the previous query of this context is tried first (frame coherence).
  /// Never "free" by accident: a non-finite pose collides. q (optional): the configuration the poses were
  /// computed from (every variable of the robot, held ones at their held values), which lets the pair
  /// tables answer; the verdict is the same with or without it. placed (optional): the links' enclosing
  /// balls, made for this robot and placed at these very poses by the caller (which shares them with its
  /// other checks); without them the context's own are placed.
  const LinkPair* firstCollision(const Pose* link_poses, SelfCollisionContext& context, const double* q = nullptr,
                                 EnclosingBalls* placed = nullptr) const noexcept;
  /// firstCollision's first stage, which needs no poses: a pair whose table proves it colliding at q (every
  /// variable of the robot, held ones at their held values), or nullptr. Its look-ups are kept in the
  /// context for a firstCollision at the same q among the next few (up to eight states later), which then
  /// does not repeat them.
  const LinkPair* tabledCollision(const double* q, SelfCollisionContext& context) const noexcept;
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
  // The context's enclosing balls placed at these poses, or null when it has none (a default-made context).
  EnclosingBalls* placeBalls(const Pose* link_poses, scene_detail::SelfScratch& s) const noexcept;
  // pairCollides, first asking the enclosing balls when given (placed at these poses).
  bool pairHits(int k, const Pose* link_poses, scene_detail::SelfScratch& s, EnclosingBalls* balls) const noexcept;
  // pairHits in two halves: the enclosing balls and the pair's cheap rungs, then (for Unsure) the convex parts
  // and the triangles (BodyPair::intersectsExactly).
  Screen pairScreen(int k, const Pose* link_poses, scene_detail::SelfScratch& s, EnclosingBalls* balls) const noexcept;
  // pairScreen in two halves: the enclosing balls and the pair's rungs of a few operations, then (for Unsure)
  // the hulls' GJK (BodyPair::screenCheap, screenDear).
  Screen pairScreenCheap(int k, const Pose* link_poses, scene_detail::SelfScratch& s,
                         EnclosingBalls* balls) const noexcept;
  Screen pairScreenDear(int k, const Pose* link_poses, scene_detail::SelfScratch& s) const noexcept;
  bool pairExactly(int k, const Pose* link_poses, scene_detail::SelfScratch& s) const noexcept;
  // Pair k's table verdict at q (Unsure without a table or q).
  PairTable::Verdict tabled(int k, const double* q) const noexcept {
    return q && !tables_.empty() && tables_[k] ? tables_[k]->lookup(q) : PairTable::Verdict::Unsure;
  }
  // Looks every table up at q: the first pair one proves colliding, else nullptr with the Free verdicts
  // (table_free) and the witnesses kept in s.
  const LinkPair* lookUp(const double* q, scene_detail::SelfScratch& s) const noexcept;
  // Records pair k as the last hit and returns it.
  const LinkPair* hit(int k, scene_detail::SelfScratch& s) const noexcept;

  std::shared_ptr<const RobotGeometry> geometry_;
  std::vector<LinkPair> pairs_;
  std::vector<double> pair_padding_;
  BoundsRows bounds_rows_;                                // pairs_, as the enclosing layer's lanes read them
  std::vector<std::shared_ptr<const PairTable>> tables_;  // per pair when options_.pair_tables
  std::vector<int> with_table_;                           // the pairs whose table may prove a collision
  std::vector<std::uint8_t> free_table_;  // per pair: its table is freeOnly(), asked only when the balls meet
  SelfCollisionOptions options_;
  // Which checker made a context: its warm starts (one BodyPair per pair, by index) serve only the checker
  // whose pairs they were made for. A copy keeps it (the same pairs, the same shared geometry).
  std::uint64_t serial_;
};

}  // namespace clearway
