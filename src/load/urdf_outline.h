#pragma once
// A first pass over a URDF with tinyxml2, before urdfdom builds the model. urdfdom reports problems
// through console_bridge without naming lines, accepts some broken files (a loop in the kinematic tree,
// inverted limits) and rejects capsules; this pass finds those problems with the element and its line,
// extracts capsules, and fixes the order of links and joints (depth first from the root, children in
// document order) so that the joint vector does not depend on urdfdom's name-sorted maps.
#include <clearway/math.h>

#include <string>
#include <vector>

namespace clearway::detail {

struct UrdfOutline {
  struct Collision {
    std::string element;  // "link 'a' <collision> (line 7)"
    bool capsule = false;
    double radius = 0.0, length = 0.0;  // capsule only: radius, length of the cylindrical part
    Pose origin;                        // capsule only
  };
  struct Link {
    std::string name, element;
    int visuals = 0;
    std::vector<Collision> collisions;  // document order
  };
  struct Joint {
    std::string name, element;
    int parent = -1, child = -1;  // indices into links
  };

  std::string robot_name;
  std::vector<Link> links;    // document order
  std::vector<Joint> joints;  // document order
  std::vector<int> link_order;   // links depth first from the root, children in joint document order
  std::vector<int> joint_order;  // joint_order[k - 1] is the parent joint of links[link_order[k]]
  std::string text_for_urdfdom;  // the document without capsule collisions, <visual> and <inertial>
  struct Warning {
    std::string element, reason;
  };
  std::vector<Warning> warnings;  // sizes grown to the smallest one computed with
};

/// Reads and checks the URDF at path; throws LoadError naming the file, element and line for malformed
/// XML, a missing or unknown joint type, an unknown link name, a non-finite or malformed number in a
/// joint or collision origin, axis, limit, mimic or geometry, a length beyond kMaxInputLength, an
/// unsupported geometry, inverted limits, a loop in the kinematic tree or several root links. <visual>
/// and <inertial> are not read. Sizes below kMinInputLength are grown to it, with a warning.
UrdfOutline readUrdfOutline(const std::string& path);

/// The URDF rotation from roll, pitch, yaw: Rz(yaw)·Ry(pitch)·Rx(roll).
Mat3 rotationFromRpy(double roll, double pitch, double yaw);

}  // namespace clearway::detail
