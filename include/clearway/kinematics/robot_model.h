#pragma once
// The robot as forward kinematics and collision checking see it: an immutable tree of links in
// topological order (root first), the joints between them, each link's collision elements, and the
// link pairs a user has declared never to check. Built once by loadRobot (or by hand in tests), then
// shared read-only by every query and thread.
#include <clearway/shape/triangle_mesh.h>
#include <clearway/math.h>
#include <clearway/shape/shape.h>

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace clearway {

/// The URDF joint types. Mimic joints are joints of a one-variable type with a Mimic set.
enum class JointType { Fixed, Revolute, Continuous, Prismatic, Planar, Floating };

/// "fixed", "revolute", ... as written in URDF.
const char* jointTypeName(JointType type) noexcept;

/// How many entries of the joint vector q a joint of this type owns: fixed 0; revolute, continuous and
/// prismatic 1; planar 3 (x, y, θ); floating 7 (x, y, z, qx, qy, qz, qw).
int jointVariableCount(JointType type) noexcept;

/// A joint whose value follows another's: value = multiplier · q[leader] + offset.
struct Mimic {
  int joint = -1;  ///< the leader joint (itself not a mimic, one variable); -1 when the joint is not a mimic
  double multiplier = 1.0;  ///< finite (RobotModel checks)
  double offset = 0.0;      ///< rad or m, finite (RobotModel checks)
};

/// A joint of the kinematic tree, as read from the URDF (the frame, axis and limits in SI units).
struct Joint {
  std::string name;                   ///< unique within the robot
  JointType type = JointType::Fixed;  ///< its URDF type (a mimic keeps its own)
  int parent_link = -1;               ///< index into RobotModel::links()
  int child_link = -1;                ///< index into RobotModel::links()
  /// The joint frame in the parent link's frame (the URDF `<origin>`).
  Pose origin;
  /// Unit axis in the joint frame: rotation axis (revolute, continuous), direction of travel (prismatic),
  /// plane normal (planar). Unused for fixed and floating joints.
  Vec3 axis = Vec3::UnitX();
  ///@{
  /// Position limits (rad or m) of revolute and prismatic joints; ±infinity for the other types.
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  ///@}
  /// Velocity limit (rad/s or m/s); infinity when the URDF gives none.
  double velocity = std::numeric_limits<double>::infinity();
  Mimic mimic;  ///< the leader this joint follows (mimic.joint = -1: none)
  /// Index of the joint's first entry in q; -1 for fixed and mimic joints (they own no entry).
  /// Assigned by RobotModel in joint order.
  int first_variable = -1;

  /// True when the joint follows a leader (and owns no entry of q).
  bool isMimic() const noexcept { return mimic.joint >= 0; }
};

/// One `<collision>` element of a link: a primitive or a triangle mesh, placed by origin in the link frame.
struct CollisionElement {
  /// The element frame in the link frame (the URDF `<collision><origin>`).
  Pose origin;
  /// Box, Sphere, Cylinder or Capsule (URDF cylinders and capsules lie along local z); empty for a mesh.
  std::optional<Shape> primitive;
  /// Index into RobotModel::meshes() when the element is a mesh (scaled already); -1 for a primitive.
  int mesh = -1;
};

/// A link of the kinematic tree: its name, its parent joint and its collision geometry (link frame).
struct Link {
  std::string name;  ///< unique within the robot
  /// The joint whose child this link is; -1 for the root.
  int parent_joint = -1;
  /// Possibly several, possibly none (a link without collision geometry is never checked).
  std::vector<CollisionElement> collisions;
};

/// One entry of the joint vector q.
struct JointVariable {
  std::string name;  ///< the joint's name; planar and floating add "/x", "/y", "/theta", "/qx", ...
  int joint = -1;    ///< the joint owning the entry, index into RobotModel::joints()
  ///@{
  double lower = -std::numeric_limits<double>::infinity();  ///< ±infinity when unbounded
  double upper = std::numeric_limits<double>::infinity();
  ///@}
};

/// A link pair never to be checked, with its SRDF reason ("Adjacent", "Never", "Default", "Always", ...).
struct DisabledCollision {
  ///@{
  int link_a = -1, link_b = -1;  ///< link indices, link_a < link_b
  ///@}
  std::string reason;  ///< as the SRDF gives it (may be empty)
};

namespace detail {
/// One link's step of forward kinematics, folded at load: its parent joint's frame and motion with
/// the lookups done (forward_kinematics.cpp reads it; nothing else should).
struct KinematicStep {
  enum class Kind : std::uint8_t { Root, Fixed, TurnZ, Turn, Slide, Other };
  Kind kind = Kind::Root;
  int parent = -1;         ///< the parent link
  int variable = -1;       ///< the q entry the joint's value comes from (a mimic's leader's)
  double multiplier = 1.0, offset = 0.0;  ///< value = multiplier · q[variable] + offset (mimics only)
  bool mimic = false;
  double axis_sign = 1.0;  ///< TurnZ: the axis is axis_sign · z
  Pose origin;
  Vec3 axis = Vec3::UnitX();  ///< Turn: the joint's axis; Slide: origin.R · axis (slides along it before parent.R)
  /// The joint's value in q (a mimic's: its leader's times the multiplier, plus the offset).
  double value(const double* q) const noexcept { return mimic ? multiplier * q[variable] + offset : q[variable]; }
};
}  // namespace detail

/// A robot, checked and frozen: links in topological order, joints, the joint vector's variables, meshes
/// and disabled pairs. Immutable, so one model may be shared by any number of threads.
class RobotModel {
 public:
  /// Checks and freezes a robot. Links must be in topological order (link 0 the root, without parent
  /// joint; every other link the child of exactly one joint whose parent link comes earlier); joint
  /// indices, mimic leaders and mesh indices must be in range; mimic leaders must own one variable;
  /// axes of revolute, continuous, prismatic and planar joints are normalised (a zero axis is an error).
  /// Assigns each joint's first_variable in joint order. Throws std::invalid_argument on any violation.
  RobotModel(std::string name, std::vector<Link> links, std::vector<Joint> joints, std::vector<TriangleMesh> meshes,
             std::vector<DisabledCollision> disabled = {}, std::vector<std::string> load_warnings = {});

  /// The robot's name (the URDF's robot name).
  const std::string& name() const noexcept { return name_; }
  /// The number of links (≥ 1).
  int linkCount() const noexcept { return static_cast<int>(links_.size()); }
  /// The number of joints (fixed and mimic ones included).
  int jointCount() const noexcept { return static_cast<int>(joints_.size()); }
  /// The length of the joint vector q.
  int variableCount() const noexcept { return static_cast<int>(variables_.size()); }

  /// The links in topological order (links()[0] is the root).
  const std::vector<Link>& links() const noexcept { return links_; }
  /// The joints, each first_variable assigned.
  const std::vector<Joint>& joints() const noexcept { return joints_; }
  /// The entries of q, in order.
  const std::vector<JointVariable>& variables() const noexcept { return variables_; }
  /// Link i, 0 ≤ i < linkCount() (not checked).
  const Link& link(int i) const { return links_[i]; }
  /// Joint i, 0 ≤ i < jointCount() (not checked).
  const Joint& joint(int i) const { return joints_[i]; }
  /// The parent link of link i (-1 for the root).
  int parentLink(int i) const { return links_[i].parent_joint < 0 ? -1 : joints_[links_[i].parent_joint].parent_link; }

  /// The triangle meshes that collision elements index (one per distinct file and scale).
  const std::vector<TriangleMesh>& meshes() const noexcept { return meshes_; }
  /// SRDF disable_collisions pairs, sorted by (link_a, link_b), without duplicates.
  const std::vector<DisabledCollision>& disabledCollisions() const noexcept { return disabled_; }
  /// What the loader found worth telling ("FILE: ELEMENT: REASON"); callers print them.
  const std::vector<std::string>& loadWarnings() const noexcept { return load_warnings_; }

  ///@{
  /// Index of the link / joint of that name, -1 if none. Hash lookups: for load time, not for queries.
  int linkIndex(const std::string& name) const;
  int jointIndex(const std::string& name) const;
  ///@}
  /// Index in q of the variable of that name (a one-variable joint's name, or "joint/x" etc.), -1 if none.
  int variableIndex(const std::string& name) const;
  /// Link i's step of forward kinematics (computeLinkPose); step 0 is the root's.
  const detail::KinematicStep& kinematicStep(int i) const noexcept { return steps_[static_cast<std::size_t>(i)]; }

 private:
  std::string name_;
  std::vector<Link> links_;
  std::vector<Joint> joints_;
  std::vector<JointVariable> variables_;
  std::vector<TriangleMesh> meshes_;
  std::vector<DisabledCollision> disabled_;
  std::vector<std::string> load_warnings_;
  std::unordered_map<std::string, int> link_index_, joint_index_, variable_index_;
  std::vector<detail::KinematicStep> steps_;
};

/// Pairs (a, b), a < b, of links that both have collision geometry and are adjacent as MoveIt's Setup
/// Assistant defines it: joined by a joint, or by a chain of joints whose intermediate links all lack
/// collision geometry. Sorted. Such pairs touch by construction and are never checked.
std::vector<std::pair<int, int>> adjacentLinkPairs(const RobotModel& model);

}  // namespace clearway
