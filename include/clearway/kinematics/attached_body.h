#pragma once
// Attached bodies: a grasped object or a tool, rigidly fixed to a link (MoveIt's AttachedCollisionObject).
// Each becomes a link of its own, child of its link through a fixed joint, so that kinematics, self- and
// environment collision, reports and the certified motion bound treat it as any other link; it may touch
// its touch links (declared like MoveIt's touch_links) and the link it hangs from.
#include <clearway/kinematics/robot_model.h>

#include <string>
#include <vector>

namespace clearway {

/// A rigid body fixed to a link.
struct AttachedBody {
  std::string name;  ///< the new link's name (unique in the robot)
  int link = -1;     ///< the link it is fixed to
  Pose pose;         ///< its frame in the link's frame
  /// Its geometry in its own frame: a primitive (mesh = -1) or a mesh (an index into `meshes` below).
  CollisionElement element;
  std::vector<int> touch_links;  ///< links it may touch (besides `link`)
};

/// The model with each body added as a link (after the model's own, in order) under a fixed joint named
/// "`<name>_joint`"; `meshes` holds the bodies' meshes, which their elements index. The state vector is
/// unchanged. Pairs of a body with its touch links are disabled with reason "Touch". Throws
/// std::invalid_argument for a name already in use, a link or touch link out of range, or a mesh index
/// out of range.
RobotModel attachBodies(const RobotModel& model, const std::vector<AttachedBody>& bodies,
                        const std::vector<TriangleMesh>& meshes = {});

/// The model without the named bodies: each must be a leaf link hanging from a fixed joint (as
/// attachBodies makes them). Their links, joints, disabled pairs and the meshes no other link uses go;
/// the other links keep their order, names and elements. Throws std::invalid_argument for a name that is
/// not such a link.
RobotModel detachBodies(const RobotModel& model, const std::vector<std::string>& names);

}  // namespace clearway
