// Asking a scene: contexts, valid states, isFree (the environment, then the self pairs), batches of
// states in SIMD lanes, clearance and reports. Building a scene (loading, init, edits) is scene.cpp.
#include <clearway/scene/scene.h>

#include <clearway/body/enclosing.h>
#include <clearway/body/link_geometry.h>
#include <clearway/detail/margins.h>
#include <clearway/per_thread.h>
#include <clearway/kinematics/forward_kinematics.h>
#include <clearway/load/input_limits.h>

#include "exact_text.h"
#include "scene_scratch.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace clearway {

using scene_detail::exactText;
using scene_detail::SceneScratch;

namespace {

// An empty scratch of this thread: a default-made (or moved-from) context's, whose queries answer Invalid
// (no poses). Out of line, so that a context's own scratch costs no thread-local look-up.
[[gnu::noinline]] SceneScratch& emptyScratch() noexcept {
  thread_local SceneScratch none;
  return none;
}

// The scratch of a context.
SceneScratch& scratchOf(const std::unique_ptr<SceneScratch>& s) noexcept { return s ? *s : emptyScratch(); }

}  // namespace

SceneContext::SceneContext() noexcept = default;
SceneContext::SceneContext(SceneContext&&) noexcept = default;
SceneContext& SceneContext::operator=(SceneContext&&) noexcept = default;
SceneContext::~SceneContext() = default;
SceneContext::SceneContext(std::unique_ptr<SceneScratch> scratch) noexcept : scratch_(std::move(scratch)) {}
const std::vector<Pose>& SceneContext::poses() const noexcept { return scratchOf(scratch_).poses; }
const std::vector<double>& SceneContext::jointValues() const noexcept { return scratchOf(scratch_).q; }
SceneCounters& SceneContext::counters() noexcept { return scratchOf(scratch_).counters; }
const SceneCounters& SceneContext::counters() const noexcept { return scratchOf(scratch_).counters; }

SceneContext Scene::makeContext() const {
  auto scratch = std::make_unique<SceneScratch>();
  SceneScratch& c = *scratch;
  c.q = base_q_;
  c.tabled_q = base_q_;
  c.poses.resize(robot().linkCount());
  c.self = self_.makeContext();
  c.balls = EnclosingBalls(*geometry_);
  c.lanes.emplace(robot());
  c.lane_q.reserve(base_q_.size() * KinematicLanes::kMaxLanes);
  for (int l = 0; l < KinematicLanes::kMaxLanes; ++l) c.lane_q.insert(c.lane_q.end(), base_q_.begin(), base_q_.end());
  c.lane_poses.resize(static_cast<std::size_t>(robot().linkCount()) * KinematicLanes::kMaxLanes);
  c.owner = serial_;
  return SceneContext(std::move(scratch));
}

// (Inline: every query asks it first, and nearly always of a context of its own. Only this file calls it.)
inline bool Scene::adopt(SceneScratch& ctx) const noexcept {
  if (ctx.owner == serial_) return true;  // (made or adopted by this scene: its sizes were checked then)
  if (ctx.poses.size() != static_cast<std::size_t>(robot().linkCount()) || ctx.q.size() != base_q_.size())
    return false;  // (another robot's, or a default-made context)
  std::copy(base_q_.begin(), base_q_.end(), ctx.q.begin());
  if (ctx.tabled_q.size() == base_q_.size()) std::copy(base_q_.begin(), base_q_.end(), ctx.tabled_q.begin());
  const std::size_t nv = base_q_.size();
  if (nv > 0 && ctx.lane_q.size() % nv == 0)
    for (std::size_t at = 0; at < ctx.lane_q.size(); at += nv)
      std::copy(base_q_.begin(), base_q_.end(), ctx.lane_q.begin() + static_cast<std::ptrdiff_t>(at));
  ctx.env_last_hit = -1;
  ctx.owner = serial_;
  return true;
}

void Scene::computePoses(const double* state, SceneContext& context) const noexcept {
  SceneScratch& ctx = scratchOf(context.scratch_);
  if (adopt(ctx)) place(state, ctx);  // (else another robot's)
}

void Scene::place(const double* state, SceneScratch& ctx) const noexcept {
  for (std::size_t i = 0; i < group_variables_.size(); ++i) ctx.q[group_variables_[i]] = state[i];
  computeLinkPoses(robot(), ctx.q.data(), ctx.poses.data());
}

bool Scene::validState(const double* state, std::string* why) const {
  const RobotModel& model = robot();
  for (std::size_t i = 0; i < group_variables_.size(); ++i) {
    const JointVariable& var = model.variables()[group_variables_[i]];
    const double x = state[i];
    const double lo = lower_[i], hi = upper_[i];
    if (!std::isfinite(x)) {
      if (why) *why = "state[" + std::to_string(i) + "] (" + var.name + ") is not finite";
      return false;
    }
    if (std::abs(x) > kMaxJointValue) {
      if (why)
        *why = "state[" + std::to_string(i) + "] (" + var.name + ") = " + exactText(x) +
               " is beyond ±1e6, the largest joint value a state may hold";
      return false;
    }
    if (x < lo - kJointLimitTolerance || x > hi + kJointLimitTolerance) {
      if (why)
        *why = "state[" + std::to_string(i) + "] (" + var.name + ") = " + exactText(x) + " is outside [" +
               exactText(lo) + ", " + exactText(hi) + "] by more than " + exactText(kJointLimitTolerance);
      return false;
    }
  }
  for (const int i : quaternions_)
    if (!rotates(state + i)) {
      if (why)
        *why = "state[" + std::to_string(i) + ".." + std::to_string(i + 3) + "] (" + model.variables()[group_variables_[i]].name +
               " ...) is a zero quaternion (its squares add up to 0): it names no rotation";
      return false;
    }
  return true;
}

bool Scene::withinBounds(const double* state) const noexcept {
  for (std::size_t i = 0; i < group_variables_.size(); ++i) {
    // Written so that a NaN fails.
    if (!(state[i] >= valid_lower_[i] && state[i] <= valid_upper_[i])) return false;
  }
  for (const int i : quaternions_)
    if (!rotates(state + i)) return false;
  return true;
}

bool Scene::isFree(const double* state, SceneContext& context, CollisionReport* report, double t) const noexcept {
  return checkState(state, scratchOf(context.scratch_), report, t);
}

bool Scene::checkState(const double* state, SceneScratch& ctx, CollisionReport* report, double t) const noexcept {
  ++ctx.counters.states;
  CollisionReport local;
  CollisionReport& r = report ? *report : local;
  r = CollisionReport{};
  // (A context of another scene's robot, such as a World's before an attach, does not fit: refused.)
  if (!withinBounds(state) || !withinTime(t) || !adopt(ctx)) {
    ++ctx.counters.invalid_states;
    r.kind = CollisionReport::Kind::Invalid;
    return false;
  }
  if (static_collision_.kind != CollisionReport::Kind::None) {
    r = static_collision_;
    return false;
  }
  const Effects& fx = description_.effects;
  if (!fx.self && !fx.environment) return true;
  // The pair tables first: they need no poses, and a pair they prove colliding (the UR5's upper arm in the
  // box it stands on: over half its self-colliding random states) ends the check before the kinematics and
  // the environment, leaving the context's last placed state as it was. Their other verdicts wait in the
  // self check's context for the self check below, at the same values.
  if (fx.self && self_.hasTables() && ctx.tabled_q.size() == ctx.q.size()) {
    for (std::size_t i = 0; i < group_variables_.size(); ++i) ctx.tabled_q[group_variables_[i]] = state[i];
    if (const LinkPair* hit = self_.tabledCollision(ctx.tabled_q.data(), ctx.self)) {
      r.kind = CollisionReport::Kind::Self;
      r.link = hit->a;
      r.other_link = hit->b;
      return false;
    }
  }
  place(state, ctx);
  return posedFree(ctx.poses.data(), ctx.q.data(), ctx, r, t);
}

bool Scene::posedFree(const Pose* poses, const double* q, SceneScratch& ctx, CollisionReport& r,
                      double t) const noexcept {
  bool balls_placed = false;
  return environmentFree(poses, ctx, r, t, balls_placed) && selfFree(poses, q, ctx, r, balls_placed);
}

bool Scene::environmentFree(const Pose* poses, SceneScratch& ctx, CollisionReport& r, double t,
                            bool& balls_placed) const noexcept {
  const Effects& fx = description_.effects;
  if (fx.environment && !environment_->empty()) {
    const double time = fx.moving ? t : 0.0;
    // The enclosing balls (placed after the lead link for the self check too) clear most links with a
    // test or a look-up each: the bounding ball against the obstacles' oriented boxes, then against the
    // clearance grid once the environment has one: the bounding ball, else every part's ball (whose union
    // holds the link, the inside of its closed meshes included, but not its hull).
    const Environment& env = *environment_;
    EnclosingBalls& balls = ctx.balls;
    const ClearanceGrid* grid = nullptr;
    const ObstacleBoxes* boxes = nullptr;
    // The slack a ball is cleared with: the padding, and the narrow phase's band for its coordinates.
    const auto slackOf = [&](double padding, const Vec3& center, double radius) {
      return env.linkSlack(padding, center.cwiseAbs().maxCoeff() + radius, options_.tolerances);
    };
    // Link i's bounding ball (placed) cleared by the boxes, else by the grid; counted.
    const auto boundCleared = [&](int i, const EnclosingBalls::Placed& bound) {
      const double slack = slackOf(link_padding_[i], bound.center, bound.radius);
      if (boxes && boxes->ballClear(bound.center, bound.radius, slack)) {
        ++ctx.counters.environment.box_clears;
        return true;
      }
      if (grid && grid->lowerBound(bound.center) > bound.radius + slack) {
        ++ctx.counters.environment.grid_clears;
        return true;
      }
      return false;
    };
    // Link i's parts' balls cleared by the grid (the balls placed): their union holds the link where its
    // bounding ball was not cleared.
    const auto partsCleared = [&](int i) {
      const int n = balls.ballCount(i);
      // (Not in Hull mode, where linkIntersects tests the hull, which the parts' balls need not hold. Nor for
      // closed meshes, which they hold only grown: on the shared robots, whose links are all closed, the
      // parts cleared too few links to pay for their look-ups, +3.8% instructions on box_panda's states.)
      if (!grid || n < 2 || options_.mode != GeometryMode::Mesh || geometry_->link(i)->solidCount() > 0) return false;
      const EnclosingBalls::Placed bound = balls.placed(i, 0);
      const double slack = slackOf(link_padding_[i], bound.center, bound.radius);
      for (int k = 1; k < n; ++k) {
        const EnclosingBalls::Placed part = balls.placed(i, k);
        if (!(grid->lowerBound(part.center) > part.radius + slack)) return false;
      }
      ++ctx.counters.environment.grid_clears;
      return true;
    };
    // Link k of env_links_ tested exactly (its balls did not clear it): true when it meets an obstacle.
    const auto hitsExactly = [&](int k) {
      const int i = env_links_[k];
      EnvironmentHit hit;
      if (!environment_->linkIntersects(*geometry_->link(i), poses[i], options_.tolerances,
                                        {link_padding_[i], options_.mode},
                                        {time, nullptr, &hit, &ctx.counters.environment}))
        return false;
      r.kind = CollisionReport::Kind::Environment;
      r.link = i;
      r.hit = hit;
      ctx.env_last_hit = k;
      return true;
    };
    const auto hits = [&](int k) {
      const int i = env_links_[k];
      if (balls_placed && balls.ballCount(i) > 0 && (boundCleared(i, balls.placed(i, 0)) || partsCleared(i)))
        return false;
      return hitsExactly(k);
    };
    // A rigid body of several links: its one ball (which holds every member's bounding ball) cleared by the
    // boxes or the grid clears them all.
    const auto bodyCleared = [&](const EnvBody& body) {
      if (body.count < 2 || !(grid || boxes) || !std::isfinite(body.radius)) return false;
      const Pose& anchor = poses[body.anchor];
      const Vec3 center = anchor * body.center;
      const double radius = margins::roundedUp(body.radius, body.center.norm() + body.radius + anchor.t.norm());
      const double slack = slackOf(body.padding, center, radius);
      if (boxes && boxes->ballClear(center, radius, slack)) {
        ctx.counters.environment.box_clears += body.count;
        return true;
      }
      if (grid && grid->lowerBound(center) > radius + slack) {
        ctx.counters.environment.grid_clears += body.count;
        return true;
      }
      return false;
    };
    // The link that met an obstacle last goes first: a planner's next state is near its last, and the links
    // before it in order would each be tested for nothing. Each link is still tested once at most.
    // Its own bounding ball, placed alone, is asked of the boxes and the grid first, as every link's is: the
    // lead stays the lead through the free states that follow a collision, and each would otherwise pay its
    // exact test (box_panda's random free states: the lead's half of all their exact tests).
    const int n = static_cast<int>(env_links_.size());
    const int lead = ctx.env_last_hit >= 0 && ctx.env_last_hit < n ? ctx.env_last_hit : -1;
    grid = env.hasMovingObstacles() ? nullptr : env.clearanceGrid();
    boxes = env.obstacleBoxes();
    if (lead >= 0) {  // (before the balls are placed: it probably still collides)
      const int i = env_links_[lead];
      if (!((grid || boxes) && boundCleared(i, EnclosingBalls::boundOf(*geometry_->link(i), poses[i]))) &&
          hitsExactly(lead))
        return false;
    }
    if ((grid || boxes) && !(balls_placed = ctx.balls.madeFor(*geometry_))) grid = nullptr, boxes = nullptr;
    if (balls_placed) ctx.balls.place(poses);
    for (const EnvBody& body : env_bodies_) {
      if (bodyCleared(body)) continue;
      for (int m = body.first; m < body.first + body.count; ++m)
        if (env_order_[m] != lead && hits(env_order_[m])) return false;
    }
  }
  return true;
}

bool Scene::selfFree(const Pose* poses, const double* q, SceneScratch& ctx, CollisionReport& r,
                     bool balls_placed) const noexcept {
  const Effects& fx = description_.effects;
  if (fx.self) {
    const long long before = ctx.self.pairTests();
    const LinkPair* hit = self_.firstCollision(poses, ctx.self, q, balls_placed ? &ctx.balls : nullptr);
    ctx.counters.self_pair_tests += ctx.self.pairTests() - before;
    if (hit) {
      r.kind = CollisionReport::Kind::Self;
      r.link = hit->a;
      r.other_link = hit->b;
      return false;
    }
  }
  return true;
}

bool Scene::lanesFit(const SceneScratch& ctx) const noexcept {
  const RobotModel& model = robot();
  return ctx.lanes && ctx.lanes->madeFor(model) && ctx.poses.size() == static_cast<std::size_t>(model.linkCount()) &&
         ctx.q.size() == base_q_.size();
}

void Scene::toLane(const double* state, int lane, SceneScratch& ctx, const double** lane_q,
                   Pose** lane_poses) const noexcept {
  const RobotModel& model = robot();
  double* q = ctx.lane_q.data() + static_cast<std::ptrdiff_t>(lane) * model.variableCount();
  for (std::size_t i = 0; i < group_variables_.size(); ++i) q[group_variables_[i]] = state[i];
  lane_q[lane] = q;
  lane_poses[lane] = ctx.lane_poses.data() + static_cast<std::ptrdiff_t>(lane) * model.linkCount();
}

int Scene::anyCollides(const double* states, int count, SceneContext& context, CollisionReport* report,
                       const double* times) const noexcept {
  SceneScratch& ctx = scratchOf(context.scratch_);
  CollisionReport local;
  CollisionReport& r = report ? *report : local;
  r = CollisionReport{};
  const int dim = dimension();
  // One state at a time and in full: the probe gives the likeliest first, and on the shared problems its first
  // state collides with itself as often as with obstacles (the UR5's three times as often), so checking every
  // state's obstacles before any state's self pairs, with their kinematics in lanes, cost 4 to 9% more
  // instructions per segment of RRTConnect's range (the VAMP bench's 2,000 of box_panda and box_ur5).
  for (int s = 0; s < count; ++s)
    if (!checkState(states + static_cast<std::ptrdiff_t>(s) * dim, ctx, &r, times ? times[s] : 0.0)) return s;
  return -1;
}

void Scene::areFree(const double* states, int count, SceneContext& context, bool* free, double t) const noexcept {
  SceneScratch& ctx = scratchOf(context.scratch_);
  const int dim = dimension();
  // A context made for another robot (or before lanes existed) takes the states one at a time.
  if (!lanesFit(ctx)) {
    for (int s = 0; s < count; ++s)
      free[s] = checkState(states + static_cast<std::ptrdiff_t>(s) * dim, ctx, nullptr, t);
    return;
  }
  adopt(ctx);  // (lanesFit: it fits)
  const Effects& fx = description_.effects;
  const int width = std::min(KinematicLanes::width(), KinematicLanes::kMaxLanes);
  const double* lane_q[KinematicLanes::kMaxLanes];
  Pose* lane_poses[KinematicLanes::kMaxLanes];
  int pending[KinematicLanes::kMaxLanes];  // the states in the lanes
  int n = 0;
  const auto flush = [&] {
    ctx.lanes->compute(lane_q, n, lane_poses);
    for (int l = 0; l < n; ++l) {
      CollisionReport r;
      free[pending[l]] = posedFree(lane_poses[l], lane_q[l], ctx, r, t);
    }
    n = 0;
  };
  for (int s = 0; s < count; ++s) {
    const double* state = states + static_cast<std::ptrdiff_t>(s) * dim;
    ++ctx.counters.states;
    if (!withinBounds(state) || !withinTime(t)) {
      ++ctx.counters.invalid_states;
      free[s] = false;
      continue;
    }
    if (static_collision_.kind != CollisionReport::Kind::None || (!fx.self && !fx.environment)) {
      free[s] = static_collision_.kind == CollisionReport::Kind::None;
      continue;
    }
    toLane(state, n, ctx, lane_q, lane_poses);
    // The pair tables first, as checkState asks them: a state they prove colliding takes no lane.
    if (fx.self && self_.hasTables() && self_.tabledCollision(lane_q[n], ctx.self)) {
      free[s] = false;
      continue;
    }
    pending[n++] = s;
    if (n == width) flush();
  }
  if (n > 0) flush();
}

bool Scene::isFree(const std::vector<double>& state, CollisionReport* report, double t) const {
  if (static_cast<int>(state.size()) != dimension()) {
    if (report) {
      *report = CollisionReport{};
      report->kind = CollisionReport::Kind::Invalid;
    }
    return false;
  }
  return isFree(state.data(), threadContext(), report, t);
}

SceneContext& Scene::threadContext() const {
  // Keyed by serial, not address: a new scene at a freed scene's address must not inherit its caches.
  return thread_context_.get([this] { return makeContext(); });
}

double Scene::clearance(const double* state, SceneContext& context, double* lower_bound, double t) const noexcept {
  SceneScratch& ctx = scratchOf(context.scratch_);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Effects& fx = description_.effects;
  if (!fx.clearance) return nan;
  if (!withinBounds(state) || !withinTime(t) || !adopt(ctx)) return nan;
  ++ctx.counters.clearance_queries;
  place(state, ctx);
  // Distances first; EPA only when something touches (then the value is minus the deepest penetration).
  const bool env = fx.environment && !environment_->empty();
  double best = env ? static_clearance_ : std::numeric_limits<double>::infinity();
  double lower = env ? static_clearance_lower_ : best;
  const double time = fx.moving ? t : 0.0;
  if (env && best > 0.0) {
    for (int i : env_links_) {
      const DistanceResult d =
          environment_->linkDistance(*geometry_->link(i), ctx.poses[i], options_.tolerances, {best + link_padding_[i]},
                                     {time, nullptr, nullptr, &ctx.counters.environment});
      if (isFailure(d.status)) return nan;
      best = std::min(best, std::max(0.0, d.distance - link_padding_[i]));
      lower = std::min(lower, std::max(0.0, d.lower_bound - link_padding_[i]));
      if (best == 0.0) break;
    }
  }
  if (fx.self && best > 0.0) {
    const DistanceResult d = self_.minimumDistance(ctx.poses.data());
    if (isFailure(d.status)) return nan;
    best = std::min(best, d.distance);
    lower = std::min(lower, d.lower_bound);
  }
  if (best == 0.0) {
    double deepest = 0.0;
    if (env)
      for (int i : geometry_->geometricLinks()) {
        const double p =
            environment_->linkPenetration(*geometry_->link(i), ctx.poses[i], options_.tolerances, link_padding_[i],
                                          {time, nullptr, nullptr, &ctx.counters.environment});
        if (std::isnan(p)) return nan;
        deepest = std::max(deepest, p);
      }
    if (fx.self) {
      const double p = self_.penetration(ctx.poses.data(), ctx.self);
      if (std::isnan(p)) return nan;
      deepest = std::max(deepest, p);
    }
    best = lower = -deepest;
  }
  if (lower_bound) *lower_bound = lower;
  return best;
}

std::string Scene::describe(const CollisionReport& r) const {
  const RobotModel& model = robot();
  switch (r.kind) {
    case CollisionReport::Kind::None: return "free";
    case CollisionReport::Kind::Invalid: return "invalid state";
    case CollisionReport::Kind::Self: return model.link(r.link).name + " " + model.link(r.other_link).name;
    case CollisionReport::Kind::Environment:
      if (r.hit.kind == EnvironmentHit::Kind::Obstacle)
        return model.link(r.link).name + " " + (r.hit.obstacle ? r.hit.obstacle->name : std::string("?"));
      if (r.hit.kind == EnvironmentHit::Kind::Voxel) return model.link(r.link).name + " octomap";
      return model.link(r.link).name + " environment";
  }
  return "?";
}

}  // namespace clearway
