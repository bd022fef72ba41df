#pragma once
// An SRDF reader for tests, reading what MoveIt's srdfdom reads (srdf::Model::initXml): the robot name,
// virtual_joint, group (link, joint, chain, subgroup), group_state, end_effector,
// link_sphere_approximation, disable_default_collisions, disable_collisions, enable_collisions,
// passive_joint and joint_property, each with the attributes srdfdom requires. Every element becomes a
// canonical line, in file order, so two SRDFs can be compared element by element; what srdfdom would
// reject (a missing required attribute, a group state or end effector of an unknown group, a subgroup
// that is not a group) is listed in `errors`, and any element srdfdom skips in `unknown`.
#include <tinyxml2.h>

#include <set>
#include <string>
#include <vector>

namespace clearway::test {

struct SrdfContent {
  std::string robot_name;
  /// Every element but disable_collisions, as canonical lines in file order ("group arm: chain(a,b)").
  std::vector<std::string> semantic;
  struct Pair {
    std::string link1, link2, reason;
  };
  std::vector<Pair> disabled;  ///< disable_collisions, in file order
  std::vector<std::string> errors, unknown;
  int comments = 0;            ///< comments anywhere in the document
  int groups = 0, group_states = 0, end_effectors = 0, virtual_joints = 0, passive_joints = 0;
};

namespace srdf_detail {
// The attribute, or "" with an error naming element and attribute when it is missing.
inline std::string required(const tinyxml2::XMLElement* e, const char* attribute, SrdfContent& out) {
  const char* v = e->Attribute(attribute);
  if (v == nullptr) out.errors.push_back(std::string("<") + e->Name() + "> line " + std::to_string(e->GetLineNum()) +
                                         ": no " + attribute + " attribute");
  return v ? v : "";
}
inline int countComments(const tinyxml2::XMLNode* node) {
  int n = 0;
  for (const tinyxml2::XMLNode* c = node->FirstChild(); c != nullptr; c = c->NextSibling())
    n += (c->ToComment() != nullptr) + countComments(c);
  return n;
}
}  // namespace srdf_detail

/// Reads SRDF text; a document that is not XML, or whose root is not <robot>, is an error.
inline SrdfContent readSrdfText(const std::string& text) {
  using srdf_detail::required;
  SrdfContent out;
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS) {
    out.errors.push_back(std::string("not well-formed XML: ") + doc.ErrorStr());
    return out;
  }
  out.comments = srdf_detail::countComments(&doc);
  const tinyxml2::XMLElement* robot = doc.RootElement();
  if (robot == nullptr || std::string(robot->Name()) != "robot") {
    out.errors.push_back("the root element is not <robot>");
    return out;
  }
  out.robot_name = required(robot, "name", out);
  std::set<std::string> groups;
  for (const tinyxml2::XMLElement* e = robot->FirstChildElement("group"); e; e = e->NextSiblingElement("group"))
    groups.insert(required(e, "name", out));
  for (const tinyxml2::XMLElement* e = robot->FirstChildElement(); e; e = e->NextSiblingElement()) {
    const std::string tag = e->Name();
    std::string line = tag;
    if (tag == "virtual_joint") {
      ++out.virtual_joints;
      line += " " + required(e, "name", out) + ": " + required(e, "type", out) + " " + required(e, "parent_frame", out) +
              " -> " + required(e, "child_link", out);
    } else if (tag == "group") {
      ++out.groups;
      line += " " + required(e, "name", out) + ":";
      for (const tinyxml2::XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
        const std::string part = c->Name();
        if (part == "link" || part == "joint") line += " " + part + "(" + required(c, "name", out) + ")";
        else if (part == "chain") line += " chain(" + required(c, "base_link", out) + "," + required(c, "tip_link", out) + ")";
        else if (part == "group") {
          const std::string sub = required(c, "name", out);
          if (!groups.count(sub)) out.errors.push_back("group " + std::string(e->Attribute("name")) + ": subgroup " + sub + " is not a group");
          line += " group(" + sub + ")";
        } else {
          // srdfdom skips it (MoveIt's own Panda SRDF has a passive_joint here); kept in the line all the same,
          // so that a writer dropping it is seen.
          const char* name = c->Attribute("name");
          line += " " + part + "(" + (name ? name : "") + ")";
          out.unknown.push_back("<" + part + "> in <group>");
        }
      }
    } else if (tag == "group_state") {
      ++out.group_states;
      const std::string group = required(e, "group", out);
      if (!groups.count(group)) out.errors.push_back("group_state of unknown group " + group);
      line += " " + required(e, "name", out) + " of " + group + ":";
      for (const tinyxml2::XMLElement* j = e->FirstChildElement("joint"); j; j = j->NextSiblingElement("joint"))
        line += " " + required(j, "name", out) + "=" + required(j, "value", out);
    } else if (tag == "end_effector") {
      ++out.end_effectors;
      const std::string group = required(e, "group", out);
      if (!groups.count(group)) out.errors.push_back("end_effector of unknown group " + group);
      const char* parent_group = e->Attribute("parent_group");  // optional in srdfdom
      line += " " + required(e, "name", out) + ": " + group + " on " + required(e, "parent_link", out) + " of " +
              (parent_group ? parent_group : "-");
    } else if (tag == "link_sphere_approximation") {
      line += " " + required(e, "link", out) + ":";
      for (const tinyxml2::XMLElement* s = e->FirstChildElement("sphere"); s; s = s->NextSiblingElement("sphere"))
        line += " sphere(" + required(s, "center", out) + "," + required(s, "radius", out) + ")";
    } else if (tag == "disable_default_collisions") {
      line += " " + required(e, "link", out);
    } else if (tag == "disable_collisions") {
      const char* reason = e->Attribute("reason");  // optional in srdfdom
      out.disabled.push_back({required(e, "link1", out), required(e, "link2", out), reason ? reason : ""});
      continue;
    } else if (tag == "enable_collisions") {
      line += " " + required(e, "link1", out) + " " + required(e, "link2", out);
    } else if (tag == "passive_joint") {
      ++out.passive_joints;
      line += " " + required(e, "name", out);
    } else if (tag == "joint_property") {
      line += " " + required(e, "joint_name", out) + " " + required(e, "property_name", out) + "=" + required(e, "value", out);
    } else {
      out.unknown.push_back("<" + tag + ">");
      continue;
    }
    out.semantic.push_back(line);
  }
  return out;
}

}  // namespace clearway::test
