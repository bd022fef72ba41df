// Building a scene: the robot and environment a description names, init (the group, holds, bounds, filter,
// self checker, pair tables), and edits that make new scenes. Asking it is scene_queries.cpp.
#include <clearway/scene/scene.h>

#include <clearway/body/enclosing.h>
#include <clearway/serial.h>
#include <clearway/body/proximity.h>
#include <clearway/detail/margins.h>
#include <clearway/detail/weak_memo.h>
#include <clearway/tree/aabb.h>

#include <clearway/per_thread.h>

#include <clearway/kinematics/attached_body.h>
#include <clearway/kinematics/forward_kinematics.h>
#include <clearway/load/input_limits.h>
#include <clearway/load/mesh_loader.h>
#include <clearway/load/robot_loader.h>

#include "exact_text.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <vector>

namespace clearway {
namespace {

// The self checker before init() makes the scene's own: without tables, which would be built twice.
SelfCollisionOptions placeholderOptions() {
  SelfCollisionOptions o;
  o.pair_tables = false;
  return o;
}

// Whether two links that no state moves apart meet, remembered: every scene over a loaded robot asks it
// again, for the same links at the same poses, and on meshes that touch (a gripper bolted to its flange)
// the answer is a search among their triangles. Keyed by both poses, padding, mode and tolerances, the
// answer remembered is the one meshesIntersect gives.
struct RigidPairKey {
  const LinkGeometry* a;
  const LinkGeometry* b;
  std::vector<double> values;
  bool operator<(const RigidPairKey& o) const { return std::tie(a, b, values) < std::tie(o.a, o.b, o.values); }
};

bool rigidPairIntersects(const RobotGeometry& geometry, int a, const Pose& pose_a, int b, const Pose& pose_b,
                         const Tolerances& tol, GeometryMode mode, double padding) {
  static detail::WeakMemo<RigidPairKey, bool, LinkGeometry> memo;
  const LinkGeometry& ga = *geometry.link(a);
  const LinkGeometry& gb = *geometry.link(b);
  RigidPairKey key{&ga, &gb, {}};
  appendPose(pose_a, key.values);
  appendPose(pose_b, key.values);
  key.values.insert(key.values.end(), {padding, static_cast<double>(mode)});
  appendTolerances(tol, key.values);
  // (A NaN would break the keys' order: such a question is answered afresh.)
  if (std::any_of(key.values.begin(), key.values.end(), [](double v) { return std::isnan(v); }))
    return meshesIntersect(ga, pose_a, gb, pose_b, tol, mode, padding);
  if (const std::optional<bool> known = memo.find(key)) return *known;
  const bool meet = meshesIntersect(ga, pose_a, gb, pose_b, tol, mode, padding);
  memo.store(std::move(key), geometry.linkPtr(a), geometry.linkPtr(b), meet);
  return meet;
}

}  // namespace

using scene_detail::exactText;

std::shared_ptr<const RobotGeometry> loadRobotGeometry(const SceneDescription& d, const LoadOptions& options) {
  LoadOptions load = options;
  load.package_paths.insert(load.package_paths.end(), d.package_paths.begin(), d.package_paths.end());
  RobotModel robot = loadRobot(d.urdf, d.srdf, load);
  if (!d.attached.empty()) {
    std::vector<AttachedBody> bodies;
    std::vector<TriangleMesh> meshes;
    for (std::size_t i = 0; i < d.attached.size(); ++i) {
      const SceneDescription::AttachedSpec& a = d.attached[i];
      const std::string key = "robot.attached[" + std::to_string(i) + "]";
      const auto link = [&](const std::string& name, const std::string& k) {
        const int l = robot.linkIndex(name);
        if (l < 0) throw LoadError(d.file, "key '" + k + "'", "link '" + inputExcerpt(name) + "' is not in robot '" + inputExcerpt(robot.name()) + "'");
        return l;
      };
      AttachedBody b;
      b.name = a.body.name;
      b.link = link(a.link, key + ".link");
      b.pose = a.body.pose;
      for (std::size_t t = 0; t < a.touch_links.size(); ++t)
        b.touch_links.push_back(link(a.touch_links[t], key + ".touch_links[" + std::to_string(t) + "]"));
      if (a.body.mesh_file.empty()) {
        b.element.primitive = a.body.shape;
      } else {
        b.element.mesh = static_cast<int>(meshes.size());
        meshes.push_back(loadMesh(a.body.mesh_file, a.body.mesh_scale, nullptr, options.mesh));
      }
      bodies.push_back(std::move(b));
    }
    try {
      robot = attachBodies(robot, bodies, meshes);
    } catch (const std::invalid_argument& e) {
      throw LoadError(d.file, "key 'robot.attached'", e.what());
    }
  }
  auto model = std::make_shared<const RobotModel>(std::move(robot));
  return std::make_shared<const RobotGeometry>(std::move(model));
}

std::shared_ptr<const Environment> loadEnvironment(const SceneDescription& d, const LoadOptions& options,
                                                   std::vector<std::string>* warnings) {
  std::vector<Obstacle> obstacles;
  for (std::size_t i = 0; i < d.obstacles.size(); ++i) {
    const SceneDescription::ObstacleSpec& s = d.obstacles[i];
    Obstacle o;
    o.name = s.name;
    o.shape = s.shape;
    o.pose = s.pose;
    o.velocity = s.velocity;
    if (!s.mesh_file.empty()) {
      // The mesh's own errors and warnings name its file; the scene's key says which obstacle reads it.
      const std::string key = "key 'environment.obstacles[" + std::to_string(i) + "].mesh'";
      std::vector<std::string> said;
      try {
        o.mesh = std::make_shared<const LinkGeometry>(loadMesh(s.mesh_file, s.mesh_scale, &said, options.mesh));
      } catch (const std::exception& e) {
        throw LoadError(d.file, key, e.what());
      }
      if (warnings)
        for (const std::string& w : said) warnings->push_back(LoadError::format(d.file, key, w));
    }
    obstacles.push_back(std::move(o));
  }
  std::shared_ptr<const OccupancyMap> map;
  if (!d.octomap.empty()) {
    try {  // (its errors name the map's file; the key says which scene reads it)
      map = std::make_shared<const OccupancyMap>(loadOctomap(d.octomap, d.unknown));
    } catch (const std::exception& e) {
      throw LoadError(d.file, "key 'environment.octomap'", e.what());
    }
  }
  return std::make_shared<const Environment>(std::move(obstacles), std::move(map));
}

Scene::Scene(const SceneDescription& description, const SceneOptions& options)
    : Scene(
          [&] {
            Described loaded{description, nullptr};
            loaded.second = loadEnvironment(description, options.load, &loaded.first.warnings);
            return loaded;
          }(),
          options) {}

Scene::Scene(Described loaded, const SceneOptions& options)
    : Scene(loaded.first, loadRobotGeometry(loaded.first, options.load), std::move(loaded.second), options) {}

Scene::Scene(const SceneDescription& description, std::shared_ptr<const RobotGeometry> robot,
             std::shared_ptr<const Environment> environment, const SceneOptions& options)
    : description_(description),
      options_(options),
      geometry_(std::move(robot)),
      environment_(environment ? std::move(environment) : std::make_shared<const Environment>()),
      filter_(geometry_->model()),
      self_(geometry_, filter_, placeholderOptions()) {
  init();
}

std::shared_ptr<const Scene> Scene::load(const std::string& path, const SceneOptions& options) {
  return std::make_shared<const Scene>(parseSceneFile(path), options);
}

void Scene::init() {
  serial_ = detail::nextSerial();
  const RobotModel& model = geometry_->model();
  const std::string& file = description_.file;
  auto fail = [&](const std::string& key, const std::string& reason) {
    throw LoadError(file, "key '" + key + "'", reason);
  };

  for (std::size_t i = 0; i < description_.attached.size(); ++i)
    if (model.linkIndex(description_.attached[i].body.name) < 0)
      fail("robot.attached[" + std::to_string(i) + "]", "the robot given has no link '" + description_.attached[i].body.name +
                                                          "' (loadRobotGeometry makes each attached body a link)");

  // Group and held joints → entries of the robot's joint vector.
  const int nv = model.variableCount();
  std::vector<char> taken(nv, 0);
  for (std::size_t i = 0; i < description_.group.size(); ++i) {
    const std::string key = "robot.group[" + std::to_string(i) + "]";
    const std::string& name = description_.group[i];
    const int j = model.jointIndex(name);
    if (j < 0) fail(key, "joint '" + inputExcerpt(name) + "' is not in robot '" + inputExcerpt(model.name()) + "' (" + description_.urdf + ")");
    const Joint& joint = model.joint(j);
    if (joint.first_variable < 0)
      fail(key, "joint '" + inputExcerpt(name) + "' is " + (joint.isMimic() ? "a mimic" : "fixed") + ": it has no value to plan");
    // A floating joint's state entries are x, y, z, then its quaternion's qx, qy, qz, qw.
    if (joint.type == JointType::Floating) quaternions_.push_back(static_cast<int>(group_variables_.size()) + 3);
    for (int k = 0; k < jointVariableCount(joint.type); ++k) {
      const int v = joint.first_variable + k;
      if (taken[v]) fail(key, "joint '" + inputExcerpt(name) + "' is listed twice");
      taken[v] = 1;
      group_variables_.push_back(v);
    }
  }
  base_q_.assign(nv, 0.0);
  for (int v = 0; v < nv; ++v) {
    const JointVariable& var = model.variables()[v];
    // MoveIt's default: zero when the limits allow it, else the middle of the limits.
    if (!(var.lower <= 0.0 && 0.0 <= var.upper) && std::isfinite(var.lower) && std::isfinite(var.upper))
      base_q_[v] = 0.5 * (var.lower + var.upper);
    if (var.name.size() > 3 && var.name.compare(var.name.size() - 3, 3, "/qw") == 0) base_q_[v] = 1.0;
  }
  for (const int v : group_variables_) {
    lower_.push_back(model.variables()[v].lower);
    upper_.push_back(model.variables()[v].upper);
  }
  for (const auto& [name, range] : description_.bounds) {
    const std::string key = "robot.bounds." + inputExcerpt(name);
    const int v = model.variableIndex(name);
    const auto it = std::find(group_variables_.begin(), group_variables_.end(), v);
    if (v < 0 || it == group_variables_.end())
      fail(key, "'" + inputExcerpt(name) + "' is not a variable of the group (planar and floating joints name theirs joint/x, joint/y, ...)");
    const std::size_t i = static_cast<std::size_t>(it - group_variables_.begin());
    const auto [lo, hi] = range;
    if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo < hi)) fail(key, "expected finite [lower, upper] with lower < upper");
    if (std::abs(lo) > kMaxJointValue || std::abs(hi) > kMaxJointValue)
      fail(key, "[" + exactText(lo) + ", " + exactText(hi) + "] reaches beyond ±1e6, the largest joint value a state may hold");
    if (lo < lower_[i] || hi > upper_[i])
      fail(key, "[" + exactText(lo) + ", " + exactText(hi) + "] is outside the joint's limits [" +
                    exactText(lower_[i]) + ", " + exactText(upper_[i]) + "]");
    lower_[i] = lo;
    upper_[i] = hi;
  }
  for (std::size_t i = 0; i < lower_.size(); ++i) {
    valid_lower_.push_back(std::max(lower_[i] - kJointLimitTolerance, -kMaxJointValue));
    valid_upper_.push_back(std::min(upper_[i] + kJointLimitTolerance, kMaxJointValue));
  }
  std::vector<std::pair<int, double>> mimic_holds;
  for (const auto& [name, value] : description_.hold) {
    const std::string key = "robot.hold." + inputExcerpt(name);
    const int j = model.jointIndex(name);
    if (j < 0) fail(key, "joint '" + inputExcerpt(name) + "' is not in robot '" + inputExcerpt(model.name()) + "'");
    if (!(std::abs(value) <= kMaxJointValue))  // (as a state's values: a link 1e300 m away is no placement)
      fail(key, "'" + exactText(value) + "' is beyond ±1e6, the largest joint value a state may hold");
    const Joint& joint = model.joint(j);
    if (joint.type == JointType::Fixed) {
      // A fixed joint has no value; MoveIt's converters still list it at 0, which says nothing.
      if (value != 0.0) fail(key, "joint '" + inputExcerpt(name) + "' is fixed: it cannot be held at " + std::to_string(value));
      continue;
    }
    if (joint.isMimic()) {
      mimic_holds.emplace_back(j, value);  // checked below, once the leader's value is known
      continue;
    }
    if (joint.first_variable < 0 || jointVariableCount(joint.type) != 1)
      fail(key, "joint '" + inputExcerpt(name) + "' does not have exactly one value to hold");
    if (taken[joint.first_variable]) fail(key, "joint '" + inputExcerpt(name) + "' is in the group: it cannot also be held");
    base_q_[joint.first_variable] = value;  // without clamping, as MoveIt applies a held state
  }
  // A mimic joint follows its leader; a held value for it is accepted when it says the same.
  for (const auto& [j, value] : mimic_holds) {
    const Joint& joint = model.joint(j);
    const Joint& leader = model.joint(joint.mimic.joint);
    const std::string key = "robot.hold." + joint.name;
    if (taken[leader.first_variable])
      fail(key, "joint '" + joint.name + "' mimics '" + leader.name + "', which is in the group");
    const double follows = joint.mimic.multiplier * base_q_[leader.first_variable] + joint.mimic.offset;
    constexpr double kSameValue = 1e-9;  // relative, or absolute below 1
    if (std::abs(follows - value) > kSameValue * std::max(1.0, std::abs(value)))
      fail(key, "joint '" + joint.name + "' mimics '" + leader.name + "' and so is " + std::to_string(follows) +
                    ", not " + std::to_string(value));
  }
  const std::size_t n = group_variables_.size();
  if (!description_.start.empty() && description_.start.size() != n)
    fail("start", "has " + std::to_string(description_.start.size()) + " values for " + std::to_string(n) + " group variables");
  if (!description_.goal.empty() && description_.goal.size() != n)
    fail("goal", "has " + std::to_string(description_.goal.size()) + " values for " + std::to_string(n) + " group variables");

  // Allowed pairs. The self checker is rebuilt with them (and with the pairs that can never move
  // relative to each other, which are checked once here instead of at every state).
  for (std::size_t i = 0; i < description_.allow.size(); ++i) {
    const auto& [a, b] = description_.allow[i];
    const std::string key = "robot.allow[" + std::to_string(i) + "]";
    const int la = model.linkIndex(a), lb = model.linkIndex(b);
    if (la < 0) fail(key, "link '" + a + "' is not in robot '" + inputExcerpt(model.name()) + "'");
    if (lb < 0) fail(key, "link '" + b + "' is not in robot '" + inputExcerpt(model.name()) + "'");
    if (la == lb) fail(key, "a link paired with itself");
    filter_.disable(la, lb, "allowed by scene");
  }

  // A link moves with the state when a group variable (or a mimic of one) lies on its chain.
  std::vector<char> moves(model.linkCount(), 0);
  std::vector<char> joint_moves(model.jointCount(), 0);
  for (int j = 0; j < model.jointCount(); ++j) {
    const Joint& joint = model.joint(j);
    const Joint& owner = joint.isMimic() ? model.joint(joint.mimic.joint) : joint;
    for (int k = 0; k < jointVariableCount(owner.type) && owner.first_variable >= 0; ++k)
      if (taken[owner.first_variable + k]) joint_moves[j] = 1;
  }
  rigid_anchor_.assign(model.linkCount(), 0);
  for (int i = 1; i < model.linkCount(); ++i) {
    const int j = model.link(i).parent_joint;
    moves[i] = moves[model.parentLink(i)] || joint_moves[j];
    rigid_anchor_[i] = joint_moves[j] ? i : rigid_anchor_[model.parentLink(i)];
  }
  for (int i : geometry_->geometricLinks())
    if (moves[i]) moving_links_.push_back(i);

  link_padding_.assign(model.linkCount(), description_.padding);
  CollisionFilter moving_filter = filter_;
  std::vector<std::pair<int, int>> static_pairs;
  for (const auto& [a, b] : filter_.enabledPairs()) {
    const bool still = !moves[a] && !moves[b];
    if (still || rigid_anchor_[a] == rigid_anchor_[b]) {  // (a gripper's links on its flange move as one)
      static_pairs.emplace_back(a, b);
      moving_filter.disable(a, b, still ? "never moves" : "one rigid body");
    }
  }
  SelfCollisionOptions so;
  so.mode = options_.mode;
  so.tolerances = options_.tolerances;
  so.link_padding = link_padding_;
  // Variables outside the group keep their base values in every query (computePoses writes only the group).
  so.pair_tables = options_.pair_tables && description_.effects.self;  // (none for a check not made)
  so.table_seconds = options_.pair_table_seconds;
  so.held = base_q_;
  for (int v : group_variables_) so.held[v] = std::numeric_limits<double>::quiet_NaN();
  self_ = SelfCollision(geometry_, moving_filter, so);

  // The parts of the scene that no state changes: decided once, reported at every state.
  std::vector<Pose> poses(model.linkCount());
  computeLinkPoses(model, base_q_.data(), poses.data());
  if (description_.effects.self)
    for (const auto& [a, b] : static_pairs)
      if (rigidPairIntersects(*geometry_, a, poses[a], b, poses[b], options_.tolerances, options_.mode,
                              link_padding_[a] + link_padding_[b])) {
        static_collision_.kind = CollisionReport::Kind::Self;
        static_collision_.link = a;
        static_collision_.other_link = b;
        break;
      }
  self_static_collision_ = static_collision_;
  initEnvironment();
}

void Scene::initEnvironment() {
  const RobotModel& model = geometry_->model();
  std::vector<char> moves(model.linkCount(), 0);
  for (const int i : moving_links_) moves[i] = 1;
  // Static links meet static obstacles the same way at every state: checked once here.
  env_links_.clear();
  for (int i : geometry_->geometricLinks())
    if (moves[i] || environment_->hasMovingObstacles()) env_links_.push_back(i);
  static_collision_ = self_static_collision_;
  static_clearance_ = static_clearance_lower_ = std::numeric_limits<double>::infinity();
  std::vector<Pose> poses(model.linkCount());
  computeLinkPoses(model, base_q_.data(), poses.data());
  // The rigid bodies among them, in the order of their first member.
  env_bodies_.clear();
  env_order_.clear();
  {
    std::vector<int> body_of(model.linkCount(), -1);
    std::vector<std::vector<int>> members;
    for (int k = 0; k < static_cast<int>(env_links_.size()); ++k) {
      int& b = body_of[rigid_anchor_[env_links_[k]]];
      if (b < 0) {
        b = static_cast<int>(members.size());
        members.emplace_back();
      }
      members[b].push_back(k);
    }
    for (const std::vector<int>& m : members) {
      EnvBody body;
      body.anchor = rigid_anchor_[env_links_[m[0]]];
      body.first = static_cast<int>(env_order_.size());
      body.count = static_cast<int>(m.size());
      env_order_.insert(env_order_.end(), m.begin(), m.end());
      if (m.size() > 1) {  // each member's bounding ball in the anchor's frame (fixed: no joint between moves)
        Aabb box;
        std::vector<std::pair<Vec3, double>> balls;
        double world = poses[body.anchor].t.norm();  // the magnitudes the relative poses were computed from
        for (const int k : m) {
          const int i = env_links_[k];
          world = std::max(world, poses[body.anchor].t.norm() + poses[i].t.norm());
          const LinkGeometry& g = *geometry_->link(i);
          balls.emplace_back(relativePose(poses[body.anchor], poses[i]) * g.sphereCenter(), g.sphereRadius());
          box.grow(balls.back().first - Vec3::Constant(balls.back().second));
          box.grow(balls.back().first + Vec3::Constant(balls.back().second));
          body.padding = std::max(body.padding, link_padding_[i]);
        }
        body.center = box.center();
        for (const auto& [c, r] : balls) body.radius = std::max(body.radius, (c - body.center).norm() + r);
        // (Grown past the rounding of the relative poses here, chains of a few products of the base state's
        // world magnitudes; the members' placement at each state adds the anchor's, at the query.)
        body.radius = margins::roundedUp(body.radius * margins::kBeyond, body.center.norm() + body.radius + world);
      }
      env_bodies_.push_back(body);
    }
  }
  if (description_.effects.environment && static_collision_.kind == CollisionReport::Kind::None &&
      !environment_->hasMovingObstacles())
    for (int i : geometry_->geometricLinks()) {
      if (moves[i]) continue;
      EnvironmentHit hit;
      if (environment_->linkIntersects(*geometry_->link(i), poses[i], options_.tolerances,
                                       {link_padding_[i], options_.mode}, {0.0, nullptr, &hit})) {
        static_collision_.kind = CollisionReport::Kind::Environment;
        static_collision_.link = i;
        static_collision_.hit = hit;
        break;
      }
    }
  // Static links' clearance, likewise (paid only by scenes that declare clearance).
  if (description_.effects.clearance && description_.effects.environment && !environment_->empty())
    for (int i : geometry_->geometricLinks()) {
      if (moves[i] || environment_->hasMovingObstacles()) continue;
      const DistanceResult d = environment_->linkDistance(*geometry_->link(i), poses[i], options_.tolerances);
      const bool failed = isFailure(d.status);
      static_clearance_ = std::min(static_clearance_, failed ? 0.0 : std::max(0.0, d.distance - link_padding_[i]));
      static_clearance_lower_ =
          std::min(static_clearance_lower_, failed ? 0.0 : std::max(0.0, d.lower_bound - link_padding_[i]));
    }
}

std::shared_ptr<const Scene> Scene::withAttached(const SceneDescription::AttachedSpec& spec, const LoadOptions& load) const {
  const RobotModel& model = robot();
  const std::string& name = spec.body.name;
  const auto link = [&](const std::string& l) {
    const int i = model.linkIndex(l);
    if (i < 0) throw std::invalid_argument("attach '" + inputExcerpt(name) + "': robot '" + inputExcerpt(model.name()) + "' has no link '" + inputExcerpt(l) + "'");
    return i;
  };
  AttachedBody b;
  b.name = name;
  b.link = link(spec.link);
  b.pose = spec.body.pose;
  for (const std::string& t : spec.touch_links) b.touch_links.push_back(link(t));
  // As a scene file's lengths (load/input_limits.h): a body placed near 1e308 overflowed the link's pose,
  // and a cast motion from a colliding state was called free.
  const auto within = [](const Vec3& v) { return v.cwiseAbs().maxCoeff() <= kMaxInputLength; };
  const Aabb box = spec.body.mesh_file.empty() ? placedBox(spec.body.shape, spec.body.pose) : Aabb{spec.body.pose.t, spec.body.pose.t};
  if (!within(box.min) || !within(box.max))
    throw std::invalid_argument("attach '" + inputExcerpt(name) + "': the body reaches beyond " +
                                std::to_string(static_cast<long long>(kMaxInputLength)) +
                                " m of its link, the largest length an input may give");
  std::vector<TriangleMesh> meshes;
  if (spec.body.mesh_file.empty()) {
    b.element.primitive = spec.body.shape;
  } else {
    b.element.mesh = 0;
    try {
      meshes.push_back(loadMesh(spec.body.mesh_file, spec.body.mesh_scale, nullptr, load.mesh));
    } catch (const std::exception& e) {
      throw std::invalid_argument("attach '" + inputExcerpt(name) + "': " + e.what());
    }
  }
  auto held = std::make_shared<const RobotModel>(attachBodies(model, {b}, meshes));
  SceneDescription d = description_;
  d.attached.push_back(spec);
  return std::make_shared<const Scene>(d, std::make_shared<const RobotGeometry>(std::move(held), *geometry_),
                                       environment_, options_);
}

std::shared_ptr<const Scene> Scene::withoutAttached(const std::string& name) const {
  SceneDescription d = description_;
  const auto it = std::find_if(d.attached.begin(), d.attached.end(),
                               [&](const SceneDescription::AttachedSpec& a) { return a.body.name == name; });
  if (it == d.attached.end()) throw std::invalid_argument("detach '" + name + "': no attached body has that name");
  d.attached.erase(it);
  // The pairs the scene allows with the body go with it: no link has its name any more.
  d.allow.erase(std::remove_if(d.allow.begin(), d.allow.end(),
                               [&](const std::pair<std::string, std::string>& p) { return p.first == name || p.second == name; }),
                d.allow.end());
  auto bare = std::make_shared<const RobotModel>(detachBodies(robot(), {name}));
  return std::make_shared<const Scene>(d, std::make_shared<const RobotGeometry>(std::move(bare), *geometry_),
                                       environment_, options_);
}

std::shared_ptr<const Scene> Scene::withEnvironment(std::shared_ptr<const Environment> environment) const {
  auto scene = std::make_shared<Scene>(*this);
  scene->environment_ = environment ? std::move(environment) : std::make_shared<const Environment>();
  scene->initEnvironment();
  return scene;
}

}  // namespace clearway
