#include <clearway/kinematics/robot_model.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace clearway {
namespace {

[[noreturn]] void fail(const std::string& robot, const std::string& what) {
  throw std::invalid_argument("RobotModel '" + robot + "': " + what);
}

bool hasAxis(JointType t) {
  return t == JointType::Revolute || t == JointType::Continuous || t == JointType::Prismatic || t == JointType::Planar;
}

}  // namespace

const char* jointTypeName(JointType type) noexcept {
  switch (type) {
    case JointType::Fixed: return "fixed";
    case JointType::Revolute: return "revolute";
    case JointType::Continuous: return "continuous";
    case JointType::Prismatic: return "prismatic";
    case JointType::Planar: return "planar";
    case JointType::Floating: return "floating";
  }
  return "unknown";
}

int jointVariableCount(JointType type) noexcept {
  switch (type) {
    case JointType::Fixed: return 0;
    case JointType::Revolute:
    case JointType::Continuous:
    case JointType::Prismatic: return 1;
    case JointType::Planar: return 3;
    case JointType::Floating: return 7;
  }
  return 0;
}

RobotModel::RobotModel(std::string name, std::vector<Link> links, std::vector<Joint> joints,
                       std::vector<TriangleMesh> meshes, std::vector<DisabledCollision> disabled,
                       std::vector<std::string> load_warnings)
    : name_(std::move(name)),
      links_(std::move(links)),
      joints_(std::move(joints)),
      meshes_(std::move(meshes)),
      load_warnings_(std::move(load_warnings)) {
  const int n_links = linkCount(), n_joints = jointCount();
  if (n_links == 0) fail(name_, "no links");
  if (n_joints != n_links - 1)
    fail(name_, "a tree of " + std::to_string(n_links) + " links has " + std::to_string(n_links - 1) +
                    " joints, got " + std::to_string(n_joints));
  for (int i = 0; i < n_links; ++i) {
    const Link& link = links_[i];
    if (!link_index_.emplace(link.name, i).second) fail(name_, "two links named '" + link.name + "'");
    if (i == 0) {
      if (link.parent_joint != -1) fail(name_, "the root link '" + link.name + "' has a parent joint");
    } else {
      if (link.parent_joint < 0 || link.parent_joint >= n_joints)
        fail(name_, "link '" + link.name + "' has no valid parent joint");
      const Joint& j = joints_[link.parent_joint];
      if (j.child_link != i) fail(name_, "joint '" + j.name + "' is not the parent of link '" + link.name + "'");
      if (j.parent_link < 0 || j.parent_link >= i)
        fail(name_, "links are not in topological order at '" + link.name + "'");
    }
    for (const CollisionElement& c : link.collisions) {
      if (c.primitive.has_value() == (c.mesh >= 0))
        fail(name_, "a collision element of link '" + link.name + "' must be either a primitive or a mesh");
      if (c.mesh >= static_cast<int>(meshes_.size()))
        fail(name_, "link '" + link.name + "' names mesh " + std::to_string(c.mesh) + " of " +
                        std::to_string(meshes_.size()));
      if (!c.origin.isFinite()) fail(name_, "link '" + link.name + "' has a non-finite collision origin");
    }
  }
  for (int j = 0; j < n_joints; ++j) {
    Joint& joint = joints_[j];
    if (!joint_index_.emplace(joint.name, j).second) fail(name_, "two joints named '" + joint.name + "'");
    if (joint.child_link <= 0 || joint.child_link >= n_links || links_[joint.child_link].parent_joint != j)
      fail(name_, "joint '" + joint.name + "' has an invalid child link");
    if (!joint.origin.isFinite()) fail(name_, "joint '" + joint.name + "' has a non-finite origin");
    if (hasAxis(joint.type)) {
      const double norm = joint.axis.norm();
      if (!(norm > 0.0) || !std::isfinite(norm))
        fail(name_, "joint '" + joint.name + "' has a zero or non-finite axis");
      joint.axis /= norm;
    }
    if (joint.type != JointType::Revolute && joint.type != JointType::Prismatic) {
      joint.lower = -std::numeric_limits<double>::infinity();
      joint.upper = std::numeric_limits<double>::infinity();
    }
    if (std::isnan(joint.lower) || std::isnan(joint.upper) || joint.lower > joint.upper)
      fail(name_, "joint '" + joint.name + "' has invalid limits");
    if (joint.isMimic()) {
      if (jointVariableCount(joint.type) != 1)
        fail(name_, "mimic joint '" + joint.name + "' must be revolute, continuous or prismatic");
      const int leader = joint.mimic.joint;
      if (leader >= n_joints || leader == j || joints_[leader].isMimic() || jointVariableCount(joints_[leader].type) != 1)
        fail(name_, "mimic joint '" + joint.name + "' needs a one-variable leader that is not a mimic itself");
      if (!std::isfinite(joint.mimic.multiplier) || !std::isfinite(joint.mimic.offset))
        fail(name_, "mimic joint '" + joint.name + "' has a non-finite multiplier or offset");
    }
  }

  // The joint vector: joints in order, each owning jointVariableCount(type) entries unless it is a mimic.
  static const char* const kPlanar[] = {"x", "y", "theta"};
  static const char* const kFloating[] = {"x", "y", "z", "qx", "qy", "qz", "qw"};
  for (int j = 0; j < n_joints; ++j) {
    Joint& joint = joints_[j];
    const int count = joint.isMimic() ? 0 : jointVariableCount(joint.type);
    joint.first_variable = count > 0 ? static_cast<int>(variables_.size()) : -1;
    for (int k = 0; k < count; ++k) {
      JointVariable v;
      v.joint = j;
      if (count == 1) {
        v.name = joint.name;
        v.lower = joint.lower;
        v.upper = joint.upper;
      } else {
        v.name = joint.name + "/" + (joint.type == JointType::Planar ? kPlanar[k] : kFloating[k]);
      }
      variables_.push_back(v);
    }
  }
  steps_.resize(links_.size());
  for (int i = 1; i < n_links; ++i) {
    const Joint& j = joints_[links_[i].parent_joint];
    detail::KinematicStep& s = steps_[i];
    s.parent = j.parent_link;
    s.origin = j.origin;
    s.axis = j.axis;
    s.mimic = j.isMimic();
    s.variable = s.mimic ? joints_[j.mimic.joint].first_variable : j.first_variable;
    if (s.mimic) s.multiplier = j.mimic.multiplier, s.offset = j.mimic.offset;
    using Kind = detail::KinematicStep::Kind;
    if (j.type == JointType::Fixed) {
      s.kind = Kind::Fixed;
    } else if (j.type == JointType::Revolute || j.type == JointType::Continuous) {
      const bool z = j.axis.x() == 0.0 && j.axis.y() == 0.0 && std::abs(j.axis.z()) == 1.0;
      s.kind = z ? Kind::TurnZ : Kind::Turn;
      s.axis_sign = z ? j.axis.z() : 1.0;
    } else if (j.type == JointType::Prismatic) {
      s.kind = Kind::Slide;
      s.axis = j.origin.R * j.axis;
    } else {
      s.kind = Kind::Other;
    }
  }
  for (int i = 0; i < variableCount(); ++i)
    if (!variable_index_.emplace(variables_[i].name, i).second)
      fail(name_, "two joint variables named '" + variables_[i].name + "'");

  for (DisabledCollision& d : disabled) {
    if (d.link_a < 0 || d.link_b < 0 || d.link_a >= n_links || d.link_b >= n_links || d.link_a == d.link_b)
      fail(name_, "a disabled collision pair names an invalid link");
    if (d.link_a > d.link_b) std::swap(d.link_a, d.link_b);
  }
  std::stable_sort(disabled.begin(), disabled.end(), [](const DisabledCollision& a, const DisabledCollision& b) {
    return std::make_pair(a.link_a, a.link_b) < std::make_pair(b.link_a, b.link_b);
  });
  for (DisabledCollision& d : disabled)
    if (disabled_.empty() || disabled_.back().link_a != d.link_a || disabled_.back().link_b != d.link_b)
      disabled_.push_back(std::move(d));
}

int RobotModel::linkIndex(const std::string& name) const {
  const auto it = link_index_.find(name);
  return it == link_index_.end() ? -1 : it->second;
}

int RobotModel::jointIndex(const std::string& name) const {
  const auto it = joint_index_.find(name);
  return it == joint_index_.end() ? -1 : it->second;
}

int RobotModel::variableIndex(const std::string& name) const {
  const auto it = variable_index_.find(name);
  return it == variable_index_.end() ? -1 : it->second;
}

std::vector<std::pair<int, int>> adjacentLinkPairs(const RobotModel& model) {
  const int n = model.linkCount();
  std::vector<std::vector<int>> neighbours(n);
  for (const Joint& j : model.joints()) {
    neighbours[j.parent_link].push_back(j.child_link);
    neighbours[j.child_link].push_back(j.parent_link);
  }
  auto hasGeometry = [&](int i) { return !model.link(i).collisions.empty(); };

  // From each link with geometry, walk the tree through links without geometry; every link with
  // geometry met on the way is adjacent (the path between them has no geometry in its interior).
  std::vector<std::pair<int, int>> pairs;
  std::vector<int> stack, seen(n, -1);
  for (int a = 0; a < n; ++a) {
    if (!hasGeometry(a)) continue;
    seen[a] = a;
    stack.assign(1, a);
    while (!stack.empty()) {
      const int i = stack.back();
      stack.pop_back();
      for (int k : neighbours[i]) {
        if (seen[k] == a) continue;
        seen[k] = a;
        if (hasGeometry(k)) {
          if (a < k) pairs.emplace_back(a, k);
        } else {
          stack.push_back(k);
        }
      }
    }
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace clearway
