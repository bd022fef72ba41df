// The scene file (docs/scene-format.md): YAML in, a SceneDescription out, every error naming the
// file and the key. Strict: an unknown key is an error, because a misspelt `padding` silently ignored
// is a collision silently missed.
#include <clearway/scene/scene_file.h>

#include <clearway/load/input_limits.h>
#include <clearway/load/load_error.h>

#include "load/mesh_uri.h"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace clearway {

namespace {

namespace fs = std::filesystem;

class Parser {
 public:
  explicit Parser(std::string file) : file_(std::move(file)), base_(fs::path(file_).parent_path()) {}
  // Text not read from a file (stdin): `name` names it in errors, paths are relative to `base`.
  Parser(std::string name, const std::string* text, fs::path base)
      : file_(std::move(name)), base_(std::move(base)), text_(text) {}

  [[noreturn]] void fail(const std::string& key, const std::string& reason) const {
    throw LoadError(file_, key.empty() ? "" : "key '" + inputExcerpt(key, 120) + "'", reason);
  }
  std::string where(const YAML::Node& n) const {
    const YAML::Mark m = n.Mark();
    return m.line >= 0 ? " (line " + std::to_string(m.line + 1) + ")" : "";
  }

  // The keys of mapping n (at key), in order: plain names, each once. yaml-cpp keeps a repeated key and
  // lookups find the first, so a second `checks:` would be silently ignored. A key repeated with the
  // same value is harmless and read once.
  std::vector<std::string> keys(const YAML::Node& n, const std::string& key) const {
    std::vector<std::string> out;
    std::vector<YAML::Node> values;
    for (const auto& kv : n) {
      if (!kv.first.IsScalar())
        fail(key, "a key must be a plain name, not a " + std::string(kv.first.IsSequence() ? "list" : "mapping") +
                      where(kv.first));
      const std::string k = kv.first.Scalar();
      const auto seen = std::find(out.begin(), out.end(), k);
      if (seen == out.end()) {
        out.push_back(k);
        values.push_back(kv.second);
      } else if (YAML::Dump(values[seen - out.begin()]) != YAML::Dump(kv.second)) {
        fail(key.empty() ? k : key + "." + k, "given twice with different values (lines " +
                                                  std::to_string(values[seen - out.begin()].Mark().line + 1) + " and " +
                                                  std::to_string(kv.first.Mark().line + 1) + ")");
      }
    }
    return out;
  }

  void requireMap(const YAML::Node& n, const std::string& key, const std::set<std::string>& allowed) const {
    if (!n.IsMap()) fail(key, "expected a mapping" + where(n));
    for (const std::string& k : keys(n, key))
      if (!allowed.count(k)) fail(key.empty() ? k : key + "." + k, "unknown key" + where(n[k]));
  }

  // A length in metres within the input limit |x| ≤ kMaxInputLength (a position of 1e308 has no box
  // centre); any shorter one, down to CAD exporters' 1e-16 residues, is a length like any other.
  double length(const YAML::Node& n, const std::string& key) const {
    const double v = number(n, key);
    if (std::abs(v) > kMaxInputLength)
      fail(key, "'" + inputExcerpt(n.Scalar()) + "' m is beyond the largest length an input may give (1e6 m)" + where(n));
    return v;
  }
  // A size in metres: a length ≥ 0 (> 0 unless zero is allowed). One in (0, kMinInputLength), below
  // which the hull arithmetic has no digits left (a radius of 1e-310), is grown to kMinInputLength with
  // a warning: the grown solid holds the one given, so no contact is lost.
  double size(const YAML::Node& n, const std::string& key, bool zero_allowed) const {
    const double v = length(n, key);
    if (v < 0.0 || (v == 0.0 && !zero_allowed))
      fail(key, "'" + inputExcerpt(n.Scalar()) + "' m: a size must be " + (zero_allowed ? ">= 0" : "> 0") + where(n));
    if (v > 0.0 && v < kMinInputLength) {
      warnings_.push_back(LoadError::format(file_, "key '" + key + "'",
                                            "'" + inputExcerpt(n.Scalar()) + "' m is below the smallest size Clearway computes "
                                            "with (1e-9 m): checked as 1e-9 m" + where(n)));
      return kMinInputLength;
    }
    return v;
  }
  Vec3 sizes(const YAML::Node& n, const std::string& key, bool zero_allowed) const {
    if (!n.IsSequence() || n.size() != 3) vec3(n, key);  // the error for a wrong type or length
    Vec3 v;
    for (int i = 0; i < 3; ++i) v[i] = size(n[i], key + "[" + std::to_string(i) + "]", zero_allowed);
    return v;
  }
  Vec3 lengths(const YAML::Node& n, const std::string& key) const {
    if (!n.IsSequence() || n.size() != 3) vec3(n, key);  // the error for a wrong type or length
    Vec3 v;
    for (int i = 0; i < 3; ++i) v[i] = length(n[i], key + "[" + std::to_string(i) + "]");
    return v;
  }

  double number(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar()) fail(key, "expected a number" + where(n));
    double v = 0.0;
    const std::string s = inputExcerpt(n.Scalar());  // (a 'number' may be a megabyte of text)
    // yaml-cpp reads ".nan" and ".inf"; a plain "nan" too. Either way: not a usable number.
    if (!YAML::convert<double>::decode(n, v)) fail(key, "'" + s + "' is not a number" + where(n));
    if (!std::isfinite(v)) fail(key, "'" + s + "' is not a finite number" + where(n));
    return v;
  }
  std::string text(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar() || n.Scalar().empty()) fail(key, "expected a non-empty string" + where(n));
    return n.Scalar();
  }
  std::vector<double> numbers(const YAML::Node& n, const std::string& key, int length = -1) const {
    if (!n.IsSequence()) fail(key, "expected a list of numbers" + where(n));
    if (length >= 0 && static_cast<int>(n.size()) != length)
      fail(key, "expected " + std::to_string(length) + " numbers, got " + std::to_string(n.size()) + where(n));
    std::vector<double> v;
    for (std::size_t i = 0; i < n.size(); ++i) v.push_back(number(n[i], key + "[" + std::to_string(i) + "]"));
    return v;
  }
  Vec3 vec3(const YAML::Node& n, const std::string& key) const {
    const std::vector<double> v = numbers(n, key, 3);
    return {v[0], v[1], v[2]};
  }
  std::vector<std::string> names(const YAML::Node& n, const std::string& key) const {
    if (!n.IsSequence()) fail(key, "expected a list of names" + where(n));
    std::vector<std::string> v;
    for (std::size_t i = 0; i < n.size(); ++i) v.push_back(text(n[i], key + "[" + std::to_string(i) + "]"));
    return v;
  }
  // A path relative to the scene file's folder.
  std::string path(const YAML::Node& n, const std::string& key, bool folder = false) const {
    const std::string written = text(n, key);
    if (const std::string why = detail::controlCharacterReason(written); !why.empty())
      fail(key, "'" + inputExcerpt(written, 4096) + "': " + why + where(n));
    const fs::path p = written;
    const fs::path full = p.is_absolute() ? p : base_ / p;
    std::error_code ec;
    if (folder && !fs::is_directory(full, ec)) fail(key, "folder not found: " + full.string() + where(n));
    if (!folder && !fs::is_regular_file(full, ec)) fail(key, "file not found: " + full.string() + where(n));
    return full.lexically_normal().string();
  }

  Pose pose(const YAML::Node& n, const std::string& key) const {
    requireMap(n, key, {"position", "orientation"});
    Vec3 t = Vec3::Zero();
    if (n["position"]) t = lengths(n["position"], key + ".position");
    if (!n["orientation"]) return Pose::translation(t);
    const std::vector<double> q = numbers(n["orientation"], key + ".orientation", 4);
    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!(norm > 1e-6)) fail(key + ".orientation", "a zero quaternion is not a rotation" + where(n));
    if (std::abs(norm - 1.0) > 1e-3)
      fail(key + ".orientation", "quaternion (x, y, z, w) has norm " + std::to_string(norm) + ", not 1" + where(n));
    return Pose::fromQuaternion(q[0], q[1], q[2], q[3], t);
  }

  // A body's name, geometry (one of box, sphere, cylinder, capsule, mesh) and pose: an obstacle or an
  // attached body, whose other keys are `extra`.
  SceneDescription::ObstacleSpec body(const YAML::Node& n, const std::string& key,
                                      const std::vector<std::string>& extra) const {
    std::set<std::string> allowed{"name", "box", "sphere", "cylinder", "capsule", "mesh", "pose"};
    allowed.insert(extra.begin(), extra.end());
    requireMap(n, key, allowed);
    SceneDescription::ObstacleSpec o;
    o.name = n["name"] ? text(n["name"], key + ".name") : key;
    int kinds = 0;
    try {
      if (const YAML::Node b = n["box"]) {
        ++kinds;
        requireMap(b, key + ".box", {"size"});
        if (!b["size"]) fail(key + ".box.size", "missing");
        o.shape = Box(0.5 * sizes(b["size"], key + ".box.size", true));
      }
      if (const YAML::Node s = n["sphere"]) {
        ++kinds;
        requireMap(s, key + ".sphere", {"radius"});
        if (!s["radius"]) fail(key + ".sphere.radius", "missing");
        o.shape = Sphere(size(s["radius"], key + ".sphere.radius", false));
      }
      for (const char* kind : {"cylinder", "capsule"}) {
        const YAML::Node c = n[kind];
        if (!c) continue;
        ++kinds;
        const std::string k = key + "." + kind;
        requireMap(c, k, {"radius", "length"});
        if (!c["radius"]) fail(k + ".radius", "missing");
        if (!c["length"]) fail(k + ".length", "missing");
        const double r = size(c["radius"], k + ".radius", false), h = 0.5 * size(c["length"], k + ".length", true);
        if (std::string(kind) == "cylinder") o.shape = Cylinder(r, h);
        else o.shape = Capsule(r, h);
      }
      if (const YAML::Node m = n["mesh"]) {
        ++kinds;
        requireMap(m, key + ".mesh", {"file", "scale"});
        if (!m["file"]) fail(key + ".mesh.file", "missing");
        o.mesh_file = path(m["file"], key + ".mesh.file");
        if (m["scale"]) {
          if (m["scale"].IsScalar()) o.mesh_scale = Vec3::Constant(number(m["scale"], key + ".mesh.scale"));
          else o.mesh_scale = vec3(m["scale"], key + ".mesh.scale");
        }
      }
    } catch (const ShapeError& e) {
      fail(key, e.what() + where(n));
    }
    if (kinds != 1) fail(key, "a body needs exactly one of box, sphere, cylinder, capsule, mesh" + where(n));
    if (n["pose"]) o.pose = pose(n["pose"], key + ".pose");
    return o;
  }

  void obstacle(const YAML::Node& n, const std::string& key, SceneDescription& d) const {
    SceneDescription::ObstacleSpec o = body(n, key, {"velocity"});
    if (n["velocity"]) o.velocity = lengths(n["velocity"], key + ".velocity");  // m/s
    d.obstacles.push_back(std::move(o));
  }

  void attached(const YAML::Node& n, const std::string& key, SceneDescription& d) const {
    SceneDescription::AttachedSpec a;
    a.body = body(n, key, {"link", "touch_links"});
    if (!n["name"]) fail(key + ".name", "missing: an attached body is named in reports");
    if (!n["link"]) fail(key + ".link", "missing: the link it is fixed to");
    a.link = text(n["link"], key + ".link");
    if (const YAML::Node t = n["touch_links"]; t && !t.IsNull()) a.touch_links = names(t, key + ".touch_links");
    d.attached.push_back(std::move(a));
  }

  // One scene per file: what a second document (after `---`) holds would otherwise be dropped unread, an
  // obstacle among it never checked. (Empty documents, a stray `---`, hold nothing to drop.) The documents
  // are walked by events, not built: yaml-cpp's LoadAll loops for ever on some stray text (a `}` after the
  // last), reading it as one empty document after another at the same place. A document must begin past
  // the last one's end, so the walk ends within the text's length in documents.
  void requireOneDocument(const std::string& bytes) const {
    struct Walk : YAML::EventHandler {
      YAML::Mark content = YAML::Mark::null_mark();  // the first event other than a null, if any
      int furthest = -1;                             // the furthest event's position
      void at(const YAML::Mark& m, bool null) {
        if (!null && content.pos < 0) content = m;
        furthest = std::max(furthest, m.pos);
      }
      void OnDocumentStart(const YAML::Mark&) override {}
      void OnDocumentEnd() override {}
      void OnNull(const YAML::Mark& m, YAML::anchor_t) override { at(m, true); }
      void OnAlias(const YAML::Mark& m, YAML::anchor_t) override { at(m, false); }
      void OnScalar(const YAML::Mark& m, const std::string&, YAML::anchor_t, const std::string&) override {
        at(m, false);
      }
      void OnSequenceStart(const YAML::Mark& m, const std::string&, YAML::anchor_t,
                           YAML::EmitterStyle::value) override {
        at(m, false);
      }
      void OnSequenceEnd() override {}
      void OnMapStart(const YAML::Mark& m, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
        at(m, false);
      }
      void OnMapEnd() override {}
    };
    std::istringstream in(bytes);
    YAML::Parser parser(in);
    int end = -1;  // the furthest position of the documents so far
    for (std::size_t document = 1; document <= bytes.size() + 2; ++document) {
      Walk w;
      if (!parser.HandleNextDocument(w)) return;
      if (document > 1 && w.content.pos >= 0)
        fail("", "holds more than one YAML document, where a scene is one: document " + std::to_string(document) +
                     " is not empty (line " + std::to_string(w.content.line + 1) + ")");
      if (document > 1 && w.furthest <= end)
        fail("", "not valid YAML: the text after line " + std::to_string(lineAt(bytes, end) + 1) +
                     " cannot be read (stray brackets or braces?)");
      end = std::max(end, w.furthest);
    }
    fail("", "not valid YAML: more documents than bytes");  // (not reached: each document moves on)
  }

  static int lineAt(const std::string& bytes, int pos) {
    return static_cast<int>(std::count(bytes.begin(), bytes.begin() + std::clamp<int>(pos, 0, bytes.size()), '\n'));
  }

  SceneDescription parse() const {
    YAML::Node root;
    std::error_code ec;
    if (!text_ && !fs::is_regular_file(file_, ec)) fail("", "scene file not found");
    std::string bytes;
    if (text_) {
      bytes = *text_;
    } else {
      std::ifstream in(file_, std::ios::binary);
      std::ostringstream all;
      all << in.rdbuf();
      if (!in && !in.eof()) fail("", "cannot be read");
      bytes = all.str();
    }
    try {
      root = YAML::Load(bytes);
      requireOneDocument(bytes);
    } catch (const YAML::Exception& e) {
      fail("", std::string("not valid YAML: ") + e.what());
    }
    SceneDescription d;
    d.file = file_;
    requireMap(root, "", {"format", "name", "source", "package_paths", "robot", "environment", "checks", "start", "goal"});
    if (!root["format"]) fail("format", "missing (this reader knows format 1)");
    if (number(root["format"], "format") != 1.0) fail("format", "unsupported format " + inputExcerpt(root["format"].Scalar()) + " (this reader knows 1)");
    d.name = root["name"] ? text(root["name"], "name") : text_ ? std::string("scene") : fs::path(file_).stem().string();

    if (const YAML::Node p = root["package_paths"]; p && !p.IsNull()) {
      if (!p.IsSequence()) fail("package_paths", "expected a list of folders" + where(p));
      for (std::size_t i = 0; i < p.size(); ++i)
        d.package_paths.push_back(path(p[i], "package_paths[" + std::to_string(i) + "]", /*folder=*/true));
    }

    const YAML::Node robot = root["robot"];
    if (!robot) fail("robot", "missing");
    requireMap(robot, "robot", {"urdf", "srdf", "group", "hold", "allow", "padding", "bounds", "attached"});
    if (!robot["urdf"]) fail("robot.urdf", "missing");
    d.urdf = path(robot["urdf"], "robot.urdf");
    if (robot["srdf"] && !robot["srdf"].IsNull()) d.srdf = path(robot["srdf"], "robot.srdf");
    if (!robot["group"]) fail("robot.group", "missing");
    d.group = names(robot["group"], "robot.group");
    if (d.group.empty()) fail("robot.group", "an empty group has nothing to plan");
    if (const YAML::Node h = robot["hold"]; h && !h.IsNull()) {
      if (!h.IsMap()) fail("robot.hold", "expected a mapping of joint: value" + where(h));
      for (const std::string& j : keys(h, "robot.hold")) d.hold.emplace_back(j, number(h[j], "robot.hold." + j));
    }
    if (const YAML::Node b = robot["bounds"]; b && !b.IsNull()) {
      if (!b.IsMap()) fail("robot.bounds", "expected a mapping of variable: [lower, upper]" + where(b));
      for (const std::string& v : keys(b, "robot.bounds")) {
        const std::string k = "robot.bounds." + v;
        const YAML::Node range = b[v];
        if (!range.IsSequence() || range.size() != 2) fail(k, "expected [lower, upper]" + where(range));
        d.bounds.emplace_back(v, std::make_pair(number(range[0], k), number(range[1], k)));
      }
    }
    if (const YAML::Node a = robot["allow"]; a && !a.IsNull()) {
      if (!a.IsSequence()) fail("robot.allow", "expected a list of [link, link] pairs" + where(a));
      for (std::size_t i = 0; i < a.size(); ++i) {
        const std::string k = "robot.allow[" + std::to_string(i) + "]";
        const std::vector<std::string> p = names(a[i], k);
        if (p.size() != 2) fail(k, "expected 2 link names, got " + std::to_string(p.size()) + where(a[i]));
        d.allow.emplace_back(p[0], p[1]);
      }
    }
    if (const YAML::Node a = robot["attached"]; a && !a.IsNull()) {
      if (!a.IsSequence()) fail("robot.attached", "expected a list of bodies" + where(a));
      for (std::size_t i = 0; i < a.size(); ++i) attached(a[i], "robot.attached[" + std::to_string(i) + "]", d);
    }
    if (robot["padding"]) {
      d.padding = number(robot["padding"], "robot.padding");
      if (d.padding < 0.0) fail("robot.padding", "must be >= 0" + where(robot["padding"]));
    }

    if (const YAML::Node env = root["environment"]; env && !env.IsNull()) {
      requireMap(env, "environment", {"octomap", "unknown", "obstacles"});
      if (env["octomap"]) d.octomap = path(env["octomap"], "environment.octomap");
      if (env["unknown"]) {
        const std::string u = text(env["unknown"], "environment.unknown");
        if (u == "free") d.unknown = UnknownSpace::Free;
        else if (u == "occupied") d.unknown = UnknownSpace::Occupied;
        else fail("environment.unknown", "'" + u + "' is neither free nor occupied" + where(env["unknown"]));
      }
      if (const YAML::Node obs = env["obstacles"]; obs && !obs.IsNull()) {
        if (!obs.IsSequence()) fail("environment.obstacles", "expected a list" + where(obs));
        std::map<std::string, std::size_t> first;  // the first obstacle of each name
        for (std::size_t i = 0; i < obs.size(); ++i) {
          const std::string key = "environment.obstacles[" + std::to_string(i) + "]";
          obstacle(obs[i], key, d);
          // Both are kept and checked (as MoveIt keeps two shapes under one id), but a report or an edit
          // naming them cannot say which one.
          const auto [at, added] = first.emplace(d.obstacles.back().name, i);
          if (!added)
            warnings_.push_back(LoadError::format(
                file_, "key '" + key + ".name'",
                "'" + inputExcerpt(at->first) + "' also names obstacles[" + std::to_string(at->second) +
                    "]: both are checked, but a report naming it does not say which, and edits by name refuse it"));
        }
      }
    }

    if (!root["checks"]) fail("checks", "missing: say what the scene needs (self, environment, ...)");
    for (const std::string& c : names(root["checks"], "checks")) {
      if (c == "self") d.effects.self = true;
      else if (c == "environment") d.effects.environment = true;
      else if (c == "continuous") d.effects.continuous = true;
      else if (c == "clearance") d.effects.clearance = true;
      else if (c == "moving") d.effects.moving = true;
      else fail("checks", "unknown check '" + c + "' (self, environment, continuous, clearance, moving)");
    }
    // Without self or environment nothing is ever checked, and every state would be called free.
    if (!d.effects.self && !d.effects.environment)
      fail("checks", std::string(root["checks"].size() == 0 ? "is empty" : "names no collision check") +
                         ": every state would be free; list self, environment or both" + where(root["checks"]));
    // Obstacles the checks never look at: a self-only scene may mean it (an audit of the robot alone), but a
    // state inside them is then free, so it is said.
    if (!d.effects.environment && (!d.obstacles.empty() || !d.octomap.empty())) {
      const std::size_t n = d.obstacles.size();
      const std::string what = (n == 0 ? std::string() : std::to_string(n) + (n == 1 ? " obstacle" : " obstacles")) +
                               (n == 0 || d.octomap.empty() ? "" : " and ") + (d.octomap.empty() ? "" : "OctoMap");
      warnings_.push_back(LoadError::format(file_, "key 'checks'",
                                            "'environment' is not among the checks: the scene's " + what +
                                                ((n + !d.octomap.empty()) == 1 ? " is" : " are") + " never checked"));
    }
    bool any_moving = false;
    for (const auto& o : d.obstacles) any_moving = any_moving || o.velocity != Vec3::Zero();
    if (any_moving && !d.effects.moving)
      fail("checks", "an obstacle has a velocity but 'moving' is not among the checks");

    // Their lengths are checked against the group's variables by the Scene (a planar joint has 3, a
    // floating one 7): the file alone does not say.
    if (root["start"]) d.start = numbers(root["start"], "start");
    if (root["goal"]) d.goal = numbers(root["goal"], "goal");
    d.warnings = warnings_;
    return d;
  }

 private:
  std::string file_;
  fs::path base_;
  const std::string* text_ = nullptr;
  mutable std::vector<std::string> warnings_;  // sizes grown; the readers are const as they only read
};

}  // namespace

SceneDescription parseSceneFile(const std::string& path) {
  try {
    return Parser(path).parse();
  } catch (const YAML::Exception& e) {
    // Every read above checks its node first; this is the net for anything yaml-cpp still refuses.
    throw LoadError(path, "", std::string("yaml-cpp: ") + e.what());
  }
}

SceneDescription parseSceneText(const std::string& yaml, const std::string& name, const std::string& base_dir) {
  try {
    return Parser(name, &yaml, base_dir).parse();
  } catch (const YAML::Exception& e) {
    throw LoadError(name, "", std::string("yaml-cpp: ") + e.what());
  }
}

std::string Effects::toString() const {
  std::string s;
  auto add = [&](bool on, const char* name) {
    if (on) s += (s.empty() ? "" : ", ") + std::string(name);
  };
  add(self, "self");
  add(environment, "environment");
  add(continuous, "continuous");
  add(clearance, "clearance");
  add(moving, "moving");
  return s;
}

}  // namespace clearway
