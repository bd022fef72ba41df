#pragma once
// What the parts of motion/ share and callers do not: the reference state, rigid bodies, quaternion ends.
#include <clearway/body/proximity.h>
#include <clearway/motion/motion.h>
#include <clearway/scene/scene.h>

#include <Eigen/Core>
#include <array>
#include <vector>

namespace clearway::motion_detail {

// How many states the probe checks.
constexpr int kProbes = 4;

// What one thread's checks of one MotionChecker keep between and within segments (MotionContext holds it).
struct Scratch {
  // The serial of the checker that made it: its pairs, warm starts and slots are that checker's items'
  // (another checker's item k may be other geometry, or geometry that checker owned and freed).
  std::uint64_t owner = 0;
  SceneContext scene;
  std::vector<double> q, dq;
  // The sweep's poses at the last few parameters it placed (items measured at one parameter share them):
  // per slot, the robot's full joint vector, every link's pose, and per link the step its pose was computed
  // for (the sweep's own: a state check in between places the scene context's).
  static constexpr int kPoseSlots = 4;
  std::array<std::vector<double>, kPoseSlots> full_q;
  std::array<std::vector<Pose>, kPoseSlots> poses;
  std::array<std::vector<std::uint64_t>, kPoseSlots> pose_stamp;
  std::vector<double> ends[2];  // the segment's ends as full variable vectors (for the pair tables)
  std::vector<double> safe_until;  // per item: where its coverage starts (Cast: where its shape cast reached)
  // Per item: its motion bound for this segment, computed when first asked (bound_stamp[k] == segment).
  std::vector<double> bound;
  std::vector<std::uint64_t> bound_stamp;
  // Per body of the bound: how far its points move over this segment (MotionBound::link), for the rake.
  std::vector<double> body_bound;
  std::vector<double> first_reach; // per item: how far its first measurement (in the middle) clears, −1: none
  std::vector<int> live;           // the items a segment still has to measure after the rake (certified.cpp)
  // Per item: the rake's settled pieces of this segment (bit i: [i, i + 1] / kRakePieces; certified.cpp),
  // and its scratch: per item the pieces of the current and next level still to test, and the items that
  // have some.
  // The rake's levels (the whole segment, halves, ... : certified.cpp) and a set of its finest pieces.
  static constexpr int kRakeLevels = 5;
  using RakeBits = std::uint16_t;
  std::vector<RakeBits> settled, rake_now, rake_next;
  std::vector<int> rake_items, rake_items_next;
  // Per body of the bound (a link, or a merged body past them): its bounding ball, world frame, at the rake's
  // piece `piece` (placed at most once per piece).
  struct RakeBall {
    Vec3 center = Vec3::Zero();
    double radius = 0.0, norm = 0.0;
    std::uint64_t piece = 0;
    const LinkGeometry* geometry = nullptr;  // the body's geometry it was placed for
  };
  std::vector<RakeBall> rake_balls;
  // The rake's test in lanes (certified.cpp: Sweep::rakeInLanes): per body its ball grown by its motion over
  // the piece, an array per coordinate (MotionChecker::rake_rows_'s layout), and per pair of the rows 1 when apart.
  std::vector<double> rake_x, rake_y, rake_z, rake_r, rake_norm;
  std::vector<std::uint8_t> rake_apart;
  std::uint64_t rake_piece = 0;  // the rake's pieces so far (names each)
  // The rake's ball centres at every piece of a level at once (MotionChecker::rake_points_): per piece its
  // full joint vector, the centres (PointLanes' layout) and the lanes' scratch.
  std::vector<std::vector<double>> rake_lane_q;
  std::vector<float> rake_xyz, rake_lane_scratch;
  // Per item: its contact distance at either end of this segment, set when it first comes within
  // contact_distance (contact_stamp[k] == segment): half an end's clearance where that is below
  // contact_distance (Sweep::contactOf grows it away from the end).
  std::vector<std::array<double, 2>> contact;
  std::vector<std::uint64_t> contact_stamp;
  // Per self item: its bodies and their warm starts, forgotten when the item is first measured on a segment
  // (pair_stamp[k] == segment once it is).
  std::vector<BodyPair> pairs;
  std::vector<std::uint64_t> pair_stamp;
  // Per environment item, its hull's GJK axes against each static obstacle, kept the same way (the
  // item's block starts at env_slot[k − first environment item], −1: none).
  std::vector<SimplexCache> env_cache;
  std::size_t warm_obstacles = 0;  // the static obstacles each block holds (the environment's when made)
  std::vector<int> env_slot;
  std::vector<std::uint64_t> env_stamp;
  // Per self item, the motion bounds of its links' convex parts against the other link for this segment
  // (a's parts, then b's, from split_slot[k]), computed when the item first needs them (split_stamp[k]).
  std::vector<double> split_bound;
  std::vector<int> split_slot;
  std::vector<std::uint64_t> split_stamp;
  double obstacle_motion = 0.0;  // how far moving obstacles travel over the segment (per unit of s)
  std::uint64_t segment = 0;     // segments checked with this context (the stamps above refer to it)
  std::vector<int> pose_path;             // scratch: links whose poses are due, deepest first
  MotionBound::StepCache step_cache;      // pairStep's walks per link at the poses of a slot's step
  std::vector<Pose> end_poses;            // Cast: the link poses at the segment's end
  std::uint64_t step_stamp = 0;
  struct Interval {
    double a, b;     // the parameters to cover
    double witness;  // a parameter ≤ a the item was measured clear at (−1: none)
  };
  std::vector<Interval> intervals;  // scratch: what items have yet to cover
  // A verdict's covers in turns (certified.cpp: Sweep::coverInTurns): per item its own intervals to cover,
  // and the items in the order of their turns (from turn_head on).
  std::vector<std::vector<Interval>> turn_stacks;
  std::vector<int> turns;
  std::size_t turn_head = 0;
  int lead = -1;                    // the item that met the last contact: measured first
  // The probe (probe.cpp): how often it has found a collision lately (a moving average over the segments
  // it ran on), and the segments since it last ran.
  double probe_rate = 1.0;
  int probe_skipped = 0;
  // Per probe state: how often it was the first to collide lately (a decaying count); the states are
  // checked in the order of these counts.
  std::array<double, kProbes> probe_hits{};
  std::vector<double> probe_states;  // the probe's states, one after another (kProbes·dimension)
};

// A verdict-only check's first look (probe.cpp): the states at s = 1, 1/2, 1/4 and 3/4 (those that collided
// first most often lately before the others), each checked as the validity checker checks states, until one
// collides (Scene::anyCollides). True, with r filled (a contact at that s,
// the state's report), when one collides: the segment is then not free whatever the items would measure.
// Only where it has lately paid for itself (planners' segments often collide; a path's or a benchmark's
// seldom do).
bool probeCollides(const MotionChecker& checker, const double* q0, double t0, const double* q1, double t1,
                   Scratch& ctx, MotionResult& r) noexcept;

// True when the state at s of q0 → q1 (at time t) collides as the validity checker sees it; `report` then
// says what. It overwrites ctx.q and ctx.scene's poses (probe.cpp).
bool stateCollides(const MotionChecker& checker, const double* q0, const double* q1, double s, double t, Scratch& ctx,
                   CollisionReport& report) noexcept;

// A state inside the scene's bounds (their midpoints) with unit quaternions, where the poses are defined.
inline std::vector<double> referenceState(const Scene& scene) {
  const RobotModel& model = scene.robot();
  std::vector<double> q(scene.dimension());
  for (int i = 0; i < scene.dimension(); ++i) {
    const double lo = scene.lower(i), hi = scene.upper(i);
    q[i] = std::isfinite(lo) && std::isfinite(hi) ? 0.5 * (lo + hi) : std::isfinite(lo) ? lo : std::isfinite(hi) ? hi : 0.0;
    const int v = scene.groupVariables()[i];
    const Joint& joint = model.joint(model.variables()[v].joint);
    if (joint.type == JointType::Floating && v >= joint.first_variable + 3) q[i] = v == joint.first_variable + 6 ? 1.0 : 0.0;
  }
  return q;
}

// The unit quaternions of q0[0..3] and q1[0..3], the second on the first's side (the short arc).
inline void alignedUnit(const double* q0, const double* q1, Eigen::Vector4d& a, Eigen::Vector4d& b) noexcept {
  a = Eigen::Vector4d(q0[0], q0[1], q0[2], q0[3]);
  b = Eigen::Vector4d(q1[0], q1[1], q1[2], q1[3]);
  a.normalize();
  b.normalize();
  if (a.dot(b) < 0.0) b = -b;
}

}  // namespace clearway::motion_detail
