#include <clearway/world/world.h>

#include <clearway/per_thread.h>

#include <stdexcept>
#include <utility>

namespace clearway {

World::World(std::shared_ptr<const Scene> scene, MotionOptions motion) : motion_options_(motion) {
  if (!scene) throw std::invalid_argument("World: null scene");
  auto checker = std::make_shared<const MotionChecker>(scene, motion);
  publish(std::move(scene), std::move(checker));
}

World::World(std::shared_ptr<const MotionChecker> motion) {
  if (!motion) throw std::invalid_argument("World: null motion checker");
  motion_options_ = motion->options();
  std::shared_ptr<const Scene> scene = motion->scenePtr();
  publish(std::move(scene), std::move(motion));
}

std::shared_ptr<World> World::load(const std::string& path, const SceneOptions& options, MotionOptions motion) {
  return std::make_shared<World>(Scene::load(path, options), motion);
}

std::shared_ptr<const WorldSnapshot> World::snapshot() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return current_;
}

const WorldSnapshot& World::current() const {
  std::shared_ptr<const WorldSnapshot>& seen = seen_.get([] { return std::shared_ptr<const WorldSnapshot>(); });
  // The version is stored after current_ is swapped, under the same lock: seeing a new version, the copy
  // taken under the lock is at least that new.
  if (!seen || seen->version != version_.load(std::memory_order_acquire)) seen = snapshot();
  return *seen;
}

void World::publish(std::shared_ptr<const Scene> scene, std::shared_ptr<const MotionChecker> motion) {
  auto next = std::make_shared<WorldSnapshot>();
  next->scene = std::move(scene);
  next->motion = std::move(motion);
  const std::lock_guard<std::mutex> lock(mutex_);
  next->version = (current_ ? current_->version : 0) + 1;
  current_ = std::move(next);
  version_.store(current_->version, std::memory_order_release);
}

template <class Edit>
void World::apply(Edit&& edit) {
  const std::lock_guard<std::mutex> lock(edit_mutex_);
  edit(*snapshot());
}

void World::editEnvironment(const Environment& next) {
  const WorldSnapshot now = *snapshot();
  auto scene = now.scene->withEnvironment(std::make_shared<const Environment>(next));
  auto checker = std::make_shared<const MotionChecker>(*now.motion, scene);
  publish(std::move(scene), std::move(checker));
}

void World::addObstacle(Obstacle obstacle) {
  apply([&](const WorldSnapshot& s) { editEnvironment(s.scene->environment().withObstacle(std::move(obstacle))); });
}

void World::moveObstacle(const std::string& name, const Pose& pose) {
  apply([&](const WorldSnapshot& s) { editEnvironment(s.scene->environment().withObstacleMoved(name, pose)); });
}

void World::removeObstacle(const std::string& name) {
  apply([&](const WorldSnapshot& s) { editEnvironment(s.scene->environment().withoutObstacle(name)); });
}

void World::insertPoints(const std::vector<Vec3>& points, double resolution) {
  apply([&](const WorldSnapshot& s) { editEnvironment(s.scene->environment().withPoints(points, resolution)); });
}

void World::setMap(std::shared_ptr<const OccupancyMap> map) {
  apply([&](const WorldSnapshot& s) { editEnvironment(s.scene->environment().withMap(std::move(map))); });
}

void World::replaceScene(std::shared_ptr<const Scene> scene) {
  auto checker = std::make_shared<const MotionChecker>(scene, motion_options_);
  publish(std::move(scene), std::move(checker));
}

void World::attach(const SceneDescription::AttachedSpec& spec, const LoadOptions& load) {
  apply([&](const WorldSnapshot& s) { replaceScene(s.scene->withAttached(spec, load)); });
}

void World::detach(const std::string& name) {
  apply([&](const WorldSnapshot& s) { replaceScene(s.scene->withoutAttached(name)); });
}

}  // namespace clearway
