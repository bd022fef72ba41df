#include <clearway/body/robot_geometry.h>

#include <clearway/detail/parallel_for.h>

#include <stdexcept>
#include <utility>

namespace clearway {

RobotGeometry::RobotGeometry(std::shared_ptr<const RobotModel> model, const TreeBuildOptions& options)
    : RobotGeometry(std::move(model), nullptr, options) {}

RobotGeometry::RobotGeometry(std::shared_ptr<const RobotModel> model, const RobotGeometry& reuse,
                             const TreeBuildOptions& options)
    : RobotGeometry(std::move(model), &reuse, options) {}

RobotGeometry::RobotGeometry(std::shared_ptr<const RobotModel> model, const RobotGeometry* reuse,
                             const TreeBuildOptions& options)
    : model_(std::move(model)) {
  if (!model_) throw std::invalid_argument("RobotGeometry: null robot model");
  links_.resize(model_->linkCount());
  std::vector<int> build;  // the links with collision geometry that `reuse` does not give
  for (int i = 0; i < model_->linkCount(); ++i) {
    const Link& link = model_->link(i);
    if (link.collisions.empty()) continue;
    geometric_.push_back(i);
    const int same = reuse ? reuse->model().linkIndex(link.name) : -1;
    if (same >= 0 && reuse->links_[same]) {
      links_[i] = reuse->links_[same];
      continue;
    }
    build.push_back(i);
  }
  // Each link's geometry on its own (its tree, hull, parts, cores: a mesh of 100k triangles takes a good
  // share of a load), on the machine's threads; the first failing link in order is the one reported.
  detail::parallelFor(build.size(), detail::loadThreads(0), [&](std::size_t k) {
    const int i = build[k];
    const Link& link = model_->link(i);
    try {
      links_[i] = std::make_shared<const LinkGeometry>(link.collisions, model_->meshes(), options);
      links_[i]->partBallMargin();  // (proven now, at load, rather than in the first query)
    } catch (const std::exception& e) {
      throw ShapeError("robot '" + model_->name() + "': link '" + link.name + "': " + e.what());
    }
  });
}

}  // namespace clearway
