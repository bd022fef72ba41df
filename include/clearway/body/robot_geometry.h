#pragma once
// A robot's bodies: the collision geometry of each of its links, built once from its model.
#include <clearway/body/link_geometry.h>
#include <clearway/kinematics/robot_model.h>

#include <memory>
#include <vector>

namespace clearway {

/// The collision geometry of every link of a robot (null for links without geometry). Immutable.
class RobotGeometry {
 public:
  /// Builds each link's trees and hull from the model's collision elements. Throws ShapeError naming
  /// the link when its geometry is unusable.
  explicit RobotGeometry(std::shared_ptr<const RobotModel> model, const TreeBuildOptions& options = {});
  /// The same, sharing the geometry of every link of `reuse` whose name the model also has: a body
  /// attached or detached rebuilds only what changed. The caller promises that same-named links have the
  /// same collision elements (true for models made from one another by attachBodies/detachBodies).
  RobotGeometry(std::shared_ptr<const RobotModel> model, const RobotGeometry& reuse, const TreeBuildOptions& options = {});

  /// The model the geometry was built from.
  const RobotModel& model() const noexcept { return *model_; }
  /// The same model, shared (it lives as long as any holder of this pointer).
  const std::shared_ptr<const RobotModel>& modelPtr() const noexcept { return model_; }
  /// Link i's geometry, or null when the link has no collision element.
  const LinkGeometry* link(int i) const noexcept { return links_[i].get(); }
  /// The same geometry of link i, shared (null for a link without geometry).
  const std::shared_ptr<const LinkGeometry>& linkPtr(int i) const noexcept { return links_[i]; }
  /// Links that have geometry, in link order.
  const std::vector<int>& geometricLinks() const noexcept { return geometric_; }

 private:
  RobotGeometry(std::shared_ptr<const RobotModel> model, const RobotGeometry* reuse, const TreeBuildOptions& options);
  std::shared_ptr<const RobotModel> model_;
  std::vector<std::shared_ptr<const LinkGeometry>> links_;
  std::vector<int> geometric_;
};

}  // namespace clearway
