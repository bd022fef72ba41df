// The Python edit API (python/src/scene.cpp) driven by the bytes: the calls the bindings make, with the
// arguments converted and checked as the bindings check them, on one of our scenes (the arm among meshes,
// the rover on a planar joint, the flyer on a floating one). Up to 8 steps, each an edit that makes a
// new scene from the last (with_obstacle, with_obstacle_moved, without_obstacle, with_points,
// with_attached, without_attached) or a query of the scene at hand (is_free and check, check_motions).
// Shapes are built by their constructors from the bytes' numbers as Python's classes build them (raw
// radii and lengths; vectors and poses refused when not finite, as toVec3 and toPose refuse them).
// Documented: std::invalid_argument (Python's ValueError; ShapeError is one) and LoadError; anything else
// a binding would raise as RuntimeError is a finding. Checked, as each call's promise:
//  - an edit leaves the scene it started from as it was (its verdicts on the probe states unchanged);
//  - adding an obstacle, points or an attached body never frees a state; removing one never makes a
//    free state collide; an obstacle edit changes the obstacle count by what it adds or removes;
//  - check (Scene::areFree) and anyCollides give each state isFree's verdict;
//  - a motion of length zero is free exactly where its state is; a free segment has free ends.
// The scenes are built without pair tables (no verdict depends on them; with them every with_attached
// would take seconds in this build), and motions stop after about 2,000 distance queries (capped).
// CLEARWAY_FUZZ_TRACE=1 makes a replay print each edit's result, added obstacle and motion verdict.
#include "fuzz_support.h"

#include <clearway/motion/motion.h>
#include <clearway/scene/scene.h>
#include <clearway/shape/convex_hull.h>

#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using namespace clearway;

std::vector<std::shared_ptr<const Scene>>& baseScenes() {
  static std::vector<std::shared_ptr<const Scene>> scenes = [] {
    SceneOptions options;
    options.pair_tables = false;
    std::vector<std::shared_ptr<const Scene>> v;
    for (const char* name : {"arm6_wall", "rover_gap", "flyer_post"})
      v.push_back(Scene::load(std::string(CLEARWAY_SOURCE_DIR "/robots/scenes/") + name + ".yaml", options));
    return v;
  }();
  return scenes;
}

// A number: often one that matters (0, ±1, tiny, huge, non-finite), else any double, else a moderate one.
double number(FuzzedDataProvider& in) {
  static const double kSpecial[] = {0.0, -0.0, 1.0, -1.0, 0.5, 0.05, 1e-9, 1e-12, 1e-310, 1e6, 1e6 + 1, 1e16, 1e308,
                                    std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                                    std::numeric_limits<double>::quiet_NaN()};
  switch (in.ConsumeIntegralInRange(0, 3)) {
    case 0: return in.PickValueInArray(kSpecial);
    case 1: return in.ConsumeFloatingPoint<double>();
    default: return in.ConsumeFloatingPointInRange(-2.0, 2.0);
  }
}

// What Python's conversions refuse with ValueError before any call (toVec3, toPose, ConvexHull's points).
struct Refused : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

Vec3 vec3(FuzzedDataProvider& in) {
  const Vec3 v(number(in), number(in), number(in));
  if (!v.allFinite()) throw Refused("not finite");
  return v;
}

// toPose: None, or (position, quaternion x y z w) of any non-zero length, scaled by its largest entry.
Pose pose(FuzzedDataProvider& in) {
  if (in.ConsumeBool()) return Pose();
  const Vec3 t = vec3(in);
  double q[4];
  for (double& x : q) x = number(in);
  if (!std::all_of(q, q + 4, [](double x) { return std::isfinite(x); })) throw Refused("quaternion not finite");
  const double m = std::max({std::abs(q[0]), std::abs(q[1]), std::abs(q[2]), std::abs(q[3])});
  if (!(m > 0.0)) throw Refused("zero quaternion");
  return Pose::fromQuaternion(q[0] / m, q[1] / m, q[2] / m, q[3] / m, t);
}

// clearway.Box, Sphere, Capsule, Cylinder, Cone, ConvexHull, Point, Segment, Triangle.
Shape shape(FuzzedDataProvider& in) {
  switch (in.ConsumeIntegralInRange(0, 8)) {
    case 0: return Box(vec3(in));
    case 1: return Sphere(number(in));
    case 2: { const double r = number(in); return Capsule(r, number(in)); }
    case 3: { const double r = number(in); return Cylinder(r, number(in)); }
    case 4: { const double r = number(in); return Cone(r, number(in)); }
    case 5: {
      std::vector<Vec3> points(in.ConsumeIntegralInRange(0, 8));
      for (Vec3& p : points) p = vec3(in);
      return ConvexHull(points);
    }
    case 6: return Point(vec3(in));
    case 7: { const Vec3 a = vec3(in); return Segment(a, vec3(in)); }
    default: { const Vec3 a = vec3(in), b = vec3(in); return Triangle(a, b, vec3(in)); }
  }
}

// A name: one the scene has (an obstacle, a link, an attached body), or a short made-up one.
std::string name(FuzzedDataProvider& in, const std::vector<std::string>& known) {
  if (!known.empty() && in.ConsumeBool()) return known[in.ConsumeIntegralInRange<std::size_t>(0, known.size() - 1)];
  return in.ConsumeRandomLengthString(8);
}

std::vector<std::string> obstacleNames(const Scene& s) {
  std::vector<std::string> names;
  for (const auto& o : s.environment().obstacles()) names.push_back(o->name);
  return names;
}

std::vector<std::string> linkNames(const Scene& s) {
  std::vector<std::string> names;
  for (const Link& l : s.robot().links()) names.push_back(l.name);
  return names;
}

// A state: mostly within the limits, sometimes any numbers (validState then refuses most).
std::vector<double> state(FuzzedDataProvider& in, const Scene& s) {
  std::vector<double> q(s.dimension());
  for (int i = 0; i < s.dimension(); ++i) {
    const double lo = std::max(s.validLower(i), -4.0), hi = std::min(s.validUpper(i), 4.0);
    q[i] = in.ConsumeBool() && lo <= hi ? in.ConsumeFloatingPointInRange(lo, hi) : number(in);
  }
  return q;
}

// Numbers as they read back exactly, for findings.
std::string exact(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", x);
  return buffer;
}
std::string exact(const std::vector<std::string>& names) {
  std::string text = "[";
  for (std::size_t i = 0; i < names.size(); ++i) text += (i ? ", " : "") + names[i];
  return text + "]";
}
std::string exact(const std::vector<double>& q) {
  std::string text = "[";
  for (std::size_t i = 0; i < q.size(); ++i) text += (i ? ", " : "") + exact(q[i]);
  return text + "]";
}

bool freeAt(const Scene& s, const std::vector<double>& q) {
  SceneContext fresh = s.makeContext();  // as Python: a fresh context per call
  return s.isFree(q.data(), fresh);
}

// What an edit does to the verdicts: adds (never frees a state), removes (never makes one collide),
// or moves (either).
enum class Change { Adds, Removes, Moves };

// Python's check_motions options (motionOptions): certified, cast or sampled:RES, a finite contact
// distance > 0; sampled resolutions from 0.001 (finer ones are the tool's cap, max_samples, at work).
std::optional<MotionOptions> motionOptions(FuzzedDataProvider& in, const std::shared_ptr<int>& asked) {
  MotionOptions o;
  o.contact_distance = number(in);
  if (!(o.contact_distance > 0.0) || !std::isfinite(o.contact_distance)) return std::nullopt;
  switch (in.ConsumeIntegralInRange(0, 2)) {
    case 0: o.mode = MotionMode::Certified; break;
    case 1: o.mode = MotionMode::Cast; break;
    default: o.mode = MotionMode::Sampled, o.resolution = in.ConsumeFloatingPointInRange(0.001, 1.0);
  }
  o.stop = [asked] { return ++*asked > 8; };
  return o;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  std::vector<std::shared_ptr<const Scene>>& bases = baseScenes();
  std::shared_ptr<const Scene> scene = bases[in.ConsumeIntegralInRange<std::size_t>(0, bases.size() - 1)];
  // The probe states: the scene's start and goal, then every state asked about.
  std::vector<std::vector<double>> probes;
  for (const std::vector<double>* q : {&scene->description().start, &scene->description().goal})
    if (!q->empty()) probes.push_back(*q);
  const auto asked = std::make_shared<int>(0);

  for (int step = 0; step < 8 && in.remaining_bytes() > 0; ++step) {
    const Scene& s = *scene;
    const int op = in.ConsumeIntegralInRange(0, 7);
    // The verdicts before an edit (0-5), to hold the edited scene and the one it came from to.
    std::vector<signed char> before(probes.size(), -1);  // -1: an invalid state here
    for (std::size_t i = 0; op <= 5 && i < probes.size(); ++i)
      if (s.validState(probes[i].data())) before[i] = freeAt(s, probes[i]);
    std::shared_ptr<const Scene> next;
    Change change = Change::Moves;
    std::ptrdiff_t obstacles = -1;  // the obstacle count the edit leaves, when it says
    try {
      switch (op) {
        case 0: {  // with_obstacle(name, shape, pose)
          Obstacle o;
          o.name = name(in, obstacleNames(s));
          o.shape = shape(in);
          o.pose = pose(in);
          if (std::getenv("CLEARWAY_FUZZ_TRACE"))
            std::fprintf(stderr, "with_obstacle: %s, bounding radius %s, at %s, rotation %s\n", shapeTypeName(o.shape),
                         exact(boundingRadius(o.shape)).c_str(),
                         exact(std::vector<double>{o.pose.t.x(), o.pose.t.y(), o.pose.t.z()}).c_str(),
                         exact(std::vector<double>(o.pose.R.data(), o.pose.R.data() + 9)).c_str());
          next = s.withEnvironment(std::make_shared<const Environment>(s.environment().withObstacle(std::move(o))));
          change = Change::Adds, obstacles = static_cast<std::ptrdiff_t>(s.environment().obstacleCount()) + 1;
          break;
        }
        case 1: {  // with_obstacle_moved(name, pose)
          const std::string n = name(in, obstacleNames(s));
          const Pose p = pose(in);
          next = s.withEnvironment(std::make_shared<const Environment>(s.environment().withObstacleMoved(n, p)));
          obstacles = static_cast<std::ptrdiff_t>(s.environment().obstacleCount());
          break;
        }
        case 2: {  // without_obstacle(name)
          const std::string n = name(in, obstacleNames(s));
          next = s.withEnvironment(std::make_shared<const Environment>(s.environment().withoutObstacle(n)));
          change = Change::Removes, obstacles = static_cast<std::ptrdiff_t>(s.environment().obstacleCount()) - 1;
          break;
        }
        case 3: {  // with_points(points, resolution): the (N, 3) array's numbers as given
          std::vector<Vec3> points(in.ConsumeIntegralInRange(0, 32));
          for (Vec3& p : points) p = Vec3(number(in), number(in), number(in));
          const double resolution = in.ConsumeBool() ? 0.0 : number(in);
          next = s.withEnvironment(std::make_shared<const Environment>(s.environment().withPoints(points, resolution)));
          change = Change::Adds, obstacles = static_cast<std::ptrdiff_t>(s.environment().obstacleCount());
          break;
        }
        case 4: {  // with_attached(name, link, shape, pose, touch_links)
          SceneDescription::AttachedSpec a;
          const std::vector<std::string> links = linkNames(s);
          a.body.name = name(in, links);
          a.link = name(in, links);
          a.body.shape = shape(in);
          a.body.pose = pose(in);
          for (int k = in.ConsumeIntegralInRange(0, 3); k > 0; --k) a.touch_links.push_back(name(in, links));
          if (std::getenv("CLEARWAY_FUZZ_TRACE"))
            std::fprintf(stderr, "with_attached: %s on %s, bounding radius %s, at %s, rotation %s, touching %s\n",
                         shapeTypeName(a.body.shape), a.link.c_str(), exact(boundingRadius(a.body.shape)).c_str(),
                         exact(std::vector<double>{a.body.pose.t.x(), a.body.pose.t.y(), a.body.pose.t.z()}).c_str(),
                         exact(std::vector<double>(a.body.pose.R.data(), a.body.pose.R.data() + 9)).c_str(),
                         exact(a.touch_links).c_str());
          next = s.withAttached(a);
          change = Change::Adds;
          break;
        }
        case 5: {  // without_attached(name)
          std::vector<std::string> held;
          for (const auto& a : s.description().attached) held.push_back(a.body.name);
          next = s.withoutAttached(name(in, held));
          change = Change::Removes;
          break;
        }
        case 6: {  // is_free(q) and check(Q): one state, then the probes with it in one batch
          const std::vector<double> q = state(in, s);
          if (!s.validState(q.data())) break;  // ValueError
          probes.push_back(q);
          std::vector<double> all;
          bool any = false;
          std::vector<char> verdicts;
          for (const std::vector<double>& p : probes) {
            all.insert(all.end(), p.begin(), p.end());
            verdicts.push_back(freeAt(s, p));
            any = any || !verdicts.back();
          }
          const int n = static_cast<int>(probes.size());
          std::unique_ptr<bool[]> batch(new bool[n]);
          SceneContext ctx = s.makeContext();
          s.areFree(all.data(), n, ctx, batch.get());
          for (int i = 0; i < n; ++i)
            if (batch[i] != static_cast<bool>(verdicts[i])) fuzz::finding("check (areFree) and is_free disagree on a state");
          const int hit = s.anyCollides(all.data(), n, ctx);
          if ((hit >= 0) != any || (hit >= 0 && verdicts[hit])) fuzz::finding("anyCollides and is_free disagree");
          break;
        }
        default: {  // check_motions(Q0, Q1, mode, contact_distance)
          const std::optional<MotionOptions> options = motionOptions(in, asked);
          const std::vector<double> q0 = state(in, s), q1 = in.ConsumeBool() ? q0 : state(in, s);
          if (!options || !s.validState(q0.data()) || !s.validState(q1.data())) break;  // ValueError
          const MotionChecker checker(scene, *options);
          MotionContext ctx = checker.makeContext();
          *asked = 0;
          const MotionResult r = checker.check(q0.data(), 0.0, q1.data(), 0.0, ctx);
          const bool free0 = freeAt(s, q0), free1 = freeAt(s, q1);
          if (std::getenv("CLEARWAY_FUZZ_TRACE"))
            std::fprintf(stderr, "step %d: check_motions: %s, ends %s %s (%d queries%s), obstacles %s, %d point voxels, attached %zu\n",
                         step, r.free ? "free" : "not free", free0 ? "free" : "colliding", free1 ? "free" : "colliding",
                         r.distance_queries, r.capped ? ", capped" : "", exact(obstacleNames(s)).c_str(),
                         s.environment().pointVoxelCount(), s.description().attached.size());
          const std::string what = " (scene " + s.name() + ", mode " + std::to_string(static_cast<int>(options->mode)) +
                                   ", contact distance " + exact(options->contact_distance) + ", q0 " + exact(q0) + ", q1 " +
                                   exact(q1) + ", " + std::to_string(s.environment().obstacleCount()) + " obstacles)";
          if (r.free && !(free0 && free1))
            fuzz::finding(std::string("a free segment has an end in collision: ") + (free0 ? "" : "q0 ") + (free1 ? "" : "q1") + what);
          if (q0 == q1 && !r.capped && r.free != free0)
            fuzz::finding(std::string("a motion of length zero is ") + (r.free ? "free" : "not free") + " from a state " +
                          (free0 ? "free" : "in collision") + what);
          break;
        }
      }
    } catch (const std::invalid_argument&) {  // ValueError (Refused, ShapeError, the edits' refusals)
      continue;
    } catch (const LoadError&) {  // clearway.LoadError
      continue;
    } catch (const std::exception& e) {
      fuzz::finding(std::string("edit ") + std::to_string(op) + " threw an undocumented " + typeid(e).name() + ": " + e.what());
    }
    if (!next) continue;
    if (std::getenv("CLEARWAY_FUZZ_TRACE"))  // replaying a finding: what each edit made
      std::fprintf(stderr, "step %d: edit %d: %zu obstacles %s, %d point voxels, links %s, attached %zu\n", step, op,
                   next->environment().obstacleCount(), exact(obstacleNames(*next)).c_str(),
                   next->environment().pointVoxelCount(), exact(linkNames(*next)).c_str(), next->description().attached.size());

    // The edit's promises, on every probe state.
    if (obstacles >= 0 && static_cast<std::ptrdiff_t>(next->environment().obstacleCount()) != obstacles)
      fuzz::finding("edit " + std::to_string(op) + " left " + std::to_string(next->environment().obstacleCount()) +
                    " obstacles, not " + std::to_string(obstacles));
    if (next->dimension() != s.dimension()) fuzz::finding("an edit changed the state's length");
    for (std::size_t i = 0; i < probes.size(); ++i) {
      if (before[i] < 0) continue;
      const bool was = before[i] == 1, now = freeAt(*next, probes[i]);
      if (change == Change::Adds && now && !was) fuzz::finding("edit " + std::to_string(op) + " added something and freed a state");
      if (change == Change::Removes && was && !now)
        fuzz::finding("edit " + std::to_string(op) + " removed something and a free state collides");
      if (freeAt(s, probes[i]) != was) fuzz::finding("edit " + std::to_string(op) + " changed the scene it started from");
    }
    scene = next;
  }
  return 0;
}
