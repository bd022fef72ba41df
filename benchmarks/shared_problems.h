#pragma once
// The shared MotionBenchMaker problems (../shared/scenes/FAMILY/FAMILY_NNNN[.octomap].yaml) as the
// benchmarks walk them: the families in order, a problem's file, and scenes whose robot is loaded once.
#include <clearway/scene/scene.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace clearway::bench {

/// The family folders under `scenes`, sorted.
inline std::vector<std::string> sceneFamilies(const std::string& scenes) {
  std::vector<std::string> families;
  for (const auto& f : std::filesystem::directory_iterator(scenes))
    if (f.is_directory()) families.push_back(f.path().filename().string());
  std::sort(families.begin(), families.end());
  return families;
}

/// Problem k of a family (primitive or OctoMap form); "" when the file does not exist.
inline std::string problemFile(const std::string& scenes, const std::string& family, int k, bool octomap = false) {
  char name[64];
  std::snprintf(name, sizeof name, "_%04d%s.yaml", k, octomap ? ".octomap" : "");
  const std::string file = scenes + "/" + family + "/" + family + name;
  return std::filesystem::exists(file) ? file : "";
}

/// Loads each robot once (UR5 meshes take a fifth of a second) for all the scenes that share it.
class RobotCache {
 public:
  std::shared_ptr<const RobotGeometry> robot(const SceneDescription& d) {
    auto& g = robots_[d.urdf];
    if (!g) g = loadRobotGeometry(d);
    return g;
  }
  std::shared_ptr<const Scene> scene(const SceneDescription& d) {
    return std::make_shared<const Scene>(d, robot(d), loadEnvironment(d));
  }

 private:
  std::map<std::string, std::shared_ptr<const RobotGeometry>> robots_;
};

}  // namespace clearway::bench
