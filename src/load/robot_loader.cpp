// loadRobot: the URDF outline (our first pass, src/load/urdf_outline.cpp) checks the file and fixes the
// order; urdfdom builds the links, joints and geometry; meshes come through loadMesh; the SRDF's
// disable_collisions pairs through tinyxml2. Every problem becomes a LoadError or a warning naming the
// file and the element.
#include <clearway/load/robot_loader.h>

#include <clearway/load/input_limits.h>
#include <clearway/load/mesh_loader.h>

#include "load/mesh_uri.h"
#include "load/urdf_outline.h"

#include <console_bridge/console.h>
#include <tinyxml2.h>
#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <unordered_map>
#include <unordered_set>

namespace clearway {
namespace {

using detail::UrdfOutline;

// A reader's message (urdfdom's, tinyxml2's) is cut to this many characters: it may quote the file.
constexpr std::size_t kReaderChars = 80;

// urdfdom speaks through console_bridge, whose output handler is global: collect its messages while
// one parse runs (one parse at a time), then put back whatever handler the application had.
class UrdfdomMessages : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) {
      errors.push_back(inputExcerpt(text, kReaderChars));
    } else if (level == console_bridge::CONSOLE_BRIDGE_LOG_WARN) {
      warnings.push_back(inputExcerpt(text, kReaderChars));
    }
  }
  std::vector<std::string> errors, warnings;
};

urdf::ModelInterfaceSharedPtr parseWithUrdfdom(const std::string& text, const std::string& path,
                                               std::vector<std::string>* warnings) {
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  UrdfdomMessages messages;
  struct Restore {
    ~Restore() { console_bridge::restorePreviousOutputHandler(); }
  };
  urdf::ModelInterfaceSharedPtr model;
  {
    console_bridge::useOutputHandler(&messages);
    Restore restore;
    try {
      model = urdf::parseURDF(text);
    } catch (const std::exception& e) {
      messages.errors.push_back(inputExcerpt(e.what(), kReaderChars));
    }
  }
  for (const std::string& w : messages.warnings) warnings->push_back(LoadError::format(path, "", "urdfdom: " + w));
  if (model == nullptr || !messages.errors.empty()) {
    std::string reason = "urdfdom rejects the file";
    for (const std::string& e : messages.errors) reason += "; " + e;
    throw LoadError(path, "", reason);
  }
  return model;
}

Pose toPose(const urdf::Pose& p) {
  return Pose::fromQuaternion(p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w,
                              Vec3(p.position.x, p.position.y, p.position.z));
}

JointType toJointType(int urdf_type) {
  switch (urdf_type) {
    case urdf::Joint::REVOLUTE: return JointType::Revolute;
    case urdf::Joint::CONTINUOUS: return JointType::Continuous;
    case urdf::Joint::PRISMATIC: return JointType::Prismatic;
    case urdf::Joint::PLANAR: return JointType::Planar;
    case urdf::Joint::FLOATING: return JointType::Floating;
    default: return JointType::Fixed;
  }
}

class Loader {
 public:
  Loader(const std::string& urdf, const LoadOptions& options)
      : urdf_(urdf), urdf_dir_(std::filesystem::path(urdf).parent_path().string()), options_(options) {}

  RobotModel load(const std::string& srdf);

 private:
  void buildLinks(const urdf::ModelInterface& model);
  void buildJoints(const urdf::ModelInterface& model);
  CollisionElement convert(const urdf::Collision& c, const std::string& element);
  int mesh(const urdf::Mesh& m, const std::string& element);
  std::vector<DisabledCollision> readSrdf(const std::string& srdf);
  void warn(const std::string& element, const std::string& reason) {
    warnings_.push_back(LoadError::format(urdf_, element, reason));
  }

  std::string urdf_, urdf_dir_;
  const LoadOptions& options_;
  UrdfOutline outline_;
  std::vector<Link> links_;
  std::vector<Joint> joints_;
  std::vector<TriangleMesh> meshes_;
  std::map<std::tuple<std::string, double, double, double>, int> mesh_index_;
  std::unordered_map<std::string, int> link_index_;
  std::vector<std::string> warnings_;
  std::set<std::string> mesh_warnings_;  // mesh warnings given so far (each begins with the mesh's path)
};

RobotModel Loader::load(const std::string& srdf) {
  outline_ = detail::readUrdfOutline(urdf_);
  if (outline_.links.size() > static_cast<std::size_t>(kMaxLinks))
    throw LoadError(urdf_, "<robot>",
                    std::to_string(outline_.links.size()) + " links, more than the " + std::to_string(kMaxLinks) +
                        " a robot may have");
  for (const auto& w : outline_.warnings) warn(w.element, w.reason);
  const urdf::ModelInterfaceSharedPtr model = parseWithUrdfdom(outline_.text_for_urdfdom, urdf_, &warnings_);
  buildLinks(*model);
  buildJoints(*model);
  std::vector<DisabledCollision> disabled;
  if (!srdf.empty()) disabled = readSrdf(srdf);
  try {
    return RobotModel(outline_.robot_name, std::move(links_), std::move(joints_), std::move(meshes_),
                      std::move(disabled), std::move(warnings_));
  } catch (const std::invalid_argument& e) {
    throw LoadError(urdf_, "", e.what());
  }
}

void Loader::buildLinks(const urdf::ModelInterface& model) {
  for (std::size_t k = 0; k < outline_.link_order.size(); ++k) {
    const UrdfOutline::Link& outline = outline_.links[outline_.link_order[k]];
    link_index_[outline.name] = static_cast<int>(k);
    const urdf::LinkConstSharedPtr link = model.getLink(outline.name);
    if (link == nullptr) throw LoadError(urdf_, outline.element, "urdfdom lost this link");

    Link out;
    out.name = outline.name;
    out.parent_joint = k == 0 ? -1 : static_cast<int>(k) - 1;
    // Capsules come from the outline, everything else from urdfdom, in document order.
    std::size_t next = 0;
    for (const UrdfOutline::Collision& c : outline.collisions) {
      if (c.capsule) {
        CollisionElement e;
        e.origin = c.origin;
        e.primitive = Capsule(c.radius, 0.5 * c.length);
        out.collisions.push_back(std::move(e));
        continue;
      }
      if (next >= link->collision_array.size() || link->collision_array[next] == nullptr)
        throw LoadError(urdf_, c.element, "urdfdom dropped this collision element");
      out.collisions.push_back(convert(*link->collision_array[next++], c.element));
    }
    if (next != link->collision_array.size())
      throw LoadError(urdf_, outline.element, "urdfdom found collision elements the first pass did not");
    if (outline.collisions.empty() && outline.visuals > 0)
      warn(outline.element, "has <visual> but no <collision>: it is never checked for collisions");
    links_.push_back(std::move(out));
  }
}

CollisionElement Loader::convert(const urdf::Collision& c, const std::string& element) {
  CollisionElement e;
  e.origin = toPose(c.origin);
  if (c.geometry == nullptr) throw LoadError(urdf_, element, "no geometry");
  try {
    switch (c.geometry->type) {
      case urdf::Geometry::BOX: {
        const auto& box = static_cast<const urdf::Box&>(*c.geometry);
        e.primitive = Box(0.5 * Vec3(box.dim.x, box.dim.y, box.dim.z));
        break;
      }
      case urdf::Geometry::SPHERE:
        e.primitive = Sphere(static_cast<const urdf::Sphere&>(*c.geometry).radius);
        break;
      case urdf::Geometry::CYLINDER: {
        const auto& cylinder = static_cast<const urdf::Cylinder&>(*c.geometry);
        e.primitive = Cylinder(cylinder.radius, 0.5 * cylinder.length);
        break;
      }
      case urdf::Geometry::MESH:
        e.mesh = mesh(static_cast<const urdf::Mesh&>(*c.geometry), element);
        break;
    }
  } catch (const ShapeError& error) {
    throw LoadError(urdf_, element, error.what());
  }
  return e;
}

int Loader::mesh(const urdf::Mesh& m, const std::string& element) {
  const detail::ResolvedUri uri = detail::resolveMeshUri(m.filename, urdf_dir_, options_.package_paths);
  // As written, but without control characters (a NUL would end the message) and at most PATH_MAX long.
  const std::string filename = inputExcerpt(m.filename, 4096);
  if (!uri.error.empty()) throw LoadError(urdf_, element, "mesh '" + filename + "': " + uri.error);
  const auto key = std::make_tuple(uri.path, m.scale.x, m.scale.y, m.scale.z);
  const auto found = mesh_index_.find(key);
  if (found != mesh_index_.end()) return found->second;

  std::vector<std::string> mesh_warnings;
  try {
    meshes_.push_back(loadMesh(uri.path, Vec3(m.scale.x, m.scale.y, m.scale.z), &mesh_warnings, options_.mesh));
  } catch (const LoadError& error) {
    throw LoadError(urdf_, element, "mesh '" + filename + "': " + error.what());
  }
  // Once per file: a mesh used at two scales (or through two URIs) says the same things twice.
  for (const std::string& w : mesh_warnings)
    if (mesh_warnings_.insert(w).second) warn(element, "mesh '" + filename + "': " + w);
  const int index = static_cast<int>(meshes_.size()) - 1;
  mesh_index_.emplace(key, index);
  return index;
}

void Loader::buildJoints(const urdf::ModelInterface& model) {
  std::unordered_map<std::string, int> joint_index;
  for (std::size_t k = 0; k < outline_.joint_order.size(); ++k)
    joint_index[outline_.joints[outline_.joint_order[k]].name] = static_cast<int>(k);

  for (std::size_t k = 0; k < outline_.joint_order.size(); ++k) {
    const UrdfOutline::Joint& outline = outline_.joints[outline_.joint_order[k]];
    const urdf::JointConstSharedPtr joint = model.getJoint(outline.name);
    if (joint == nullptr) throw LoadError(urdf_, outline.element, "urdfdom lost this joint");
    Joint out;
    out.name = outline.name;
    out.type = toJointType(joint->type);
    out.parent_link = link_index_.at(outline_.links[outline.parent].name);
    out.child_link = link_index_.at(outline_.links[outline.child].name);
    out.origin = toPose(joint->parent_to_joint_origin_transform);
    out.axis = Vec3(joint->axis.x, joint->axis.y, joint->axis.z);
    if (joint->limits) {
      if (out.type == JointType::Revolute || out.type == JointType::Prismatic) {
        out.lower = joint->limits->lower;
        out.upper = joint->limits->upper;
      }
      if (joint->limits->velocity > 0.0) out.velocity = joint->limits->velocity;
    }
    if (joint->mimic && out.type == JointType::Fixed) {
      // urdfdom accepts it and MoveIt ignores it: a fixed joint has no value for a mimic to set.
      warn(outline.element, "a fixed joint cannot mimic: <mimic joint=\"" + joint->mimic->joint_name + "\"> ignored");
    } else if (joint->mimic) {
      const auto leader = joint_index.find(joint->mimic->joint_name);
      if (leader == joint_index.end())
        throw LoadError(urdf_, outline.element, "mimics '" + joint->mimic->joint_name + "', which is not a joint");
      out.mimic.joint = leader->second;
      out.mimic.multiplier = joint->mimic->multiplier;
      out.mimic.offset = joint->mimic->offset;
      if (jointVariableCount(out.type) != 1)
        throw LoadError(urdf_, outline.element, std::string("a ") + jointTypeName(out.type) + " joint cannot mimic");
    }
    joints_.push_back(std::move(out));
  }

  // A mimic of a mimic follows the first joint of the chain: compose value = m·(m'·q + o') + o.
  for (Joint& j : joints_) {
    if (!j.isMimic()) continue;
    for (std::size_t steps = 0; joints_[j.mimic.joint].isMimic(); ++steps) {
      const Mimic& next = joints_[j.mimic.joint].mimic;
      if (steps >= joints_.size())
        throw LoadError(urdf_, outline_.joints[outline_.joint_order[&j - joints_.data()]].element,
                        "mimic cycle: the chain of mimicked joints comes back to itself");
      j.mimic.offset += j.mimic.multiplier * next.offset;
      j.mimic.multiplier *= next.multiplier;
      j.mimic.joint = next.joint;
    }
    const Joint& leader = joints_[j.mimic.joint];
    const std::string& element = outline_.joints[outline_.joint_order[&j - joints_.data()]].element;
    if (jointVariableCount(leader.type) != 1)
      throw LoadError(urdf_, element,
                      "mimics '" + leader.name + "', a " + jointTypeName(leader.type) + " joint (not one variable)");
    // Bounded as a held value is: a multiplier of 1e300 placed a link 1e300 m away (at infinity, composed).
    for (const auto& [what, value] : {std::pair{"multiplier", j.mimic.multiplier}, std::pair{"offset", j.mimic.offset}})
      if (!(std::abs(value) <= kMaxJointValue)) {
        std::ostringstream text;
        text << std::setprecision(17) << value;
        throw LoadError(urdf_, element,
                        std::string("mimic ") + what + " " + text.str() + " (composed along its chain of mimics) " +
                            "is beyond ±1e6, the largest joint value an input may give");
      }
  }
}

std::vector<DisabledCollision> Loader::readSrdf(const std::string& srdf) {
  using tinyxml2::XMLElement;
  tinyxml2::XMLDocument doc;
  const tinyxml2::XMLError status = doc.LoadFile(srdf.c_str());
  if (status == tinyxml2::XML_ERROR_FILE_NOT_FOUND || status == tinyxml2::XML_ERROR_FILE_COULD_NOT_BE_OPENED)
    throw LoadError(srdf, "", "cannot open the file");
  if (status != tinyxml2::XML_SUCCESS)
    throw LoadError(srdf, "line " + std::to_string(doc.ErrorLineNum()), "malformed XML: " + inputExcerpt(doc.ErrorStr(), kReaderChars));
  const XMLElement* robot = doc.RootElement();
  if (robot == nullptr || std::string(robot->Name()) != "robot") throw LoadError(srdf, "", "the root element is not <robot>");
  const char* name = robot->Attribute("name");
  if (name != nullptr && outline_.robot_name != name)
    warnings_.push_back(LoadError::format(srdf, "<robot>", "names robot '" + inputExcerpt(name) + "', the URDF '" +
                                                               inputExcerpt(outline_.robot_name) + "'"));

  std::vector<DisabledCollision> pairs;
  std::set<std::pair<int, int>> seen;
  // Pairs naming a link the URDF lacks are skipped as MoveIt skips them (SRDFs shipped with robots often
  // name links of another variant); one warning for all of them, not one per pair.
  std::size_t unknown_pairs = 0;
  std::vector<std::string> unknown_links;  // in order of first mention, for the warning
  std::unordered_set<std::string> unknown_seen;  // the same, to look up: SRDFs can name tens of thousands
  for (const XMLElement* e = robot->FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
    const std::string tag = e->Name();
    const std::string element = "<" + tag + "> (line " + std::to_string(e->GetLineNum()) + ")";
    if (tag == "disable_default_collisions" || tag == "enable_collisions") {
      warnings_.push_back(LoadError::format(srdf, element, "not supported, ignored (more pairs are checked)"));
      continue;
    }
    if (tag != "disable_collisions") continue;
    int link[2];
    bool known = true;
    for (int k = 0; k < 2; ++k) {
      const char* attribute = k == 0 ? "link1" : "link2";
      const char* value = e->Attribute(attribute);
      if (value == nullptr) throw LoadError(srdf, element, std::string("no ") + attribute + " attribute");
      const auto it = link_index_.find(value);
      if (it == link_index_.end()) {
        known = false;
        if (unknown_seen.insert(value).second) unknown_links.emplace_back(value);
        continue;
      }
      link[k] = it->second;
    }
    if (!known) {
      ++unknown_pairs;
      continue;
    }
    if (link[0] == link[1]) {
      warnings_.push_back(LoadError::format(srdf, element, "names one link twice, ignored"));
      continue;
    }
    if (!seen.emplace(std::min(link[0], link[1]), std::max(link[0], link[1])).second) {
      warnings_.push_back(LoadError::format(srdf, element, "repeats a pair listed before, ignored"));
      continue;
    }
    const char* reason = e->Attribute("reason");
    pairs.push_back({link[0], link[1], reason ? reason : ""});
  }
  if (unknown_pairs > 0) {
    constexpr std::size_t kNamesShown = 5;
    std::string names;
    for (std::size_t i = 0; i < std::min(unknown_links.size(), kNamesShown); ++i)
      names += (i ? ", '" : "'") + unknown_links[i] + "'";
    if (unknown_links.size() > kNamesShown) names += ", ...";
    warnings_.push_back(LoadError::format(
        srdf, "", std::to_string(unknown_pairs) + " <disable_collisions> pair" + (unknown_pairs > 1 ? "s" : "") +
                      " skipped (as MoveIt does): " + std::to_string(unknown_links.size()) + " link name" +
                      (unknown_links.size() > 1 ? "s" : "") + " not in " + urdf_ + ": " + names));
  }
  return pairs;
}

}  // namespace

RobotModel loadRobot(const std::string& urdf_path, const std::string& srdf_path, const LoadOptions& options) {
  return Loader(urdf_path, options).load(srdf_path);
}

}  // namespace clearway
