#include "load/urdf_outline.h"

#include <clearway/load/input_limits.h>
#include <clearway/load/load_error.h>

#include <tinyxml2.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <unordered_map>

namespace clearway::detail {
namespace {

using tinyxml2::XMLElement;

std::string attribute(const XMLElement* e, const char* name) {
  const char* v = e->Attribute(name);
  return v ? v : "";
}

// "link 'base' <collision> <origin> (line 9)": the element's tags up to its link or joint, and its line.
std::string describe(const XMLElement* e) {
  std::vector<std::string> parts;
  for (const XMLElement* x = e; x != nullptr; x = x->Parent() ? x->Parent()->ToElement() : nullptr) {
    const std::string tag = x->Name();
    if (tag == "robot") break;
    if (tag == "link" || tag == "joint") {
      parts.push_back(tag + " '" + attribute(x, "name") + "'");
      break;
    }
    parts.push_back("<" + tag + ">");
  }
  std::string s;
  for (auto it = parts.rbegin(); it != parts.rend(); ++it) s += (s.empty() ? "" : " ") + *it;
  return s + " (line " + std::to_string(e->GetLineNum()) + ")";
}

class Reader {
 public:
  explicit Reader(const std::string& path) : path_(path) {}

  UrdfOutline read();

 private:
  [[noreturn]] void fail(const XMLElement* e, const std::string& reason) const {
    throw LoadError(path_, e ? describe(e) : "", reason);
  }

  // Exactly n whitespace-separated finite numbers in attribute name of e (absent: false, out untouched).
  bool numbers(const XMLElement* e, const char* name, int n, double* out) const;
  double number(const XMLElement* e, const char* name, double fallback) const {
    double x = fallback;
    numbers(e, name, 1, &x);
    return x;
  }
  // Lengths in metres no longer than the input limit: |x| ≤ kMaxInputLength. A shorter one of any size,
  // down to 1e-300 (CAD exporters' residues), is a length like any other.
  void checkLengths(const XMLElement* e, const char* name, const double* x, int n) const;
  // Sizes in (0, kMinInputLength) are grown to kMinInputLength, with a warning, and written back to the
  // attribute that urdfdom reads: below it the hull arithmetic has no digits left, and the grown solid
  // holds the one given, so no contact is lost.
  void growTinySizes(const XMLElement* e, const char* name, double* x, int n);
  void checkOrigin(const XMLElement* owner, Pose* pose = nullptr) const;
  UrdfOutline::Collision readCollision(const XMLElement* c);
  void readLink(const XMLElement* e);
  void readJoint(const XMLElement* e);
  void orderTree();

  std::string path_;
  UrdfOutline out_;
  std::unordered_map<std::string, int> link_index_;
  std::vector<const XMLElement*> link_elements_, joint_elements_;
};

bool Reader::numbers(const XMLElement* e, const char* name, int n, double* out) const {
  const char* text = e->Attribute(name);
  if (text == nullptr) return false;
  const char* p = text;
  const char* end = text + std::strlen(text);
  for (int i = 0; i < n; ++i) {
    while (p < end && std::isspace(static_cast<unsigned char>(*p))) ++p;
    if (p < end && *p == '+') ++p;
    double x = 0.0;
    auto [next, ec] = std::from_chars(p, end, x);
    if (ec == std::errc::result_out_of_range) {
      // Below the smallest double (1e-330) is a residue that rounds to 0 or a subnormal, as strtod and
      // urdfdom read it; beyond the largest is no number at all.
      x = std::strtod(std::string(p, next).c_str(), nullptr);
      if (!(std::abs(x) < 1.0)) fail(e, std::string(name) + "=\"" + text + "\" has a value out of the range of double");
      ec = std::errc();
    }
    if (ec != std::errc() || next == p || (next < end && !std::isspace(static_cast<unsigned char>(*next))))
      fail(e, std::string(name) + "=\"" + text + "\": expected " + std::to_string(n) + " number" + (n > 1 ? "s" : ""));
    if (!std::isfinite(x)) fail(e, std::string(name) + "=\"" + text + "\" has a non-finite value (NaN or infinity)");
    out[i] = x;
    p = next;
  }
  while (p < end && std::isspace(static_cast<unsigned char>(*p))) ++p;
  if (p != end) fail(e, std::string(name) + "=\"" + text + "\": expected " + std::to_string(n) + " numbers, got more");
  return true;
}

void Reader::checkLengths(const XMLElement* e, const char* name, const double* x, int n) const {
  for (int i = 0; i < n; ++i) {
    if (std::abs(x[i]) <= kMaxInputLength) continue;
    std::ostringstream value;
    value << std::setprecision(17) << x[i];
    fail(e, std::string(name) + "=\"" + attribute(e, name) + "\": " + value.str() +
                " m is beyond the largest length an input may give (1e6 m)");
  }
}

void Reader::growTinySizes(const XMLElement* e, const char* name, double* x, int n) {
  bool grown = false;
  for (int i = 0; i < n; ++i) {
    if (x[i] > 0.0 && x[i] < kMinInputLength) {
      x[i] = kMinInputLength;
      grown = true;
    }
  }
  if (!grown) return;
  std::string text;
  for (int i = 0; i < n; ++i) {
    char buffer[32];
    const auto end = std::to_chars(buffer, buffer + sizeof buffer, x[i]).ptr;  // reads back as x[i]
    text += (i ? " " : "") + std::string(buffer, end);
  }
  out_.warnings.push_back({describe(e), std::string(name) + "=\"" + attribute(e, name) +
                                            "\" is below the smallest size Clearway computes with (1e-9 m): "
                                            "checked as " + name + "=\"" + text + "\""});
  // The document is this reader's own copy, and urdfdom reads the size from it.
  const_cast<XMLElement*>(e)->SetAttribute(name, text.c_str());
}

void Reader::checkOrigin(const XMLElement* owner, Pose* pose) const {
  const XMLElement* o = owner->FirstChildElement("origin");
  if (o == nullptr) return;
  double xyz[3] = {0, 0, 0}, rpy[3] = {0, 0, 0};
  if (numbers(o, "xyz", 3, xyz)) checkLengths(o, "xyz", xyz, 3);
  numbers(o, "rpy", 3, rpy);
  if (pose) {
    pose->t = Vec3(xyz[0], xyz[1], xyz[2]);
    pose->R = rotationFromRpy(rpy[0], rpy[1], rpy[2]);
  }
}

UrdfOutline::Collision Reader::readCollision(const XMLElement* c) {
  UrdfOutline::Collision out;
  out.element = describe(c);
  checkOrigin(c, &out.origin);
  const XMLElement* geometry = c->FirstChildElement("geometry");
  const XMLElement* g = geometry ? geometry->FirstChildElement() : nullptr;
  if (g == nullptr) fail(c, "no <geometry> shape");
  if (g->NextSiblingElement() != nullptr) fail(geometry, "more than one shape in one <geometry>");
  const std::string shape = g->Name();
  double v[3] = {0, 0, 0};
  if (shape == "box") {
    if (!numbers(g, "size", 3, v)) fail(g, "box without size");
    if (v[0] < 0 || v[1] < 0 || v[2] < 0) fail(g, "box size must not be negative");
    checkLengths(g, "size", v, 3);
    growTinySizes(g, "size", v, 3);
  } else if (shape == "sphere" || shape == "cylinder" || shape == "capsule") {
    if (!numbers(g, "radius", 1, &v[0]) || !(v[0] > 0)) fail(g, shape + " needs a radius > 0");
    checkLengths(g, "radius", &v[0], 1);
    growTinySizes(g, "radius", &v[0], 1);
    if (shape != "sphere" && (!numbers(g, "length", 1, &v[1]) || v[1] < 0))
      fail(g, shape + " needs a length >= 0");
    if (shape != "sphere") {
      checkLengths(g, "length", &v[1], 1);
      growTinySizes(g, "length", &v[1], 1);
    }
    if (shape == "capsule") {
      out.capsule = true;
      out.radius = v[0];
      out.length = v[1];
    }
  } else if (shape == "mesh") {
    if (attribute(g, "filename").empty()) fail(g, "mesh without filename");
    if (numbers(g, "scale", 3, v) && (v[0] == 0 || v[1] == 0 || v[2] == 0))
      fail(g, "mesh scale has a zero component");
  } else {
    fail(g, "unsupported geometry <" + shape + "> (expected box, sphere, cylinder, capsule or mesh)");
  }
  return out;
}

void Reader::readLink(const XMLElement* e) {
  UrdfOutline::Link link;
  link.name = attribute(e, "name");
  link.element = describe(e);
  if (link.name.empty()) fail(e, "link without a name");
  if (!link_index_.emplace(link.name, static_cast<int>(out_.links.size())).second)
    fail(e, "a second link named '" + link.name + "'");
  for (const XMLElement* c = e->FirstChildElement(); c != nullptr; c = c->NextSiblingElement()) {
    const std::string tag = c->Name();
    if (tag == "collision") {
      link.collisions.push_back(readCollision(c));
    } else if (tag == "visual") {
      ++link.visuals;  // never read otherwise, as in urdfdom and MoveIt: nothing in it can refuse the robot
    }
  }
  out_.links.push_back(std::move(link));
  link_elements_.push_back(e);
}

void Reader::readJoint(const XMLElement* e) {
  static const char* const kTypes[] = {"revolute", "continuous", "prismatic", "fixed", "floating", "planar"};
  UrdfOutline::Joint joint;
  joint.name = attribute(e, "name");
  joint.element = describe(e);
  if (joint.name.empty()) fail(e, "joint without a name");
  const std::string type = attribute(e, "type");
  if (std::none_of(std::begin(kTypes), std::end(kTypes), [&](const char* t) { return type == t; }))
    fail(e, "unknown joint type '" + type + "' (expected revolute, continuous, prismatic, fixed, floating or planar)");
  checkOrigin(e);
  for (const char* end : {"parent", "child"}) {
    const XMLElement* p = e->FirstChildElement(end);
    if (p == nullptr) fail(e, std::string("no <") + end + ">");
    const std::string name = attribute(p, "link");
    const auto it = link_index_.find(name);
    if (it == link_index_.end()) fail(p, "no link named '" + name + "'");
    (std::strcmp(end, "parent") == 0 ? joint.parent : joint.child) = it->second;
  }
  if (const XMLElement* axis = e->FirstChildElement("axis")) {
    double a[3];
    if (numbers(axis, "xyz", 3, a) && a[0] == 0 && a[1] == 0 && a[2] == 0 && type != "fixed" && type != "floating")
      fail(axis, "zero axis");
  }
  const XMLElement* limit = e->FirstChildElement("limit");
  if (limit == nullptr && (type == "revolute" || type == "prismatic"))
    fail(e, "a " + type + " joint needs <limit lower=... upper=... velocity=... effort=...>");
  if (limit != nullptr) {
    const double lower = number(limit, "lower", 0.0), upper = number(limit, "upper", 0.0);
    number(limit, "velocity", 0.0);
    number(limit, "effort", 0.0);
    if (type == "prismatic" && !(std::abs(lower) <= kMaxInputLength && std::abs(upper) <= kMaxInputLength))
      fail(limit, "a prismatic joint's limits must lie within ±1e6 m (the largest length an input may give)");
    if ((type == "revolute" || type == "prismatic") && lower > upper) {
      std::ostringstream s;
      s << "inverted limits: lower " << lower << " > upper " << upper;
      fail(limit, s.str());
    }
  }
  if (const XMLElement* mimic = e->FirstChildElement("mimic")) {
    number(mimic, "multiplier", 1.0);
    number(mimic, "offset", 0.0);
  }
  out_.joints.push_back(std::move(joint));
  joint_elements_.push_back(e);
}

// The tree: every link the child of at most one joint, one root, every link reachable from it.
void Reader::orderTree() {
  const int n = static_cast<int>(out_.links.size());
  if (n == 0) throw LoadError(path_, "", "no <link>");
  std::vector<int> parent_joint(n, -1);
  std::vector<std::vector<int>> child_joints(n);
  for (int j = 0; j < static_cast<int>(out_.joints.size()); ++j) {
    const UrdfOutline::Joint& joint = out_.joints[j];
    if (joint.parent == joint.child)
      fail(joint_elements_[j], "loop in the kinematic tree: the joint connects link '" +
                                   out_.links[joint.child].name + "' to itself");
    if (parent_joint[joint.child] >= 0)
      fail(joint_elements_[j], "loop in the kinematic tree: link '" + out_.links[joint.child].name +
                                   "' is already the child of joint '" + out_.joints[parent_joint[joint.child]].name + "'");
    parent_joint[joint.child] = j;
    child_joints[joint.parent].push_back(j);
  }
  std::vector<int> roots;
  for (int i = 0; i < n; ++i)
    if (parent_joint[i] < 0) roots.push_back(i);
  if (roots.empty())
    throw LoadError(path_, "", "loop in the kinematic tree: every link is the child of a joint, there is no root");
  if (roots.size() > 1)
    fail(link_elements_[roots[1]], "a second root link (besides '" + out_.links[roots[0]].name +
                                       "'): the links do not form one tree");
  std::vector<int> stack{roots[0]};
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    out_.link_order.push_back(i);
    if (parent_joint[i] >= 0) out_.joint_order.push_back(parent_joint[i]);
    // Push in reverse so that the first child in document order is visited first.
    for (auto it = child_joints[i].rbegin(); it != child_joints[i].rend(); ++it) stack.push_back(out_.joints[*it].child);
  }
  if (static_cast<int>(out_.link_order.size()) < n) {
    std::vector<char> reached(n, 0);
    for (int i : out_.link_order) reached[i] = 1;
    const int lost = static_cast<int>(std::find(reached.begin(), reached.end(), 0) - reached.begin());
    fail(link_elements_[lost], "loop in the kinematic tree: link '" + out_.links[lost].name +
                                   "' lies on a cycle of joints, unreachable from the root '" +
                                   out_.links[roots[0]].name + "'");
  }
}

UrdfOutline Reader::read() {
  std::ifstream in(path_, std::ios::binary);
  if (!in) throw LoadError(path_, "", "cannot open the file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();

  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.c_str(), text.size()) != tinyxml2::XML_SUCCESS)
    throw LoadError(path_, "line " + std::to_string(doc.ErrorLineNum()),
                    std::string("malformed XML: ") + doc.ErrorStr());
  const XMLElement* robot = doc.RootElement();
  if (robot == nullptr || std::strcmp(robot->Name(), "robot") != 0)
    throw LoadError(path_, "", "the root element is not <robot>");
  out_.robot_name = attribute(robot, "name");

  // Links first (joints name them), then joints, both in document order.
  for (const XMLElement* e = robot->FirstChildElement("link"); e; e = e->NextSiblingElement("link")) readLink(e);
  for (const XMLElement* e = robot->FirstChildElement("joint"); e; e = e->NextSiblingElement("joint")) readJoint(e);
  std::unordered_map<std::string, int> joint_names;
  for (std::size_t j = 0; j < out_.joints.size(); ++j) {
    if (!joint_names.emplace(out_.joints[j].name, static_cast<int>(j)).second)
      fail(joint_elements_[j], "a second joint named '" + out_.joints[j].name + "'");
  }
  for (std::size_t j = 0; j < out_.joints.size(); ++j) {
    const XMLElement* mimic = joint_elements_[j]->FirstChildElement("mimic");
    // A fixed joint's mimic is ignored (with a warning, by the loader), whatever it names.
    if (mimic != nullptr && attribute(joint_elements_[j], "type") != "fixed" && joint_names.count(attribute(mimic, "joint")) == 0)
      fail(mimic, "mimics '" + attribute(mimic, "joint") + "', which is not a joint");
  }
  orderTree();

  // urdfdom gets the document without what it need not see: capsules (urdfdom 3 drops them with an
  // error; they are in the outline), <visual> and <inertial> (unused here; a problem in them would make
  // urdfdom drop the element or fail the whole file).
  for (XMLElement* link = doc.RootElement()->FirstChildElement("link"); link; link = link->NextSiblingElement("link")) {
    for (XMLElement* c = link->FirstChildElement(); c != nullptr;) {
      XMLElement* next = c->NextSiblingElement();
      const std::string tag = c->Name();
      const XMLElement* geometry = c->FirstChildElement("geometry");
      if (tag == "visual" || tag == "inertial" ||
          (tag == "collision" && geometry != nullptr && geometry->FirstChildElement("capsule") != nullptr))
        link->DeleteChild(c);
      c = next;
    }
  }
  tinyxml2::XMLPrinter printer;
  doc.Print(&printer);
  out_.text_for_urdfdom = printer.CStr();
  return std::move(out_);
}

}  // namespace

Mat3 rotationFromRpy(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Vec3::UnitZ()) * Eigen::AngleAxisd(pitch, Vec3::UnitY()) *
          Eigen::AngleAxisd(roll, Vec3::UnitX()))
      .toRotationMatrix();
}

UrdfOutline readUrdfOutline(const std::string& path) { return Reader(path).read(); }

}  // namespace clearway::detail
