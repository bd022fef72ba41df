// A scene file with attached bodies (robot.attached) and package:// meshes (package_paths), loaded as
// `clearway check SCENE` loads it (parseSceneFile, loadRobotGeometry, loadEnvironment, Scene), then
// queried at its start, its goal and half way, as a planner would. The file is written to
// <scratch>/scenes/scene.yaml beside links to our robots' folders (../arm6/arm6.urdf resolves) and a
// workspace, <scratch>/ws/src/fuzz_arm: a package (package.xml) holding a small arm's URDF whose meshes
// are named package://fuzz_arm/meshes/... (our arm's); `package_paths: [../ws/src]` finds it.
// ROS_PACKAGE_PATH and AMENT_PREFIX_PATH are unset, and only inputs whose files and folders all lie in
// robots/ or the workspace are loaded (a fuzzed path could otherwise name any file on the machine).
// Documented: parsing and loading throw LoadError; Scene::withoutAttached std::invalid_argument; queries
// are noexcept. Checked, as each verdict's promise:
//  - areFree and anyCollides give each state the verdict isFree gives it;
//  - a motion of length zero is free exactly where its state is (a free state can always be left);
//  - a free segment has free ends;
//  - without an attached body a free state stays free (a link fewer can add no collision).
#include "fuzz_support.h"

#include <clearway/motion/motion.h>
#include <clearway/scene/scene.h>

#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using namespace clearway;

const fs::path kRobots = fs::path(CLEARWAY_SOURCE_DIR) / "robots";

fs::path workspace() { return fuzz::scratchDir() / "ws"; }

bool within(const fs::path& path, const fs::path& root) {
  const fs::path relative = path.lexically_normal().lexically_relative(root);
  return !relative.empty() && *relative.begin() != "..";
}

// A path the input names, with the scratch folder's links to robots/ followed, lies in robots/ or the
// workspace ("" names nothing).
bool allowed(const std::string& path) {
  if (path.empty()) return true;
  fs::path p = fs::path(path).lexically_normal();
  if (within(p, workspace())) return true;
  if (within(p, fuzz::scratchDir())) p = kRobots / p.lexically_relative(fuzz::scratchDir());
  return within(p, kRobots);
}

bool allAllowed(const SceneDescription& d) {
  bool ok = allowed(d.urdf) && allowed(d.srdf) && allowed(d.octomap);
  for (const std::string& p : d.package_paths) ok = ok && allowed(p);
  for (const auto& o : d.obstacles) ok = ok && allowed(o.mesh_file);
  for (const auto& a : d.attached) ok = ok && allowed(a.body.mesh_file);
  return ok;
}

// Motions stop after a few thousand distance queries (capped, never free): a fuzzed segment near contact
// could otherwise run the 200,000 the cap allows. `asked` counts the stop condition's calls (every 256
// queries) since it was last set to 0.
MotionOptions boundedMotions(const std::shared_ptr<int>& asked) {
  MotionOptions o;
  o.stop = [asked] { return ++*asked > 8; };
  return o;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const fs::path& dir = fuzz::scratchDir();
  fs::create_directory(dir / "scenes");
  for (const fs::directory_entry& e : fs::directory_iterator(kRobots))
    if (e.is_directory() && e.path().filename() != "scenes") fs::create_directory_symlink(e.path(), dir / e.path().filename());
  // The workspace: a small arm as a ROS package whose URDF names two of our arm's meshes by package://
  // (an OBJ and a COLLADA file: small, as this target is about the scene, not the mesh readers).
  const fs::path package = workspace() / "src" / "fuzz_arm";
  fs::create_directories(package / "urdf");
  fs::create_directory_symlink(kRobots / "arm6" / "meshes", package / "meshes");
  std::ofstream(package / "package.xml") << "<?xml version=\"1.0\"?>\n<package format=\"3\"><name>fuzz_arm</name>"
                                            "<version>0.0.0</version></package>\n";
  std::ofstream(package / "urdf" / "fuzz_arm.urdf") << R"(<?xml version="1.0"?>
<robot name="fuzz_arm">
  <link name="base_link">
    <collision><geometry><mesh filename="package://fuzz_arm/meshes/upper_arm.obj"/></geometry></collision>
  </link>
  <link name="link1">
    <collision><origin xyz="0.25 0 0"/><geometry><box size="0.5 0.08 0.08"/></geometry></collision>
  </link>
  <link name="link2">
    <collision><geometry><mesh filename="package://fuzz_arm/meshes/forearm.dae" scale="0.5 0.5 0.5"/></geometry></collision>
  </link>
  <link name="tool">
    <collision><geometry><sphere radius="0.03"/></geometry></collision>
  </link>
  <joint name="pan" type="revolute">
    <origin xyz="0 0 0.3"/><parent link="base_link"/><child link="link1"/><axis xyz="0 0 1"/>
    <limit lower="-3.14" upper="3.14" velocity="1" effort="1"/>
  </joint>
  <joint name="lift" type="revolute">
    <origin xyz="0.5 0 0"/><parent link="link1"/><child link="link2"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" velocity="1" effort="1"/>
  </joint>
  <joint name="slide" type="prismatic">
    <origin xyz="0 0 0.2"/><parent link="link2"/><child link="tool"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="0.2" velocity="1" effort="1"/>
  </joint>
</robot>
)";
  unsetenv("ROS_PACKAGE_PATH");
  unsetenv("AMENT_PREFIX_PATH");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = fuzz::writeFile("scenes/scene.yaml", data, size);
  SceneDescription d;
  if (!fuzz::expectOnly<LoadError>("parseSceneFile", [&] { d = parseSceneFile(path); })) return 0;
  if (!allAllowed(d)) return 0;
  // Without pair tables: they change no verdict (scene/pair_table.h), and a robot's tables take seconds
  // in this build, where everything else about a scene takes milliseconds.
  SceneOptions options;
  options.pair_tables = false;
  std::shared_ptr<const Scene> scene;
  if (!fuzz::expectOnly<LoadError>("Scene", [&] { scene = std::make_shared<const Scene>(d, options); })) return 0;
  const int n = scene->dimension();

  // The file's start and goal, and the state half way, where valid.
  std::vector<std::vector<double>> states;
  for (const std::vector<double>* q : {&d.start, &d.goal})
    if (static_cast<int>(q->size()) == n && scene->validState(q->data())) states.push_back(*q);
  if (states.size() == 2) {
    std::vector<double> mid(n);
    for (int i = 0; i < n; ++i) mid[i] = 0.5 * (states[0][i] + states[1][i]);
    if (scene->validState(mid.data())) states.push_back(mid);
  }
  if (states.empty()) return 0;

  SceneContext context = scene->makeContext();
  std::vector<char> free(states.size());
  std::vector<double> all;
  for (std::size_t s = 0; s < states.size(); ++s) {
    SceneContext fresh = scene->makeContext();
    free[s] = scene->isFree(states[s].data(), fresh);
    all.insert(all.end(), states[s].begin(), states[s].end());
  }
  bool batch[3];
  scene->areFree(all.data(), static_cast<int>(states.size()), context, batch);
  const int hit = scene->anyCollides(all.data(), static_cast<int>(states.size()), context);
  bool any = false;
  for (std::size_t s = 0; s < states.size(); ++s) {
    if (batch[s] != static_cast<bool>(free[s])) fuzz::finding("areFree and isFree disagree on state " + std::to_string(s));
    any = any || !free[s];
  }
  if ((hit >= 0) != any || (hit >= 0 && free[hit])) fuzz::finding("anyCollides and isFree disagree");

  const auto asked = std::make_shared<int>(0);
  const auto checker = std::make_shared<const MotionChecker>(scene, boundedMotions(asked));
  MotionContext motion = checker->makeContext();
  for (std::size_t s = 0; s < states.size(); ++s) {
    *asked = 0;
    const MotionResult r = checker->check(states[s].data(), states[s].data(), motion);
    if (!r.capped && r.free != static_cast<bool>(free[s]))
      fuzz::finding(std::string("a motion of length zero is ") + (r.free ? "free" : "not free") + " from a state " +
                    (free[s] ? "free" : "in collision") + " (state " + std::to_string(s) + ")");
  }
  if (states.size() >= 2) {
    *asked = 0;
    const MotionResult r = checker->check(states[0].data(), states[1].data(), motion);
    if (r.free && !(free[0] && free[1])) fuzz::finding("a free segment from start to goal has an end in collision");
  }

  // The first attached body taken off: what was free stays free.
  if (!d.attached.empty()) {
    std::shared_ptr<const Scene> bare;
    if (!fuzz::expectOnly<std::invalid_argument>("withoutAttached", [&] { bare = scene->withoutAttached(d.attached[0].body.name); }))
      fuzz::finding("an attached body of the scene file cannot be taken off");
    for (std::size_t s = 0; s < states.size(); ++s) {
      SceneContext fresh = bare->makeContext();
      if (free[s] && !bare->isFree(states[s].data(), fresh))
        fuzz::finding("a free state collides once an attached body is taken off (state " + std::to_string(s) + ")");
    }
  }
  return 0;
}
