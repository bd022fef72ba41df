#pragma once
// One state's link poses in SIMD lanes (kinematic_lanes.cpp): computeLinkPoses' engine.
#include <clearway/kinematics/robot_model.h>

namespace clearway::detail {

/// Computes the poses of links[k] for k < count (first + k when links is null), in that order, each after
/// its parent (earlier in the list, or already in poses): equal bit for bit to computeLinkPose for each, on
/// every SIMD target (the target chosen at run time, as KinematicLanes'). `poses` holds every link's pose.
void computeLinksInLanes(const RobotModel& model, const double* q, Pose* poses, const int* links, int first,
                         int count) noexcept;

}  // namespace clearway::detail
