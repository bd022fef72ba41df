#pragma once
// Continuous checks of a straight joint-space segment q(s) = q0 + s·(q1 − q0), s ∈ [0, 1].
//
// Certified mode is conservative advancement with kinematic motion bounds. Based on: F. Schwarzer,
// M. Saha, J.-C. Latombe, "Exact Collision Checking of Robot Paths" (WAFR 2002 / IEEE T-ASE 2005).
// For a link A and a step Δq, no point of A moves farther than Σ_v |Δq_v|·c_{v,A}, where c_{v,A} sums,
// over the joints of A's chain that variable v drives, the joint's reach: for a revolute joint, the
// largest distance from its axis to A's geometry (a configuration-independent bound: the lengths of
// the joint offsets in between plus A's radius, or exact when A is rigid with the axis); for a
// prismatic joint, 1. A planar joint is two slides and a turn; a floating joint three slides and a spin
// about its origin, whose quaternion entries (both ends normalized, the end on the start's side)
// turn it by at most π/√2 times their change. Two links of one robot move relative to each other only through the joints on
// the path between them, and may be watched from any link on that path: the joints on one side of it
// move A, the others B; the pair's bound is that of the cheapest such link. If a pair is d apart at s,
// it cannot touch within s ± d / B_pair; tighter where measured from the poses at s, as the larger of the
// per-joint reaches from the axes there and the link's velocity field there (the joints' turns added as
// vectors, with a bound on how fast the field changes). Each item (a pair, or a link against the environment) covers
// the segment on its own with such balls: measured at the middle of what is left, it leaves up to two
// shorter intervals, left first, so a free segment costs one measurement per ball twice as wide as
// one-sided advancement's. A measurement within contact_distance switches the item to advancement from
// the interval's left end, whose first contact then bounds every item's work (nothing after it matters).
// A verdict alone (locate_contact false) ends at any contact: it covers the item that met the last one
// first, then the others in turns, a measurement each, every item in its own order.
// Bounds get tighter and dearer (balls, hulls, convex parts, triangles) only until one clears what is
// asked. Links joined by joints the group does not move (a gripper on its flange) are one rigid body:
// two bodies whose every link pair is checked are measured as one item on their merged hulls, and a body
// against the environment likewise, until the merged hulls come within contact; the member pairs then
// cover that interval. Before any distance is measured, the rake (MotionOptions::rake) settles each item on
// the pieces of the segment (the whole, quarters, sixteenths) over which its bodies' bounding balls,
// grown by the item's motion over the piece, stay farther apart than the contact distance; only the rest is
// covered by measurements. A self item whose pairs are tabulated (scene/pair_table.h) over joints that keep
// them more than padding + 2·contact_distance apart in every cell the segment crosses is not swept at all.
// A ball keeps back 2⁻¹² of its reach, so every state of a free segment stays a share of the least clearance
// measured farther than touching: its margin (MotionResult::margin), which makes the segments that lie within
// it free too (MotionChecker::within). Every ball is at least contact_distance / B wide, so the loops end;
// a cap on the number of distance queries ends them too (reported as a collision).
#include <clearway/body/enclosing.h>
#include <clearway/kinematics/point_lanes.h>
#include <clearway/serial.h>
#include <clearway/scene/scene.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace clearway {

/// Per-link and per-pair coefficients of the motion bound of one scene's group.
class MotionBound {
 public:
  /// Points that move with link `anchor`, seen as one more link: the links that move as one (joined by
  /// joints the group does not move) merged, or a convex piece of a link; in the anchor's frame.
  struct Body {
    int anchor = 0;                    ///< the link the points move with (their frame is its frame)
    const ConvexHull* hull = nullptr;  ///< the points' hull
    Vec3 center = Vec3::Zero();        ///< a ball that contains them
    double radius = 0.0;               ///< that ball's radius (metres)
  };
  /// A planar or floating joint's slides are bounded by the scene's limits of its x, y (and z) entries.
  /// Body k takes the link index scene.robot().linkCount() + k in every call below.
  explicit MotionBound(const Scene& scene, const std::vector<Body>& bodies = {});

  /// Upper bound on how far any point of link `link` moves (world frame) for the state step dq.
  double link(int link, const double* dq) const noexcept;
  /// link(i, dq) of the first `count` bodies (links, then merged bodies) into out[i] (∞ past the last body).
  void links(const double* dq, int count, double* out) const noexcept;
  /// Upper bound on how much the distance between links a and b can change for the step dq.
  double pair(int a, int b, const double* dq) const noexcept;
  /// The joints between two links and their reaches to either, set up once by path(a, b) for pair(path, dq)
  /// (a default-made one is no path: pair() gives it 0).
  class PairPath {
    friend class MotionBound;
    struct Joint {
      int var;        // the state entry that drives it
      double mult;    // |multiplier| of a mimic, kSpin for a spin, else 1
      double to_a, to_b;  // its reach to a and to b (1 for a slide)
    };
    std::vector<Joint> joints_;  // in path order: a's side upwards, then b's downwards
    int a_ = -1, b_ = -1;
    bool long_ = false;  // longer than any real robot's: pair(a, b, dq) answers
  };
  /// The path between links a and b (bodies too), for pair(path, dq).
  PairPath path(int a, int b) const;
  /// pair(a, b, dq) for path(a, b), the same number, without walking the chains for every step.
  double pair(const PairPath& path, const double* dq) const noexcept;
  /// The largest h (possibly above 1, or ∞) such that, for the step ±h·dq from the state whose link poses
  /// are `poses` (the link's and its ancestors' at least), no point of the link moves d or farther: the
  /// reaches measured from where the joint axes are now (a point's distance from joint k's axis changes
  /// only through the joints after k, either way), which is much tighter than d / link(dq) for a link near
  /// the axes that turn it. Never below d / link(dq). `extra`: more motion, extra·h for the step h·dq (the
  /// obstacles it is measured from moving too).
  double linkStep(int link, const double* dq, const Pose* poses, double d, double extra = 0.0) const noexcept;
  /// The same for the distance between links a and b (poses of both and their ancestors needed), watched
  /// from their common ancestor; where pair() watches from a better link, d / pair(a, b, dq) may be larger.
  double pairStep(int a, int b, const double* dq, const Pose* poses, double d) const noexcept;

 private:
  struct Tables;     // motion_bound.cpp: the chains, reaches and coefficients, shared by copies
  struct LinkTerms;  // motion_bound.cpp: one link's share of pairStep's bound

 public:
  /// What pairStep walks per link, kept for the next pair that shares the link, its fork and its poses.
  /// Made per thread (makeStepCache); a cache of another bound's robot is not used.
  class StepCache {
    friend class MotionBound;
    friend struct MotionBound::Tables;
    struct Entry {
      std::uint64_t id = 0;  // the poses it was walked at (0: none)
      std::size_t from = 0;
      int room = 0;
      std::shared_ptr<LinkTerms> terms;
    };
    std::vector<Entry> entries_;  // per link
    std::uint64_t owner_ = 0;     // the serial of the bound's tables (shared by its copies) that made it
  };
  /// An empty cache for this bound's robot.
  StepCache makeStepCache() const;
  /// pairStep(a, b, dq, poses, d), the same number, reusing each link's walk from `cache` where it was made
  /// for the same poses, dq and fork. poses_id names the poses and dq: the caller promises that one id
  /// (nonzero) is never given two different ones.
  double pairStep(int a, int b, const double* dq, const Pose* poses, double d, StepCache& cache,
                  std::uint64_t poses_id) const noexcept;
  /// The terms of the second bound linkStep() takes the larger of, from the link's velocity field now: for
  /// the step ±h·dq no point of the link moves h·speed + h²·accel/2 or farther, speed bounding its points'
  /// speed at `poses` and accel their acceleration anywhere (per unit step). False, with no terms, when a
  /// joint of the chain that dq moves does not turn (a slide, a planar or floating joint).
  bool linkTwist(int link, const double* dq, const Pose* poses, double& speed, double& accel) const noexcept;
  /// True when the step dq moves links a and b relative to each other by a pure translation (every
  /// joint it moves on the path between them is prismatic), which is then linear in the step.
  bool translates(int a, int b, const double* dq) const noexcept;
  /// True when the step dq moves link `link` in the world by a pure translation.
  bool translates(int link, const double* dq) const noexcept;
  /// The spin of a floating joint: the angle between unit quaternions on one side is at most this times
  /// their Euclidean distance (4·asin(c/2) ≤ (π/√2)·c for c ≤ √2).
  static constexpr double kSpin = 2.2214414690791831;
  /// Coefficient of state entry v for link i (metres per radian, or 1 for prismatic).
  double linkCoefficient(int link, int v) const noexcept;

 private:
  std::shared_ptr<const Tables> t_;
};

/// How a segment is checked.
enum class MotionMode {
  Certified,  ///< conservative advancement: no collision is ever missed (within contact_distance)
  Sampled,    ///< states at a fixed resolution, like OMPL's DiscreteMotionValidator: may tunnel
  /// Certified, and an item whose links only translate on the segment (relative to each other, or in the
  /// world for the environment) is first measured by a GJK shape cast of its hulls grown by the contact
  /// distance and padding: clear up to the cast's time of impact in one query, where advancement would
  /// approach in many steps. The same verdicts as Certified.
  Cast,
};

/// Near an end of a segment that is itself within contact_distance of touching, a pair's contact distance
/// is half that end's clearance plus this fraction of the pair's motion bound over the way from the end
/// (up to contact_distance): a motion that leaves the end at least 1/16 as fast as its bound allows is
/// free at any clearance, and the balls near the end grow geometrically, so certifying it takes a few
/// hundred measurements however near the end is (a constant contact distance of half the end's clearance
/// crawled along an obstacle in steps of that size: 200,000 queries from a nanometre).
inline constexpr double kContactGrowth = 1.0 / 16.0;

/// How MotionChecker checks a segment: the mode, and each mode's accuracy and work bounds.
struct MotionOptions {
  MotionMode mode = MotionMode::Certified;  ///< Certified, Sampled or Cast
  /// Certified: a pair closer than this (metres) counts as in contact; larger is faster near obstacles.
  /// Near an end of the segment that is itself nearer, the pair's contact distance is lower (half that
  /// end's clearance, growing away from it: kContactGrowth), so a free state can always be left (a free
  /// motion from it, such as one of length zero, is certified free).
  double contact_distance = 1e-3;
  /// Certified: GJK's relative error allowed in distances (only lower bounds are used, so any value is safe;
  /// looser bounds end each GJK sooner but send more pairs down to the dearer parts and triangles).
  double distance_relative_error = 0.1;
  /// Certified: cap on distance queries per segment; reaching it reports a collision (never free by accident).
  int max_queries = 200000;
  /// Certified: asked every 256 distance queries of a segment; true ends the check as the cap does
  /// (capped, never free). A planner's termination condition here keeps its time limit however long a
  /// segment near contact would take (200,000 queries of meshes are tens of seconds). Empty: never asked.
  std::function<bool()> stop;
  /// Certified: before any distance is measured, the bodies' bounding balls settle the pieces of the
  /// segment (quarters down to sixteenths) on which they stay farther apart than contact_distance (certified.cpp:
  /// the rake). false: every item is measured (the same verdicts but where a clearance lies within
  /// distance_relative_error of the contact distance, for comparing).
  bool rake = true;
  /// Sampled: the largest step between checked states, in the state's Euclidean norm.
  double resolution = 0.01;
  /// Sampled: cap on states per segment; a segment needing more is reported as a collision (capped),
  /// never free (a resolution of 1e-9 once overflowed the step count and called a colliding segment free).
  int max_samples = 1000000;
};

/// The verdict on a segment.
struct MotionResult {
  bool free = false;  ///< true only when the whole segment is free (certified, or at every sample)
  ///@{
  /// When not free: the segment parameter of the first contact found (certified: a state within
  /// contact_distance of touching there, and none touching before it; an invalid state: where the segment
  /// leaves the bounds), and the last parameter at which the state is known to be free (≤ first_contact;
  /// 0 when q0 itself collides).
  double first_contact = 0.0;
  double last_valid = 0.0;
  ///@}
  /// When free and certified: every body stays farther than this (metres, beyond its padding) from what it
  /// is checked against all along the segment, so a segment within it (MotionChecker::within) is free too;
  /// 0 otherwise (sampled, a scene with moving obstacles, not free).
  double margin = 0.0;
  CollisionReport report;   ///< what collided
  int steps = 0;            ///< parameters whose poses were computed (certified) or states checked (sampled)
  int distance_queries = 0; ///< pair or link distances computed (certified)
  bool capped = false;      ///< the query cap was reached (reported as a collision)
};

namespace motion_detail {
struct Scratch;  // motion_detail.h
}  // namespace motion_detail

/// One thread's scratch for MotionChecker::check (allocated once, then reused): made by the checking
/// MotionChecker's makeContext(). Movable, not copyable; a default-made one is empty and only good for
/// assigning to (a check given it, or a context another checker made, reports a collision).
class MotionContext {
 public:
  MotionContext() noexcept;
  ///@{
  /// Takes the other context's scratch, leaving that one empty.
  MotionContext(MotionContext&&) noexcept;
  MotionContext& operator=(MotionContext&&) noexcept;
  ///@}
  ~MotionContext();

 private:
  friend class MotionChecker;
  explicit MotionContext(std::unique_ptr<motion_detail::Scratch> scratch) noexcept;
  std::unique_ptr<motion_detail::Scratch> scratch_;
};

/// Checks the segment. Both ends must be states of the scene's dimension; an invalid state (NaN, out
/// of bounds) anywhere makes the segment not free. Thread-safe given one context per thread.
class MotionChecker {
 public:
  /// Throws std::invalid_argument for options out of range.
  MotionChecker(std::shared_ptr<const Scene> scene, MotionOptions options = {});
  /// base's checker for `scene`, an edit of base's scene (Scene::withEnvironment): with the same robot and
  /// the same links checked against the environment, it shares base's merged bodies, bound and items, and
  /// only the obstacles' speed is read again; otherwise it is built as the constructor above builds it.
  MotionChecker(const MotionChecker& base, std::shared_ptr<const Scene> scene);
  /// base's checker with other options: it shares base's merged bodies, bound and items (building those
  /// costs up to a third of a second for a robot of large meshes), and builds its pair tables again only
  /// for another contact distance, or where one of the two modes is Sampled and the other is not. Throws
  /// std::invalid_argument for options out of range. Contexts made by base do not fit it.
  MotionChecker(const MotionChecker& base, MotionOptions options);

  /// The scene whose segments are checked.
  const Scene& scene() const noexcept { return *scene_; }
  /// The same scene, shared.
  const std::shared_ptr<const Scene>& scenePtr() const noexcept { return scene_; }
  /// The options the checker was built with.
  const MotionOptions& options() const noexcept { return options_; }
  /// The motion bound of the scene's group, with the merged bodies.
  const MotionBound& bound() const noexcept { return bound_; }
  /// A new scratch for check() on one thread (allocates; reuse it for every check of that thread).
  MotionContext makeContext() const;

  /// The verdict on q0 → q1 (each of scene().dimension() values). With locate_contact, a certified check
  /// of a segment that is not free finds its first contact and ends with a full state check there (then
  /// last_valid is first_contact if that state is free, else where the contacting item's last clear
  /// measurement still certifies half the contact distance). Without it, only the verdict: the first
  /// measurement within contact_distance ends the check (first_contact is then a contact, not
  /// necessarily the first, and last_valid 0) — OMPL's checkMotion(s1, s2), where planners try many
  /// colliding motions; while many of a context's segments collide, the states at s = 1, 1/2, 1/4
  /// and 3/4 are checked first, and one that collides ends it there. It says free exactly where the located check
  /// does (both measure the same parameters until a contact, and a colliding state is within contact);
  /// its verdict depends on the segment alone, its first_contact and report also on the context's
  /// earlier segments.
  MotionResult check(const double* q0, const double* q1, MotionContext& context,
                     bool locate_contact = true) const noexcept;
  /// The same for q0 at time t0 → q1 at time t1 (the time linear in s), with the scene's moving obstacles
  /// where they are at each moment: their speed adds to every environment item's motion bound. Scenes that
  /// do not declare `moving` ignore the times; the check above is this one at t0 = t1 = 0.
  MotionResult check(const double* q0, double t0, const double* q1, double t1, MotionContext& context,
                     bool locate_contact = true) const noexcept;
  /// The state at parameter s of q0 → q1, into out: linear, except that a floating joint's quaternion
  /// follows the short great arc at constant speed (slerp, as OMPL's SO(3) space), normalized.
  void interpolate(const double* q0, const double* q1, double s, double* out) const noexcept;
  /// True when q0 → q1 is free because it lies within p0 → p1, a segment check() certified free with
  /// `margin` (its MotionResult::margin): both ends are valid states so near p0 → p1 (entry by entry, with
  /// the roundings of measuring it) that no checked body moves by the margin between a state of q0 → q1 and
  /// the nearest state of p0 → p1 (MotionBound::links of that step). (A check of q0 → q1 alone could still
  /// stop within the contact distance, at a parameter p0 → p1's check did not measure.) False proves nothing;
  /// always false for a context this checker did not make, for floating joints (slerp is not linear in the
  /// entries) and for moving obstacles.
  bool within(const double* q0, const double* q1, const double* p0, const double* p1, double margin,
              MotionContext& context) const noexcept;

 private:
  // True when the context was made by this checker (makeContext) and fits it.
  bool fits(const motion_detail::Scratch& ctx) const noexcept;
  MotionResult certified(const double* q0, double t0, const double* q1, double t1, motion_detail::Scratch& ctx,
                         bool locate_contact) const noexcept;
  MotionResult sampled(const double* q0, double t0, const double* q1, double t1, motion_detail::Scratch& ctx) const noexcept;
  // Cast mode: items that only translate on the segment start from their shape cast's time of impact.
  void castAhead(const double* q0, const double* q1, double t0, int n_items, motion_detail::Scratch& ctx,
                 MotionResult& r) const noexcept;

  // Links that move rigidly together: those with geometry merged, per body of two or more.
  struct Bodies {
    std::vector<int> anchor;  // per link: the link nearest the root that it moves rigidly with
    std::vector<int> index;   // per link: its body in `list` when merged, else -1
    std::vector<Pose> reference;  // per link: its pose at a reference state (rigid offsets are read from it)
    std::vector<std::shared_ptr<const LinkGeometry>> geometry;  // per merged body, in its anchor's frame
    std::vector<MotionBound::Body> list;  // the merged bodies, then every link's and body's convex parts
    std::vector<int> parts_begin;  // per link, then per merged body: the bound's link of its first part, −1: none
  };
  static Bodies mergeBodies(const Scene& scene);
  // What certified mode measures: a self pair (b ≥ 0) or a link against the environment (b < 0); or a
  // group of them (the pairs between two bodies, or one body's links), measured as one on the merged
  // geometry until it comes within contact, when its members take over.
  struct Item {
    int a = -1, b = -1;              // links of the bound (a merged body: past the robot's links)
    int frame_a = -1, frame_b = -1;  // the links whose poses place them
    const LinkGeometry* ga = nullptr;
    const LinkGeometry* gb = nullptr;
    double padding = 0.0;
    int first = 0, last = 0;  // a group: its members, items [first, last)
    int group = -1;           // a member: its group
    bool boxes = false;       // a self pair the rake also tests by the hulls' boxes
  };
  // Fills items_: groups where two bodies' every link pair (or a body's every link) is checked.
  void buildItems();
  // Item k's motion bound for the step dq.
  double itemBound(int k, const double* dq, double obstacle_motion) const noexcept;
  struct Sweep;  // certified.cpp

  void validateOptions() const;
  std::shared_ptr<const Scene> scene_;
  MotionOptions options_;
  Bodies bodies_;
  MotionBound bound_;
  std::vector<Item> items_;  // self groups and their members, other self pairs; then the same for the environment
  // Per self item: the path between its links, and those from each of a's parts to b and from a to each of
  // b's parts (a's first), for the bound's pair().
  std::vector<MotionBound::PairPath> paths_;
  std::vector<std::vector<MotionBound::PairPath>> split_paths_;
  int env_begin_ = 0;        // the first environment item
  // Names this checker's contexts (a copy shares its items, so its serial too).
  std::uint64_t serial_ = detail::nextSerial();
  double obstacle_speed_ = 0.0;   // the fastest obstacle's speed (m/s)
  std::vector<int> quaternions_;  // state entries where a floating joint's quaternion starts (qx)
  // Per self item (group or pair): its pairs' tables (scene/pair_table.h) built with the padding plus twice
  // the contact distance, when every pair has one (else empty): an item they prove apart along the whole
  // segment is not swept.
  std::vector<std::vector<std::shared_ptr<const PairTable>>> item_tables_;
  void buildItemTables();
  // The rake's first test of many self items at once (certified.cpp: Sweep::rakeInLanes): the self items
  // that are not a group's members as pairs of bodies, padded by the contact distance; per item its pair
  // there (−1: none); and the bodies they name, each with the link that places it and its geometry.
  BoundsRows rake_rows_;
  std::vector<int> rake_pair_;
  struct RakeBody {
    int body = 0, frame = 0;
    const LinkGeometry* geometry = nullptr;
  };
  std::vector<RakeBody> rake_bodies_;
  int rake_body_count_ = 0;  // bodies the items name (merged ones included): the rows', a context's per body
  void buildRakeRows();
  // The rake's balls at a level's pieces, all pieces at once in float lanes (certified.cpp: Sweep::placeInLanes):
  // the centres of the bounding balls of the bodies the items name; per body its point (−1: none) and the
  // geometry it was made for.
  PointLanes rake_points_;
  std::vector<int> rake_point_;
  std::vector<const LinkGeometry*> rake_point_geometry_;
  void buildRakePoints();
};

}  // namespace clearway
