// MotionChecker: rigid bodies merged, the items certified mode measures, contexts, interpolation, and the
// choice of mode.
#include <clearway/motion/motion.h>

#include <clearway/body/proximity.h>
#include <clearway/detail/margins.h>
#include <clearway/detail/weak_memo.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <tuple>

#include "motion_detail.h"

namespace clearway {

using motion_detail::alignedUnit;
using motion_detail::referenceState;

namespace {

// Environment items keep a GJK warm start per static obstacle up to this many obstacles (2.5 KiB a link).
constexpr std::size_t kWarmObstacles = 64;

// A rigid body's links merged into one geometry in its anchor's frame, remembered while its robot lives:
// every checker over a loaded robot (each scene, each form of it) merges the same links at the same
// offsets again, and on a gripper bolted to a force sensor that is most of a checker's construction (hull,
// tree, cores and convex parts of thousands of triangles). Keyed by the robot, the members and each
// member's offset: the merge reads nothing else.
struct MergedKey {
  const RobotGeometry* robot;
  std::vector<int> members;
  std::vector<double> offsets;
  bool operator<(const MergedKey& o) const {
    return std::tie(robot, members, offsets) < std::tie(o.robot, o.members, o.offsets);
  }
};

std::shared_ptr<const LinkGeometry> mergedGeometry(const std::shared_ptr<const RobotGeometry>& robot,
                                                   const std::vector<int>& members, const std::vector<Pose>& offsets) {
  static detail::WeakMemo<MergedKey, std::shared_ptr<const LinkGeometry>, RobotGeometry> memo;
  const RobotModel& model = robot->model();
  MergedKey key{robot.get(), members, {}};
  for (const Pose& p : offsets) appendPose(p, key.offsets);
  // (A NaN would break the keys' order: such a body is merged afresh.)
  const bool keyed = std::none_of(key.offsets.begin(), key.offsets.end(), [](double v) { return std::isnan(v); });
  if (keyed)
    if (std::optional<std::shared_ptr<const LinkGeometry>> known = memo.find(key)) return std::move(*known);
  // Every member's elements, placed in the anchor's frame (fixed: the joints in between do not move).
  std::vector<CollisionElement> elements;
  for (std::size_t i = 0; i < members.size(); ++i)
    for (CollisionElement e : model.link(members[i]).collisions) {
      e.origin = offsets[i] * e.origin;
      elements.push_back(std::move(e));
    }
  auto merged = std::make_shared<const LinkGeometry>(elements, model.meshes());
  if (keyed) memo.store(std::move(key), robot, robot, merged);
  return merged;
}

}  // namespace

// ---- MotionChecker ------------------------------------------------------------------------------------

MotionChecker::Bodies MotionChecker::mergeBodies(const Scene& scene) {
  const RobotModel& model = scene.robot();
  Bodies out;
  out.anchor = scene.rigidAnchors();
  out.index.assign(model.linkCount(), -1);
  std::vector<std::vector<int>> members(model.linkCount());
  for (const int l : scene.geometry().geometricLinks()) members[out.anchor[l]].push_back(l);
  SceneContext ctx = scene.makeContext();
  scene.computePoses(referenceState(scene).data(), ctx);
  out.reference = ctx.poses();
  for (int anchor = 0; anchor < model.linkCount(); ++anchor) {
    if (members[anchor].size() < 2) continue;
    std::vector<Pose> offsets;
    for (const int l : members[anchor]) offsets.push_back(relativePose(out.reference[anchor], out.reference[l]));
    for (const int l : members[anchor]) out.index[l] = static_cast<int>(out.list.size());
    out.geometry.push_back(mergedGeometry(scene.geometryPtr(), members[anchor], offsets));
    const LinkGeometry& g = *out.geometry.back();
    out.list.push_back({anchor, &g.hull(), g.sphereCenter(), g.sphereRadius()});
  }
  // Then each link's and merged body's convex pieces, as links of the bound of their own.
  const int merged = static_cast<int>(out.list.size());
  out.parts_begin.assign(model.linkCount() + merged, -1);
  for (int l = 0; l < model.linkCount() + merged; ++l) {
    const LinkGeometry* g = l < model.linkCount() ? scene.geometry().link(l) : out.geometry[l - model.linkCount()].get();
    if (!g) continue;
    out.parts_begin[l] = model.linkCount() + static_cast<int>(out.list.size());
    const int frame = l < model.linkCount() ? l : out.list[l - model.linkCount()].anchor;
    for (const LinkGeometry::Part& part : g->parts()) out.list.push_back({frame, &part.hull, part.center, part.radius});
  }
  return out;
}

MotionChecker::MotionChecker(std::shared_ptr<const Scene> scene, MotionOptions options)
    : scene_(std::move(scene)), options_(options), bodies_(mergeBodies(*scene_)), bound_(*scene_, bodies_.list) {
  validateOptions();
  for (const auto& o : scene_->environment().movingObstacles()) obstacle_speed_ = std::max(obstacle_speed_, o->velocity.norm());
  // A floating joint's quaternion turns along the great arc (slerp), as OMPL's SO(3) interpolates.
  const RobotModel& model = scene_->robot();
  for (int i = 0; i < scene_->dimension(); ++i) {
    const int v = scene_->groupVariables()[i];
    const Joint& joint = model.joint(model.variables()[v].joint);
    if (joint.type == JointType::Floating && v == joint.first_variable + 3) quaternions_.push_back(i);
  }
  buildItems();
  buildItemTables();
  buildRakeRows();
  buildRakePoints();
  const std::vector<int>& begin = bodies_.parts_begin;
  for (int k = 0; k < env_begin_; ++k) {
    const Item& it = items_[k];
    paths_.push_back(bound_.path(it.a, it.b));
    std::vector<MotionBound::PairPath> split;
    const int na = static_cast<int>(it.ga->parts().size()), nb = static_cast<int>(it.gb->parts().size());
    for (int i = 0; i < na; ++i) split.push_back(bound_.path(begin[it.a] + i, it.b));
    for (int j = 0; j < nb; ++j) split.push_back(bound_.path(it.a, begin[it.b] + j));
    split_paths_.push_back(std::move(split));
  }
}

void MotionChecker::buildRakeRows() {
  std::vector<std::int64_t> a, b;
  std::vector<double> padding;
  rake_pair_.assign(items_.size(), -1);
  rake_bodies_.clear();
  rake_body_count_ = 0;
  for (const Item& it : items_) rake_body_count_ = std::max({rake_body_count_, it.a + 1, it.b + 1});
  std::vector<char> named(rake_body_count_, 0);
  for (int k = 0; k < env_begin_; ++k) {
    const Item& it = items_[k];
    if (it.group >= 0 || it.b < 0) continue;
    rake_pair_[k] = static_cast<int>(a.size());
    a.push_back(it.a), b.push_back(it.b);
    padding.push_back(it.padding + options_.contact_distance);
    for (const auto& [body, frame, g] : {std::tuple{it.a, it.frame_a, it.ga}, std::tuple{it.b, it.frame_b, it.gb}})
      if (!named[body]) {
        named[body] = 1;
        rake_bodies_.push_back({body, frame, g});
      }
  }
  rake_rows_ = BoundsRows(a, b, padding, rake_body_count_);
}

void MotionChecker::buildRakePoints() {
  const Scene& sc = *scene_;
  const RobotModel& model = sc.robot();
  rake_point_.assign(rake_body_count_, -1);
  rake_point_geometry_.assign(rake_body_count_, nullptr);
  std::vector<PointLanes::Point> points;
  for (const Item& it : items_) {
    if (it.group >= 0) continue;  // (a group's members are measured, never raked)
    for (const auto& [body, frame, g] : {std::tuple{it.a, it.frame_a, it.ga}, std::tuple{it.b, it.frame_b, it.gb}}) {
      if (body < 0 || !g || rake_point_[body] >= 0) continue;
      rake_point_[body] = static_cast<int>(points.size());
      rake_point_geometry_[body] = g;
      points.push_back({frame, g->sphereCenter()});
    }
  }
  // The joint values a segment between valid states can hold: the group's within its bounds (a box: convex),
  // the others at the values the scene holds them.
  std::vector<double> most(model.variableCount());
  const SceneContext held = sc.makeContext();
  for (int v = 0; v < model.variableCount(); ++v) most[v] = std::abs(held.jointValues()[v]);
  for (int i = 0; i < sc.dimension(); ++i)
    most[sc.groupVariables()[i]] = std::max(std::abs(sc.validLower(i)), std::abs(sc.validUpper(i)));
  rake_points_ = PointLanes(model, std::move(points), most);
}

void MotionChecker::buildItemTables() {
  const Scene& sc = *scene_;
  item_tables_.assign(env_begin_, {});
  if (options_.mode == MotionMode::Sampled || !sc.options().pair_tables) return;
  const SelfCollisionOptions& so = sc.selfCollision().options();
  const PairTableOptions table = so.table_options.within(so.table_seconds);
  const double margin = 2.0 * options_.contact_distance;
  // Every self item's table (a group's: each member's), built at once; an item whose every pair has one
  // keeps them.
  std::vector<PairTable::Request> requests;
  std::vector<int> request_of(env_begin_, -1);  // per item that is not a group's head: its request
  for (int m = 0; m < env_begin_; ++m) {
    if (items_[m].last > items_[m].first) continue;
    request_of[m] = static_cast<int>(requests.size());
    requests.push_back({items_[m].a, items_[m].b, items_[m].padding + margin});
  }
  const std::vector<std::shared_ptr<const PairTable>> tables =
      PairTable::sharedMany(sc.geometryPtr(), requests, sc.options().mode, sc.options().tolerances, so.held, table);
  for (int k = 0; k < env_begin_; ++k) {
    const Item& item = items_[k];
    if (item.group >= 0) continue;  // (a member: its group's list holds its table)
    std::vector<std::shared_ptr<const PairTable>> list;
    const int first = item.first < item.last ? item.first : k, last = item.first < item.last ? item.last : k + 1;
    for (int m = first; m < last; ++m) {
      const std::shared_ptr<const PairTable>& t = tables[request_of[m]];
      if (!t) {
        list.clear();
        break;
      }
      list.push_back(t);
    }
    item_tables_[k] = std::move(list);
  }
}

MotionChecker::MotionChecker(const MotionChecker& base, std::shared_ptr<const Scene> scene)
    : MotionChecker(scene->geometryPtr() == base.scene_->geometryPtr() &&
                            scene->environmentLinks() == base.scene_->environmentLinks() &&
                            scene->selfCollision().pairs().size() == base.scene_->selfCollision().pairs().size()
                        ? base
                        : MotionChecker(scene, base.options_)) {
  scene_ = std::move(scene);
  obstacle_speed_ = 0.0;
  for (const auto& o : scene_->environment().movingObstacles()) obstacle_speed_ = std::max(obstacle_speed_, o->velocity.norm());
}

MotionChecker::MotionChecker(const MotionChecker& base, MotionOptions options) : MotionChecker(base) {
  const bool sampled = options.mode == MotionMode::Sampled, base_sampled = base.options_.mode == MotionMode::Sampled;
  const bool tables = options.contact_distance != base.options_.contact_distance || sampled != base_sampled;
  options_ = std::move(options);
  validateOptions();
  // (A context sized for base's mode, Cast's end poses, must not reach this one.)
  serial_ = detail::nextSerial();
  if (tables) buildItemTables();
}

void MotionChecker::validateOptions() const {
  if (!(options_.contact_distance > 0.0) || !std::isfinite(options_.contact_distance))
    throw std::invalid_argument("MotionChecker: contact_distance must be finite and > 0");
  if (!(options_.resolution > 0.0) || !std::isfinite(options_.resolution))
    throw std::invalid_argument("MotionChecker: resolution must be finite and > 0");
  if (!(options_.distance_relative_error >= 0.0) || !std::isfinite(options_.distance_relative_error))
    throw std::invalid_argument("MotionChecker: distance_relative_error must be finite and >= 0");
  if (options_.max_queries < 1) throw std::invalid_argument("MotionChecker: max_queries must be >= 1");
  if (options_.max_samples < 1) throw std::invalid_argument("MotionChecker: max_samples must be >= 1");
}

void MotionChecker::buildItems() {
  const Scene& sc = *scene_;
  const RobotModel& model = sc.robot();
  const int n_links = model.linkCount();
  const std::vector<int>& anchor = bodies_.anchor;
  std::vector<int> geometric(n_links, 0);  // per anchor: its links with geometry
  for (const int l : sc.geometry().geometricLinks()) ++geometric[anchor[l]];
  // A link's body as one link of the bound: merged, or the link itself when it is the body's only one.
  const auto whole = [&](int link, Item& item, bool second) {
    const int body = bodies_.index[link];
    const int index = body >= 0 ? n_links + body : link;
    const int frame = body >= 0 ? bodies_.list[body].anchor : link;
    const LinkGeometry* g = body >= 0 ? bodies_.geometry[body].get() : sc.geometry().link(link);
    (second ? item.b : item.a) = index;
    (second ? item.frame_b : item.frame_a) = frame;
    (second ? item.gb : item.ga) = g;
  };
  // Groups of members (indices into `single`): the members follow their group, in order.
  const auto emit = [&](const std::vector<Item>& single, const std::vector<std::vector<int>>& groups,
                        const std::vector<Item>& heads) {
    std::vector<char> taken(single.size(), 0);
    std::vector<Item> tail;
    for (std::size_t g = 0; g < groups.size(); ++g) items_.push_back(heads[g]);
    const std::size_t first_group = items_.size() - groups.size();
    for (std::size_t g = 0; g < groups.size(); ++g) {
      Item& head = items_[first_group + g];
      head.first = static_cast<int>(items_.size() + tail.size());
      for (const int m : groups[g]) {
        Item member = single[m];
        member.group = static_cast<int>(first_group + g);
        tail.push_back(member);
        taken[m] = 1;
      }
      head.last = static_cast<int>(items_.size() + tail.size());
    }
    items_.insert(items_.end(), tail.begin(), tail.end());
    for (std::size_t m = 0; m < single.size(); ++m)
      if (!taken[m]) items_.push_back(single[m]);
  };

  // Self pairs. Two bodies whose every link pair is checked are one item: the least distance over those
  // pairs is the distance of the merged geometries (padding: the largest of the pairs').
  std::vector<Item> single, heads;
  std::vector<std::vector<int>> groups;
  if (sc.effects().self) {
    const SelfCollision& self = sc.selfCollision();
    std::vector<std::pair<std::pair<int, int>, int>> keyed;  // (anchors, index in single)
    for (int k = 0; k < static_cast<int>(self.pairs().size()); ++k) {
      const LinkPair& p = self.pairs()[k];  // (never two links of one rigid body: the scene checks those once)
      Item item;
      item.a = item.frame_a = p.a;
      item.b = item.frame_b = p.b;
      item.ga = sc.geometry().link(p.a);
      item.gb = sc.geometry().link(p.b);
      item.padding = self.pairPadding(k);
      keyed.push_back({std::minmax(anchor[p.a], anchor[p.b]), static_cast<int>(single.size())});
      single.push_back(item);
    }
    std::sort(keyed.begin(), keyed.end());
    for (std::size_t i = 0, j; i < keyed.size(); i = j) {
      for (j = i; j < keyed.size() && keyed[j].first == keyed[i].first; ++j) {}
      const auto [x, y] = keyed[i].first;
      const std::size_t n = j - i;
      if (x == y || n < 2 || n != static_cast<std::size_t>(geometric[x]) * geometric[y]) continue;
      Item head;
      whole(single[keyed[i].second].a, head, false);
      whole(single[keyed[i].second].b, head, true);
      groups.emplace_back();
      for (std::size_t m = i; m < j; ++m) {
        groups.back().push_back(keyed[m].second);
        head.padding = std::max(head.padding, single[keyed[m].second].padding);
      }
      heads.push_back(head);
    }
  }
  emit(single, groups, heads);
  env_begin_ = static_cast<int>(items_.size());

  // Environment links. A body whose every geometric link is checked is one item.
  single.clear(), heads.clear(), groups.clear();
  const std::vector<int>& env_links = sc.environmentLinks();
  std::vector<int> checked(n_links, 0);
  for (const int l : env_links) ++checked[anchor[l]];
  std::vector<int> group_of(n_links, -1);
  for (std::size_t k = 0; k < env_links.size(); ++k) {
    const int l = env_links[k];
    Item item;
    item.a = item.frame_a = l;
    item.ga = sc.geometry().link(l);
    item.padding = sc.linkPadding(l);
    single.push_back(item);
    const int x = anchor[l];
    if (checked[x] < 2 || checked[x] != geometric[x]) continue;
    if (group_of[x] < 0) {
      group_of[x] = static_cast<int>(groups.size());
      groups.emplace_back();
      Item head;
      whole(l, head, false);
      heads.push_back(head);
    }
    groups[group_of[x]].push_back(static_cast<int>(k));
    heads[group_of[x]].padding = std::max(heads[group_of[x]].padding, item.padding);
  }
  emit(single, groups, heads);

  // The rake's boxes: for pairs with a slender body, whose ball is at least kSlender times its box's middle
  // half-extent (the UR5's upper arm and forearm: 4.2, 4.3), the boxes settle pieces the balls leave; for
  // stouter bodies (the Panda's: 1.3 to 2.4) they settled too few to pay for the test (asked of every pair, the
  // Panda's free segments took 0.3 to 0.7% more instructions).
  constexpr double kSlender = 2.5;
  const auto slender = [](const LinkGeometry& g) {
    const Vec3 h = g.bounds().halfExtents();
    return g.sphereRadius() >= kSlender * (h.sum() - h.maxCoeff() - h.minCoeff());
  };
  for (Item& it : items_) it.boxes = it.b >= 0 && (slender(*it.ga) || slender(*it.gb));
}

MotionContext::MotionContext() noexcept = default;
MotionContext::MotionContext(MotionContext&&) noexcept = default;
MotionContext& MotionContext::operator=(MotionContext&&) noexcept = default;
MotionContext::~MotionContext() = default;
MotionContext::MotionContext(std::unique_ptr<motion_detail::Scratch> scratch) noexcept : scratch_(std::move(scratch)) {}

MotionContext MotionChecker::makeContext() const {
  auto scratch = std::make_unique<motion_detail::Scratch>();
  motion_detail::Scratch& c = *scratch;
  c.owner = serial_;
  c.scene = scene_->makeContext();
  for (int k = 0; k < motion_detail::Scratch::kPoseSlots; ++k) {
    c.full_q[k] = c.scene.jointValues();
    c.poses[k].resize(scene_->robot().linkCount());
    c.pose_stamp[k].assign(scene_->robot().linkCount(), 0);
  }
  c.q.resize(scene_->dimension());
  c.dq.resize(scene_->dimension());
  c.safe_until.resize(items_.size());
  c.bound.resize(items_.size());
  c.bound_stamp.assign(items_.size(), 0);
  c.first_reach.resize(items_.size());
  c.live.reserve(items_.size());
  c.settled.assign(items_.size(), 0);
  c.rake_now.assign(items_.size(), 0);
  c.rake_next.assign(items_.size(), 0);
  c.rake_balls.assign(rake_body_count_, {});
  for (std::vector<double>* v : {&c.rake_x, &c.rake_y, &c.rake_z, &c.rake_r, &c.rake_norm})
    v->assign(static_cast<std::size_t>(rake_body_count_ + BoundsRows::kSpare), 0.0);
  c.rake_apart.assign(static_cast<std::size_t>(rake_rows_.size() + BoundsRows::kSpare), 0);
  c.body_bound.assign(rake_body_count_, 0.0);
  if (rake_points_.serves()) {
    c.rake_lane_q.assign(PointLanes::kLanes, c.scene.jointValues());
    constexpr int passes =
        ((1 << (motion_detail::Scratch::kRakeLevels - 1)) + PointLanes::kLanes - 1) / PointLanes::kLanes;
    c.rake_xyz.resize(static_cast<std::size_t>(3 * rake_points_.size() * PointLanes::kLanes * passes));
    c.rake_lane_scratch.resize(rake_points_.scratchSize());
  }
  c.contact.assign(items_.size(), {options_.contact_distance, options_.contact_distance});
  c.contact_stamp.assign(items_.size(), 0);
  c.split_slot.assign(env_begin_, 0);
  c.split_stamp.assign(env_begin_, 0);
  c.pair_stamp.assign(env_begin_, 0);
  for (int k = 0; k < env_begin_; ++k) {
    const Item& it = items_[k];
    c.split_slot[k] = static_cast<int>(c.split_bound.size());
    c.split_bound.resize(c.split_bound.size() + it.ga->parts().size() + it.gb->parts().size());
    c.pairs.emplace_back(*it.ga, *it.gb);
  }
  // (Warm starts per static obstacle while there are few: with many, the tree visits only a few per query.)
  const std::size_t obstacles = scene_->environment().staticCount();
  const int env_items = static_cast<int>(items_.size()) - env_begin_;
  c.env_slot.assign(env_items, -1);
  c.env_stamp.assign(env_items, 0);
  c.warm_obstacles = obstacles;
  if (obstacles > 0 && obstacles <= kWarmObstacles) {
    for (int k = 0; k < env_items; ++k) c.env_slot[k] = static_cast<int>(k * obstacles);
    c.env_cache.resize(env_items * obstacles);
  }
  c.probe_states.resize(static_cast<std::size_t>(motion_detail::kProbes) * scene_->dimension());
  c.pose_path.reserve(scene_->robot().linkCount());
  c.step_cache = bound_.makeStepCache();
  c.intervals.reserve(256);
  c.turn_stacks.assign(items_.size(), {});
  c.turns.reserve(256);
  if (options_.mode == MotionMode::Cast) c.end_poses.resize(scene_->robot().linkCount());
  return MotionContext(std::move(scratch));
}


void MotionChecker::interpolate(const double* q0, const double* q1, double s, double* out) const noexcept {
  for (int i = 0; i < scene_->dimension(); ++i) out[i] = q0[i] + s * (q1[i] - q0[i]);
  for (const int k : quaternions_) {
    Eigen::Vector4d a, b;
    alignedUnit(q0 + k, q1 + k, a, b);
    const double angle = std::acos(std::clamp(a.dot(b), -1.0, 1.0));
    // Slerp; nearly equal ends interpolate linearly (then renormalized), where sin(angle) loses digits.
    constexpr double kLinearBelow = 1e-9;  // rad
    Eigen::Vector4d q = angle > kLinearBelow ? Eigen::Vector4d((std::sin((1 - s) * angle) * a + std::sin(s * angle) * b) / std::sin(angle))
                                     : Eigen::Vector4d(a + s * (b - a));
    q.normalize();
    for (int c = 0; c < 4; ++c) out[k + c] = q[c];
  }
}

MotionResult MotionChecker::check(const double* q0, const double* q1, MotionContext& ctx,
                                  bool locate_contact) const noexcept {
  return check(q0, 0.0, q1, 0.0, ctx, locate_contact);
}

MotionResult MotionChecker::check(const double* q0, double t0, const double* q1, double t1, MotionContext& context,
                                  bool locate_contact) const noexcept {
  if (!context.scratch_) {  // an empty context: a collision, never free by accident
    MotionResult r;
    r.report.kind = CollisionReport::Kind::Invalid;
    return r;
  }
  motion_detail::Scratch& ctx = *context.scratch_;
  if (!(std::abs(t0) <= kMaxTime && std::abs(t1) <= kMaxTime)) {  // (NaN fails)
    MotionResult r;
    r.report.kind = CollisionReport::Kind::Invalid;
    return r;
  }
  if (!fits(ctx)) {
    MotionResult r;
    r.report.kind = CollisionReport::Kind::Invalid;
    return r;
  }
  return options_.mode == MotionMode::Sampled ? sampled(q0, t0, q1, t1, ctx)
                                              : certified(q0, t0, q1, t1, ctx, locate_contact);
}

bool MotionChecker::fits(const motion_detail::Scratch& ctx) const noexcept {
  // A context made by another checker (of another robot: a World before an attach, say; of another group:
  // its buffers sized for another dimension; or of the same robot elsewhere: its pairs and warm starts are
  // that checker's items', perhaps freed with it) does not fit.
  const std::size_t dim = static_cast<std::size_t>(scene_->dimension());
  return ctx.owner == serial_ && ctx.safe_until.size() == items_.size() &&
         ctx.poses[0].size() == static_cast<std::size_t>(scene_->robot().linkCount()) && ctx.q.size() == dim &&
         ctx.dq.size() == dim && ctx.probe_states.size() == motion_detail::kProbes * dim;
}

bool MotionChecker::within(const double* q0, const double* q1, const double* p0, const double* p1, double margin,
                           MotionContext& context) const noexcept {
  const Scene& sc = *scene_;
  if (!context.scratch_ || !fits(*context.scratch_) || !(margin > 0.0) || !std::isfinite(margin)) return false;
  if (!quaternions_.empty() || (sc.effects().moving && sc.environment().hasMovingObstacles())) return false;
  if (!sc.validState(q0) || !sc.validState(q1)) return false;
  motion_detail::Scratch& ctx = *context.scratch_;
  const int n = sc.dimension();
  double uu = 0.0;
  for (int i = 0; i < n; ++i) uu += (p1[i] - p0[i]) * (p1[i] - p0[i]);
  if (!(uu > 0.0 && uu < INFINITY)) return false;  // (a segment of length 0 holds only its own ends)
  // Each end's distance, entry by entry, from the point of p0 → p1 at its projection's parameter t (clamped:
  // the exact point p0 + t·(p1 − p0) then lies on the segment), with the roundings of computing it. The
  // states between q0 and q1 are convex combinations of the ends, and so of the nearest points: no entry
  // differs by more than the larger of the ends' (the checker's own interpolation rounds both alike).
  std::vector<double>& dev = ctx.dq;
  std::fill(dev.begin(), dev.end(), 0.0);
  for (const double* x : {q0, q1}) {
    double along = 0.0;
    for (int i = 0; i < n; ++i) along += (x[i] - p0[i]) * (p1[i] - p0[i]);
    const double t = along / uu;
    if (std::isnan(t)) return false;
    const double s = std::clamp(t, 0.0, 1.0);
    for (int i = 0; i < n; ++i) {
      const double u = p1[i] - p0[i];
      const double rounding = 4.0 * margins::kUlp * (std::abs(x[i]) + std::abs(p0[i]) + std::abs(u));
      dev[i] = std::max(dev[i], std::abs(x[i] - (p0[i] + s * u)) + rounding);
    }
  }
  // No body moves farther than its motion bound for that step; a pair's clearance changes by at most the
  // sum of its bodies' moves, a link's from the (static) obstacles by its own.
  bound_.links(dev.data(), static_cast<int>(ctx.body_bound.size()), ctx.body_bound.data());
  const std::vector<double>& moved = ctx.body_bound;
  for (const Item& it : items_) {
    const double d = it.b >= 0 ? moved[it.a] + moved[it.b] : moved[it.a];
    if (!(d * margins::kBeyond < margin)) return false;  // (NaN or ∞: not within)
  }
  return true;
}

}  // namespace clearway
