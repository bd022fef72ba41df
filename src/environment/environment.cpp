// Environment: the obstacle store. Static obstacles and the voxels of withPoints in a persistent AABB
// tree (each edit a new version sharing the rest), moving obstacles in a list, the OctoMap's voxels in a
// tree of their own, the names, and the clearance grid built once enough queries asked. The link queries
// against it are in environment_queries.cpp.
#include <clearway/environment/environment.h>
#include <clearway/environment/voxel_blocks.h>
#include <clearway/load/input_limits.h>

#include "environment_boxes.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <utility>

namespace clearway {

using environment_detail::maxAbs;
using environment_detail::obstacleBox;


struct Environment::Clearance {
  std::atomic<const ClearanceGrid*> ready{nullptr};  // published once `grid` is whole
  std::atomic<int> asked{0};
  std::once_flag once;
  std::unique_ptr<const ClearanceGrid> grid;
};

Environment::Environment(std::vector<Obstacle> obstacles, std::shared_ptr<const OccupancyMap> map) {
  std::vector<std::pair<Aabb, Static>> items;
  std::vector<std::string> item_names;
  for (Obstacle& o : obstacles) {
    if (!o.pose.isFinite()) throw std::invalid_argument("environment: obstacle '" + o.name + "' has a non-finite pose");
    if (!o.velocity.allFinite())
      throw std::invalid_argument("environment: obstacle '" + o.name + "' has a non-finite velocity");
    auto shared = std::make_shared<const Obstacle>(std::move(o));
    ++named_count_;
    if (shared->moving()) {
      if (const Named* n = names_.find(shared->name)) {
        Named twice = *n;
        ++twice.count;
        names_ = names_.assigned(shared->name, twice);
      } else {
        Named named;
        named.moving = true;
        names_ = names_.inserted(shared->name, named);
      }
      moving_.push_back(std::move(shared));
      continue;
    }
    const Aabb box = obstacleBox(*shared, shared->pose);
    if (box.isEmpty() || !box.min.allFinite() || !box.max.allFinite())
      throw std::invalid_argument("environment: obstacle '" + shared->name + "' has no finite bounds");
    item_names.push_back(shared->name);
    items.push_back({box, Static{std::move(shared), slot_count_++, false}});
  }
  std::vector<StaticTree::Key> keys;
  static_ = StaticTree::build(std::move(items), &keys);
  for (std::size_t i = 0; i < keys.size(); ++i) {
    Named named;
    if (const Named* n = names_.find(item_names[i])) {
      named = *n;
      ++named.count;
    } else {
      named.key = keys[i];
    }
    names_ = names_.assigned(item_names[i], named);
  }
  clearance_ = std::make_shared<Clearance>();
  *this = withMap(std::move(map));
}

Environment Environment::withMap(std::shared_ptr<const OccupancyMap> map) const {
  Environment e = *this;
  e.map_ = std::move(map);
  e.voxel_tree_.reset();
  e.blocks_.reset();
  // Voxels lie on a grid: the median split is as good as the SAH there and builds several times faster.
  if (e.map_ && !e.map_->occupied.empty()) {
    e.voxel_tree_ = std::make_shared<const AabbTree>(e.map_->occupied, TreeBuildOptions{TreeSplit::Median, 2});
    e.blocks_ = std::make_shared<const VoxelBlocks>(*e.map_, !e.without_blocks_);
  }
  e.rescale();
  return e;
}

void Environment::rescale() {
  scale_ = std::max(maxAbs(static_.bounds()), voxel_tree_ ? maxAbs(voxel_tree_->bounds()) : 0.0);
  if (clearance_) clearance_ = std::make_shared<Clearance>();  // (none stays none: withoutClearanceGrid)
  boxes_.reset();
  if (without_boxes_ || static_.size() > ObstacleBoxes::kMaxBoxes) return;
  std::vector<ObstacleBoxes::Placed> boxes;
  static_.forEach([&](const Static& s, const Aabb& box) {
    if (s.voxel) {
      boxes.push_back({Pose::identity(), box});
    } else {
      const Obstacle& o = *s.obstacle;  // (its box in its own frame: a mesh's of its hull)
      boxes.push_back({o.pose, o.mesh ? o.mesh->bounds() : placedBox(o.shape, Pose::identity())});
    }
  });
  boxes_ = ObstacleBoxes::build(boxes);
}

const ClearanceGrid* Environment::clearanceGrid() const noexcept {
  return clearance_ ? clearance_->ready.load(std::memory_order_acquire) : nullptr;
}

void Environment::countQuery() const noexcept {
  if (!clearance_ || clearance_->ready.load(std::memory_order_acquire)) return;
  // One query, the one that reaches the count, builds it; the others go on without it meanwhile.
  if (clearance_->asked.fetch_add(1, std::memory_order_relaxed) == kClearanceAfter) prepareClearanceGrid();
}

void Environment::prepareClearanceGrid() const noexcept {
  if (!clearance_) return;
  Clearance& c = *clearance_;
  try {
    std::call_once(c.once, [&] {
      std::vector<Aabb> boxes;
      static_.forEach([&](const Static&, const Aabb& box) { boxes.push_back(box); });
      if (map_) boxes.insert(boxes.end(), map_->occupied.begin(), map_->occupied.end());
      c.grid = std::make_unique<const ClearanceGrid>(boxes);
      c.ready.store(c.grid.get(), std::memory_order_release);
    });
  } catch (...) {  // (out of memory: the queries go on through the trees)
  }
}

Environment Environment::withoutClearanceGrid() const {
  Environment e = *this;
  e.clearance_.reset();
  return e;
}

Environment Environment::withoutVoxelBlocks() const {
  Environment e = *this;
  e.without_blocks_ = true;
  return e.withMap(map_);
}

Environment Environment::withoutObstacleBoxes() const {
  Environment e = *this;
  e.without_boxes_ = true;
  e.boxes_.reset();
  return e;
}

std::vector<std::shared_ptr<const Obstacle>> Environment::obstacles() const {
  std::vector<std::shared_ptr<const Obstacle>> all;
  static_.forEach([&](const Static& s, const Aabb&) {
    if (!s.voxel) all.push_back(s.obstacle);
  });
  all.insert(all.end(), moving_.begin(), moving_.end());
  return all;
}

const Obstacle* Environment::obstacle(const std::string& name) const noexcept {
  const Named* n = names_.find(name);
  if (!n || n->count != 1) return nullptr;
  if (!n->moving) {
    const Static* s = static_.find(n->key);
    return s ? s->obstacle.get() : nullptr;
  }
  for (const auto& o : moving_)
    if (o->name == name) return o.get();
  return nullptr;
}

Environment Environment::withStatic(std::shared_ptr<const Obstacle> o) const {
  Environment e = *this;
  const Aabb box = obstacleBox(*o, o->pose);
  if (box.isEmpty() || !box.min.allFinite() || !box.max.allFinite())
    throw std::invalid_argument("environment: obstacle '" + o->name + "' has no finite bounds");
  int slot;
  if (e.free_slots_) {
    slot = e.free_slots_->slot;
    e.free_slots_ = e.free_slots_->next;
  } else {
    slot = e.slot_count_++;
  }
  const std::string name = o->name;
  Named named;
  e.static_ = e.static_.inserted(box, Static{std::move(o), slot, false}, &named.key);
  e.names_ = e.names_.inserted(name, named);
  ++e.named_count_;
  e.rescale();
  return e;
}

Environment Environment::withObstacle(Obstacle obstacle) const {
  const std::string& name = obstacle.name;
  if (name.empty()) throw std::invalid_argument("environment: an obstacle added needs a name");
  if (names_.find(name)) throw std::invalid_argument("environment: obstacle '" + name + "' already exists");
  if (!obstacle.pose.isFinite()) throw std::invalid_argument("environment: obstacle '" + name + "' has a non-finite pose");
  if (!obstacle.velocity.allFinite())
    throw std::invalid_argument("environment: obstacle '" + name + "' has a non-finite velocity");
  // As in a scene file (load/input_limits.h): past kMaxInputLength the boxes and radii the culls sum
  // overflow (a hull of points near 1e200 had an infinite radius, and a segment between two states
  // inside it was certified free).
  const Aabb box = obstacle.mesh ? placedBox(obstacle.mesh->hull(), obstacle.pose) : placedBox(obstacle.shape, obstacle.pose);
  if (!(box.min.cwiseAbs().maxCoeff() <= kMaxInputLength) || !(box.max.cwiseAbs().maxCoeff() <= kMaxInputLength))
    throw std::invalid_argument("environment: obstacle '" + name + "' reaches beyond " +
                                std::to_string(static_cast<long long>(kMaxInputLength)) +
                                " m, the largest length an input may give");
  auto shared = std::make_shared<const Obstacle>(std::move(obstacle));
  if (!shared->moving()) return withStatic(std::move(shared));
  Environment e = *this;
  Named named;
  named.moving = true;
  e.names_ = e.names_.inserted(shared->name, named);
  e.moving_.push_back(std::move(shared));
  ++e.named_count_;
  return e;
}

Environment Environment::withoutObstacle(const std::string& name) const {
  const Named* n = names_.find(name);
  if (!n) throw std::invalid_argument("environment: no obstacle is named '" + name + "'");
  if (n->count != 1)
    throw std::invalid_argument("environment: " + std::to_string(n->count) + " obstacles are named '" + name +
                                "': an edit needs a name of its own");
  Environment e = *this;
  if (n->moving) {
    e.moving_.erase(std::find_if(e.moving_.begin(), e.moving_.end(), [&](const auto& o) { return o->name == name; }));
  } else {
    const Static* s = static_.find(n->key);
    e.free_slots_ = std::make_shared<const FreeSlot>(FreeSlot{s->slot, free_slots_});
    e.static_ = static_.erased(n->key);
  }
  e.names_ = names_.erased(name);
  --e.named_count_;
  e.rescale();
  return e;
}

Environment Environment::withObstacleMoved(const std::string& name, const Pose& pose) const {
  if (!pose.isFinite()) throw std::invalid_argument("environment: obstacle '" + name + "' moved to a non-finite pose");
  const Obstacle* old = obstacle(name);
  Obstacle moved = old ? *old : Obstacle{};
  Environment e = withoutObstacle(name);  // (throws for a missing or shared name)
  moved.pose = pose;
  return e.withObstacle(std::move(moved));
}

Environment Environment::withPoints(const std::vector<Vec3>& points, double resolution) const {
  if (resolution == 0.0 && map_) resolution = map_->resolution;
  if (!(resolution > 0.0) || !std::isfinite(resolution))
    throw std::invalid_argument("environment: points need a finite voxel size > 0 (the map's, or given)");
  // As a map's cells and an obstacle's extent (load/input_limits.h): a cell below kMinInputLength has no
  // hull, and a point beyond kMaxInputLength no digit of a link's size.
  if (resolution < kMinInputLength) {
    char text[64];
    std::snprintf(text, sizeof text, "%.17g m is below %g m", resolution, kMinInputLength);
    throw std::invalid_argument(std::string("environment: a voxel size of ") + text + ", the smallest length computed with");
  }
  // Each point's cell, once: a cloud holds many points per voxel.
  std::vector<Aabb> cells;
  cells.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3& p = points[i];
    if (!p.allFinite()) throw std::invalid_argument("environment: point " + std::to_string(i) + " is not finite");
    if (!(p.cwiseAbs().maxCoeff() + resolution <= kMaxInputLength))
      throw std::invalid_argument("environment: point " + std::to_string(i) + "'s voxel reaches beyond " +
                                  std::to_string(static_cast<long long>(kMaxInputLength)) +
                                  " m, the largest length an input may give");
    const Vec3 lo = (p / resolution).array().floor() * resolution;
    Aabb cell = Aabb::fromMinMax(lo, lo + Vec3::Constant(resolution));
    cell.grow(p);  // (where rounding leaves the point just outside its cell, the cell grows to it)
    cells.push_back(cell);
  }
  const auto corners = [](const Aabb& b) {
    return std::array<double, 6>{b.min.x(), b.min.y(), b.min.z(), b.max.x(), b.max.y(), b.max.z()};
  };
  std::sort(cells.begin(), cells.end(), [&](const Aabb& a, const Aabb& b) { return corners(a) < corners(b); });
  cells.erase(std::unique(cells.begin(), cells.end(), [&](const Aabb& a, const Aabb& b) { return corners(a) == corners(b); }),
              cells.end());
  std::vector<std::pair<Aabb, Static>> added;
  for (const Aabb& cell : cells) {
    bool held = false;
    const Aabb probe = Aabb::ofPoint(cell.center());
    if (voxel_tree_) voxel_tree_->query(probe, [&](std::int32_t v) { return held = map_->occupied[v].contains(cell); });
    if (!held)
      static_.query(probe, [&](const Static& s, const Aabb& box) { return held = s.voxel && corners(box) == corners(cell); });
    if (!held) added.push_back({cell, Static{nullptr, -1, true}});
  }
  std::vector<Aabb>().swap(cells);
  Environment e = *this;
  e.point_voxels_ += static_cast<int>(added.size());
  e.static_ = static_.insertedAll(std::move(added));
  e.rescale();
  return e;
}

}  // namespace clearway
