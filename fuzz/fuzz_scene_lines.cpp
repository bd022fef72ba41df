// The state lines of `clearway check` and the segment lines of `clearway motion` (one source, two
// targets: CLEARWAY_FUZZ_MOTION selects segments). Each line is read as the tool reads it (parseNumbers,
// the count, validState) and checked in every one of our scenes whose state length fits: the arm (6
// values), the twin arm (7), the rover (a planar joint and a swing: 4) and the flyer (a floating joint,
// whose state holds a quaternion: 7). Documented: parseNumbers and validState report a bad line in
// their result; isFree and MotionChecker::check are noexcept. Nothing may throw.
#include "fuzz_support.h"

#include "cli/scene_commands.h"

#include <clearway/motion/motion.h>
#include <clearway/scene/scene.h>

#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace clearway;

struct Loaded {
  std::shared_ptr<const Scene> scene;
  std::unique_ptr<MotionChecker> checker;
  SceneContext scene_context;
  MotionContext motion_context;
};

std::vector<Loaded>& loadedScenes() {
  static std::vector<Loaded> loaded = [] {
    std::vector<Loaded> v;
    for (const char* name : {"arm6_wall", "twin_arm_table", "rover_gap", "flyer_post"}) {
      auto scene = Scene::load(std::string(CLEARWAY_SOURCE_DIR "/robots/scenes/") + name + ".yaml");
      auto checker = std::make_unique<MotionChecker>(scene);
      SceneContext scene_context = scene->makeContext();
      MotionContext motion_context = checker->makeContext();
      v.push_back({scene, std::move(checker), std::move(scene_context), std::move(motion_context)});
    }
    return v;
  }();
  return loaded;
}

#ifndef CLEARWAY_FUZZ_MOTION
// `clearway check`: n values, a valid state, then its verdict.
void checkLine(Loaded& l, const std::vector<double>& q) {
  const Scene& scene = *l.scene;
  std::string why;
  if (static_cast<int>(q.size()) != scene.dimension() || !scene.validState(q.data(), &why)) return;
  CollisionReport report;
  if (!scene.isFree(q.data(), l.scene_context, &report)) scene.describe(report);
}
#else

// `clearway motion`: 2n values, or 2n + 2 with each state's time first; valid states, finite times.
void checkLine(Loaded& l, const std::vector<double>& q) {
  const Scene& scene = *l.scene;
  const int n = scene.dimension();
  const bool timed = static_cast<int>(q.size()) == 2 * n + 2;
  if (static_cast<int>(q.size()) != 2 * n && !timed) return;
  const double* q0 = q.data() + (timed ? 1 : 0);
  const double* q1 = q.data() + (timed ? n + 2 : n);
  const double t0 = timed ? q[0] : 0.0, t1 = timed ? q[n + 1] : 0.0;
  std::string why;
  if (!scene.validState(q0, &why) || !scene.validState(q1, &why) || !std::isfinite(t0) || !std::isfinite(t1)) return;
  const MotionResult r = l.checker->check(q0, t0, q1, t1, l.motion_context);
  if (!r.free && !r.capped) scene.describe(r.report);
}
#endif

}  // namespace

// The scenes load before the first input (their pair tables take seconds under the sanitizers): an input
// is timed for what it does, not for what every input shares.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  loadedScenes();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  std::string line, why;
  std::vector<double> q;
  try {
    std::vector<Loaded>& scenes = loadedScenes();
    while (std::getline(in, line)) {
      if (!cli::parseNumbers(line, q, why) || q.empty()) continue;
      for (Loaded& l : scenes) checkLine(l, q);
    }
  } catch (const std::exception& e) {
    fuzz::finding(std::string("a scene line threw: ") + e.what());
  }
  return 0;
}
