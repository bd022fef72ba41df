#include <clearway/motion/motion.h>

#include <clearway/narrowphase/gjk.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace clearway {

// ---- MotionBound --------------------------------------------------------------------------------------

MotionBound::MotionBound(const Scene& scene) : dim_(scene.dimension()), links_(scene.robot().linkCount()) {
  const RobotModel& model = scene.robot();
  // Which state entry drives each joint (through a mimic too), and by how much.
  std::vector<int> var_to_state(model.variableCount(), -1);
  for (int i = 0; i < dim_; ++i) var_to_state[scene.groupVariables()[i]] = i;
  joint_var_.assign(model.jointCount(), -1);
  joint_mult_.assign(model.jointCount(), 1.0);
  prismatic_.assign(model.jointCount(), 0);
  for (int j = 0; j < model.jointCount(); ++j) {
    const Joint& joint = model.joint(j);
    const Joint& owner = joint.isMimic() ? model.joint(joint.mimic.joint) : joint;
    if (owner.first_variable < 0) continue;
    const int v = var_to_state[owner.first_variable];
    if (v < 0) continue;
    if (joint.type == JointType::Planar || joint.type == JointType::Floating)
      throw std::invalid_argument("MotionBound: joint '" + joint.name + "' is " + jointTypeName(joint.type) +
                                  ": continuous checks support revolute, continuous and prismatic joints");
    joint_var_[j] = v;
    prismatic_[j] = joint.type == JointType::Prismatic;
    if (joint.isMimic()) joint_mult_[j] = std::abs(joint.mimic.multiplier);
  }
  // The chain of each link, and each chain joint's reach to the link: the joint offsets in between
  // (lengths do not change under rotation; a prismatic joint in between adds its largest travel) plus
  // the link's radius about its own origin.
  chain_.resize(links_);
  joint_reach_.resize(links_);
  link_coef_.assign(static_cast<std::size_t>(links_) * dim_, 0.0);
  for (int i = 0; i < links_; ++i) {
    for (int l = i; model.link(l).parent_joint >= 0; l = model.parentLink(l)) chain_[i].push_back(model.link(l).parent_joint);
    std::reverse(chain_[i].begin(), chain_[i].end());
    const LinkGeometry* g = scene.geometry().link(i);
    double reach = g ? g->boundingRadius() : 0.0;
    joint_reach_[i].assign(chain_[i].size(), 0.0);
    // From the link upwards: the reach of joint k is measured from its own origin, which is where the
    // joint's motion acts; the offsets of the joints after it (their origins) stand between.
    for (int k = static_cast<int>(chain_[i].size()) - 1; k >= 0; --k) {
      const Joint& joint = model.joint(chain_[i][k]);
      joint_reach_[i][k] = reach;
      reach += joint.origin.t.norm();
      if (joint.type == JointType::Prismatic)
        reach += std::max(std::abs(joint.lower), std::abs(joint.upper));  // may be infinite: then so is the bound
      if (joint.type == JointType::Planar || joint.type == JointType::Floating)
        reach = std::numeric_limits<double>::infinity();
    }
    for (std::size_t k = 0; k < chain_[i].size(); ++k) {
      const int j = chain_[i][k];
      if (joint_var_[j] < 0) continue;
      const double w = prismatic_[j] ? 1.0 : joint_reach_[i][k];
      link_coef_[static_cast<std::size_t>(i) * dim_ + joint_var_[j]] += joint_mult_[j] * w;
    }
  }
}

double MotionBound::link(int link, const double* dq) const noexcept {
  double b = 0.0;
  const double* c = &link_coef_[static_cast<std::size_t>(link) * dim_];
  for (int v = 0; v < dim_; ++v) b += c[v] * std::abs(dq[v]);
  return b;
}

double MotionBound::pair(int a, int b, const double* dq) const noexcept {
  // Joints shared by both chains move the pair rigidly: measured in the frame of the last shared
  // joint's child, only the joints after the fork move either link.
  const std::vector<int>& ca = chain_[a];
  const std::vector<int>& cb = chain_[b];
  std::size_t fork = 0;
  while (fork < ca.size() && fork < cb.size() && ca[fork] == cb[fork]) ++fork;
  double bound = 0.0;
  for (int side = 0; side < 2; ++side) {
    const int l = side == 0 ? a : b;
    const std::vector<int>& c = chain_[l];
    for (std::size_t k = fork; k < c.size(); ++k) {
      const int j = c[k];
      if (joint_var_[j] < 0) continue;
      const double w = prismatic_[j] ? 1.0 : joint_reach_[l][k];
      bound += joint_mult_[j] * w * std::abs(dq[joint_var_[j]]);
    }
  }
  return bound;
}

}  // namespace clearway

namespace clearway {

// ---- MotionChecker ------------------------------------------------------------------------------------


MotionChecker::MotionChecker(std::shared_ptr<const Scene> scene, MotionOptions options)
    : scene_(std::move(scene)), options_(options), bound_(*scene_) {
  if (!(options_.contact_distance > 0.0) || !std::isfinite(options_.contact_distance))
    throw std::invalid_argument("MotionChecker: contact_distance must be finite and > 0");
  if (!(options_.resolution > 0.0) || !std::isfinite(options_.resolution))
    throw std::invalid_argument("MotionChecker: resolution must be finite and > 0");
  if (!(options_.distance_relative_error >= 0.0) || !std::isfinite(options_.distance_relative_error))
    throw std::invalid_argument("MotionChecker: distance_relative_error must be finite and >= 0");
  if (options_.max_queries < 1) throw std::invalid_argument("MotionChecker: max_queries must be >= 1");
  // A segment has no time axis yet: moving obstacles would be checked where they are at t = 0 only.
  if (scene_->effects().moving && scene_->environment().hasMovingObstacles())
    throw std::invalid_argument("MotionChecker: scene '" + scene_->name() +
                                "' has moving obstacles; segment checks against moving obstacles are not supported");
  const SelfCollision& self = scene_->selfCollision();
  if (scene_->effects().self)
    for (int k = 0; k < static_cast<int>(self.pairs().size()); ++k) {
      self_items_.push_back(self.pairs()[k]);
      self_padding_.push_back(self.pairPadding(k));
    }
}

MotionContext MotionChecker::makeContext() const {
  MotionContext c;
  c.scene = scene_->makeContext();
  c.q.resize(scene_->dimension());
  c.dq.resize(scene_->dimension());
  const std::size_t items = self_items_.size() + scene_->environmentLinks().size();
  c.safe_until.resize(items);
  c.bound.resize(items);
  return c;
}

void MotionChecker::interpolate(const double* q0, const double* q1, double s, double* out) const noexcept {
  for (int i = 0; i < scene_->dimension(); ++i) out[i] = q0[i] + s * (q1[i] - q0[i]);
}

MotionResult MotionChecker::check(const double* q0, const double* q1, MotionContext& ctx) const noexcept {
  return options_.mode == MotionMode::Certified ? certified(q0, q1, ctx) : sampled(q0, q1, ctx);
}

MotionResult MotionChecker::sampled(const double* q0, const double* q1, MotionContext& ctx) const noexcept {
  MotionResult r;
  const Scene& sc = *scene_;
  double len2 = 0.0;
  for (int i = 0; i < sc.dimension(); ++i) len2 += (q1[i] - q0[i]) * (q1[i] - q0[i]);
  // As OMPL's DiscreteMotionValidator: the ends, then the states in between at the resolution.
  const double len = std::sqrt(len2);
  const int n = std::isfinite(len) ? std::max(1, static_cast<int>(std::ceil(len / options_.resolution))) : 1;
  r.steps = 1;
  if (!sc.isFree(q0, ctx.scene, &r.report)) return r;
  // The end first (each state is checked once); if it collides, the states in between say whether the
  // segment collides earlier.
  ++r.steps;
  CollisionReport end;
  const bool end_free = sc.isFree(q1, ctx.scene, &end);
  double last = 0.0;
  for (int k = 1; k < n; ++k) {
    const double s = static_cast<double>(k) / n;
    interpolate(q0, q1, s, ctx.q.data());
    ++r.steps;
    if (!sc.isFree(ctx.q.data(), ctx.scene, &r.report)) {
      r.first_contact = s;
      r.last_valid = last;
      return r;
    }
    last = s;
  }
  r.report = end_free ? CollisionReport{} : end;
  if (end_free) {
    r.free = true;
  } else {
    r.first_contact = 1.0;
    r.last_valid = last;
  }
  return r;
}

MotionResult MotionChecker::certified(const double* q0, const double* q1, MotionContext& ctx) const noexcept {
  MotionResult r;
  const Scene& sc = *scene_;
  const Tolerances& tol = sc.options().tolerances;
  const double contact = options_.contact_distance;
  const bool hull_mode = sc.options().mode == GeometryMode::Hull;
  r.steps = 1;
  if (!sc.isFree(q0, ctx.scene, &r.report)) return r;  // first_contact = last_valid = 0
  for (int i = 0; i < sc.dimension(); ++i) ctx.dq[i] = q1[i] - q0[i];
  for (int i = 0; i < sc.dimension(); ++i)
    if (!std::isfinite(ctx.dq[i])) {
      r.report.kind = CollisionReport::Kind::Invalid;
      return r;
    }
  // The segment stays within bounds when both ends do (boxes are convex): an invalid end is reported
  // after the advancement has looked for an earlier contact.
  const bool end_invalid = !sc.validState(q1);

  const std::vector<int>& env_links = sc.environmentLinks();
  const bool check_env = sc.effects().environment && !sc.environment().empty();
  const int n_self = static_cast<int>(self_items_.size());
  const int n_items = n_self + (check_env ? static_cast<int>(env_links.size()) : 0);
  for (int k = 0; k < n_items; ++k) {
    ctx.bound[k] = k < n_self ? bound_.pair(self_items_[k].a, self_items_[k].b, ctx.dq.data())
                              : bound_.link(env_links[k - n_self], ctx.dq.data());
    ctx.safe_until[k] = ctx.bound[k] > 0.0 ? 0.0 : 2.0;  // a pair that does not move stays as q0 had it
  }

  const RobotGeometry& geometry = sc.geometry();
  double s = 0.0, last_certified = 0.0;
  while (true) {
    sc.computePoses([&] {
      interpolate(q0, q1, s, ctx.q.data());
      return ctx.q.data();
    }(), ctx.scene);
    const Pose* poses = ctx.scene.poses.data();
    double next = 2.0;
    for (int k = 0; k < n_items; ++k) {
      if (ctx.safe_until[k] <= s) {
        // How far this item can still move on the rest of the segment: nothing farther matters.
        const double remaining = ctx.bound[k] * (1.0 - s);
        double d;  // a certified lower bound on the clearance (padding removed)
        ++r.distance_queries;
        if (k < n_self) {
          const LinkPair& p = self_items_[k];
          const LinkGeometry& a = *geometry.link(p.a);
          const LinkGeometry& b = *geometry.link(p.b);
          // The hulls contain the links: their distance bounds the links' from below, in one GJK call.
          const DistanceResult h = gjkDistance(a.hull(), poses[p.a], b.hull(), poses[p.b], tol);
          d = isFailure(h.status) ? 0.0 : h.lower_bound - self_padding_[k];
          if (d <= contact && !hull_mode && !isFailure(h.status)) {
            const DistanceResult m = meshDistance(a, poses[p.a], b, poses[p.b], tol, options_.distance_relative_error);
            d = isFailure(m.status) ? 0.0 : m.lower_bound - self_padding_[k];
          }
          if (d <= contact) {
            r.report.kind = CollisionReport::Kind::Self;
            r.report.link = p.a;
            r.report.other_link = p.b;
          }
        } else {
          const int link = env_links[k - n_self];
          const double pad = sc.linkPadding(link);
          const double cutoff = remaining + pad + contact;
          // As for pairs: the hull's distance first, the exact geometry only when the hull comes close.
          const DistanceResult h = sc.environment().linkDistance(*geometry.link(link), poses[link], tol, cutoff, 0.0, 0.0,
                                                                 &ctx.scene.counters.environment, GeometryMode::Hull);
          d = isFailure(h.status) ? 0.0 : h.lower_bound - pad;
          if (d <= contact && !hull_mode && !isFailure(h.status)) {
            const DistanceResult e = sc.environment().linkDistance(*geometry.link(link), poses[link], tol, cutoff, 0.0,
                                                                   options_.distance_relative_error,
                                                                   &ctx.scene.counters.environment);
            d = isFailure(e.status) ? 0.0 : e.lower_bound - pad;
          }
          if (d <= contact) {
            r.report.kind = CollisionReport::Kind::Environment;
            r.report.link = link;
            // Which obstacle or voxel (for the report only): one within the contact distance, widened by
            // the relative error the distance's lower bound was allowed.
            sc.environment().linkIntersects(*geometry.link(link), poses[link], tol, sc.options().mode,
                                            pad + (contact + 1e-9) * (1.0 + options_.distance_relative_error),
                                            0.0, &r.report.hit);
          }
        }
        if (d <= contact) {
          r.first_contact = s;
          // The state at s is within contact_distance of touching: if it is still free, it is the last
          // valid one; otherwise the last parameter every item had certified.
          r.last_valid = sc.isFree(ctx.q.data(), ctx.scene) ? s : last_certified;
          r.free = false;
          return r;
        }
        ctx.safe_until[k] = s + d / ctx.bound[k];
      }
      next = std::min(next, ctx.safe_until[k]);
    }
    last_certified = s;
    ++r.steps;
    if (next >= 1.0) break;
    if (r.distance_queries >= options_.max_queries) {
      r.capped = true;
      r.first_contact = r.last_valid = s;
      r.report = CollisionReport{};
      r.report.kind = CollisionReport::Kind::Invalid;
      return r;
    }
    s = next;
  }
  if (end_invalid) {
    r.first_contact = 1.0;
    r.last_valid = last_certified;
    r.report = CollisionReport{};
    r.report.kind = CollisionReport::Kind::Invalid;
    return r;
  }
  r.free = true;
  r.report = CollisionReport{};
  return r;
}

}  // namespace clearway
