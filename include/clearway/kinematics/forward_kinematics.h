#pragma once
// Forward kinematics: the world pose of every link for a joint vector q, in one pass over the links in
// topological order. The root link's frame is the world frame.
//
// Joint motion, in the joint frame (the joint's <origin> in its parent link):
//   revolute, continuous  rotation by q about the axis
//   prismatic             translation by q along the axis
//   planar                translation x·u + y·v, then rotation by θ about the axis (the plane normal);
//                         u, v complete the axis to a right-handed frame: for axis z they are x and y
//   floating              translation (x, y, z), rotation by the quaternion (qx, qy, qz, qw), normalised
//   mimic                 as its type, with value multiplier · q[leader] + offset
#include <clearway/kinematics/robot_model.h>

#include <string>

namespace clearway {

/// Slack (rad or m) allowed beyond a joint limit by validateJointVector: planners interpolate and
/// round, and a value a hair outside a limit is not a different configuration.
constexpr double kJointLimitTolerance = 1e-9;

/// Writes the world pose of link i to link_poses[i] for i < model.linkCount(). q holds
/// model.variableCount() values. No allocation, no check: validate q first where it comes from outside
/// (a NaN in q gives NaN poses, which collision queries report as NotConverged/InvalidInput).
void computeLinkPoses(const RobotModel& model, const double* q, Pose* link_poses) noexcept;

/// Writes link i's world pose (i ≥ 1) from its parent link's, which must be in link_poses already: one
/// step of computeLinkPoses, for callers that need a few links only.
void computeLinkPose(const RobotModel& model, const double* q, Pose* link_poses, int i) noexcept;

/// Writes the poses of links[0 .. count), in that order, each from its parent's (earlier in the list or
/// already in link_poses, which holds every link's): the bits computeLinkPose gives, in SIMD lanes where
/// the CPU has four of doubles (a pose's rows side by side, four joints' sines at once).
void computeLinkPoses(const RobotModel& model, const double* q, Pose* link_poses, const int* links, int count) noexcept;

/// The frames u, v of a planar joint's plane: with the unit axis n, (u, v, n) is right-handed.
void planarBasis(const Vec3& axis, Vec3* u, Vec3* v) noexcept;

/// True when every entry of q is finite, every bounded variable is within its limits (with
/// kJointLimitTolerance; continuous joints and planar/floating translations are unbounded) and every
/// floating joint's quaternion is non-zero. Otherwise false, and *why (when given) names the variable,
/// its value and the limit broken.
bool validateJointVector(const RobotModel& model, const double* q, std::string* why = nullptr);

}  // namespace clearway
