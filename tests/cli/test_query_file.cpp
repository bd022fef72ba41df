// `clearway query`: lines of the query-file format in, result objects out. Answers are compared
// with closed forms within 1e-9 (distances, depths, times of impact; the default relative tolerance
// 1e-6 bounds the gap between GJK's bounds and these pairs converge far below it) unless a looser
// bound is stated beside the check; bad input must name the offending key.
#include "cli/query_file.h"
#include "cli/tool_run.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>

using namespace clearway;
using nlohmann::ordered_json;

namespace {

// A case of the given query between two bodies; `extra` is appended inside the top-level object.
std::string pair(const std::string& query, const std::string& a, const std::string& b, const std::string& extra = "") {
  return R"({"id": "t", "query": ")" + query + R"(", "a": )" + a + R"(, "b": )" + b + extra + "}";
}
std::string body(const std::string& shape, const std::string& position = "[0, 0, 0]") {
  return R"({"shape": )" + shape + R"(, "pose": {"position": )" + position + R"(, "orientation": [0, 0, 0, 1]}})";
}

ordered_json ok(const std::string& line) {
  const QueryLineResult r = runQueryLine(line, 1);
  EXPECT_FALSE(r.error) << line << "\n-> " << r.json.dump();
  EXPECT_NE(r.json.value("status", std::string()), "not_converged") << r.json.dump();
  return r.json;
}

// Runs a line that must be rejected; returns the error text after checking the error object's shape.
std::string error(const std::string& line, long line_number = 7) {
  const QueryLineResult r = runQueryLine(line, line_number);
  EXPECT_TRUE(r.error) << line << "\n-> " << r.json.dump();
  EXPECT_EQ(r.json.value("status", std::string()), "error");
  EXPECT_EQ(r.json.value("line", -1L), line_number);
  EXPECT_TRUE(r.json.contains("id"));
  return r.json.value("error", std::string());
}

Vec3 vec(const ordered_json& j) { return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()}; }

void expectVec(const ordered_json& j, const Vec3& expected, double tol) {
  const Vec3 got = vec(j);
  EXPECT_NEAR((got - expected).norm(), 0.0, tol) << "got " << got.transpose() << " expected " << expected.transpose();
}

double distanceOf(const std::string& shape_a, const std::string& position_b, const std::string& shape_b = R"({"type": "point"})") {
  return ok(pair("distance", body(shape_a), body(shape_b, position_b)))["distance"].get<double>();
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Query kinds

TEST(QueryFile, DistanceSphereSphere) {
  const ordered_json r = ok(pair("distance", body(R"({"type": "sphere", "radius": 0.5})", "[1, 2, 3]"),
                                 body(R"({"type": "sphere", "radius": 0.25})", "[1, 2, 5]")));
  EXPECT_EQ(r["id"], "t");
  EXPECT_GE(r["iterations"].get<int>(), 1);
  EXPECT_NEAR(r["distance"].get<double>(), 1.25, 1e-12);
  expectVec(r["point_a"], Vec3(1, 2, 3.5), 1e-12);
  expectVec(r["point_b"], Vec3(1, 2, 4.75), 1e-12);
  expectVec(r["normal"], Vec3(0, 0, 1), 1e-12);
  // The fields come in the documented order: id, status, iterations, then the query's own.
  std::vector<std::string> keys;
  for (auto it = r.begin(); it != r.end(); ++it) keys.push_back(it.key());
  EXPECT_EQ(keys, (std::vector<std::string>{"id", "status", "iterations", "distance", "point_a", "point_b", "normal"}));
}

TEST(QueryFile, Intersect) {
  const std::string unit = R"({"type": "sphere", "radius": 1})";
  ordered_json r = ok(pair("intersect", body(unit), body(unit, "[2, 0, 0]")));  // touching: closed solids
  EXPECT_TRUE(r["intersect"].get<bool>());
  r = ok(pair("intersect", body(unit), body(unit, "[2.001, 0, 0]")));
  EXPECT_FALSE(r["intersect"].get<bool>());
  EXPECT_EQ(r["status"], "separated");
  r = ok(pair("intersect", body(R"({"type": "box", "half_extents": [1, 1, 1]})"), body(unit, "[1.5, 1.5, 0]")));
  EXPECT_TRUE(r["intersect"].get<bool>());  // corner distance sqrt(0.5) < 1
  r = ok(pair("intersect", body(R"({"type": "box", "half_extents": [1, 1, 1]})"), body(unit, "[1.8, 1.8, 0]")));
  EXPECT_FALSE(r["intersect"].get<bool>());  // corner distance 0.8·sqrt(2) > 1
}

TEST(QueryFile, PenetrationCapsuleInBoxAndSpheres) {
  // The capsule's lowest point is at 1.6 − 0.5 − 0.2 = 0.9, so it sinks 0.1 into the box top.
  ordered_json r = ok(pair("penetration", body(R"({"type": "box", "half_extents": [1, 1, 1]})"),
                           body(R"({"type": "capsule", "radius": 0.2, "half_length": 0.5})", "[0, 0, 1.6]")));
  EXPECT_NEAR(r["depth"].get<double>(), 0.1, 1e-9);
  EXPECT_NEAR(r["signed_distance"].get<double>(), -0.1, 1e-9);
  expectVec(r["normal"], Vec3(0, 0, 1), 1e-9);
  expectVec(r["point_a"], Vec3(0, 0, 1), 1e-9);
  expectVec(r["point_b"], Vec3(0, 0, 0.9), 1e-9);

  const std::string unit = R"({"type": "sphere", "radius": 1})";
  r = ok(pair("penetration", body(unit), body(unit, "[1.5, 0, 0]")));
  EXPECT_NEAR(r["depth"].get<double>(), 0.5, 1e-12);
  expectVec(r["normal"], Vec3(1, 0, 0), 1e-12);

  // Separated: depth 0 and the signed distance is the distance.
  r = ok(pair("penetration", body(unit), body(unit, "[0, 3, 0]")));
  EXPECT_EQ(r["depth"].get<double>(), 0.0);
  EXPECT_NEAR(r["signed_distance"].get<double>(), 1.0, 1e-12);
}

TEST(QueryFile, PenetrationDeepBoxes) {
  // Unit boxes overlapping by 0.5 along x, 1.8 along y, 1.9 along z: the shallowest axis is x.
  const std::string box = R"({"type": "box", "half_extents": [1, 1, 1]})";
  const ordered_json r = ok(pair("penetration", body(box), body(box, "[1.5, 0.2, 0.1]")));
  EXPECT_NEAR(r["depth"].get<double>(), 0.5, 1e-6);
  EXPECT_NEAR(r["signed_distance"].get<double>(), -0.5, 1e-6);
  expectVec(r["normal"], Vec3(1, 0, 0), 1e-6);
}

TEST(QueryFile, RaycastBoxSphereAndMiss) {
  const std::string box = body(R"({"type": "box", "half_extents": [1, 1, 1]})", "[5, 0, 0]");
  ordered_json r = ok(R"({"id": 3, "query": "raycast", "a": )" + box +
                      R"(, "ray": {"origin": [0, 0, 0], "direction": [1, 0, 0], "max_t": 10}})");
  EXPECT_EQ(r["id"], 3);  // numeric ids are echoed as numbers
  EXPECT_TRUE(r["hit"].get<bool>());
  EXPECT_NEAR(r["t"].get<double>(), 4.0, 1e-9);
  expectVec(r["normal"], Vec3(-1, 0, 0), 1e-9);
  expectVec(r["point"], Vec3(4, 0, 0), 1e-9);
  // t is in units of the direction's length.
  r = ok(R"({"id": 3, "query": "raycast", "a": )" + box +
         R"(, "ray": {"origin": [0, 0.5, 0], "direction": [2, 0, 0], "max_t": 10}})");
  EXPECT_NEAR(r["t"].get<double>(), 2.0, 1e-9);
  // Beyond max_t: no hit.
  r = ok(R"({"id": 3, "query": "raycast", "a": )" + box +
         R"(, "ray": {"origin": [0, 0, 0], "direction": [1, 0, 0], "max_t": 3.5}})");
  EXPECT_FALSE(r["hit"].get<bool>());
  // Sphere of radius 1 at x = 5, ray at height 0.5: enters at x = 5 − sqrt(0.75). A curved surface
  // is approached by successive tangent planes, so t is a lower bound within the cast tolerance
  // (cast_relative 1e-6 times the size, about 5 here), not exact to rounding.
  r = ok(R"({"id": "s", "query": "raycast", "a": )" + body(R"({"type": "sphere", "radius": 1})", "[5, 0, 0]") +
         R"(, "ray": {"origin": [0, 0.5, 0], "direction": [1, 0, 0], "max_t": 10}})");
  const double exact = 5.0 - std::sqrt(0.75);
  EXPECT_NEAR(r["t"].get<double>(), exact, 5e-6);
  EXPECT_LE(r["t"].get<double>(), exact + 1e-12);
  expectVec(r["normal"], Vec3(-std::sqrt(0.75), 0.5, 0), 1e-6);
}

TEST(QueryFile, ShapecastSphereIntoBox) {
  // The sphere's centre reaches x = −1.5 (touching the face x = −1) after t = 1.5.
  const ordered_json r =
      ok(pair("shapecast", body(R"({"type": "sphere", "radius": 0.5})", "[-3, 0, 0]"),
              body(R"({"type": "box", "half_extents": [1, 1, 1]})"), R"(, "cast": {"velocity_a": [1, 0, 0], "max_t": 10})"));
  EXPECT_TRUE(r["hit"].get<bool>());
  EXPECT_NEAR(r["t"].get<double>(), 1.5, 1e-9);
  expectVec(r["normal"], Vec3(-1, 0, 0), 1e-9);  // outward normal of the still shape B
  expectVec(r["point"], Vec3(-1, 0, 0), 1e-9);
  const ordered_json miss =
      ok(pair("shapecast", body(R"({"type": "sphere", "radius": 0.5})", "[-3, 0, 0]"),
              body(R"({"type": "box", "half_extents": [1, 1, 1]})"), R"(, "cast": {"velocity_a": [1, 0, 0], "max_t": 1})"));
  EXPECT_FALSE(miss["hit"].get<bool>());
}

TEST(QueryFile, ShapecastConeIntoTriangle) {
  // The cone's rim (radius 0.3, at z = −0.4) leads; it meets the plane x = 0 at t = 2 − 0.3, inside the triangle.
  const ordered_json r = ok(pair("shapecast", body(R"({"type": "cone", "radius": 0.3, "half_length": 0.4})", "[-2, 0, 0]"),
                                 body(R"({"type": "triangle", "vertices": [[0, -1, -1], [0, 1, -1], [0, 0, 1]]})"),
                                 R"(, "cast": {"velocity_a": [1, 0, 0], "max_t": 5})"));
  EXPECT_NEAR(r["t"].get<double>(), 1.7, 1e-6 * 2.5);  // curved rim: within the cast tolerance
  EXPECT_LE(r["t"].get<double>(), 1.7 + 1e-12);         // a lower bound on the time of impact
  expectVec(r["normal"], Vec3(-1, 0, 0), 1e-6);
}

// ---------------------------------------------------------------------------------------------
// Every shape type, against a point or sphere with a closed-form distance.

TEST(QueryFile, EveryShapeType) {
  EXPECT_NEAR(distanceOf(R"({"type": "point"})", "[3, 4, 0]"), 5.0, 1e-12);
  // Segment along z from −1 to 1; the point projects inside it.
  EXPECT_NEAR(distanceOf(R"({"type": "segment", "p0": [0, 0, -1], "p1": [0, 0, 1]})", "[2, 0, 0.5]"), 2.0, 1e-9);
  EXPECT_NEAR(distanceOf(R"({"type": "segment", "p0": [0, 0, -1], "p1": [0, 0, 1]})", "[0, 0, 4]"), 3.0, 1e-9);
  const ordered_json tri = ok(pair("distance", body(R"({"type": "triangle", "vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0]]})"),
                                   body(R"({"type": "point"})", "[0.25, 0.25, 2]")));
  EXPECT_NEAR(tri["distance"].get<double>(), 2.0, 1e-9);
  expectVec(tri["point_a"], Vec3(0.25, 0.25, 0), 1e-9);
  EXPECT_NEAR(distanceOf(R"({"type": "box", "half_extents": [1, 2, 3]})", "[3, 0, 0]", R"({"type": "sphere", "radius": 0.5})"),
              1.5, 1e-9);
  EXPECT_NEAR(distanceOf(R"({"type": "box", "half_extents": [1, 2, 3]})", "[2, 3, 4]"), std::sqrt(3.0), 1e-9);
  EXPECT_NEAR(distanceOf(R"({"type": "sphere", "radius": 1})", "[0, 3, 0]"), 2.0, 1e-12);
  // Capsule along z: the cap above, the side at the middle.
  EXPECT_NEAR(distanceOf(R"({"type": "capsule", "radius": 0.5, "half_length": 1})", "[0, 0, 3]"), 1.5, 1e-9);
  EXPECT_NEAR(distanceOf(R"({"type": "capsule", "radius": 0.5, "half_length": 1})", "[2, 0, 0.3]"), 1.5, 1e-9);
  // Cylinder along z: side, flat end, rim.
  EXPECT_NEAR(distanceOf(R"({"type": "cylinder", "radius": 0.5, "half_length": 1})", "[0, 2, 0]"), 1.5, 1e-9);
  EXPECT_NEAR(distanceOf(R"({"type": "cylinder", "radius": 0.5, "half_length": 1})", "[0.1, 0, 3]"), 2.0, 1e-9);
  EXPECT_NEAR(distanceOf(R"({"type": "cylinder", "radius": 0.5, "half_length": 1})", "[2, 0, 2]"), std::hypot(1.5, 1.0),
              1e-6);
  // Cone of radius 1, base at z = −1, apex at z = 1: apex, base, and the slant 2r + z = 1 with
  // outward normal (2, 0, 1)/sqrt(5); the point (2, 0, 0) projects onto the slant at (0.8, 0, −0.6).
  const std::string cone = R"({"type": "cone", "radius": 1, "half_length": 1})";
  EXPECT_NEAR(distanceOf(cone, "[0, 0, 3]"), 2.0, 1e-9);
  EXPECT_NEAR(distanceOf(cone, "[0.2, 0, -2]"), 1.0, 1e-9);
  const ordered_json slant = ok(pair("distance", body(cone), body(R"({"type": "point"})", "[2, 0, 0]")));
  EXPECT_NEAR(slant["distance"].get<double>(), 3.0 / std::sqrt(5.0), 1e-6);
  expectVec(slant["point_a"], Vec3(0.8, 0, -0.6), 1e-5);
  // Convex hull with a duplicate and an interior point: the tetrahedron above the unit box.
  const ordered_json hull = ok(pair(
      "distance", body(R"({"type": "box", "half_extents": [0.5, 0.5, 0.5]})"),
      body(R"({"type": "convex", "vertices": [[0, 0, 2], [1, 0, 2], [0, 1, 2], [0, 0, 3], [1, 0, 2], [0.1, 0.1, 2.1]]})")));
  EXPECT_NEAR(hull["distance"].get<double>(), 1.5, 1e-9);
  expectVec(hull["normal"], Vec3(0, 0, 1), 1e-9);
}

// ---------------------------------------------------------------------------------------------
// Poses, tolerance, numbers

TEST(QueryFile, BothPoseFormsAgree) {
  // Box (1, 2, 3) turned 90° about z presents its y extent (2) along x: the point at x = 3 is 1 away.
  const std::string box = R"({"type": "box", "half_extents": [1, 2, 3]})";
  const std::string point = body(R"({"type": "point"})", "[3, 0, 0]");
  const double s = std::sqrt(0.5);
  const std::string quat = R"({"shape": )" + box + R"(, "pose": {"position": [0, 0, 0], "orientation": [0, 0, )" +
                           ordered_json(s).dump() + ", " + ordered_json(s).dump() + "]}}";
  const std::string quat_unnormalised = R"({"shape": )" + box + R"(, "pose": {"position": [0, 0, 0], "orientation": [0, 0, 2, 2]}})";
  const std::string matrix = R"({"shape": )" + box + R"(, "pose": {"R": [[0, -1, 0], [1, 0, 0], [0, 0, 1]], "t": [0, 0, 0]}})";
  for (const std::string& a : {quat, quat_unnormalised, matrix}) {
    const ordered_json r = ok(pair("distance", a, point));
    EXPECT_NEAR(r["distance"].get<double>(), 1.0, 1e-9) << a;
    expectVec(r["point_a"], Vec3(2, 0, 0), 1e-9);
  }
  // Translation in both forms: world point = R·local + t.
  const ordered_json r = ok(pair("distance", R"({"shape": )" + box + R"(, "pose": {"R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "t": [10, 0, 0]}})",
                                 body(R"({"type": "point"})", "[13, 0, 0]")));
  EXPECT_NEAR(r["distance"].get<double>(), 2.0, 1e-9);
}

TEST(QueryFile, ToleranceOverridesEveryRelativeTolerance) {
  const std::string unit = body(R"({"type": "sphere", "radius": 1})");
  QueryCase q = parseQueryCase(nlohmann::json::parse(pair("distance", unit, unit, R"(, "tolerance": 0.125)")));
  EXPECT_EQ(q.tolerances.gjk_relative, 0.125);
  EXPECT_EQ(q.tolerances.cast_relative, 0.125);
  EXPECT_EQ(q.tolerances.epa_relative, 0.125);
  EXPECT_EQ(q.tolerances.gjk_max_iterations, Tolerances{}.gjk_max_iterations);  // caps untouched
  q = parseQueryCase(nlohmann::json::parse(pair("distance", unit, unit)));
  EXPECT_EQ(q.tolerances.gjk_relative, Tolerances{}.gjk_relative);

  // And it reaches the solver: between two cylinders (curved rims) a loose tolerance stops GJK
  // sooner, still within its stated relative error.
  const std::string cyl = R"({"type": "cylinder", "radius": 0.5, "half_length": 1})";
  const std::string b = R"({"shape": )" + cyl + R"(, "pose": {"position": [2, 0.3, 2.5], "orientation": [0.3, 0.1, 0, 1]}})";
  const ordered_json tight = ok(pair("distance", body(cyl), b, R"(, "tolerance": 1e-12)"));
  const ordered_json loose = ok(pair("distance", body(cyl), b, R"(, "tolerance": 0.2)"));
  const double exact = tight["distance"].get<double>();
  EXPECT_LT(loose["iterations"].get<int>(), tight["iterations"].get<int>());
  EXPECT_GE(loose["distance"].get<double>(), exact - 1e-12);
  EXPECT_LE(loose["distance"].get<double>(), exact * 1.25 + 1e-12);
}

TEST(QueryFile, NumbersAreTakenAndPrintedExactly) {
  const QueryCase q = parseQueryCase(nlohmann::json::parse(
      pair("distance", body(R"({"type": "sphere", "radius": 0.1})", "[1.0000000000000002, -0, 1e-300]"),
           body(R"({"type": "sphere", "radius": 0.30000000000000004})", "[3, 0, 0]"))));
  EXPECT_EQ(std::get<Sphere>(q.a.shape).r, 0.1);
  EXPECT_EQ(std::get<Sphere>(q.b->shape).r, 0.1 + 0.2);
  EXPECT_EQ(q.a.pose.t.x(), 1.0000000000000002);
  EXPECT_EQ(q.a.pose.t.z(), 1e-300);
  // Printed doubles parse back to the same bits (nlohmann prints the shortest round-trip form).
  const ordered_json r = runQueryCase(q);
  const std::string text = r.dump();
  const nlohmann::json back = nlohmann::json::parse(text);
  EXPECT_EQ(back["distance"].get<double>(), r["distance"].get<double>()) << text;
  EXPECT_EQ(std::strtod(ordered_json(0.1 + 0.2).dump().c_str(), nullptr), 0.1 + 0.2);
}

// ---------------------------------------------------------------------------------------------
// Bad input: each yields an error naming the key, and the rest of the file still runs.

TEST(QueryFileErrors, NotJson) {
  const QueryLineResult r = runQueryLine("{\"id\": \"x\", ", 4);
  EXPECT_TRUE(r.error);
  EXPECT_TRUE(r.json["id"].is_null());
  EXPECT_EQ(r.json["line"], 4);
  EXPECT_MENTIONS(r.json["error"].get<std::string>(), "not valid JSON");
  EXPECT_MENTIONS(error("[1, 2, 3]"), "must be an object");
}

// A key given twice kept its last value (a case answered for a shape other than the one written first), and
// what followed a NUL byte was dropped unread: both refused, naming where.
TEST(QueryFileErrors, RepeatedKeysAndNulBytes) {
  const std::string sphere = R"({"type": "sphere", "radius": 1})";
  const std::string line = pair("intersect", body(sphere), body(sphere, "[1, 0, 0]"));
  EXPECT_TRUE(ok(line)["intersect"].get<bool>());
  EXPECT_EQ(error(pair("intersect", body(sphere), body(sphere, "[1, 0, 0]"), R"(, "b": )" + body(sphere, "[5, 0, 0]"))),
            "b is given twice (each key once)");
  EXPECT_EQ(
      error(pair("distance", body(R"({"type": "sphere", "radius": 1, "radius": 0.1})"), body(sphere, "[3, 0, 0]"))),
      "a.shape.radius is given twice (each key once)");
  EXPECT_EQ(error(pair("distance", body(sphere),
                       body(R"({"type": "convex", "vertices": [[0, 0, 0], [1, 0, 0], )"
                            R"([0, 1, 0], [0, 0, 1]], "vertices": [[0, 0, 0]]})",
                            "[3, 0, 0]"))),
            "b.shape.vertices is given twice (each key once)");
  std::string nul = line;
  nul.insert(nul.size() - 1, std::string(", \"b\": ") + '\0');
  EXPECT_EQ(error(nul), "a NUL byte at column " + std::to_string(line.size() + 7) + ": a query line is text");
}

TEST(QueryFileErrors, MissingKeys) {
  const std::string unit = body(R"({"type": "sphere", "radius": 1})");
  EXPECT_MENTIONS(error(R"({"query": "distance", "a": )" + unit + R"(, "b": )" + unit + "}"), "id is missing");
  const QueryLineResult no_query = runQueryLine(R"({"id": "q1", "a": )" + unit + R"(, "b": )" + unit + "}", 2);
  EXPECT_EQ(no_query.json["id"], "q1");  // the id is known, so it is echoed
  EXPECT_MENTIONS(no_query.json["error"].get<std::string>(), "query is missing");
  EXPECT_MENTIONS(error(R"({"id": "x", "query": "distance", "a": )" + unit + "}"), "b is missing");
  EXPECT_MENTIONS(error(pair("distance", body(R"({"type": "sphere"})"), unit)), "a.shape.radius is missing");
  EXPECT_MENTIONS(error(pair("distance", unit, R"({"shape": {"type": "point"}})")), "b.pose is missing");
  EXPECT_MENTIONS(error(pair("distance", unit, R"({"shape": {"type": "point"}, "pose": {"position": [0, 0, 0]}})")),
                  "b.pose.orientation is missing");
  EXPECT_MENTIONS(error(pair("distance", unit, R"({"shape": {"type": "point"}, "pose": {"R": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}})")),
                  "b.pose.t is missing");
  EXPECT_MENTIONS(error(pair("distance", unit, R"({"shape": {"type": "point"}, "pose": {"position": [0, 0, 0], "orientation": [0, 0, 0, 1], "t": [0, 0, 0]}})")),
                  "b.pose must have either position and orientation, or R and t");
  EXPECT_MENTIONS(error(R"({"id": "x", "query": "raycast", "a": )" + unit + "}"), "ray is missing");
  EXPECT_MENTIONS(error(R"({"id": "x", "query": "raycast", "a": )" + unit + R"(, "ray": {"origin": [0, 0, 0], "direction": [1, 0, 0]}})"),
                  "ray.max_t is missing");
  EXPECT_MENTIONS(error(pair("shapecast", unit, unit)), "cast is missing");
  EXPECT_MENTIONS(error(pair("shapecast", unit, unit, R"(, "cast": {"max_t": 1})")), "cast.velocity_a is missing");
  EXPECT_MENTIONS(error(pair("distance", body(R"({"radius": 1})"), unit)), "a.shape.type is missing");
}

TEST(QueryFileErrors, WrongTypes) {
  const std::string unit = body(R"({"type": "sphere", "radius": 1})");
  EXPECT_MENTIONS(error(pair("distance", body(R"({"type": "sphere", "radius": "1"})"), unit)), "a.shape.radius must be a number");
  EXPECT_MENTIONS(error(pair("distance", body(R"({"type": "sphere", "radius": true})"), unit)), "a.shape.radius must be a number");
  EXPECT_MENTIONS(error(pair("distance", body(R"({"type": "sphere", "radius": [1]})"), unit)), "a.shape.radius must be a number");
  EXPECT_MENTIONS(error(pair("distance", unit, body(R"({"type": 3})"))), "b.shape.type must be a string");
  EXPECT_MENTIONS(error(pair("distance", unit, R"("sphere")")), "b must be an object");
  EXPECT_MENTIONS(error(pair("distance", unit, body(R"({"type": "box", "half_extents": {"x": 1}})"))), "b.shape.half_extents must be an array");
  EXPECT_MENTIONS(error(R"({"id": ["x"], "query": "distance", "a": )" + unit + R"(, "b": )" + unit + "}"), "id must be a string or a number");
  EXPECT_MENTIONS(error(R"({"id": "x", "query": 1, "a": )" + unit + R"(, "b": )" + unit + "}"), "query must be a string");
  EXPECT_MENTIONS(error(pair("distance", unit, unit, R"(, "tolerance": "1e-3")")), "tolerance must be a number");
}

TEST(QueryFileErrors, UnknownShapeQueryAndKey) {
  const std::string unit = body(R"({"type": "sphere", "radius": 1})");
  EXPECT_MENTIONS(error(pair("distance", unit, body(R"({"type": "torus", "radius": 1})"))), "b.shape.type");
  EXPECT_MENTIONS(error(pair("distance", unit, body(R"({"type": "torus", "radius": 1})"))), "torus");
  const std::string q = error(pair("closest", unit, unit));
  EXPECT_MENTIONS(q, "query");
  EXPECT_MENTIONS(q, "closest");
  EXPECT_MENTIONS(error(pair("distance", unit, unit, R"(, "tolerence": 0.1)")), "tolerence");
  EXPECT_MENTIONS(error(pair("distance", body(R"({"type": "sphere", "radius": 1, "half_length": 2})"), unit)), "a.shape.half_length");
  EXPECT_MENTIONS(error(pair("distance", unit, unit, R"(, "ray": {"origin": [0, 0, 0], "direction": [1, 0, 0], "max_t": 1})")),
                  "ray");
  EXPECT_MENTIONS(error(pair("raycast", unit, unit, R"(, "ray": {"origin": [0, 0, 0], "direction": [1, 0, 0], "max_t": 1})")),
                  "unknown key b");
}

TEST(QueryFileErrors, WrongVectorLength) {
  const std::string unit = body(R"({"type": "sphere", "radius": 1})");
  EXPECT_MENTIONS(error(pair("distance", unit, body(R"({"type": "point"})", "[1, 2]"))), "b.pose.position must have 3 elements");
  EXPECT_MENTIONS(error(pair("distance", unit, body(R"({"type": "box", "half_extents": [1, 1, 1, 1]})"))), "b.shape.half_extents");
  EXPECT_MENTIONS(error(pair("distance", unit, R"({"shape": {"type": "point"}, "pose": {"position": [0, 0, 0], "orientation": [0, 0, 1]}})")),
                  "b.pose.orientation must have 4 elements");
  EXPECT_MENTIONS(error(pair("distance", unit, R"({"shape": {"type": "point"}, "pose": {"R": [[1, 0, 0], [0, 1, 0]], "t": [0, 0, 0]}})")),
                  "b.pose.R must have 3 elements");
  EXPECT_MENTIONS(error(pair("distance", unit, R"({"shape": {"type": "point"}, "pose": {"R": [[1, 0, 0], [0, 1], [0, 0, 1]], "t": [0, 0, 0]}})")),
                  "b.pose.R[1] must have 3 elements");
  EXPECT_MENTIONS(error(pair("distance", unit, body(R"({"type": "triangle", "vertices": [[0, 0, 0], [1, 0, 0]]})"))),
                  "b.shape.vertices must have 3 elements");
  EXPECT_MENTIONS(error(pair("distance", unit, body(R"({"type": "convex", "vertices": [[0, 0, 0], [1, 0]]})"))),
                  "b.shape.vertices[1] must have 3 elements");
  EXPECT_MENTIONS(error(pair("shapecast", unit, unit, R"(, "cast": {"velocity_a": [1, 0], "max_t": 1})")), "cast.velocity_a");
}

TEST(QueryFileErrors, NonFiniteNumbers) {
  const std::string unit = body(R"({"type": "sphere", "radius": 1})");
  // JSON has no NaN or infinity: written as strings they are wrongly typed, written bare they are not JSON.
  EXPECT_MENTIONS(error(pair("distance", unit, body(R"({"type": "point"})", R"([0, "NaN", 0])"))), "b.pose.position[1] must be a number");
  EXPECT_MENTIONS(error(pair("distance", unit, body(R"({"type": "sphere", "radius": "inf"})"))), "b.shape.radius must be a number");
  EXPECT_MENTIONS(error(pair("distance", unit, body(R"({"type": "sphere", "radius": "Infinity"})"))), "b.shape.radius");
  EXPECT_MENTIONS(error(pair("distance", unit, body(R"({"type": "point"})", "[0, NaN, 0]"))), "not valid JSON");
  // A number too large for a double is the one non-finite value JSON can spell; the key is still named.
  EXPECT_MENTIONS(error(pair("distance", unit, body(R"({"type": "point"})", "[0, 0, 1e999]"))), "b.pose.position[2] must be finite");
  EXPECT_MENTIONS(error(pair("distance", unit, body(R"({"type": "sphere", "radius": -1e400})"))), "b.shape.radius must be finite");
  EXPECT_EQ(runQueryLine(pair("distance", unit, body(R"({"type": "sphere", "radius": 1e400})")), 1).json["id"], "t");
  EXPECT_MENTIONS(error(pair("distance", unit, body(R"({"type": "convex", "vertices": [[0, 0, 0], [1, 1e999, 0]]})"))),
                  "b.shape.vertices[1][1] must be finite");
  EXPECT_MENTIONS(error(R"({"id": "x", "query": "raycast", "a": )" + unit + R"(, "ray": {"origin": [0, 0, 0], "direction": [1, 0, 0], "max_t": 1e999}})"),
                  "ray.max_t must be finite");
}

TEST(QueryFileErrors, BadRadiiExtentsAndParameters) {
  const std::string unit = body(R"({"type": "sphere", "radius": 1})");
  EXPECT_MENTIONS(error(pair("distance", body(R"({"type": "sphere", "radius": 0})"), unit)), "a.shape.radius must be > 0");
  EXPECT_MENTIONS(error(pair("distance", body(R"({"type": "sphere", "radius": -0.5})"), unit)), "a.shape.radius must be > 0");
  for (const char* type : {"capsule", "cylinder", "cone"}) {
    const std::string s = std::string(R"({"type": ")") + type + R"(", "radius": 0, "half_length": 1})";
    EXPECT_MENTIONS(error(pair("distance", unit, body(s))), "b.shape.radius must be > 0");
    const std::string h = std::string(R"({"type": ")") + type + R"(", "radius": 1, "half_length": -1})";
    EXPECT_MENTIONS(error(pair("distance", unit, body(h))), "b.shape.half_length must be");
  }
  // A flat cylinder or capsule is allowed; a cone needs a height.
  ok(pair("distance", unit, body(R"({"type": "cylinder", "radius": 1, "half_length": 0})", "[5, 0, 0]")));
  EXPECT_MENTIONS(error(pair("distance", unit, body(R"({"type": "cone", "radius": 1, "half_length": 0})"))), "b.shape.half_length must be > 0");
  EXPECT_MENTIONS(error(pair("distance", unit, body(R"({"type": "box", "half_extents": [1, -1, 1]})"))), "b.shape.half_extents[1] must be >= 0");
  EXPECT_MENTIONS(error(pair("distance", unit, unit, R"(, "tolerance": 0)")), "tolerance must be > 0");
  EXPECT_MENTIONS(error(pair("distance", unit, unit, R"(, "tolerance": -1e-6)")), "tolerance must be > 0");
  EXPECT_MENTIONS(error(R"({"id": "x", "query": "raycast", "a": )" + unit + R"(, "ray": {"origin": [0, 0, 0], "direction": [1, 0, 0], "max_t": -1}})"),
                  "ray.max_t must be >= 0");
  EXPECT_MENTIONS(error(pair("shapecast", unit, unit, R"(, "cast": {"velocity_a": [1, 0, 0], "max_t": -2})")), "cast.max_t must be >= 0");
}

TEST(QueryFileErrors, EmptyVertexList) {
  const std::string unit = body(R"({"type": "sphere", "radius": 1})");
  EXPECT_MENTIONS(error(pair("distance", unit, body(R"({"type": "convex", "vertices": []})"))), "b.shape.vertices must not be empty");
  EXPECT_MENTIONS(error(pair("distance", unit, body(R"({"type": "triangle", "vertices": []})"))), "b.shape.vertices");
}

TEST(QueryFileErrors, DeepNestingIsAnErrorNotAStackOverflow) {
  // 100,000 levels as the id or as a radius once overflowed the stack (nlohmann's dump recurses).
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  EXPECT_MENTIONS(error(R"({"id": )" + deep + R"(, "query": "distance"})"), "nested deeper than 32 levels");
  const std::string sphere = R"({"type": "sphere", "radius": )" + deep + "}";
  EXPECT_MENTIONS(error(pair("distance", body(sphere), body(sphere))), "nested deeper than 32 levels");
  // Brackets inside strings do not count, and 32 levels are still read (and refused for what they hold).
  EXPECT_MENTIONS(error(R"({"id": ")" + std::string(100, '[') + R"(\"[", "query": "distance"})"), "a is missing");
  const std::string deep32 = std::string(31, '[') + "1" + std::string(31, ']');
  EXPECT_MENTIONS(error(R"({"id": )" + deep32 + "}"), "id must be a string or a number");
}

TEST(QueryFileErrors, BadRotations) {
  const std::string unit = body(R"({"type": "sphere", "radius": 1})");
  auto with_r = [&](const std::string& R) {
    return pair("distance", unit, R"({"shape": {"type": "point"}, "pose": {"R": )" + R + R"(, "t": [0, 0, 0]}})");
  };
  // Scaled, sheared, a reflection, and off by more than 1e-9.
  EXPECT_MENTIONS(error(with_r("[[2, 0, 0], [0, 2, 0], [0, 0, 2]]")), "b.pose.R is not a rotation");
  EXPECT_MENTIONS(error(with_r("[[1, 0.1, 0], [0, 1, 0], [0, 0, 1]]")), "b.pose.R is not a rotation");
  EXPECT_MENTIONS(error(with_r("[[1, 0, 0], [0, 1, 0], [0, 0, -1]]")), "b.pose.R is not a rotation");
  EXPECT_MENTIONS(error(with_r("[[1.00000001, 0, 0], [0, 1, 0], [0, 0, 1]]")), "b.pose.R is not a rotation");
  EXPECT_MENTIONS(error(with_r("[[0, 0, 0], [0, 0, 0], [0, 0, 0]]")), "b.pose.R is not a rotation");
  // Within 1e-9 it is accepted as written.
  ok(with_r("[[1.0000000001, 0, 0], [0, 1, 0], [0, 0, 1]]"));
  EXPECT_MENTIONS(error(pair("distance", unit, R"({"shape": {"type": "point"}, "pose": {"position": [0, 0, 0], "orientation": [0, 0, 0, 0]}})")),
                  "b.pose.orientation must not be the zero quaternion");
  // A tiny but non-zero quaternion is a valid rotation.
  const ordered_json r = ok(pair("distance", R"({"shape": {"type": "box", "half_extents": [1, 2, 3]}, "pose": {"position": [0, 0, 0], "orientation": [0, 0, 1e-200, 1e-200]}})",
                                 body(R"({"type": "point"})", "[3, 0, 0]")));
  EXPECT_NEAR(r["distance"].get<double>(), 1.0, 1e-9);
}

TEST(QueryFileErrors, StreamKeepsGoingAndSkipsBlankLines) {
  const std::string unit = body(R"({"type": "sphere", "radius": 1})");
  std::istringstream in(pair("distance", unit, body(R"({"type": "sphere", "radius": 1})", "[3, 0, 0]")) + "\n" +
                        "\n   \n" + "not json\r\n" + pair("distance", unit, body(R"({"type": "sphere", "radius": 0})")) + "\n" +
                        pair("intersect", unit, unit));  // no final newline
  std::ostringstream out;
  EXPECT_EQ(runQueryStream(in, out), 1);
  std::istringstream lines(out.str());
  std::vector<nlohmann::json> results;
  for (std::string l; std::getline(lines, l);) results.push_back(nlohmann::json::parse(l));
  ASSERT_EQ(results.size(), 4u);
  EXPECT_EQ(results[0]["distance"], 1.0);
  EXPECT_EQ(results[1]["status"], "error");
  EXPECT_EQ(results[1]["line"], 4);  // blank lines count
  EXPECT_TRUE(results[1]["id"].is_null());
  EXPECT_EQ(results[2]["status"], "error");
  EXPECT_EQ(results[2]["line"], 5);
  EXPECT_EQ(results[2]["id"], "t");
  EXPECT_EQ(results[3]["intersect"], true);

  std::istringstream good(pair("intersect", unit, unit) + "\n\n");
  std::ostringstream sink;
  EXPECT_EQ(runQueryStream(good, sink), 0);
}

// ---------------------------------------------------------------------------------------------
// The built tool.

#ifdef CLEARWAY_TOOL_PATH
using namespace clearway_test;
namespace {
std::vector<nlohmann::json> jsonLines(const std::string& text) {
  std::vector<nlohmann::json> v;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) v.push_back(nlohmann::json::parse(l));
  return v;
}
}  // namespace

TEST(QueryTool, RunsTheDemoFile) {
  const ToolRun r = runTool(std::string("query '") + CLEARWAY_SOURCE_DIR + "/robots/demo/queries.jsonl'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  const std::vector<nlohmann::json> lines = jsonLines(r.out);
  ASSERT_EQ(lines.size(), 5u) << r.out;
  const char* ids[] = {"box-vs-hull", "spheres-touching", "capsule-in-box", "ray-cylinder", "cone-cast"};
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(lines[i]["id"], ids[i]);
    EXPECT_NE(lines[i]["status"], "error");
    EXPECT_NE(lines[i]["status"], "not_converged");
  }
  EXPECT_NEAR(lines[0]["distance"].get<double>(), 1.5, 1e-9);
  EXPECT_EQ(lines[1]["intersect"], true);
  EXPECT_NEAR(lines[2]["depth"].get<double>(), 0.1, 1e-9);
  EXPECT_NEAR(lines[3]["t"].get<double>(), 2.5, 1e-9);
  EXPECT_NEAR(lines[4]["t"].get<double>(), 1.7, 1e-5);
}

TEST(QueryTool, ExitCodes) {
  // A bad line: exit 1, and the good lines still print.
  const std::string file = testing::TempDir() + "clearway_query_bad_" + std::to_string(::getpid()) + ".jsonl";
  std::ofstream(file) << pair("intersect", body(R"({"type": "point"})"), body(R"({"type": "point"})")) << "\n{oops\n";
  ToolRun r = runTool("query '" + file + "'");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(jsonLines(r.out).size(), 2u);
  // stdin.
  r = runTool("query - <'" + file + "'");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(jsonLines(r.out).size(), 2u);
  // Missing file: exit 2, the reason names it.
  r = runTool("query /nonexistent/queries.jsonl");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "/nonexistent/queries.jsonl");
  EXPECT_TRUE(r.out.empty());
  r = runTool("query '" + testing::TempDir() + "'");
  EXPECT_EQ(r.exit_code, 2);
  // Usage errors.
  EXPECT_EQ(runTool("").exit_code, 2);
  EXPECT_EQ(runTool("query").exit_code, 2);
  EXPECT_EQ(runTool("query a b").exit_code, 2);
  r = runTool("frobnicate");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "frobnicate");
  EXPECT_MENTIONS(r.err, "usage");
  r = runTool("--help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_MENTIONS(r.out, "query");
  EXPECT_EQ(runTool("query --help").exit_code, 0);
}

// ---- clearway plan and clearway check on the bundled scene.

std::string bundledScene() { return std::string("'") + CLEARWAY_SOURCE_DIR + "/robots/scenes/arm6_wall.yaml'"; }

TEST(PlanTool, PlansTheBundledSceneWithoutArguments) {
  // From any working directory: the build-tree binary finds the default scene in the source tree.
  const ToolRun r = runTool("plan --seed 3 --time 30");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::istringstream out(r.out);
  std::string word;
  int n = 0;
  out >> word >> n;
  EXPECT_EQ(word, "path");
  EXPECT_GE(n, 3) << "the wall blocks the straight line";
  int values = 0;
  for (double v; out >> v;) ++values;
  EXPECT_EQ(values, 6 * n);
  EXPECT_MENTIONS(r.err, "certified: yes");
}

// The time limit is the planner's termination condition: an optimizing planner (RRT*, which improves its
// path until then) plans for the whole limit and stops there, and so does a parallel one's every thread.
// (Under the sanitizers a second may end before any path: then the tool says so, and for how long it planned.)
TEST(PlanTool, PlannersStopAtTheTimeLimit) {
  for (const char* planner : {"RRTstar", "pRRT"}) {
    const ToolRun r = runTool(std::string("plan --planner ") + planner + " --seed 2 --time 1");
    ASSERT_TRUE(r.exit_code == 0 || r.exit_code == 1) << planner << ": " << r.err;
    const std::string says = r.exit_code == 0 ? "solved in " : "planned for ";
    const std::size_t at = r.err.find(says);
    ASSERT_NE(at, std::string::npos) << r.err;
    const double solve = std::stod(r.err.substr(at + says.size()));
    EXPECT_LE(solve, 1.5) << planner << ": planned past its limit";
    if (std::string(planner) == "RRTstar") EXPECT_GE(solve, 0.9) << "RRT* stopped before its limit";
  }
}

TEST(PlanTool, BadInput) {
  ToolRun r = runTool("plan " + bundledScene() + " --planner Teleport");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "Teleport");
  r = runTool("plan /nonexistent/scene.yaml");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "/nonexistent/scene.yaml");
  EXPECT_EQ(runTool("plan " + bundledScene() + " --time -1").exit_code, 2);
  EXPECT_EQ(runTool("plan " + bundledScene() + " --geometry fuzzy").exit_code, 2);
  // A start in collision: no path (exit 1), and the links are named.
  const std::string dir = testing::TempDir() + "clearway_plan_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  std::ifstream in(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/arm6_wall.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  s.replace(s.find("urdf: ../arm6"), 13, std::string("urdf: ") + CLEARWAY_SOURCE_DIR + "/robots/arm6");
  s.replace(s.find("srdf: ../arm6"), 13, std::string("srdf: ") + CLEARWAY_SOURCE_DIR + "/robots/arm6");
  s.replace(s.find("start: ["), 8, "start: [0, 1.7, 0.5, 0, 0, 0]\nold_start: [");  // into the floor
  s = s.substr(0, s.find("\nold_start")) + s.substr(s.find("\ngoal:"));
  std::ofstream(dir + "/floor.yaml") << s;
  r = runTool("plan '" + dir + "/floor.yaml'");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_MENTIONS(r.err, "start is in collision");
  EXPECT_MENTIONS(r.err, "floor");
  std::filesystem::remove_all(dir);
}

TEST(CheckTool, ClassifiesStates) {
  const std::string file = testing::TempDir() + "clearway_check_" + std::to_string(::getpid()) + ".txt";
  std::ofstream(file) << "# start, goal, into the floor, a bad line, out of bounds; empty fields (read as\n"
                         "# values left out: they were skipped, shifting the rest into other joints)\n"
                         "0 -0.6 -1.2 -1.34 0 0\n0, 0.6, 1.2, 1.34, 0, 0\n0 1.7 0.5 0 0 0\n0 1 x\n0 0 0 0 0 99\n"
                         "0,,0.6, 1.2, 1.34, 0, 0\n,0, 0.6, 1.2, 1.34, 0, 0\n0, 0.6, 1.2, 1.34, 0, 0,\n";
  ToolRun r = runTool("check " + bundledScene() + " --states '" + file + "'");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  std::istringstream out(r.out);
  std::vector<std::string> lines;
  for (std::string l; std::getline(out, l);) lines.push_back(l);
  ASSERT_EQ(lines.size(), 8u) << r.out;
  EXPECT_EQ(lines[0], "free");
  EXPECT_EQ(lines[1], "free");
  EXPECT_EQ(lines[2].rfind("collision ", 0), 0u) << lines[2];
  EXPECT_NE(lines[2].find("floor"), std::string::npos) << lines[2];
  EXPECT_EQ(lines[3].rfind("error ", 0), 0u) << lines[3];
  EXPECT_EQ(lines[4].rfind("error ", 0), 0u) << lines[4];
  EXPECT_NE(lines[4].find("wrist_3_joint"), std::string::npos) << lines[4];
  EXPECT_EQ(lines[5], "error line 8: an empty field at column 3 (a comma needs a number on each side)");
  EXPECT_EQ(lines[6], "error line 9: an empty field at column 1 (a comma needs a number on each side)");
  EXPECT_EQ(lines[7], "error line 10: an empty field at column 25 (a comma needs a number on each side)");
  r = runTool("check " + bundledScene());
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_MENTIONS(r.out, "start: free");
  EXPECT_EQ(runTool("check").exit_code, 2);
  EXPECT_EQ(runTool("check /nonexistent.yaml").exit_code, 2);
}

TEST(MotionTool, ChecksSegments) {
  const std::string file = testing::TempDir() + "clearway_motion_" + std::to_string(::getpid()) + ".txt";
  std::ofstream(file) << "# start -> goal crosses the wall; a short free step; bad lines\n"
                         "0 -0.6 -1.2 -1.34 0 0   0 0.6 1.2 1.34 0 0\n"
                         "0 -0.6 -1.2 -1.34 0 0,  0 -0.5 -1.2 -1.34 0 0\n"
                         "1 2\n"
                         "0 0 0 0 0 99  0 0 0 0 0 0\n";
  ToolRun r = runTool("motion " + bundledScene() + " --motions '" + file + "'");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  std::istringstream out(r.out);
  std::vector<std::string> lines;
  for (std::string l; std::getline(out, l);) lines.push_back(l);
  ASSERT_EQ(lines.size(), 4u) << r.out;
  std::istringstream first(lines[0]);
  std::string word, link, what;
  double fraction = -1;
  first >> word >> fraction >> link >> what;
  EXPECT_EQ(word, "collision") << lines[0];
  EXPECT_GT(fraction, 0.0);
  EXPECT_LT(fraction, 1.0);
  EXPECT_NE(what, "environment") << "the obstacle is named: " << lines[0];
  EXPECT_EQ(lines[1], "free");
  EXPECT_EQ(lines[2].rfind("error line 4", 0), 0u) << lines[2];
  EXPECT_EQ(lines[3].rfind("error line 5", 0), 0u) << lines[3];
  EXPECT_NE(lines[3].find("wrist_3_joint"), std::string::npos) << lines[3];
  // Without --motions: start -> goal; the sampled mode with a resolution; bad modes.
  r = runTool("motion " + bundledScene() + " --motion sampled:0.01");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_MENTIONS(r.out, "start -> goal: collision");
  EXPECT_EQ(runTool("motion " + bundledScene() + " --motion sampled:0").exit_code, 2);
  EXPECT_EQ(runTool("motion " + bundledScene() + " --motion warp").exit_code, 2);
  // The arm only turns: cast mode has nothing to cast and gives certified's verdict, word for word.
  r = runTool("motion " + bundledScene() + " --motion cast");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, runTool("motion " + bundledScene()).out);
  EXPECT_MENTIONS(r.out, "start -> goal: collision");
  EXPECT_EQ(runTool("motion").exit_code, 2);
}

TEST(MotionTool, TimedLinesAgainstMovingObstacles) {
  // A block on a slider holds still at x = 0 while a wall moving at 1 m/s along +x sweeps past it
  // between t = 0.9 and t = 1.1: a line with times sees it; without times, or later, the segment is free.
  const std::string base = testing::TempDir() + "clearway_moving_" + std::to_string(::getpid());
  std::ofstream(base + ".urdf") << R"(<?xml version="1.0"?>
<robot name="slider">
  <link name="base"/>
  <link name="block"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <joint name="slide" type="prismatic">
    <parent link="base"/><child link="block"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/>
  </joint>
</robot>
)";
  std::ofstream(base + ".yaml") << "format: 1\nname: moving\nrobot:\n  urdf: " << base << ".urdf\n  group: [slide]\n"
                                   "environment:\n  obstacles:\n    - {name: wall, box: {size: [0.001, 2, 2]}, "
                                   "pose: {position: [-1, 0, 0]}, velocity: [1, 0, 0]}\n"
                                   "checks: [environment, continuous, moving]\nstart: [0]\ngoal: [0]\n";
  std::ofstream(base + ".txt") << "0 0  2 0\n"   // the wall sweeps past
                                  "0  0\n"        // no times: the wall at t = 0, far away
                                  "3 0  5 0\n"   // after it has passed
                                  "0 0 0\n";     // three values: neither 2n nor 2n + 2
  const ToolRun r = runTool("motion " + base + ".yaml --motions " + base + ".txt");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  std::istringstream out(r.out);
  std::vector<std::string> lines;
  for (std::string line; std::getline(out, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 4u) << r.out;
  EXPECT_EQ(lines[0].rfind("collision 0.47", 0), 0u) << lines[0];  // the faces meet at t = 0.9495
  EXPECT_NE(lines[0].find("wall"), std::string::npos) << lines[0];
  EXPECT_EQ(lines[1], "free");
  EXPECT_EQ(lines[2], "free");
  EXPECT_EQ(lines[3].rfind("error line 4", 0), 0u) << lines[3];
}

TEST(AuditTool, WritesSrdfAndReport) {
  const std::string dir = testing::TempDir() + "clearway_audit_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  const std::string urdf = std::string(CLEARWAY_SOURCE_DIR) + "/robots/arm6/arm6.urdf";
  const std::string srdf = std::string(CLEARWAY_SOURCE_DIR) + "/robots/arm6/arm6.srdf";
  ToolRun r = runTool("audit '" + urdf + "' --srdf '" + srdf + "' --samples 400 --seed 2 --srdf-out '" + dir +
                      "/out.srdf' --report '" + dir + "/report.md'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_MENTIONS(r.out, "Adjacent");
  EXPECT_MENTIONS(r.out, "pairs differ from");
  EXPECT_MENTIONS(slurp(dir + "/out.srdf"), "<disable_collisions link1=");
  EXPECT_MENTIONS(slurp(dir + "/report.md"), "| link 1 | link 2 | verdict |");
  // The heat map beside the report, linked from it (gnuplot draws it; without gnuplot the script stays).
  EXPECT_TRUE(std::filesystem::exists(dir + "/report.png.gp"));
  if (std::system("command -v gnuplot >/dev/null 2>&1") == 0) {
    EXPECT_GT(std::filesystem::file_size(dir + "/report.png"), 1000u);
    EXPECT_MENTIONS(slurp(dir + "/report.md"), "![link-pair matrix](report.png)");
  }
  // An Adjacent row shows no evidence (nothing was measured), not "0/0 colliding, p <= 1".
  EXPECT_EQ(r.out.find("0/0 colliding"), std::string::npos) << r.out;
  r = runTool("audit /nonexistent.urdf");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_MENTIONS(r.err, "/nonexistent.urdf");
  EXPECT_EQ(runTool("audit '" + urdf + "' --samples 0").exit_code, 2);
  EXPECT_EQ(runTool("audit").exit_code, 2);
  std::filesystem::remove_all(dir);
}

TEST(AuditTool, PairsThatMisleadComeFirst) {
  // link1 turns past a post: at the default configuration (0) it lies across it, elsewhere it meets it in
  // 4.6% of the turn. MoveIt's rule disables the pair as Default: the audit says so, but warns first.
  const std::string dir = testing::TempDir() + "clearway_audit_warn_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  const std::string robot = R"(<robot name="w">
    <link name="base"><collision><origin xyz="0 0 0.05"/><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
    <link name="link1"><collision><origin xyz="0.5 0 0"/><geometry><box size="1 0.1 0.1"/></geometry></collision></link>
    <link name="post"><collision><geometry><cylinder radius="0.05" length="0.4"/></geometry></collision></link>
    <joint name="shoulder" type="continuous"><parent link="base"/><child link="link1"/><origin xyz="0 0 0.1"/>
      <axis xyz="0 0 1"/></joint>
    <joint name="p" type="fixed"><parent link="base"/><child link="post"/><origin xyz="X 0 0.1"/></joint>
  </robot>)";
  const auto write = [&](const std::string& name, std::string text, const std::string& x) {
    if (!x.empty()) text.replace(text.find("\"X "), 3, "\"" + x + " ");
    std::ofstream(dir + "/" + name) << text;
    return "'" + dir + "/" + name + "'";
  };
  ToolRun r = runTool("audit " + write("a.urdf", robot, "0.7") + " --samples 2000 --report '" + dir + "/a.md'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("warning: link1 post: disabled as Default but collides in ", 0), 0u) << r.out;
  // The report lists it first as well, and leaves the unmeasured cells of Adjacent rows empty.
  const std::string report = slurp(dir + "/a.md");
  const std::size_t table = report.find("|---|");
  ASSERT_NE(table, std::string::npos) << report;
  EXPECT_EQ(report.find("| link1 | post | Default (warning) |"), report.find('\n', table) + 1) << report;
  EXPECT_MENTIONS(report, "| base | link1 | Adjacent | - | - | - | - |");
  // The post behind the base instead: the pair is checked, and an SRDF that disables it is warned about,
  // first; an SRDF verdict that differs on an Adjacent pair is printed without evidence.
  const std::string srdf = write("a.srdf", R"(<robot name="w">
    <disable_collisions link1="link1" link2="post" reason="Never"/>
    <disable_collisions link1="base" link2="link1" reason="Never"/>
  </robot>)", "");
  r = runTool("audit " + write("b.urdf", robot, "-0.7") + " --samples 2000 --srdf " + srdf);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("warning: link1 post: " + dir + "/a.srdf disables it (Never) but it collides in ", 0), 0u) << r.out;
  EXPECT_MENTIONS(r.out, "\ndiffers: base link1: SRDF Never, audit Adjacent\n");
  EXPECT_MENTIONS(r.out, "differs: base post: SRDF checked, audit Adjacent\n");
  std::filesystem::remove_all(dir);
}

#endif
