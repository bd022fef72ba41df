#include "query_file.h"

#include "exit_codes.h"

#include <clearway/narrowphase/epa.h>
#include <clearway/narrowphase/gjk.h>
#include <clearway/narrowphase/ray_cast.h>
#include <clearway/narrowphase/status.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <istream>
#include <ostream>
#include <vector>

namespace clearway {

namespace {

using nlohmann::json;
using nlohmann::ordered_json;

// ---------------------------------------------------------------------------------------------
// Reading checked values. Every reader takes the key path of the value ("a.shape.radius",
// "b.shape.vertices[2]") so that an error names exactly what is wrong.

std::string join(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }
std::string index(const std::string& path, std::size_t i) { return path + "[" + std::to_string(i) + "]"; }

// The input value as written, shortened, for error messages.
std::string shown(const json& v) {
  std::string s = v.dump(-1, ' ', false, json::error_handler_t::replace);
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

[[noreturn]] void fail(const std::string& message) { throw QueryError(message); }

[[noreturn]] void wrongType(const std::string& path, const char* expected, const json& v) {
  fail(path + " must be " + expected + ", got " + v.type_name() + " " + shown(v));
}

const json& member(const json& obj, const std::string& path, const char* key) {
  const auto it = obj.find(key);
  if (it == obj.end()) fail(join(path, key) + " is missing");
  return *it;
}

const json& object(const json& v, const std::string& path) {
  if (!v.is_object()) wrongType(path, "an object", v);
  return v;
}

// Rejects keys outside `allowed`, so that a misspelt key is an error rather than silently ignored.
void onlyKeys(const json& obj, const std::string& path, std::initializer_list<const char*> allowed) {
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    const bool known = std::any_of(allowed.begin(), allowed.end(), [&](const char* k) { return it.key() == k; });
    if (known) continue;
    std::string list;
    for (const char* k : allowed) list += std::string(list.empty() ? "" : ", ") + k;
    fail("unknown key " + join(path, it.key()) + " (expected " + list + ")");
  }
}

std::string string(const json& v, const std::string& path) {
  if (!v.is_string()) wrongType(path, "a string", v);
  return v.get<std::string>();
}

double number(const json& v, const std::string& path) {
  // JSON has no NaN or infinity literals; a string such as "NaN" or "inf" is a wrongly typed value.
  if (!v.is_number()) wrongType(path, "a number", v);
  const double x = v.get<double>();
  if (!std::isfinite(x)) fail(path + " must be finite, got " + shown(v));
  return x;
}

double positive(const json& v, const std::string& path) {
  const double x = number(v, path);
  if (!(x > 0.0)) fail(path + " must be > 0, got " + shown(v));
  return x;
}

double nonNegative(const json& v, const std::string& path) {
  const double x = number(v, path);
  if (!(x >= 0.0)) fail(path + " must be >= 0, got " + shown(v));
  return x;
}

const json& array(const json& v, const std::string& path, std::size_t size) {
  if (!v.is_array()) wrongType(path, "an array", v);
  if (v.size() != size)
    fail(path + " must have " + std::to_string(size) + " elements, got " + std::to_string(v.size()));
  return v;
}

Vec3 vec3(const json& v, const std::string& path) {
  array(v, path, 3);
  return {number(v[0], index(path, 0)), number(v[1], index(path, 1)), number(v[2], index(path, 2))};
}

std::vector<Vec3> points(const json& v, const std::string& path) {
  if (!v.is_array()) wrongType(path, "an array of points", v);
  if (v.empty()) fail(path + " must not be empty");
  std::vector<Vec3> out;
  out.reserve(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) out.push_back(vec3(v[i], index(path, i)));
  return out;
}

// ---------------------------------------------------------------------------------------------
// Shapes and poses.

Shape parseShape(const json& v, const std::string& path) {
  object(v, path);
  const std::string type = string(member(v, path, "type"), join(path, "type"));
  auto key = [&](const char* k) -> const json& { return member(v, path, k); };
  auto at = [&](const char* k) { return join(path, k); };
  // The constructors check the same conditions; the checks here exist to name the key.
  try {
    if (type == "point") {
      onlyKeys(v, path, {"type"});
      return Point();
    }
    if (type == "segment") {
      onlyKeys(v, path, {"type", "p0", "p1"});
      return Segment(vec3(key("p0"), at("p0")), vec3(key("p1"), at("p1")));
    }
    if (type == "triangle") {
      onlyKeys(v, path, {"type", "vertices"});
      const json& vs = array(key("vertices"), at("vertices"), 3);
      const std::string p = at("vertices");
      return Triangle(vec3(vs[0], index(p, 0)), vec3(vs[1], index(p, 1)), vec3(vs[2], index(p, 2)));
    }
    if (type == "box") {
      onlyKeys(v, path, {"type", "half_extents"});
      const Vec3 h = vec3(key("half_extents"), at("half_extents"));
      for (int i = 0; i < 3; ++i)
        if (!(h[i] >= 0.0)) fail(index(at("half_extents"), i) + " must be >= 0, got " + shown(key("half_extents")[i]));
      return Box(h);
    }
    if (type == "sphere") {
      onlyKeys(v, path, {"type", "radius"});
      return Sphere(positive(key("radius"), at("radius")));
    }
    if (type == "capsule" || type == "cylinder" || type == "cone") {
      onlyKeys(v, path, {"type", "radius", "half_length"});
      const double r = positive(key("radius"), at("radius"));
      // A cone needs a height to have an apex; capsules and cylinders may be flat (a sphere, a disc).
      const double h = type == "cone" ? positive(key("half_length"), at("half_length"))
                                      : nonNegative(key("half_length"), at("half_length"));
      if (type == "capsule") return Capsule(r, h);
      if (type == "cylinder") return Cylinder(r, h);
      return Cone(r, h);
    }
    if (type == "convex") {
      onlyKeys(v, path, {"type", "vertices"});
      return ConvexHull(points(key("vertices"), at("vertices")));
    }
  } catch (const ShapeError& e) {
    fail(path + ": " + e.what());
  }
  fail(at("type") + ": unknown shape type \"" + type +
       "\" (expected point, segment, triangle, box, sphere, capsule, cylinder, cone or convex)");
}

// Rotation from a quaternion (x, y, z, w). Any non-zero length is accepted and normalised; the
// components are first scaled by the largest so that tiny or huge quaternions normalise exactly.
Mat3 rotationFromQuaternion(const json& v, const std::string& path) {
  array(v, path, 4);
  double q[4];
  for (int i = 0; i < 4; ++i) q[i] = number(v[i], index(path, i));
  const double m = std::max({std::abs(q[0]), std::abs(q[1]), std::abs(q[2]), std::abs(q[3])});
  if (!(m > 0.0)) fail(path + " must not be the zero quaternion");
  return Pose::fromQuaternion(q[0] / m, q[1] / m, q[2] / m, q[3] / m, Vec3::Zero()).R;
}

// A rotation matrix given row by row, taken as written once it is proven a rotation: orthonormal
// within 1e-9 in every entry of RᵀR − I, and right-handed (det > 0, so det ≈ +1).
Mat3 rotationFromMatrix(const json& v, const std::string& path) {
  array(v, path, 3);
  Mat3 R;
  for (int i = 0; i < 3; ++i) R.row(i) = vec3(v[i], index(path, i)).transpose();
  const double off = (R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff();
  const double det = R.determinant();
  constexpr double kOrthonormal = 1e-9;
  if (!(off <= kOrthonormal))
    fail(path + " is not a rotation: max |R^T R - I| = " + json(off).dump() + " exceeds 1e-9");
  if (!(det > 0.0)) fail(path + " is not a rotation: det = " + json(det).dump() + " (a reflection)");
  return R;
}

Pose parsePose(const json& v, const std::string& path) {
  object(v, path);
  Pose pose;
  const bool matrix = v.contains("R") || v.contains("t");
  if (matrix && (v.contains("position") || v.contains("orientation")))
    fail(path + " must have either position and orientation, or R and t, not both");
  if (matrix) {
    onlyKeys(v, path, {"R", "t"});
    pose.R = rotationFromMatrix(member(v, path, "R"), join(path, "R"));
    pose.t = vec3(member(v, path, "t"), join(path, "t"));
  } else {
    onlyKeys(v, path, {"position", "orientation"});
    pose.t = vec3(member(v, path, "position"), join(path, "position"));
    pose.R = rotationFromQuaternion(member(v, path, "orientation"), join(path, "orientation"));
  }
  return pose;
}

PosedShape parseBody(const json& v, const std::string& path) {
  object(v, path);
  onlyKeys(v, path, {"shape", "pose"});
  return {parseShape(member(v, path, "shape"), join(path, "shape")), parsePose(member(v, path, "pose"), join(path, "pose"))};
}

QueryKind parseKind(const json& v) {
  const std::string q = string(v, "query");
  if (q == "intersect") return QueryKind::Intersect;
  if (q == "distance") return QueryKind::Distance;
  if (q == "penetration") return QueryKind::Penetration;
  if (q == "raycast") return QueryKind::Raycast;
  if (q == "shapecast") return QueryKind::Shapecast;
  fail("query: unknown query \"" + q + "\" (expected intersect, distance, penetration, raycast or shapecast)");
}

bool validId(const json& id) { return id.is_string() || id.is_number(); }

// ---------------------------------------------------------------------------------------------
// Results.

ordered_json toJson(const Vec3& v) { return ordered_json::array({v.x(), v.y(), v.z()}); }

ordered_json header(const QueryCase& q, Status status, int iterations) {
  ordered_json r;
  r["id"] = q.id;
  r["status"] = statusName(status);
  r["iterations"] = iterations;
  return r;
}

ordered_json errorResult(const json& id, long line_number, const std::string& message) {
  ordered_json r;
  r["id"] = id;
  r["line"] = line_number;
  r["status"] = "error";
  r["error"] = message;
  return r;
}

// The deepest nesting of arrays and objects a line may have. The format needs 4 ({"a": {"shape":
// {"vertices": [[x, y, z]]}}}); nlohmann's dump (used in error messages) recurses once per level, so a
// line nested tens of thousands deep would overflow the stack.
constexpr int kMaxJsonDepth = 32;

// The nesting depth of JSON text ([ and { outside strings), counted up to limit + 1.
int nestingDepth(const std::string& text, int limit) {
  int depth = 0, deepest = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size() && deepest <= limit; ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;  // the escaped character cannot end the string
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

// The text of a nlohmann exception without its "[json.exception.parse_error.101] " prefix.
std::string bareMessage(const std::exception& e) {
  const std::string s = e.what();
  const auto cut = s.rfind("] ", s.find(' '));
  return cut == std::string::npos ? s : s.substr(cut + 2);
}

// Where a parse is, followed through nlohmann's callback events: the key path of the current value, and
// the keys each open object gave so far.
struct KeyPath {
  struct Frame {
    bool is_array;
    std::string key;
    std::size_t count = 0;
    std::vector<std::string> keys;  // (an object's few keys: a scan beats a set)
  };
  std::vector<Frame> stack;

  // Follows one event; true when it is a key its object gave before.
  bool follow(json::parse_event_t event, const json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
        stack.push_back({false, "", 0, {}});
        break;
      case json::parse_event_t::array_start:
        stack.push_back({true, "", 0, {}});
        break;
      case json::parse_event_t::key:
        if (!stack.empty()) {
          Frame& f = stack.back();
          f.key = parsed.get<std::string>();
          if (std::find(f.keys.begin(), f.keys.end(), f.key) != f.keys.end()) return true;
          f.keys.push_back(f.key);
        }
        break;
      case json::parse_event_t::value:
        if (!stack.empty() && stack.back().is_array) ++stack.back().count;
        break;
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        if (!stack.empty()) stack.pop_back();
        if (!stack.empty() && stack.back().is_array) ++stack.back().count;
        break;
    }
    return false;
  }
  std::string path() const {
    std::string out;
    for (const Frame& f : stack) out = f.is_array ? index(out, f.count) : join(out, f.key);
    return out;
  }
};

// Parses the line again, every event through `callback` (which keeps every value: it returns true); an
// error ends it quietly, as it is the one the line already gave (the callback has recorded where).
template <class Callback>
void parseFollowing(const std::string& line, Callback&& callback) {
  try {
    const json discarded = json::parse(line, callback);
    static_cast<void>(discarded);
  } catch (const json::exception&) {
  }
}

// Where nlohmann stopped on a number that overflows a double (JSON's only way to spell a
// non-finite number): the key path of that value, and the case's id if it came earlier in the line.
struct OverflowSite {
  std::string path;
  json id;
};

// Re-parses the line following the key path; used only on that error.
OverflowSite locateOverflow(const std::string& line) {
  KeyPath at;
  json id = nullptr;
  parseFollowing(line, [&](int depth, json::parse_event_t event, json& parsed) {
    at.follow(event, parsed);
    if (event == json::parse_event_t::value && depth == 1 && at.stack.size() == 1 && at.stack[0].key == "id" &&
        validId(parsed))
      id = parsed;
    return true;
  });
  const std::string path = at.path();
  return {path.empty() ? "line" : path, id};
}

// The key path of the first key an object of the line repeats ("" for none). nlohmann::json keeps the last
// value of a repeated key, so a case could be answered for a shape other than the one written first; the
// scene files refuse repeated keys too. Parsed again only for a line that parsed.
std::string repeatedKey(const std::string& line) {
  KeyPath at;
  std::string found;
  parseFollowing(line, [&](int, json::parse_event_t event, json& parsed) {
    if (found.empty() && at.follow(event, parsed)) found = at.path();
    return true;
  });
  return found;
}

}  // namespace

QueryCase parseQueryCase(const json& line) {
  object(line, "line");
  QueryCase q;
  q.id = member(line, "", "id");
  if (!validId(q.id)) wrongType("id", "a string or a number", q.id);
  q.kind = parseKind(member(line, "", "query"));
  switch (q.kind) {
    case QueryKind::Raycast: onlyKeys(line, "", {"id", "query", "a", "ray", "tolerance"}); break;
    case QueryKind::Shapecast: onlyKeys(line, "", {"id", "query", "a", "b", "cast", "tolerance"}); break;
    default: onlyKeys(line, "", {"id", "query", "a", "b", "tolerance"}); break;
  }
  q.a = parseBody(member(line, "", "a"), "a");
  if (q.kind != QueryKind::Raycast) q.b = parseBody(member(line, "", "b"), "b");
  if (q.kind == QueryKind::Raycast) {
    const json& ray = object(member(line, "", "ray"), "ray");
    onlyKeys(ray, "ray", {"origin", "direction", "max_t"});
    q.ray.origin = vec3(member(ray, "ray", "origin"), "ray.origin");
    q.ray.direction = vec3(member(ray, "ray", "direction"), "ray.direction");
    q.ray.max_t = nonNegative(member(ray, "ray", "max_t"), "ray.max_t");
  }
  if (q.kind == QueryKind::Shapecast) {
    const json& cast = object(member(line, "", "cast"), "cast");
    onlyKeys(cast, "cast", {"velocity_a", "max_t"});
    q.velocity_a = vec3(member(cast, "cast", "velocity_a"), "cast.velocity_a");
    q.max_t = nonNegative(member(cast, "cast", "max_t"), "cast.max_t");
  }
  if (const auto it = line.find("tolerance"); it != line.end()) {
    const double t = positive(*it, "tolerance");
    q.tolerances.gjk_relative = t;
    q.tolerances.cast_relative = t;
    q.tolerances.epa_relative = t;
  }
  return q;
}

ordered_json runQueryCase(const QueryCase& q) {
  const Tolerances& tol = q.tolerances;
  switch (q.kind) {
    case QueryKind::Intersect: {
      SimplexCache cache;  // fresh: each case stands alone
      const IntersectResult r = gjkIntersect(q.a.shape, q.a.pose, q.b->shape, q.b->pose, tol, cache);
      ordered_json out = header(q, r.status, r.iterations);
      out["intersect"] = r.intersecting;
      return out;
    }
    case QueryKind::Distance: {
      const DistanceResult r = gjkDistance(q.a.shape, q.a.pose, q.b->shape, q.b->pose, tol);
      ordered_json out = header(q, r.status, r.iterations);
      out["distance"] = r.distance;
      out["point_a"] = toJson(r.point_a);
      out["point_b"] = toJson(r.point_b);
      out["normal"] = toJson(r.normal);
      return out;
    }
    case QueryKind::Penetration: {
      const PenetrationResult r = epaPenetration(q.a.shape, q.a.pose, q.b->shape, q.b->pose, tol);
      ordered_json out = header(q, r.status, r.iterations);
      out["depth"] = r.depth;
      out["signed_distance"] = r.signed_distance;
      out["normal"] = toJson(r.normal);
      out["point_a"] = toJson(r.point_a);
      out["point_b"] = toJson(r.point_b);
      return out;
    }
    case QueryKind::Raycast:
    case QueryKind::Shapecast: {
      const CastResult r = q.kind == QueryKind::Raycast
                               ? gjkRayCast(q.a.shape, q.a.pose, q.ray, tol)
                               : gjkShapeCast(q.a.shape, q.a.pose, q.velocity_a, q.b->shape, q.b->pose, q.max_t, tol);
      ordered_json out = header(q, r.status, r.iterations);
      out["hit"] = r.hit;
      out["t"] = r.t;
      out["normal"] = toJson(r.normal);
      out["point"] = toJson(r.point);
      return out;
    }
  }
  return header(q, Status::InvalidInput, 0);  // unreachable: every kind is handled above
}

QueryLineResult runQueryLine(const std::string& line, long line_number) {
  if (nestingDepth(line, kMaxJsonDepth) > kMaxJsonDepth)
    return {errorResult(nullptr, line_number, "arrays and objects nested deeper than " + std::to_string(kMaxJsonDepth) +
                                                  " levels (a query needs at most 4)"),
            true};
  // (nlohmann::json reads a line only to its first NUL byte: what follows was dropped unread.)
  if (const std::size_t nul = line.find('\0'); nul != std::string::npos)
    return {
        errorResult(nullptr, line_number, "a NUL byte at column " + std::to_string(nul + 1) + ": a query line is text"),
        true};
  json parsed;
  try {
    parsed = json::parse(line);
  } catch (const json::out_of_range& e) {
    // A number too large for a double: the only way JSON can spell a non-finite value.
    const OverflowSite site = locateOverflow(line);
    return {errorResult(site.id, line_number, site.path + " must be finite: " + bareMessage(e)), true};
  } catch (const json::exception& e) {
    return {errorResult(nullptr, line_number, "not valid JSON: " + bareMessage(e)), true};
  }
  json id = nullptr;
  if (parsed.is_object()) {
    const auto it = parsed.find("id");
    if (it != parsed.end() && validId(*it)) id = *it;
  }
  if (const std::string repeated = repeatedKey(line); !repeated.empty())
    return {errorResult(id, line_number, repeated + " is given twice (each key once)"), true};
  try {
    return {runQueryCase(parseQueryCase(parsed)), false};
  } catch (const QueryError& e) {
    return {errorResult(id, line_number, e.what()), true};
  } catch (const std::exception& e) {
    // Not expected (every check above throws QueryError), but one bad line must not end the file.
    return {errorResult(id, line_number, std::string("unexpected error: ") + e.what()), true};
  }
}

int runQueryStream(std::istream& in, std::ostream& out, bool flush_each_line) {
  bool any_error = false;
  long line_number = 0;
  std::string line;
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();  // files written on Windows
    if (line.find_first_not_of(" \t\r\n") == std::string::npos) continue;
    const QueryLineResult r = runQueryLine(line, line_number);
    any_error = any_error || r.error;
    out << r.json.dump(-1, ' ', false, ordered_json::error_handler_t::replace) << '\n';
    if (flush_each_line) out.flush();
  }
  return any_error ? cli::kExitNo : cli::kExitOk;
}

}  // namespace clearway
