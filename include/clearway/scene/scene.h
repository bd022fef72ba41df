#pragma once
// A planning scene: a robot (URDF, SRDF, the planned group, held joints, allowed pairs, padding), its
// environment, and the effects it calls for. A scene computes only what it declares: without
// `environment` no obstacle or voxel is looked at, without `clearance` no distance is computed, without
// `moving` there is no time. Immutable once built; queries are thread-safe given one SceneContext per
// thread (or through the convenience overloads, which keep one per thread themselves).
#include <clearway/environment/environment.h>
#include <clearway/kinematics/kinematic_lanes.h>
#include <clearway/kinematics/robot_model.h>
#include <clearway/load/input_limits.h>
#include <clearway/load/robot_loader.h>
#include <clearway/per_thread.h>
#include <clearway/scene/collision_filter.h>
#include <clearway/scene/scene_file.h>
#include <clearway/scene/self_collision.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace clearway {

/// Why a state is not free.
struct CollisionReport {
  ///@{
  /// None: free; Self: two robot links; Environment: a link and an obstacle or voxel; Invalid: not a
  /// valid state (non-finite, out of bounds), no geometry looked at.
  enum class Kind { None, Self, Environment, Invalid } kind = Kind::None;
  ///@}
  int link = -1;        ///< the robot link (the first of the pair for Self)
  int other_link = -1;  ///< Self: the second link
  EnvironmentHit hit;   ///< Environment: what the link touched
};

/// Work done by queries of one context (cumulative), to show what a scene pays for what it asks.
struct SceneCounters {
  long long states = 0;         ///< isFree calls
  long long invalid_states = 0; ///< states rejected before any geometry (NaN, out of bounds)
  long long self_pair_tests = 0;   ///< self link pairs tested (pairs a pair table clears are not counted)
  EnvironmentCounters environment;  ///< the environment's work for these queries
  long long clearance_queries = 0;  ///< clearance calls that computed (valid state, scene with clearance)
};

namespace scene_detail {
struct SceneScratch;  // scene_scratch.h
}  // namespace scene_detail

/// One thread's scratch for a scene's queries (joint vector, link poses, the self checker's context, the
/// links' enclosing balls, the lanes' kinematics): made by Scene::makeContext(), then reused; queries
/// allocate nothing in it. Movable, not copyable; a default-made one holds nothing (a query given it
/// answers Invalid).
class SceneContext {
 public:
  SceneContext() noexcept;
  ///@{
  /// Takes the other context's scratch, leaving that one empty.
  SceneContext(SceneContext&&) noexcept;
  SceneContext& operator=(SceneContext&&) noexcept;
  ///@}
  ~SceneContext();

  /// Every link's world pose at the state the context's last query (or Scene::computePoses) placed. A
  /// query that needs no poses places none: a state out of bounds, or one a pair table proves colliding.
  const std::vector<Pose>& poses() const noexcept;
  /// The robot's full joint vector at that state (group values, held values, defaults).
  const std::vector<double>& jointValues() const noexcept;
  ///@{
  /// This context's work since it was made (the caller may reset it).
  SceneCounters& counters() noexcept;
  const SceneCounters& counters() const noexcept;
  ///@}

 private:
  friend class Scene;
  explicit SceneContext(std::unique_ptr<scene_detail::SceneScratch> scratch) noexcept;
  std::unique_ptr<scene_detail::SceneScratch> scratch_;
};

/// The robot a description names (URDF, SRDF, meshes → trees and hulls), with its attached bodies as links
/// of their own; options.package_paths are searched before the description's. Throws LoadError.
std::shared_ptr<const RobotGeometry> loadRobotGeometry(const SceneDescription& description,
                                                       const LoadOptions& options = {});
/// The environment a description names (obstacles, meshes read with options.mesh, OctoMap). Throws LoadError
/// naming the scene file and the obstacle's key; the meshes' warnings (a mesh that is not closed, ...) are
/// appended to `warnings` when given, in the same form.
std::shared_ptr<const Environment> loadEnvironment(const SceneDescription& description, const LoadOptions& options = {},
                                                   std::vector<std::string>* warnings = nullptr);

/// How a scene checks geometry (not part of the scene file: a choice of the caller).
struct SceneOptions {
  GeometryMode mode = GeometryMode::Mesh;  ///< hulls only, or hulls then triangles (exact)
  Tolerances tolerances;                   ///< the narrow phase's, for every query of the scene
  /// How robot and mesh files are read (package:// folders searched before the scene file's own; the
  /// COLLADA up axis).
  LoadOptions load;
  /// Tabulate the self pairs moved by one or two joints, or three whose lowest turns the lower link, at load
  /// (scene/pair_table.h): same verdicts, faster queries, a longer load. None when the checks leave out self.
  bool pair_tables = true;
  /// Seconds the tables may take to build (SelfCollisionOptions::table_seconds): none by default.
  double pair_table_seconds = std::numeric_limits<double>::infinity();
};

/// A robot in its environment, asked whether states and segments are free. Immutable once built;
/// const queries are thread-safe with one SceneContext per thread (or the per-thread overloads).
class Scene {
 public:
  /// Loads the robot and environment a description names and checks that they fit together: every
  /// group and hold joint exists, held joints are not in the group, allowed links exist, start and goal
  /// have the group's length. Throws LoadError naming the scene file and key (or the robot file). The
  /// obstacles' mesh warnings join description().warnings.
  explicit Scene(const SceneDescription& description, const SceneOptions& options = {});
  /// The scene with a robot already loaded (shared with other scenes) and an environment built in code.
  Scene(const SceneDescription& description, std::shared_ptr<const RobotGeometry> robot,
        std::shared_ptr<const Environment> environment, const SceneOptions& options = {});

  /// This scene over another environment (an edited one): the robot, its self pairs and everything
  /// else are shared or copied, and only what depends on the obstacles is computed again (which links
  /// meet them at every state, the static links' collision and clearance). The description still lists
  /// the obstacles the scene was first built from.
  std::shared_ptr<const Scene> withEnvironment(std::shared_ptr<const Environment> environment) const;

  /// This scene with a body attached to a robot link, as a scene file's robot.attached entry attaches it
  /// (a mesh read from body.body.mesh_file with `load`): a new robot that shares every other link's
  /// geometry. Throws std::invalid_argument for an unknown link or touch link, a name a link already has,
  /// a body reaching beyond kMaxInputLength of its link, or a mesh that cannot be read.
  std::shared_ptr<const Scene> withAttached(const SceneDescription::AttachedSpec& body, const LoadOptions& load = {}) const;
  /// This scene without the named attached body (one attached by withAttached or by the scene file), and
  /// without the allowed pairs (robot.allow) that name it. Throws std::invalid_argument when no attached
  /// body has that name.
  std::shared_ptr<const Scene> withoutAttached(const std::string& name) const;

  /// parseSceneFile + the constructor.
  static std::shared_ptr<const Scene> load(const std::string& path, const SceneOptions& options = {});

  /// The description the scene was built from (withEnvironment keeps the first one's obstacles).
  const SceneDescription& description() const noexcept { return description_; }
  /// description().name.
  const std::string& name() const noexcept { return description_.name; }
  /// What the scene checks (description().effects).
  const Effects& effects() const noexcept { return description_.effects; }
  /// The robot model, attached bodies included as links.
  const RobotModel& robot() const noexcept { return geometry_->model(); }
  /// The robot's collision geometry, link by link.
  const RobotGeometry& geometry() const noexcept { return *geometry_; }
  /// The same geometry, to share with another Scene of the same robot.
  const std::shared_ptr<const RobotGeometry>& geometryPtr() const noexcept { return geometry_; }
  /// The obstacles and voxels the scene is checked against.
  const Environment& environment() const noexcept { return *environment_; }
  /// The environment, to share with another Scene over the same obstacles (another mode, say).
  const std::shared_ptr<const Environment>& environmentPtr() const noexcept { return environment_; }
  /// The self-collision checker: the link pairs checked, with their pair tables.
  const SelfCollision& selfCollision() const noexcept { return self_; }
  /// Which link pairs are never checked, and why.
  const CollisionFilter& filter() const noexcept { return filter_; }
  /// The options the scene was built with.
  const SceneOptions& options() const noexcept { return options_; }

  /// The number of planned variables (the length of a state).
  int dimension() const noexcept { return static_cast<int>(group_variables_.size()); }
  /// Index in the robot's joint vector of each state entry.
  const std::vector<int>& groupVariables() const noexcept { return group_variables_; }
  ///@{
  /// Limits of each state entry: the joint's, or the scene's robot.bounds (±infinity when unbounded). A
  /// state holds values within them (to kJointLimitTolerance) and within ±kMaxJointValue.
  double lower(int i) const noexcept { return lower_[i]; }
  double upper(int i) const noexcept { return upper_[i]; }
  ///@}
  ///@{
  /// The range a valid state's entry i lies in: the limits widened by kJointLimitTolerance, within ±kMaxJointValue.
  double validLower(int i) const noexcept { return valid_lower_[i]; }
  double validUpper(int i) const noexcept { return valid_upper_[i]; }
  ///@}
  /// Links with geometry whose pose depends on the state (others never move, so self pairs among
  /// them never change; they still meet obstacles).
  const std::vector<int>& movingLinks() const noexcept { return moving_links_; }

  /// Links checked against the environment at every state (static links are checked once, at construction).
  const std::vector<int>& environmentLinks() const noexcept { return env_links_; }
  /// Per link: the link nearest the root that it moves rigidly with at every state (joined to it by joints
  /// the group does not move); the link itself when the group moves its own joint, and the root for links
  /// that never move.
  const std::vector<int>& rigidAnchors() const noexcept { return rigid_anchor_; }
  /// Metres of padding around link i.
  double linkPadding(int i) const noexcept { return link_padding_[i]; }
  /// A collision no state can undo (between links that never move or move as one rigid body, or a static
  /// link and a static obstacle), found at construction; kind None when there is none.
  const CollisionReport& staticCollision() const noexcept { return static_collision_; }

  /// A context for this scene (allocates: make one per thread and reuse it).
  SceneContext makeContext() const;

  /// Places the state in the context (its jointValues() and poses()); no checks.
  void computePoses(const double* state, SceneContext& context) const noexcept;

  /// True when the state is within bounds and finite, and each floating joint's quaternion is not zero
  /// (then `why` is untouched), else false and `why` names the entry, its value and the bound.
  bool validState(const double* state, std::string* why = nullptr) const;

  /// True when the state is valid and free of every declared collision effect at time t (t is used
  /// only when the scene declares `moving`). `report` (optional) says what collided (the first collision found; the link
  /// that last met an obstacle in this context is tried first).
  bool isFree(const double* state, SceneContext& context, CollisionReport* report = nullptr,
              double t = 0.0) const noexcept;
  /// The same with this thread's own context.
  bool isFree(const std::vector<double>& state, CollisionReport* report = nullptr, double t = 0.0) const;
  /// isFree of `count` states at once, state s at states + s·dimension(): free[s] is the verdict isFree
  /// gives it (a batch changes no verdict), at time t. The kinematics of several states run together in
  /// SIMD lanes (KinematicLanes); then each state's links meet the obstacles and each other.
  void areFree(const double* states, int count, SceneContext& context, bool* free, double t = 0.0) const noexcept;

  /// The first colliding state among `count` states (state s at states + s·dimension(), at time times[s], or
  /// 0 without times): its index, with `report` (optional) saying what collided, or −1 when every state is
  /// free (each verdict as isFree gives it). For a segment's probe: each state is checked in full before the
  /// next, and the states after the first colliding one are not checked.
  int anyCollides(const double* states, int count, SceneContext& context, CollisionReport* report = nullptr,
                  const double* times = nullptr) const noexcept;

  /// Signed clearance: the distance from the robot to the nearest declared hazard (environment and/or
  /// self) minus padding when free; when something touches, minus the deepest penetration (EPA between
  /// convex hulls, which contain the links: never shallower than the exact depth). NaN when the scene
  /// does not declare `clearance`, the state is invalid or a query failed. `lower_bound` (optional)
  /// receives a certified lower bound.
  double clearance(const double* state, SceneContext& context, double* lower_bound = nullptr,
                   double t = 0.0) const noexcept;

  /// "link a / link b", "link / obstacle NAME", "link / voxel", "invalid state" for a report.
  std::string describe(const CollisionReport& report) const;

 private:
  // The description with its environment's load warnings, and that environment (Scene(description, options)).
  using Described = std::pair<SceneDescription, std::shared_ptr<const Environment>>;
  Scene(Described loaded, const SceneOptions& options);
  void init();
  void initEnvironment();  // the part of init() that depends on the environment
  SceneContext& threadContext() const;
  bool withinBounds(const double* state) const noexcept;  // the cheap check of every query (no reason)
  // A moment obstacles may be placed at: finite and within ±kMaxTime (NaN fails).
  static bool withinTime(double t) noexcept { return std::abs(t) <= kMaxTime; }
  // A floating joint's quaternion (qx, qy, qz, qw) that the kinematics can normalise: its squares do not
  // add up to 0, as validateJointVector asks (a zero quaternion's poses are NaN).
  static bool rotates(const double* q) noexcept { return q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] > 0.0; }
  // True when the context fits this robot (its joint vector and poses); it then holds this scene's held
  // values and no other scene's lead.
  bool adopt(scene_detail::SceneScratch& ctx) const noexcept;
  // computePoses and isFree, given the context's scratch (which adopt() accepted).
  void place(const double* state, scene_detail::SceneScratch& ctx) const noexcept;
  bool checkState(const double* state, scene_detail::SceneScratch& ctx, CollisionReport* report,
                  double t) const noexcept;
  // isFree's geometry, once the poses of the state's links (and its full joint vector q) are known.
  bool posedFree(const Pose* poses, const double* q, scene_detail::SceneScratch& ctx, CollisionReport& r,
                 double t) const noexcept;
  // Its two halves: the environment (placing the enclosing balls where the clearance grid is read, which
  // balls_placed then says), and the self pairs.
  bool environmentFree(const Pose* poses, scene_detail::SceneScratch& ctx, CollisionReport& r, double t,
                       bool& balls_placed) const noexcept;
  bool selfFree(const Pose* poses, const double* q, scene_detail::SceneScratch& ctx, CollisionReport& r,
                bool balls_placed) const noexcept;
  // True when the context has kinematic lanes for this robot (areFree, anyCollides; else one state at a time).
  bool lanesFit(const scene_detail::SceneScratch& ctx) const noexcept;
  // A state into lane `lane` of the context's lanes: its full joint vector and where its poses go.
  void toLane(const double* state, int lane, scene_detail::SceneScratch& ctx, const double** lane_q,
              Pose** lane_poses) const noexcept;

  SceneDescription description_;
  SceneOptions options_;
  std::shared_ptr<const RobotGeometry> geometry_;
  std::shared_ptr<const Environment> environment_;
  CollisionFilter filter_;
  SelfCollision self_;
  std::vector<int> group_variables_;
  std::vector<double> lower_, upper_;  // per state entry
  // What a state entry may hold: the limits widened by kJointLimitTolerance, within ±kMaxJointValue.
  std::vector<double> valid_lower_, valid_upper_;
  std::vector<double> base_q_;  // held values and defaults; group entries overwritten per query
  // Which scene a context serves: a context made (or last used) by another scene of this robot holds that
  // scene's held values in its joint vectors, and its lead names that scene's links (adopt() resets them).
  std::uint64_t serial_ = 0;
  std::vector<int> quaternions_;  // the state index of each floating joint's qx (qy, qz, qw follow)
  std::vector<int> moving_links_, env_links_;
  std::vector<int> rigid_anchor_;  // per link: see rigidAnchors()
  // The links checked against the environment, by rigid body (links joined by joints the group does not
  // move: a gripper's links on its flange): env_order_[first, first + count) are a body's members (indices
  // in env_links_), and a body of several has one ball in its anchor's frame that holds every member's
  // bounding ball, so the obstacles' boxes or the clearance grid clear them all with one test.
  struct EnvBody {
    int anchor = -1;
    Vec3 center = Vec3::Zero();  // anchor frame
    double radius = 0.0;
    double padding = 0.0;  // the largest of its members'
    int first = 0, count = 0;
  };
  std::vector<EnvBody> env_bodies_;
  std::vector<int> env_order_;
  std::vector<double> link_padding_;
  CollisionReport static_collision_;  // a collision no state can undo, found at construction
  CollisionReport self_static_collision_;  // the part of it among the robot's own links
  double static_clearance_ = std::numeric_limits<double>::infinity();  // static links to static obstacles
  double static_clearance_lower_ = std::numeric_limits<double>::infinity();
  PerThread<SceneContext> thread_context_;  // each thread's context for the overloads without one
};

}  // namespace clearway
