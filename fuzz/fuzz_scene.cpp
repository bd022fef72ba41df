// A scene file → SceneDescription → (robot, environment) → Scene, as `clearway check SCENE` loads it.
// The file is written to <scratch>/scenes/scene.yaml beside links to our robots' folders, so that the
// seeds' relative paths (../arm6/arm6.urdf) resolve. Robots are cached by file (loading a robot is the
// URDF target's work); the environment and the Scene are built for every input whose files all lie in
// our robots/ folder (a fuzzed path could otherwise name any file on the machine).
// Documented: parseSceneFile, loadRobotGeometry, loadEnvironment and Scene throw LoadError.
#include "fuzz_support.h"

#include <clearway/scene/scene.h>

#include <map>
#include <memory>
#include <string>
#include <utility>

namespace {

namespace fs = std::filesystem;
const fs::path kRobots = fs::path(CLEARWAY_SOURCE_DIR) / "robots";

bool insideRobots(const std::string& path) {
  if (path.empty()) return true;
  const fs::path relative = fs::path(path).lexically_normal().lexically_relative(kRobots);
  return !relative.empty() && *relative.begin() != "..";
}

// The scratch folder's robot links stand for robots/, so its paths are mapped back before the check.
std::string throughLinks(const std::string& path) {
  const std::string scratch = clearway::fuzz::scratchDir().string();
  if (path.compare(0, scratch.size(), scratch) != 0) return path;
  return (kRobots / fs::path(path).lexically_relative(clearway::fuzz::scratchDir())).lexically_normal().string();
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const fs::path& dir = clearway::fuzz::scratchDir();
  fs::create_directory(dir / "scenes");
  for (const fs::directory_entry& e : fs::directory_iterator(kRobots))
    if (e.is_directory() && e.path().filename() != "scenes") fs::create_directory_symlink(e.path(), dir / e.path().filename());
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace clearway;
  const std::string path = fuzz::writeFile("scenes/scene.yaml", data, size);
  SceneDescription d;
  if (!fuzz::expectOnly<LoadError>("parseSceneFile", [&] { d = parseSceneFile(path); })) return 0;

  bool ours = insideRobots(throughLinks(d.urdf)) && insideRobots(throughLinks(d.srdf)) &&
              insideRobots(throughLinks(d.octomap)) && d.package_paths.empty();
  for (const auto& o : d.obstacles) ours = ours && insideRobots(throughLinks(o.mesh_file));
  if (!ours) return 0;

  static std::map<std::pair<std::string, std::string>, std::shared_ptr<const RobotGeometry>> robots;
  auto cached = robots.find({d.urdf, d.srdf});
  if (cached == robots.end()) {
    std::shared_ptr<const RobotGeometry> robot;
    fuzz::expectOnly<LoadError>("loadRobotGeometry", [&] { robot = loadRobotGeometry(d); });
    cached = robots.emplace(std::make_pair(d.urdf, d.srdf), robot).first;  // null: it does not load
  }
  if (!cached->second) return 0;
  std::shared_ptr<const Environment> environment;
  if (!fuzz::expectOnly<LoadError>("loadEnvironment", [&] { environment = loadEnvironment(d); })) return 0;
  // Without pair tables, as in fuzz_scene_attached: they change no verdict (scene/pair_table.h) and depend
  // on the robot, not on the file's bytes, and the dual arm's take over 10 s in this build (the timeout).
  SceneOptions options;
  options.pair_tables = false;
  std::shared_ptr<const Scene> scene;
  if (!fuzz::expectOnly<LoadError>(
          "Scene", [&] { scene = std::make_shared<const Scene>(d, cached->second, environment, options); }))
    return 0;
  // The file's own start and goal, as `clearway check SCENE` checks them.
  for (const std::vector<double>* q : {&d.start, &d.goal})
    if (!q->empty() && scene->validState(q->data())) {
      SceneContext ctx = scene->makeContext();
      scene->isFree(q->data(), ctx);
    }
  return 0;
}
