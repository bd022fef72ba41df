#pragma once
// What the parts of motion/ share and callers do not: the reference state, rigid bodies, quaternion ends.
#include <clearway/scene/scene.h>

#include <Eigen/Core>
#include <vector>

namespace clearway::motion_detail {

// A state inside the scene's bounds (their midpoints) with unit quaternions, where the poses are defined.
inline std::vector<double> referenceState(const Scene& scene) {
  const RobotModel& model = scene.robot();
  std::vector<double> q(scene.dimension());
  for (int i = 0; i < scene.dimension(); ++i) {
    const double lo = scene.lower(i), hi = scene.upper(i);
    q[i] = std::isfinite(lo) && std::isfinite(hi) ? 0.5 * (lo + hi) : std::isfinite(lo) ? lo : std::isfinite(hi) ? hi : 0.0;
    const int v = scene.groupVariables()[i];
    const Joint& joint = model.joint(model.variables()[v].joint);
    if (joint.type == JointType::Floating && v >= joint.first_variable + 3) q[i] = v == joint.first_variable + 6 ? 1.0 : 0.0;
  }
  return q;
}

// Per link: the link nearest the root that it moves rigidly with (joined by joints the group does not move).
inline std::vector<int> rigidAnchors(const Scene& scene) {
  const RobotModel& model = scene.robot();
  std::vector<char> in_group(model.variableCount(), 0);
  for (const int v : scene.groupVariables()) in_group[v] = 1;
  const auto still = [&](const Joint& joint) {
    const Joint& owner = joint.isMimic() ? model.joint(joint.mimic.joint) : joint;
    for (int k = 0; owner.first_variable >= 0 && k < jointVariableCount(owner.type); ++k)
      if (in_group[owner.first_variable + k]) return false;
    return true;
  };
  std::vector<int> anchor(model.linkCount());
  for (int l = 0; l < model.linkCount(); ++l) {
    int a = l;
    while (model.link(a).parent_joint >= 0 && still(model.joint(model.link(a).parent_joint))) a = model.parentLink(a);
    anchor[l] = a;
  }
  return anchor;
}


// The unit quaternions of q0[0..3] and q1[0..3], the second on the first's side (the short arc).
inline void alignedUnit(const double* q0, const double* q1, Eigen::Vector4d& a, Eigen::Vector4d& b) noexcept {
  a = Eigen::Vector4d(q0[0], q0[1], q0[2], q0[3]);
  b = Eigen::Vector4d(q1[0], q1[1], q1[2], q1[3]);
  a.normalize();
  b.normalize();
  if (a.dot(b) < 0.0) b = -b;
}

}  // namespace clearway::motion_detail
