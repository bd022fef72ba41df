#pragma once
// A scene file (docs/scene-format.md) as data: what it declares, parsed and checked, before anything it
// names is loaded. scene.h loads a description into a Scene.
#include <clearway/environment/environment.h>
#include <clearway/math.h>
#include <clearway/shape/shape.h>

#include <string>
#include <utility>
#include <vector>

namespace clearway {

/// What a scene calls for (its `checks:` list).
struct Effects {
  bool self = false;         ///< robot link pairs against each other
  bool environment = false;  ///< robot links against obstacles and the OctoMap
  bool continuous = false;   ///< motions are certified segment by segment (motion/)
  bool clearance = false;    ///< distances are computed (Scene::clearance)
  bool moving = false;       ///< obstacles move with time
  /// "self, environment, ..." in the order above.
  std::string toString() const;
};

/// Everything a scene file says, after parsing and before loading anything (paths are absolute).
struct SceneDescription {
  std::string file;  ///< the scene file ("" for one built in code); errors name it
  std::string name;  ///< the scene's name (the file's `name:`)
  ///@{
  std::string urdf, srdf;  ///< the robot's files, absolute ("" for no SRDF)
  ///@}
  /// Folders searched for the robot's package:// meshes (the file's `package_paths:`, absolute), after
  /// those the caller gives and before ROS_PACKAGE_PATH and AMENT_PREFIX_PATH.
  std::vector<std::string> package_paths;
  std::vector<std::string> group;                          ///< planned joints, in state order
  std::vector<std::pair<std::string, double>> hold;        ///< other one-variable joints, fixed
  /// Narrower limits for group variables, by variable name ("base/x"): planar and floating joints have
  /// none of their own, and a planner needs them to sample positions.
  std::vector<std::pair<std::string, std::pair<double, double>>> bounds;
  std::vector<std::pair<std::string, std::string>> allow;  ///< extra link pairs never checked
  double padding = 0.0;                                    ///< metres around every link
  std::string octomap;                                     ///< "" when none
  UnknownSpace unknown = UnknownSpace::Free;  ///< how the OctoMap's unknown cells count
  /// An obstacle as the file gives it (`environment.obstacles` entry), before any mesh is read.
  struct ObstacleSpec {
    std::string name;             ///< as Obstacle::name
    Shape shape = Sphere(1.0);    ///< the shape (unused when mesh_file is set)
    std::string mesh_file;  ///< a mesh obstacle's file ("" for a shape)
    Vec3 mesh_scale = Vec3::Ones();  ///< per-axis scale of the mesh's coordinates
    Pose pose;                    ///< world frame (an attached body's: the link frame), at time 0
    Vec3 velocity = Vec3::Zero();  ///< m/s, world frame (zero: static)
  };
  std::vector<ObstacleSpec> obstacles;  ///< in file order
  /// A body fixed to a robot link (robot.attached): named, shaped and posed (relative to the link) as an
  /// obstacle is; it may touch its touch_links and its link. loadRobotGeometry makes each a link.
  struct AttachedSpec {
    std::string link;                      ///< the robot link it is fixed to
    ObstacleSpec body;                     ///< its name, geometry and pose in the link frame
    std::vector<std::string> touch_links;  ///< robot links it may touch besides `link`
  };
  std::vector<AttachedSpec> attached;  ///< in file order
  Effects effects;                     ///< the file's `checks:`
  ///@{
  std::vector<double> start, goal;  ///< states (group order); empty when the file gives none
  ///@}
  std::vector<std::string> warnings;  ///< "file: key 'k': reason" for each input taken other than as given
};

/// Parses a scene file (docs/scene-format.md). Throws LoadError(file, "key 'a.b'", reason) for an
/// unknown key, a missing required key, a value of the wrong type or length, a non-finite number, an
/// unknown check, or a file that is missing or not YAML.
SceneDescription parseSceneFile(const std::string& path);

/// parseSceneFile on text read elsewhere (stdin): `name` names it in errors, relative paths start at `base_dir`.
SceneDescription parseSceneText(const std::string& yaml, const std::string& name, const std::string& base_dir);

}  // namespace clearway
