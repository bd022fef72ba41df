#pragma once
// URDF (+ SRDF + meshes) → RobotModel. Everything that can be wrong with a robot file is found here,
// at load time, and named: errors throw LoadError ("FILE: ELEMENT: REASON"), warnings are kept in
// RobotModel::loadWarnings() in the same form for the caller to print.
#include <clearway/kinematics/robot_model.h>
#include <clearway/load/load_error.h>
#include <clearway/load/mesh_loader.h>

#include <string>
#include <vector>

namespace clearway {

/// How loadRobot finds and reads mesh files.
struct LoadOptions {
  /// Searched first for package://NAME/... mesh URIs: each entry is a package folder named NAME, a
  /// folder holding NAME (directly, under share/, or up to three levels below), or an install prefix.
  std::vector<std::string> package_paths;
  /// How mesh files are read (COLLADA `<up_axis>` ignored by default, as ROS does).
  MeshOptions mesh;
};

/// Loads a robot:
///  - the URDF through urdfdom, after a first pass that names the element and line of any problem;
///    links in topological order (depth first from the root, children in document order), joints in
///    the order of their child links, and the joint vector in joint order;
///  - every `<collision>` element: box, sphere, cylinder, capsule (`<capsule radius length>`, length of
///    the cylindrical part), or a mesh through loadMesh with its scale (one TriangleMesh per distinct
///    file and scale, read with options.mesh; each distinct mesh warning is given once); mesh URIs
///    relative to the URDF, absolute, file:// or package://;
///  - the SRDF's `<disable_collisions link1 link2 reason>` pairs, when srdf_path is not empty.
/// Errors (LoadError): a missing or malformed URDF/SRDF; an unknown joint type; a non-finite number
/// in an origin, axis, limit or geometry; a loop in the kinematic tree or several roots; inverted
/// limits; a mimic of a missing joint or a mimic cycle; an unresolved package:// or other bad URI; a
/// missing, unsupported or empty mesh; anything urdfdom rejects or drops. Warnings (the file still
/// loads, as it does in MoveIt): a link with `<visual>` but no `<collision>`; a `<mimic>` on a fixed joint
/// (ignored); mesh warnings (zero-area triangles, not closed, probably millimetres, a COLLADA file that
/// is not Z_UP); urdfdom's warnings; SRDF pairs listed twice or naming one link twice; SRDF pairs naming
/// a link the URDF does not have (skipped; one warning per SRDF with their count and first names).
RobotModel loadRobot(const std::string& urdf_path, const std::string& srdf_path = "", const LoadOptions& options = {});

}  // namespace clearway
