#include <clearway/kinematics/attached_body.h>

#include <algorithm>
#include <stdexcept>

namespace clearway {

RobotModel attachBodies(const RobotModel& model, const std::vector<AttachedBody>& bodies,
                        const std::vector<TriangleMesh>& meshes) {
  std::vector<Link> links = model.links();
  std::vector<Joint> joints = model.joints();
  std::vector<TriangleMesh> all_meshes = model.meshes();
  std::vector<DisabledCollision> disabled = model.disabledCollisions();
  const int mesh_base = static_cast<int>(all_meshes.size());
  all_meshes.insert(all_meshes.end(), meshes.begin(), meshes.end());
  for (const AttachedBody& b : bodies) {
    const auto bad = [&](const std::string& reason) {
      throw std::invalid_argument("attached body '" + b.name + "': " + reason);
    };
    if (b.name.empty()) bad("a body needs a name");
    for (const Link& l : links)
      if (l.name == b.name) bad("its name is already a link of robot '" + model.name() + "'");
    if (b.link < 0 || b.link >= model.linkCount()) bad("link index " + std::to_string(b.link) + " out of range");
    if (!b.pose.isFinite() || !b.element.origin.isFinite()) bad("its pose is not finite");
    CollisionElement element = b.element;
    if (element.mesh >= 0) {
      if (element.mesh >= static_cast<int>(meshes.size())) bad("mesh index " + std::to_string(element.mesh) + " out of range");
      element.mesh += mesh_base;
    } else if (!element.primitive) {
      bad("it has neither a primitive nor a mesh");
    }
    const int index = static_cast<int>(links.size());
    Joint j;
    j.name = b.name + "_joint";
    j.type = JointType::Fixed;
    j.parent_link = b.link;
    j.child_link = index;
    j.origin = b.pose;
    joints.push_back(j);
    Link l;
    l.name = b.name;
    l.parent_joint = static_cast<int>(joints.size()) - 1;
    l.collisions.push_back(element);
    links.push_back(std::move(l));
    for (const int t : b.touch_links) {
      if (t < 0 || t >= model.linkCount()) bad("touch link index " + std::to_string(t) + " out of range");
      disabled.push_back({std::min(t, index), std::max(t, index), "Touch"});
    }
  }
  return RobotModel(model.name(), std::move(links), std::move(joints), std::move(all_meshes), std::move(disabled),
                    model.loadWarnings());
}

}  // namespace clearway
