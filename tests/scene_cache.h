#pragma once
// Scenes for the tests that walk every shared family: the same Scene as Scene::load, with each robot
// loaded once per test process. Those tests load the UR5 up to eight times (each form, each geometry
// mode), and under the sanitizers a UR5 and its pair tables take 10 s to load; sharing the robot shares
// its tables too (PairTable::shared). Loading itself is tested where Scene::load is called.
#include <clearway/scene/scene.h>
#include <clearway/scene/scene_file.h>

#include <map>
#include <memory>
#include <mutex>
#include <string>

namespace clearway::test {

/// Scene::load(path, options), its robot shared with earlier calls for the same URDF, SRDF and package
/// paths (a scene with attached bodies, or load options of its own, loads its robot as Scene::load does).
inline std::shared_ptr<const Scene> loadScene(const std::string& path, const SceneOptions& options = {}) {
  const SceneDescription d = parseSceneFile(path);
  const bool shareable = d.attached.empty() && options.load.package_paths.empty() &&
                         options.load.mesh.honour_up_axis == MeshOptions{}.honour_up_axis &&
                         options.load.mesh.max_expanded_triangles == MeshOptions{}.max_expanded_triangles;
  if (!shareable) return std::make_shared<const Scene>(d, options);
  static std::mutex mutex;
  static std::map<std::string, std::shared_ptr<const RobotGeometry>> robots;
  std::string key = d.urdf + '\n' + d.srdf;
  for (const std::string& p : d.package_paths) key += '\n' + p;
  std::shared_ptr<const RobotGeometry> robot;
  {
    const std::lock_guard<std::mutex> lock(mutex);
    robot = robots[key];
  }
  if (!robot) {
    robot = loadRobotGeometry(d, options.load);
    const std::lock_guard<std::mutex> lock(mutex);
    robots[key] = robot;
  }
  return std::make_shared<const Scene>(d, robot, loadEnvironment(d, options.load), options);
}

}  // namespace clearway::test
