#pragma once
// A world that changes between planning queries, as MoveIt's planning scene and FCL's dynamic managers
// change: obstacles added, moved and removed, points inserted into the occupancy, bodies attached to
// links and detached. Scenes and motion checkers stay immutable; an edit makes the next pair from the
// current one, sharing what it did not touch (an obstacle edit costs O(log n) in the environment, and
// keeps the robot, its pairs and the motion bound; an attached body rebuilds the robot's pairs, sharing
// every link's geometry), and publishes it as one snapshot. A query takes the current snapshot without
// waiting for edits, and the snapshot it holds stays whole while edits go on: each verdict is the
// verdict of the world before an edit or after it, never of a mixture.
#include <clearway/motion/motion.h>
#include <clearway/per_thread.h>
#include <clearway/scene/scene.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace clearway {

/// One consistent state of a World, never changed once published.
struct WorldSnapshot {
  std::shared_ptr<const Scene> scene;            ///< the scene as of this version (never null)
  std::shared_ptr<const MotionChecker> motion;  ///< the scene's certified motion checker
  std::uint64_t version = 0;                    ///< 1 as built, one more per edit
};

/// A scene that edits replace; thread-safe: any number of threads query while one or more edit.
class World {
 public:
  /// The world of a built scene, with motions checked with `motion` options. Throws std::invalid_argument
  /// for options out of range (MotionChecker).
  explicit World(std::shared_ptr<const Scene> scene, MotionOptions motion = {});
  /// The world of a built checker's scene, with motions checked by it (and by checkers made from it as
  /// edits come: its options). Throws std::invalid_argument for a null checker.
  explicit World(std::shared_ptr<const MotionChecker> motion);
  /// Scene::load + the constructor.
  static std::shared_ptr<World> load(const std::string& path, const SceneOptions& options = {},
                                     MotionOptions motion = {});

  /// The current snapshot, to keep (takes a short lock).
  std::shared_ptr<const WorldSnapshot> snapshot() const;
  /// The current snapshot as this thread last took it, taken again only when an edit has published a
  /// newer one: a query's way in, one atomic load when nothing changed. Valid until this thread's next
  /// call of current() on this world (the thread holds it until then, even past the world's end).
  const WorldSnapshot& current() const;
  /// The current snapshot's version.
  std::uint64_t version() const noexcept { return version_.load(std::memory_order_acquire); }

  /// Adds an obstacle (Environment::withObstacle; throws std::invalid_argument as it does).
  void addObstacle(Obstacle obstacle);
  /// Moves the named obstacle to `pose` (Environment::withObstacleMoved).
  void moveObstacle(const std::string& name, const Pose& pose);
  /// Removes the named obstacle (Environment::withoutObstacle).
  void removeObstacle(const std::string& name);
  /// Marks the voxels holding the points occupied (Environment::withPoints: resolution 0 is the map's).
  void insertPoints(const std::vector<Vec3>& points, double resolution = 0.0);
  /// Replaces the occupancy map (a changed .bt, loadOctomap); obstacles and inserted points stay.
  void setMap(std::shared_ptr<const OccupancyMap> map);
  /// Attaches a body to a robot link (Scene::withAttached; throws as it does).
  void attach(const SceneDescription::AttachedSpec& body, const LoadOptions& load = {});
  /// Detaches the named attached body (Scene::withoutAttached; throws as it does).
  void detach(const std::string& name);

 private:
  // Builds the next snapshot from the current one with `edit` (under edit_mutex_) and publishes it.
  template <class Edit>
  void apply(Edit&& edit);
  void publish(std::shared_ptr<const Scene> scene, std::shared_ptr<const MotionChecker> motion);
  void editEnvironment(const Environment& next);
  void replaceScene(std::shared_ptr<const Scene> scene);  // a new robot: the motion checker built anew

  std::mutex edit_mutex_;          // one edit at a time
  mutable std::mutex mutex_;       // guards current_ (held only to copy or swap the pointer)
  std::shared_ptr<const WorldSnapshot> current_;
  std::atomic<std::uint64_t> version_{0};
  MotionOptions motion_options_;
  PerThread<std::shared_ptr<const WorldSnapshot>> seen_;  // each thread's copy of the snapshot it last saw
};

}  // namespace clearway
