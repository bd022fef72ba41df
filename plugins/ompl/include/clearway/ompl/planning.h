#pragma once
// One planning query, start → goal on a scene, as `clearway plan` runs it and Python's clearway.plan: an
// OMPL geometric planner with Clearway's validity checker and certified motion validator, the path
// simplified and then checked again segment by segment with the certified check, so that a path
// returned as certified is one. The tool and the Python module call this one function, so the same seed
// gives them the same path.
#include <clearway/motion/motion.h>
#include <clearway/scene/scene.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace clearway {

/// The OMPL geometric planners plan() knows, by their OMPL class names (RRTConnect first).
const std::vector<std::string>& plannerNames();

/// What plan() is asked.
struct PlanRequest {
  std::string planner = "RRTConnect";  ///< one of plannerNames()
  double time = 10.0;                  ///< seconds the planner may take, in (0, kMaxPlanTime]
  /// OMPL's random seed (0 plans as 1, which OMPL takes for 0); none: OMPL's own sequence goes on (from the clock).
  std::optional<std::uint64_t> seed;
  bool simplify = true;       ///< shorten the path with OMPL's simplifier before certifying it
  std::vector<double> start;  ///< the start state (scene.dimension() values); empty: the scene file's
  std::vector<double> goal;   ///< the goal state; empty: the scene file's
};

/// The largest time limit plan() takes, in seconds: OMPL's deadline, a clock time point, overflows near 7.5e9 s.
inline constexpr double kMaxPlanTime = 1e6;

/// How a query ended; only Solved returns a path.
enum class PlanStatus {
  Solved,          ///< a path from start to goal, every segment certified free
  NoPath,          ///< the planner found no exact solution within the time
  NotCertified,    ///< the simplified path has a segment the certified check does not call free
  StartColliding,  ///< the start is in collision
  GoalColliding,   ///< the goal is in collision
  StartStuck,      ///< the start is free but no motion leaves it (a touch within the narrow phase's band)
  GoalStuck,       ///< the same at the goal
};

/// The path and the statistics `clearway plan` prints.
struct PlanResult {
  PlanStatus status = PlanStatus::NoPath;  ///< how the query ended
  std::string message;      ///< why it is not Solved, one line naming what collides; empty when Solved
  std::string ompl_status;  ///< the planner's ompl::base::PlannerStatus as text ("Exact solution", "Timeout", ...)
  int dimension = 0;        ///< values per state
  /// The states, one after another (dimension values each); set when a path was found, certified or not.
  /// The angles of continuous and planar joints are unwrapped along the path (each within π of the one
  /// before, so beyond [−π, π) where the path turns past it): each straight segment turns the short way.
  std::vector<double> path;
  double length = 0.0;            ///< the path's length in OMPL's state space metric
  double solve_seconds = 0.0;     ///< wall time of the planner's solve
  double simplify_seconds = 0.0;  ///< wall time of the simplification (0 without it)
  ///@{
  std::uint64_t state_checks = 0, motion_checks = 0;  ///< checker calls of the whole query
  ///@}
  ///@{
  double state_check_seconds = 0.0, motion_check_seconds = 0.0;  ///< time spent in them (all threads)
  ///@}
  ///@{
  std::uint64_t simplify_state_checks = 0, simplify_motion_checks = 0;  ///< the calls made by the simplifier
  ///@}
  std::vector<std::size_t> uncertified_segments;  ///< NotCertified: the segments (i → i+1) not certified free

  /// True when status is Solved: path holds a certified path.
  bool solved() const noexcept { return status == PlanStatus::Solved; }
  /// The number of states in path.
  std::size_t stateCount() const noexcept { return dimension > 0 ? path.size() / dimension : 0; }
};

/// A short name of a status ("solved", "no path", "not certified", "start colliding", ...).
const char* toString(PlanStatus status) noexcept;

/// Plans request.start → request.goal on scene (its OMPL space: makeStateSpace). A start or goal within
/// validState's tolerance past a limit is planned from the limit. Throws std::invalid_argument naming the
/// field for a bad request: an unknown planner, a time outside (0, kMaxPlanTime] or NaN, a missing or
/// invalid start or goal, a scene OMPL cannot plan in (moving obstacles, an unbounded planar or floating
/// joint). A seeded query runs alone in the process (OMPL's seeds come from one process-wide generator;
/// unseeded queries run side by side), so with a single-threaded planner the same seed gives the same
/// path on every call. Thread-safe.
PlanResult plan(const std::shared_ptr<const Scene>& scene, const PlanRequest& request);
/// The same on checker's scene, its segments checked as checker checks them (its options; its stop
/// condition, if any, is asked beside the time limit): a checker built once serves every query, where the
/// overload above builds one per query (up to a third of a second for a robot of large meshes). Throws
/// as the overload above, and for a Sampled checker (it certifies nothing).
PlanResult plan(const std::shared_ptr<const MotionChecker>& checker, const PlanRequest& request);

}  // namespace clearway
