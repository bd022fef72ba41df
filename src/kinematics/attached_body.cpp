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

RobotModel detachBodies(const RobotModel& model, const std::vector<std::string>& names) {
  std::vector<char> gone_link(model.linkCount(), 0), gone_joint(model.jointCount(), 0);
  std::vector<char> has_child(model.linkCount(), 0);
  for (const Joint& j : model.joints()) has_child[j.parent_link] = 1;
  for (const std::string& name : names) {
    const int l = model.linkIndex(name);
    const auto bad = [&](const std::string& reason) {
      throw std::invalid_argument("detach '" + name + "': " + reason);
    };
    if (l < 0) bad("robot '" + model.name() + "' has no such link");
    const int j = model.link(l).parent_joint;
    if (j < 0 || model.joint(j).type != JointType::Fixed) bad("it does not hang from a fixed joint");
    if (has_child[l]) bad("other links hang from it");
    gone_link[l] = 1;
    gone_joint[j] = 1;
  }
  // New indices of what stays (−1: gone).
  const auto renumber = [](const std::vector<char>& gone) {
    std::vector<int> to(gone.size(), -1);
    int n = 0;
    for (std::size_t i = 0; i < gone.size(); ++i)
      if (!gone[i]) to[i] = n++;
    return to;
  };
  const std::vector<int> link_to = renumber(gone_link), joint_to = renumber(gone_joint);
  std::vector<char> mesh_unused(model.meshes().size(), 1);
  for (int l = 0; l < model.linkCount(); ++l)
    if (!gone_link[l])
      for (const CollisionElement& e : model.link(l).collisions)
        if (e.mesh >= 0) mesh_unused[e.mesh] = 0;
  const std::vector<int> mesh_to = renumber(mesh_unused);

  std::vector<Link> links;
  for (int l = 0; l < model.linkCount(); ++l) {
    if (gone_link[l]) continue;
    Link link = model.link(l);
    if (link.parent_joint >= 0) link.parent_joint = joint_to[link.parent_joint];
    for (CollisionElement& e : link.collisions)
      if (e.mesh >= 0) e.mesh = mesh_to[e.mesh];
    links.push_back(std::move(link));
  }
  std::vector<Joint> joints;
  for (int j = 0; j < model.jointCount(); ++j) {
    if (gone_joint[j]) continue;
    Joint joint = model.joint(j);
    joint.parent_link = link_to[joint.parent_link];
    joint.child_link = link_to[joint.child_link];
    if (joint.mimic.joint >= 0) joint.mimic.joint = joint_to[joint.mimic.joint];
    joints.push_back(std::move(joint));
  }
  std::vector<TriangleMesh> meshes;
  for (std::size_t m = 0; m < model.meshes().size(); ++m)
    if (!mesh_unused[m]) meshes.push_back(model.meshes()[m]);
  std::vector<DisabledCollision> disabled;
  for (DisabledCollision d : model.disabledCollisions()) {
    if (gone_link[d.link_a] || gone_link[d.link_b]) continue;
    d.link_a = link_to[d.link_a];
    d.link_b = link_to[d.link_b];
    disabled.push_back(std::move(d));
  }
  return RobotModel(model.name(), std::move(links), std::move(joints), std::move(meshes), std::move(disabled),
                    model.loadWarnings());
}

}  // namespace clearway
