#pragma once
// The Scene Python holds (clearway.Scene): shared by the scene bindings (scene.cpp) and planning
// (planning.cpp).
#include <clearway/motion/motion.h>
#include <clearway/scene/scene.h>

#include <algorithm>
#include <list>
#include <memory>
#include <mutex>
#include <tuple>

namespace clearway::python {

// The scene Python holds, and the motion checkers made for it (one per mode and contact distance: a
// checker's construction measures the robot, too dear to repeat per call). The most recently used few
// are kept: a caller sweeping 20,000 contact distances kept 20,000 checkers (788 MB).
class PyScene {
 public:
  explicit PyScene(std::shared_ptr<const Scene> s) : scene(std::move(s)) {}
  std::shared_ptr<const Scene> scene;

  /// The checker for these options (finite: motionOptions checks them, so keys compare exactly); the
  /// caller's handle keeps it alive however many others are asked for meanwhile.
  std::shared_ptr<const MotionChecker> checker(const MotionOptions& options) {
    const auto key = std::make_tuple(static_cast<int>(options.mode), options.resolution, options.contact_distance);
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = std::find_if(checkers_.begin(), checkers_.end(), [&](const auto& c) { return c.first == key; });
    if (it == checkers_.end()) {
      if (checkers_.size() >= kKept) checkers_.pop_back();
      checkers_.emplace_front(key, std::make_shared<const MotionChecker>(scene, options));
    } else {
      checkers_.splice(checkers_.begin(), checkers_, it);
    }
    return checkers_.front().second;
  }
  /// How many checkers are kept (at most kKept).
  std::size_t kept() {
    std::lock_guard<std::mutex> lock(mutex_);
    return checkers_.size();
  }

 private:
  static constexpr std::size_t kKept = 8;
  std::mutex mutex_;
  std::list<std::pair<std::tuple<int, double, double>, std::shared_ptr<const MotionChecker>>> checkers_;  // newest first
};

}  // namespace clearway::python
