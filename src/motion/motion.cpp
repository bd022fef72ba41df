#include <clearway/motion/motion.h>

#include <clearway/kinematics/forward_kinematics.h>
#include <clearway/narrowphase/gjk.h>
#include <clearway/narrowphase/ray_cast.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace clearway {

namespace {

// Environment items keep a GJK warm start per static obstacle up to this many obstacles (2.5 KiB a link).
constexpr std::size_t kWarmObstacles = 64;

// A state inside the scene's bounds (their midpoints) with unit quaternions, where the poses are defined.
std::vector<double> referenceState(const Scene& scene) {
  const RobotModel& model = scene.robot();
  std::vector<double> q(scene.dimension());
  for (int i = 0; i < scene.dimension(); ++i) {
    const double lo = scene.lower(i), hi = scene.upper(i);
    q[i] = std::isfinite(lo) && std::isfinite(hi) ? 0.5 * (lo + hi) : std::isfinite(lo) ? lo : std::isfinite(hi) ? hi : 0.0;
    const int v = scene.groupVariables()[i];
    const Joint& joint = model.joint(model.variables()[v].joint);
    if (joint.type == JointType::Floating && v >= joint.first_variable + 3) q[i] = v == joint.first_variable + 6 ? 1.0 : 0.0;
  }
  return q;
}

// Per link: the link nearest the root that it moves rigidly with (joined by joints the group does not move).
std::vector<int> rigidAnchors(const Scene& scene) {
  const RobotModel& model = scene.robot();
  std::vector<char> in_group(model.variableCount(), 0);
  for (const int v : scene.groupVariables()) in_group[v] = 1;
  const auto still = [&](const Joint& joint) {
    const Joint& owner = joint.isMimic() ? model.joint(joint.mimic.joint) : joint;
    for (int k = 0; owner.first_variable >= 0 && k < jointVariableCount(owner.type); ++k)
      if (in_group[owner.first_variable + k]) return false;
    return true;
  };
  std::vector<int> anchor(model.linkCount());
  for (int l = 0; l < model.linkCount(); ++l) {
    int a = l;
    while (model.link(a).parent_joint >= 0 && still(model.joint(model.link(a).parent_joint))) a = model.parentLink(a);
    anchor[l] = a;
  }
  return anchor;
}

}  // namespace

// ---- MotionBound --------------------------------------------------------------------------------------

MotionBound::MotionBound(const Scene& scene, const std::vector<Body>& bodies)
    : dim_(scene.dimension()), links_(scene.robot().linkCount() + static_cast<int>(bodies.size())) {
  const RobotModel& model = scene.robot();
  const int model_links = model.linkCount();
  // A body is one more link: its merged geometry in the frame of its anchor link.
  frame_.resize(links_);
  for (int i = 0; i < links_; ++i) frame_[i] = i < model_links ? i : bodies[i - model_links].anchor;
  // Each link's (or body's) points: their hull, and a ball containing them.
  std::vector<Body> shape(links_);
  for (int i = 0; i < links_; ++i) {
    if (i >= model_links) {
      shape[i] = bodies[i - model_links];
    } else if (const LinkGeometry* g = scene.geometry().link(i)) {
      shape[i] = Body{i, &g->hull(), g->sphereCenter(), g->sphereRadius()};
    }
  }
  // The farthest hull vertex from the frame's origin.
  radius_.assign(links_, 0.0);
  for (int i = 0; i < links_; ++i)
    if (shape[i].hull)
      for (const Vec3& v : shape[i].hull->vertices()) radius_[i] = std::max(radius_[i], v.norm());
  // Which state entry drives each joint variable (through a mimic too).
  std::vector<int> var_to_state(model.variableCount(), -1);
  for (int i = 0; i < dim_; ++i) var_to_state[scene.groupVariables()[i]] = i;
  // The farthest a slide driven by state entry v (or, without one, a variable held still) goes.
  const auto travel = [&](int v, const JointVariable& var) {
    const double lo = v >= 0 ? scene.lower(v) : var.lower, hi = v >= 0 ? scene.upper(v) : var.upper;
    return std::max(std::abs(lo), std::abs(hi));
  };
  // Elements: one per joint of one variable; a planar joint is two slides and a turn about its axis; a
  // floating joint is three slides and a spin about its origin, one element per quaternion entry (the
  // angle turned is at most kSpin times the quaternions' distance).
  const int joints = model.jointCount();
  std::vector<std::vector<int>> elements_of(joints);
  for (int j = 0; j < joints; ++j) {
    const Joint& joint = model.joint(j);
    const Joint& owner = joint.isMimic() ? model.joint(joint.mimic.joint) : joint;
    const auto add = [&](int k, Kind kind, double step) {
      const int var = owner.first_variable >= 0 ? owner.first_variable + k : -1;
      const int v = var >= 0 ? var_to_state[var] : -1;
      elements_of[j].push_back(static_cast<int>(joint_var_.size()));
      joint_of_.push_back(j);
      joint_var_.push_back(v);
      kind_.push_back(static_cast<char>(kind));
      joint_mult_.push_back(kind == Kind::Spin ? kSpin : joint.isMimic() ? std::abs(joint.mimic.multiplier) : 1.0);
      step_.push_back(step);
      axis_.push_back(joint.axis.normalized());
      child_.push_back(joint.child_link);
    };
    const double origin = joint.origin.t.norm();
    const std::vector<JointVariable>& vars = model.variables();
    const auto slide = [&](int k) {
      const int var = owner.first_variable >= 0 ? owner.first_variable + k : -1;
      return var >= 0 ? travel(var_to_state[var], vars[var]) : 0.0;
    };
    switch (joint.type) {
      case JointType::Fixed: add(-1, Kind::Revolute, origin); break;  // (no variable: never moves)
      case JointType::Revolute:
      case JointType::Continuous: add(0, Kind::Revolute, origin); break;
      case JointType::Prismatic:
        add(0, Kind::Prismatic,
            origin + (joint.isMimic() ? std::abs(joint.mimic.multiplier) * slide(0) + std::abs(joint.mimic.offset) : slide(0)));
        break;
      case JointType::Planar:
        add(0, Kind::Prismatic, origin + slide(0));
        add(1, Kind::Prismatic, slide(1));
        add(2, Kind::Revolute, 0.0);
        break;
      case JointType::Floating:
        for (int k = 0; k < 3; ++k) add(k, Kind::Prismatic, (k ? 0.0 : origin) + slide(k));
        for (int k = 3; k < 7; ++k) add(k, Kind::Spin, 0.0);
        break;
    }
  }
  const int elements = static_cast<int>(joint_var_.size());
  // A revolute joint's axis is fixed in the links rigidly attached to either side of it (through joints
  // the group does not move): their distances from it are exact, so a link turning about a nearby axis
  // (a base about its own turntable, a gripper about the wrist) barely counts. The rigid transforms
  // come from the poses at one reference state, which also give a still joint's exact offset.
  exact_.assign(static_cast<std::size_t>(links_) * elements, std::numeric_limits<double>::infinity());
  // The farthest hull vertex of a link from a line (point o, unit direction u) in the link's frame.
  const auto axisReach = [&](int link, const Vec3& o, const Vec3& u) {
    const ConvexHull* hull = shape[link].hull;
    double r = 0.0;
    if (hull)
      for (const Vec3& v : hull->vertices()) {
        const Vec3 w = v - o;
        r = std::max(r, (w - w.dot(u) * u).norm());
      }
    return r * (1.0 + 1e-12) + 1e-12 * (hull ? radius_[link] + o.norm() : 0.0);  // rounding
  };
  {
    SceneContext ctx = scene.makeContext();
    scene.computePoses(referenceState(scene).data(), ctx);
    // Links joined through joints without a state entry form rigid bodies.
    const auto still = [&](int j) {
      for (const int e : elements_of[j])
        if (joint_var_[e] >= 0) return false;
      return true;
    };
    const std::vector<int> anchor = rigidAnchors(scene);  // (the same rigid bodies MotionChecker merges)
    for (int j = 0; j < joints; ++j) {
      const Joint& joint = model.joint(j);
      if (!still(j) || joint.parent_link < 0 || joint.child_link < 0) continue;
      // Held where the reference state has it (a held planar or floating joint has no limits to bound it).
      const double offset = relativePose(ctx.poses[joint.parent_link], ctx.poses[joint.child_link]).t.norm();
      for (const int e : elements_of[j]) step_[e] = e == elements_of[j].front() ? offset * (1.0 + 1e-12) : 0.0;
    }
    for (int e = 0; e < elements; ++e) {
      const Joint& joint = model.joint(joint_of_[e]);
      if (joint_var_[e] < 0 || kind_[e] != static_cast<char>(Kind::Revolute) || joint.child_link < 0 || joint.parent_link < 0)
        continue;
      const Pose& child = ctx.poses[joint.child_link];  // the joint frame, turned by q about the axis
      const Vec3 point = child.t, dir = child.R * axis_[e];
      for (int l = 0; l < links_; ++l) {
        const int root = anchor[frame_[l]];
        if (root != anchor[joint.child_link] && root != anchor[joint.parent_link]) continue;
        const Pose& pose = ctx.poses[frame_[l]];
        exact_[static_cast<std::size_t>(l) * elements + e] =
            axisReach(l, pose.R.transpose() * (point - pose.t), pose.R.transpose() * dir);
      }
    }
  }
  chain_.resize(links_);
  prefix_.resize(links_);
  joint_reach_.resize(links_);
  sphere_center_.assign(links_, Vec3::Zero());
  sphere_radius_.assign(links_, 0.0);
  link_coef_.assign(static_cast<std::size_t>(links_) * dim_, 0.0);
  for (int i = 0; i < links_; ++i) {
    for (int l = frame_[i]; model.link(l).parent_joint >= 0; l = model.parentLink(l)) {
      const std::vector<int>& e = elements_of[model.link(l).parent_joint];
      chain_[i].insert(chain_[i].end(), e.rbegin(), e.rend());
    }
    std::reverse(chain_[i].begin(), chain_[i].end());
    sphere_center_[i] = shape[i].center, sphere_radius_[i] = shape[i].radius;
    const std::size_t n = chain_[i].size();
    prefix_[i].assign(n, 0.0);
    for (std::size_t k = 0; k < n; ++k) prefix_[i][k] = (k ? prefix_[i][k - 1] : 0.0) + step_[chain_[i][k]];
    // A chain joint's reach to the link: the offsets of the joints after it, plus the link's radius (the
    // lengths do not change under rotation); the link's own joint knows it exactly.
    joint_reach_[i].assign(n, 0.0);
    for (std::size_t k = 0; k < n; ++k) {
      joint_reach_[i][k] = radius_[i] + (prefix_[i][n - 1] - prefix_[i][k]);
      joint_reach_[i][k] = std::min(joint_reach_[i][k], exactReach(i, chain_[i][k]));
    }
    for (std::size_t k = 0; k < n; ++k) {
      const int j = chain_[i][k];
      if (joint_var_[j] < 0) continue;
      const double w = isSlide(j) ? 1.0 : joint_reach_[i][k];
      link_coef_[static_cast<std::size_t>(i) * dim_ + joint_var_[j]] += joint_mult_[j] * w;
    }
  }
}

bool MotionBound::translates(int a, int b, const double* dq) const noexcept {
  // Joints above the fork move both links alike; only the path between them matters.
  std::size_t fork = 0;
  while (fork < chain_[a].size() && fork < chain_[b].size() && chain_[a][fork] == chain_[b][fork]) ++fork;
  for (const int l : {a, b})
    for (std::size_t k = fork; k < chain_[l].size(); ++k) {
      const int j = chain_[l][k], v = joint_var_[j];
      if (v >= 0 && dq[v] != 0.0 && !isSlide(j)) return false;
    }
  return true;
}

bool MotionBound::translates(int link, const double* dq) const noexcept {
  for (const int j : chain_[link])
    if (joint_var_[j] >= 0 && dq[joint_var_[j]] != 0.0 && !isSlide(j)) return false;
  return true;
}

double MotionBound::link(int link, const double* dq) const noexcept {
  double b = 0.0;
  const double* c = &link_coef_[static_cast<std::size_t>(link) * dim_];
  for (int v = 0; v < dim_; ++v)
    if (dq[v] != 0.0) b += c[v] * std::abs(dq[v]);
  return b;
}

// A bound on how far points of links move for a step h·dq, measured from where the joint axes are now:
// joint k turns a link by h·w_k about its axis; the link's points are within r_k (now, from its bounding
// ball) of the axis, plus how far the joints after k can move them relative to it, h·γ_k, and never
// beyond the static reach R_k. So they move at most f(h) = h·Σ w_k·min(R_k, r_k + h·γ_k): convex and
// piecewise quadratic, a piece starting where a joint's dynamic reach meets its static one.
struct MotionBound::DynamicBound {
  static constexpr int kMax = 64;
  double a = 0.0, c = 0.0;   // f(h) = h·(a + c·h) on the first piece
  double fixed = 0.0;        // Σ w·R: the static bound for h = 1
  double cap[kMax], gain[kMax], excess[kMax];  // per piece start: where, w·γ and w·(R − r) there
  int n = 0;

  // h ↦ the largest step with f(h) ≤ d, never below the static d / fixed.
  double solve(double d) {
    for (int i = 1; i < n; ++i)
      for (int k = i; k > 0 && cap[k] < cap[k - 1]; --k) {
        std::swap(cap[k], cap[k - 1]);
        std::swap(gain[k], gain[k - 1]);
        std::swap(excess[k], excess[k - 1]);
      }
    double h = INFINITY;
    for (int i = 0; i <= n; ++i) {
      const double end = i < n ? cap[i] : INFINITY;
      const double root = c > 0.0 ? 2.0 * d / (a + std::sqrt(a * a + 4.0 * c * d)) : a > 0.0 ? d / a : INFINITY;
      if (root <= end) {
        h = root;
        break;
      }
      // Past its cap, joint i moves the link by its static reach: c·h gives way to w·(R − r).
      a += excess[i];
      c = std::max(0.0, c - gain[i]);
    }
    h = std::max(fixed > 0.0 ? d / fixed : INFINITY, h);
    return std::isnan(h) ? 0.0 : h;
  }
};

void MotionBound::addDynamic(int link, std::size_t from, const double* dq, const Pose* poses, DynamicBound& f) const noexcept {
  const std::vector<int>& chain = chain_[link];
  const Vec3 center = poses[frame_[link]] * sphere_center_[link];
  double after = 0.0;  // Σ w·R over the joints below k: γ_k
  for (std::size_t k = chain.size(); k-- > from;) {
    const int j = chain[k], v = joint_var_[j];
    if (v < 0 || dq[v] == 0.0) continue;
    const double w = joint_mult_[j] * std::abs(dq[v]);
    const double reach = isSlide(j) ? 1.0 : joint_reach_[link][k];
    if (kind_[j] != static_cast<char>(Kind::Revolute) || f.n == DynamicBound::kMax) {  // slides, spins: static
      f.a += w * reach;
    } else {
      const Pose& frame = poses[child_[j]];
      const Vec3 u = frame.R * axis_[j], r = center - frame.t;
      const double now = std::min(reach, (r - r.dot(u) * u).norm() + sphere_radius_[link]);
      f.a += w * now;
      if (now < reach && after > 0.0) {
        f.c += w * after;
        f.cap[f.n] = (reach - now) / after, f.gain[f.n] = w * after, f.excess[f.n] = w * (reach - now);
        ++f.n;
      }
    }
    after += w * reach;
  }
  f.fixed += after;
}

double MotionBound::linkStep(int link, const double* dq, const Pose* poses, double d, double extra) const noexcept {
  DynamicBound f;
  addDynamic(link, 0, dq, poses, f);
  f.a += extra, f.fixed += extra;  // (linear in h)
  return f.solve(d);
}

double MotionBound::pairStep(int a, int b, const double* dq, const Pose* poses, double d) const noexcept {
  // Watched from the fork: each link moves by the joints below it, from where their axes are now.
  std::size_t fork = 0;
  while (fork < chain_[a].size() && fork < chain_[b].size() && chain_[a][fork] == chain_[b][fork]) ++fork;
  DynamicBound f;
  addDynamic(a, fork, dq, poses, f);
  addDynamic(b, fork, dq, poses, f);
  return f.solve(d);
}

double MotionBound::pair(int a, int b, const double* dq) const noexcept {
  // Joints shared by both chains move the pair rigidly. The others lie on the path a → fork → b, and
  // the pair may be watched from any link X on that path: the joints between a and X move a, the rest
  // move b. Each joint costs |Δq| times its reach to the link it moves (for a link above the joint, the
  // offsets up to the fork and down to that link); the bound is the cheapest X, found in one sweep.
  const std::vector<int>& ca = chain_[a];
  const std::vector<int>& cb = chain_[b];
  const std::size_t na = ca.size(), nb = cb.size();
  std::size_t fork = 0;
  while (fork < na && fork < nb && ca[fork] == cb[fork]) ++fork;
  const double above = fork ? prefix_[a][fork - 1] : 0.0;  // equal for b: the shared joints
  const double side_a = na > fork ? prefix_[a][na - 1] - above : 0.0;
  const double side_b = nb > fork ? prefix_[b][nb - 1] - above : 0.0;
  // Path order: a's joints upwards, then b's downwards. cost_a[k]: the joint moving a; cost_b[k]: moving b.
  constexpr std::size_t kMaxPath = 128;
  double cost_a[kMaxPath], cost_b[kMaxPath];
  std::size_t n = 0;
  const auto add = [&](int j, double reach_a, double reach_b) {
    const int v = joint_var_[j];
    if (v < 0 || dq[v] == 0.0) return;
    const double w = joint_mult_[j] * std::abs(dq[v]);
    cost_a[n] = (isSlide(j) ? 1.0 : reach_a) * w;
    cost_b[n] = (isSlide(j) ? 1.0 : reach_b) * w;
    ++n;
  };
  if (na - fork + nb - fork > kMaxPath) {  // beyond any real robot: watched from the fork
    double bound = 0.0;
    for (int side = 0; side < 2; ++side) {
      const int l = side ? b : a;
      for (std::size_t k = fork; k < chain_[l].size(); ++k) {
        const int j = chain_[l][k], v = joint_var_[j];
        if (v >= 0 && dq[v] != 0.0) bound += joint_mult_[j] * std::abs(dq[v]) * (isSlide(j) ? 1.0 : joint_reach_[l][k]);
      }
    }
    return bound;
  }
  for (std::size_t k = na; k-- > fork;) {
    // From this joint up to the fork, then down to b.
    const double reach_b = radius_[b] + (prefix_[a][k] - above) + side_b;
    add(ca[k], joint_reach_[a][k], std::min(reach_b, exactReach(b, ca[k])));
  }
  for (std::size_t k = fork; k < nb; ++k) {
    const double reach_a = radius_[a] + (prefix_[b][k] - above) + side_a;
    add(cb[k], std::min(reach_a, exactReach(a, cb[k])), joint_reach_[b][k]);
  }
  // Split after i joints: Σ_{k<i} cost_a + Σ_{k≥i} cost_b, smallest over i, by a suffix sweep.
  double suffix_b = 0.0;
  double best = INFINITY;
  double prefix_a[kMaxPath + 1];
  prefix_a[0] = 0.0;
  for (std::size_t k = 0; k < n; ++k) prefix_a[k + 1] = prefix_a[k] + cost_a[k];
  for (std::size_t i = n + 1; i-- > 0;) {
    best = std::min(best, prefix_a[i] + suffix_b);
    if (i > 0) suffix_b += cost_b[i - 1];
  }
  return best;
}

}  // namespace clearway

namespace clearway {

// ---- MotionChecker ------------------------------------------------------------------------------------

MotionChecker::Bodies MotionChecker::mergeBodies(const Scene& scene) {
  const RobotModel& model = scene.robot();
  Bodies out;
  out.anchor = rigidAnchors(scene);
  out.index.assign(model.linkCount(), -1);
  std::vector<std::vector<int>> members(model.linkCount());
  for (const int l : scene.geometry().geometricLinks()) members[out.anchor[l]].push_back(l);
  SceneContext ctx = scene.makeContext();
  scene.computePoses(referenceState(scene).data(), ctx);
  out.reference = ctx.poses;
  for (int anchor = 0; anchor < model.linkCount(); ++anchor) {
    if (members[anchor].size() < 2) continue;
    // Every member's elements, placed in the anchor's frame (fixed: the joints in between do not move).
    std::vector<CollisionElement> elements;
    for (const int l : members[anchor]) {
      const Pose in_anchor = relativePose(out.reference[anchor], out.reference[l]);
      for (CollisionElement e : model.link(l).collisions) {
        e.origin = in_anchor * e.origin;
        elements.push_back(std::move(e));
      }
    }
    for (const int l : members[anchor]) out.index[l] = static_cast<int>(out.list.size());
    out.geometry.push_back(std::make_unique<const LinkGeometry>(elements, model.meshes()));
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
  if (!(options_.contact_distance > 0.0) || !std::isfinite(options_.contact_distance))
    throw std::invalid_argument("MotionChecker: contact_distance must be finite and > 0");
  if (!(options_.resolution > 0.0) || !std::isfinite(options_.resolution))
    throw std::invalid_argument("MotionChecker: resolution must be finite and > 0");
  if (!(options_.distance_relative_error >= 0.0) || !std::isfinite(options_.distance_relative_error))
    throw std::invalid_argument("MotionChecker: distance_relative_error must be finite and >= 0");
  if (options_.max_queries < 1) throw std::invalid_argument("MotionChecker: max_queries must be >= 1");
  if (options_.max_samples < 1) throw std::invalid_argument("MotionChecker: max_samples must be >= 1");
  for (const Obstacle& o : scene_->environment().obstacles()) obstacle_speed_ = std::max(obstacle_speed_, o.velocity.norm());
  // A floating joint's quaternion turns along the great arc (slerp), as OMPL's SO(3) interpolates.
  const RobotModel& model = scene_->robot();
  for (int i = 0; i < scene_->dimension(); ++i) {
    const int v = scene_->groupVariables()[i];
    const Joint& joint = model.joint(model.variables()[v].joint);
    if (joint.type == JointType::Floating && v == joint.first_variable + 3) quaternions_.push_back(i);
  }
  buildItems();
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
    const std::vector<Pose>& at = bodies_.reference;
    for (int k = 0; k < static_cast<int>(self.pairs().size()); ++k) {
      const LinkPair& p = self.pairs()[k];
      if (anchor[p.a] == anchor[p.b]) {  // one rigid body: as at every state
        if (rigid_collision_.kind == CollisionReport::Kind::None &&
            meshesIntersect(*sc.geometry().link(p.a), at[p.a], *sc.geometry().link(p.b), at[p.b],
                            sc.options().tolerances, sc.options().mode, self.pairPadding(k))) {
          rigid_collision_.kind = CollisionReport::Kind::Self;
          rigid_collision_.link = p.a;
          rigid_collision_.other_link = p.b;
        }
        continue;
      }
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
}

MotionContext MotionChecker::makeContext() const {
  MotionContext c;
  c.scene = scene_->makeContext();
  c.q.resize(scene_->dimension());
  c.dq.resize(scene_->dimension());
  c.safe_until.resize(items_.size());
  c.bound.resize(items_.size());
  c.first_reach.resize(items_.size());
  c.contact.assign(items_.size(), options_.contact_distance);
  c.contact_stamp.assign(items_.size(), 0);
  c.hull_cache.resize(env_begin_);
  c.part_slot.assign(env_begin_, -1);
  c.part_stamp.assign(env_begin_, 0);
  c.split_slot.assign(env_begin_, 0);
  c.split_stamp.assign(env_begin_, 0);
  for (int k = 0; k < env_begin_; ++k) {
    const Item& it = items_[k];
    c.split_slot[k] = static_cast<int>(c.split_bound.size());
    c.split_bound.resize(c.split_bound.size() + it.ga->parts().size() + it.gb->parts().size());
    if (it.last > it.first) continue;  // a head stops at its hulls
    c.part_slot[k] = static_cast<int>(c.part_cache.size());
    c.part_cache.resize(c.part_cache.size() + it.ga->parts().size() * it.gb->parts().size());
  }
  // (Warm starts per static obstacle while there are few: with many, the tree visits only a few per query.)
  const std::size_t obstacles = scene_->environment().staticCount();
  const int env_items = static_cast<int>(items_.size()) - env_begin_;
  c.env_slot.assign(env_items, -1);
  c.env_stamp.assign(env_items, 0);
  if (obstacles > 0 && obstacles <= kWarmObstacles) {
    for (int k = 0; k < env_items; ++k) c.env_slot[k] = static_cast<int>(k * obstacles);
    c.env_cache.resize(env_items * obstacles);
  }
  c.pose_stamp.assign(scene_->robot().linkCount(), 0);
  c.pose_path.reserve(scene_->robot().linkCount());
  c.intervals.reserve(256);
  if (options_.mode == MotionMode::Cast) c.end_poses.resize(scene_->robot().linkCount());
  return c;
}

namespace {

// The unit quaternions of q0[0..3] and q1[0..3], the second on the first's side (the short arc).
void alignedUnit(const double* q0, const double* q1, Eigen::Vector4d& a, Eigen::Vector4d& b) noexcept {
  a = Eigen::Vector4d(q0[0], q0[1], q0[2], q0[3]);
  b = Eigen::Vector4d(q1[0], q1[1], q1[2], q1[3]);
  a.normalize();
  b.normalize();
  if (a.dot(b) < 0.0) b = -b;
}

}  // namespace

void MotionChecker::interpolate(const double* q0, const double* q1, double s, double* out) const noexcept {
  for (int i = 0; i < scene_->dimension(); ++i) out[i] = q0[i] + s * (q1[i] - q0[i]);
  for (const int k : quaternions_) {
    Eigen::Vector4d a, b;
    alignedUnit(q0 + k, q1 + k, a, b);
    const double angle = std::acos(std::clamp(a.dot(b), -1.0, 1.0));
    // Slerp; nearly equal ends interpolate linearly (then renormalized), where sin(angle) loses digits.
    Eigen::Vector4d q = angle > 1e-9 ? Eigen::Vector4d((std::sin((1 - s) * angle) * a + std::sin(s * angle) * b) / std::sin(angle))
                                     : Eigen::Vector4d(a + s * (b - a));
    q.normalize();
    for (int c = 0; c < 4; ++c) out[k + c] = q[c];
  }
}

MotionResult MotionChecker::check(const double* q0, const double* q1, MotionContext& ctx,
                                  bool locate_contact) const noexcept {
  return check(q0, 0.0, q1, 0.0, ctx, locate_contact);
}

MotionResult MotionChecker::check(const double* q0, double t0, const double* q1, double t1, MotionContext& ctx,
                                  bool locate_contact) const noexcept {
  return options_.mode == MotionMode::Sampled ? sampled(q0, t0, q1, t1, ctx)
                                              : certified(q0, t0, q1, t1, ctx, locate_contact);
}

MotionResult MotionChecker::sampled(const double* q0, double t0, const double* q1, double t1,
                                    MotionContext& ctx) const noexcept {
  MotionResult r;
  const Scene& sc = *scene_;
  const auto time = [&](double s) { return t0 + s * (t1 - t0); };
  double len2 = 0.0;
  for (int i = 0; i < sc.dimension(); ++i) len2 += (q1[i] - q0[i]) * (q1[i] - q0[i]);
  // As OMPL's DiscreteMotionValidator: the ends, then the states in between at the resolution.
  const double len = std::sqrt(len2);
  // The step count in double first: len / resolution may exceed every int.
  const double steps = std::isfinite(len) ? std::max(1.0, std::ceil(len / options_.resolution)) : 1.0;
  if (!(steps <= options_.max_samples)) {
    r.capped = true;
    r.report.kind = CollisionReport::Kind::Invalid;
    return r;  // first_contact = last_valid = 0: nothing is known free
  }
  const int n = static_cast<int>(steps);
  r.steps = 1;
  if (!sc.isFree(q0, ctx.scene, &r.report, t0)) return r;
  // The end first (each state is checked once); if it collides, the states in between say whether the
  // segment collides earlier.
  ++r.steps;
  CollisionReport end;
  const bool end_free = sc.isFree(q1, ctx.scene, &end, t1);
  double last = 0.0;
  for (int k = 1; k < n; ++k) {
    const double s = static_cast<double>(k) / n;
    interpolate(q0, q1, s, ctx.q.data());
    ++r.steps;
    if (!sc.isFree(ctx.q.data(), ctx.scene, &r.report, time(s))) {
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

void MotionChecker::castAhead(const double* q0, const double* q1, double t0, int n_items, MotionContext& ctx,
                              MotionResult& r) const noexcept {
  const Scene& sc = *scene_;
  const Tolerances& tol = sc.options().tolerances;
  const double contact = options_.contact_distance;
  bool posed = false;
  for (int k = 0; k < n_items; ++k) {
    const Item& it = items_[k];
    if (it.group >= 0) continue;  // its group's coverage decides where it starts
    const bool self = it.b >= 0;
    if (!self && ctx.obstacle_motion > 0.0) continue;  // (the cast holds obstacles still, where they are at t0)
    if (self ? !bound_.translates(it.a, it.b, ctx.dq.data()) : !bound_.translates(it.a, ctx.dq.data())) continue;
    if (!posed) {  // both ends' poses, once: the end's kept aside, the start's left in the scene context
      sc.computePoses(q1, ctx.scene);
      ctx.end_poses = ctx.scene.poses;
      sc.computePoses(q0, ctx.scene);
      posed = true;
    }
    const std::vector<Pose>& start = ctx.scene.poses;
    const std::vector<Pose>& end = ctx.end_poses;
    ++r.distance_queries;
    double first;  // certified: the grown hulls do not touch before it
    if (self) {
      // In b's frame a translates (the rotations on the path do not change): one cast of a's grown hull.
      const Pose from = relativePose(start[it.frame_b], start[it.frame_a]);
      const Vec3 shift = relativePose(end[it.frame_b], end[it.frame_a]).t - from.t;
      const CastResult c = gjkShapeCast(Margin<ConvexHull>{it.ga->hull(), it.padding + contact}, from, shift,
                                        it.gb->hull(), Pose::identity(), 1.0, tol);
      first = c.hit ? std::max(0.0, c.t) : 2.0;
    } else {
      first = sc.environment().linkCast(*it.ga, start[it.frame_a], end[it.frame_a].t - start[it.frame_a].t,
                                        it.padding + contact, tol, 1.0, t0, &ctx.scene.counters.environment);
    }
    ctx.safe_until[k] = std::min(first, 2.0);
  }
}

// One certified check in progress. Each item covers [0, limit] on its own with balls: a clearance d
// measured at s clears s ± d / B (B the item's motion bound; or the larger reach its axes allow). An
// interval is measured at its middle, and what the ball leaves uncovered on either side is an interval
// again, left first; a measurement within contact_distance makes the item step from the interval's left
// end by conservative advancement to its first contact, which becomes the limit: nothing after it
// matters to any item. So a free segment costs about one measurement per ball of twice the radius that
// advancement alone would use, and the first contact is exact all the same.
struct MotionChecker::Sweep {
  // A clearance proven beyond the contact distance (the search said "not within it"), in contact distances.
  static constexpr double kBeyond = 1.0 + 1e-9;
  // Once the convex bounds are within contact, how far (in contact distances) the exact geometry is
  // measured: near fine meshes, a search farther out visits a great many triangles.
  static constexpr double kNear = 8.0;

  const MotionChecker& mc;
  MotionContext& ctx;
  MotionResult& r;
  const double* q0;
  const double* q1;
  double t0 = 0.0, t1 = 0.0;  // the times at q0 and q1 (moving obstacles)
  double limit = 1.0;         // the first contact found so far, or the segment's end
  bool hit = false;           // a contact at `limit`
  double clear_before = 0.0;  // a parameter before `limit` the contacting item is certified clear at
  bool capped = false;
  int contacts = 0;           // how often the limit was lowered
  // Only the verdict is asked: the first measurement within contact settles it (it is a contact, if not
  // the first one), and nothing else is measured.
  bool verdict_only = false;
  bool stop() const noexcept { return capped || (verdict_only && hit); }
  double at_s = -1.0;         // the parameter ctx.scene.q holds
  // The last measurement's self item whose hulls' GJK axis separates them (splitClearances), −1: none.
  static constexpr std::size_t kSplit = 8;
  int split_item = -1;
  double clear_a[kSplit], clear_b[kSplit];

  Sweep(const MotionChecker& checker, MotionContext& c, MotionResult& result, const double* from, const double* to)
      : mc(checker), ctx(c), r(result), q0(from), q1(to) {
    ctx.scene.poses[0] = Pose::identity();
  }

  // The time at parameter s.
  double time(double s) const noexcept { return t0 + s * (t1 - t0); }

  // The link's pose (and its ancestors') at parameter s.
  const Pose& pose(double s, int link) {
    if (s != at_s) {
      mc.interpolate(q0, q1, s, ctx.q.data());
      const std::vector<int>& group = mc.scene_->groupVariables();
      for (std::size_t i = 0; i < group.size(); ++i) ctx.scene.q[group[i]] = ctx.q[i];
      ++ctx.step_stamp;
      ++r.steps;
      at_s = s;
    }
    const RobotModel& model = mc.scene_->robot();
    Pose* poses = ctx.scene.poses.data();
    for (int l = link; l > 0 && ctx.pose_stamp[l] != ctx.step_stamp; l = model.parentLink(l)) ctx.pose_path.push_back(l);
    for (; !ctx.pose_path.empty(); ctx.pose_path.pop_back()) {
      computeLinkPose(model, ctx.scene.q.data(), poses, ctx.pose_path.back());
      ctx.pose_stamp[ctx.pose_path.back()] = ctx.step_stamp;
    }
    return poses[link];
  }

  // One item's warm starts, the block of n at `slot` in `all` (none for −1), emptied when this segment
  // first uses them: a verdict depends on nothing but its segment.
  SimplexCache* warmStarts(std::vector<SimplexCache>& all, int slot, std::uint64_t& stamp, std::size_t n) {
    if (slot < 0) return nullptr;
    SimplexCache* block = all.data() + slot;
    if (stamp != ctx.segment) {
      std::fill(block, block + n, SimplexCache{});
      stamp = ctx.segment;
    }
    return block;
  }

  // Item k's contact distance on this segment.
  double contactOf(int k) const noexcept {
    return ctx.contact_stamp[k] == ctx.segment ? ctx.contact[k] : mc.options_.contact_distance;
  }

  // measure(), and when item k first comes within contact on this segment, its ends' clearances: where the
  // nearer end is closer than twice the contact distance, the item's contact distance becomes half that
  // end's clearance (never 0: an end that touches keeps it), and s is measured again. A state the
  // validity checker accepts can then be left; the loops still end, each ball being at least that wide.
  double measureItem(int k, double s, double need, CollisionReport& report) {
    const double d = measure(k, s, need, report);
    if (!(d <= contactOf(k)) || ctx.contact_stamp[k] == ctx.segment) return d;
    ctx.contact_stamp[k] = ctx.segment;
    ctx.contact[k] = mc.options_.contact_distance;
    const Item& it = mc.items_[k];
    if (it.last > it.first) return d;  // a group's members decide, each with its own ends
    const double e0 = endClearance(k, 0.0);
    const double e = e0 > 0.0 ? std::min(e0, endClearance(k, 1.0)) : 0.0;
    if (!(e > 0.0) || !(0.5 * e < ctx.contact[k])) return d;
    ctx.contact[k] = 0.5 * e;
    return measure(k, s, need, report);
  }

  // A certified lower bound on item k's clearance at s (padding removed) where it is below the contact
  // distance; at least the contact distance otherwise. As the scene's geometry mode sees it.
  double endClearance(int k, double s) {
    const Scene& sc = *mc.scene_;
    const Tolerances& tol = sc.options().tolerances;
    const double relative = mc.options_.distance_relative_error;
    const Item& it = mc.items_[k];
    const double cutoff = it.padding + mc.options_.contact_distance;
    const bool exact = sc.options().mode != GeometryMode::Hull;
    ++r.distance_queries;
    if (r.distance_queries >= mc.options_.max_queries) capped = true;
    const Pose pa = pose(s, it.frame_a);
    double d;
    if (it.b >= 0) {
      const Pose& pb = pose(s, it.frame_b);
      if (exact) {
        const DistanceResult m = meshDistance(*it.ga, pa, *it.gb, pb, tol, relative, cutoff);
        d = isFailure(m.status) ? 0.0 : m.lower_bound;
      } else {
        SimplexCache cold;
        d = gjkLowerBound(it.ga->hull(), pa, it.gb->hull(), pb, tol, cold, cutoff, relative);
      }
    } else {
      EnvironmentCounters* counters = &ctx.scene.counters.environment;
      if (exact) {
        const DistanceResult m = sc.environment().linkDistance(*it.ga, pa, tol, cutoff, time(s), relative, counters);
        d = isFailure(m.status) ? 0.0 : m.lower_bound;
      } else {
        d = sc.environment().hullLowerBound(*it.ga, pa, tol, cutoff, relative, time(s), counters);
      }
    }
    return d - it.padding;
  }

  // A certified lower bound on item k's clearance at s (padding removed), computed only as far as `need`
  // (beyond it, the answer only has to say so). A contact fills `report`.
  double measure(int k, double s, double need, CollisionReport& report) {
    const Scene& sc = *mc.scene_;
    const Tolerances& tol = sc.options().tolerances;
    const double contact = contactOf(k), relative = mc.options_.distance_relative_error;
    // Below the scene's contact distance (an end of the segment is that near), only distances decide: an
    // intersection test within it would count the narrow phase's band as contact.
    const bool lowered = contact < mc.options_.contact_distance;
    const bool exact = sc.options().mode != GeometryMode::Hull;
    const Item& it = mc.items_[k];
    const bool head = it.last > it.first;  // a group stops at the merged hulls: its members decide the rest
    ++r.distance_queries;
    split_item = -1;
    need = std::max(need, 2.0 * contact);  // a clearance must exceed the contact distance to count
    const Pose pa = pose(s, it.frame_a);
    double d;
    if (it.b >= 0) {
      const Pose& pb = pose(s, it.frame_b);
      const LinkGeometry& a = *it.ga;
      const LinkGeometry& b = *it.gb;
      // Ever tighter and dearer lower bounds, each only when the one before falls short of `enough`: the
      // bounding balls, the hulls (warm-started GJK), the convex parts, and last the triangles.
      const double enough = need + it.padding;
      double lower = (pa * a.sphereCenter() - pb * b.sphereCenter()).norm() - a.sphereRadius() - b.sphereRadius();
      if (!(lower >= enough))  // (the GJK bound first in max(): it is a number even if the balls' is not)
        lower = std::max(gjkLowerBound(a.hull(), pa, b.hull(), pb, tol, ctx.hull_cache[k], enough, relative), lower);
      d = lower - it.padding;
      if (d > contact) split_item = k;  // (the hulls' last GJK axis: this measurement's, or an earlier one's)
      if (d <= contact && exact && !head) {
        SimplexCache* caches =
            warmStarts(ctx.part_cache, ctx.part_slot[k], ctx.part_stamp[k], a.parts().size() * b.parts().size());
        d = std::max(d, partsLowerBound(a, pa, b, pb, tol, enough, relative, caches) - it.padding);  // (d first: NaN)
      }
      if (d <= contact && exact && !head) {
        // The convex pieces are within contact, so the triangles are near (and a fine mesh has many near):
        // whether they are within contact is a search that stops at the first pair; only if not, how far
        // they are, measured no farther than a few contact distances.
        if (!lowered && meshesIntersect(a, pa, b, pb, tol, GeometryMode::Mesh, it.padding + contact)) {
          d = 0.0;
        } else {
          const DistanceResult m = meshDistance(a, pa, b, pb, tol, relative, std::min(enough, it.padding + kNear * contact));
          d = isFailure(m.status) ? 0.0 : std::max(m.lower_bound - it.padding, lowered ? 0.0 : kBeyond * contact);
        }
      }
      if (d <= contact && !head) {
        report = CollisionReport{};
        report.kind = CollisionReport::Kind::Self;
        report.link = it.a;
        report.other_link = it.b;
      }
    } else {
      const double cutoff = need + it.padding + contact;
      const double t = time(s);  // where moving obstacles are
      // As for pairs: the hull's bound first, the exact geometry only when the hull comes close.
      const int e = k - mc.env_begin_;
      SimplexCache* warm = warmStarts(ctx.env_cache, ctx.env_slot[e], ctx.env_stamp[e], sc.environment().staticCount());
      const double h =
          sc.environment().hullLowerBound(*it.ga, pa, tol, cutoff, relative, t, &ctx.scene.counters.environment, warm);
      d = h - it.padding;
      EnvironmentHit hit;
      bool found = false;  // `hit` names what is within contact
      EnvironmentCounters* counters = &ctx.scene.counters.environment;
      if (d <= contact && exact && !head)  // the convex parts, then (as for pairs) within contact, then how far
        d = std::max(d, sc.environment().hullLowerBound(*it.ga, pa, tol, cutoff, relative, t, counters, nullptr, true) -
                            it.padding);  // (d first: NaN)
      if (d <= contact && exact && !head) {
        if (!lowered &&
            sc.environment().linkIntersects(*it.ga, pa, tol, GeometryMode::Mesh, it.padding + contact, t, &hit, counters)) {
          d = 0.0;
          found = true;
        } else {
          const DistanceResult e =
              sc.environment().linkDistance(*it.ga, pa, tol, std::min(cutoff, it.padding + kNear * contact), t, relative, counters);
          d = isFailure(e.status) ? 0.0 : std::max(e.lower_bound - it.padding, lowered ? 0.0 : kBeyond * contact);
        }
      }
      if (d <= contact && !head) {
        report = CollisionReport{};
        report.kind = CollisionReport::Kind::Environment;
        report.link = it.a;
        // Which obstacle or voxel (for the report only): one within the contact distance, widened by the
        // relative error the distance's lower bound was allowed.
        if (!found)
          sc.environment().linkIntersects(*it.ga, pa, tol, sc.options().mode,
                                          it.padding + (contact + 1e-9) * (1.0 + relative), t, &hit);
        report.hit = hit;
      }
    }
    if (r.distance_queries >= mc.options_.max_queries) capped = true;
    return d;
  }

  // Self item k's parts' clearances from the other link, from the hulls' separating plane: any unit u gives,
  // for a part of A whose points reach at most P_i along u and a B whose points start at Q, a clearance of
  // at least Q − P_i (the last GJK axis makes it tight for the nearest part); never below d, the hulls'.
  // False when there is no axis or too many parts.
  bool splitClearances(int k, double d) {
    const Item& it = mc.items_[k];
    const SimplexCache& cache = ctx.hull_cache[k];
    const std::vector<LinkGeometry::Part>& parts_a = it.ga->parts();
    const std::vector<LinkGeometry::Part>& parts_b = it.gb->parts();
    if (!cache.valid || parts_a.size() > kSplit || parts_b.size() > kSplit) return false;
    const Pose& pa = ctx.scene.poses[it.frame_a];  // (as measured)
    const Pose& pb = ctx.scene.poses[it.frame_b];
    const Vec3 u_a = -cache.axis.normalized();  // A towards B, in A's frame
    const Vec3 u = pa.R * u_a, u_b = pb.R.transpose() * u;
    if (!u.allFinite()) return false;
    std::int32_t hint_a = cache.hint_a, hint_b = cache.hint_b;
    const double p = u.dot(pa.t) + u_a.dot(it.ga->hull().support(u_a, hint_a));
    const double q = u.dot(pb.t) + u_b.dot(it.gb->hull().support(-u_b, hint_b));
    // Rounding: each term is a dot product of coordinates of a few metres at most.
    const double slack = it.padding + 1e-12 * (1.0 + std::abs(p) + std::abs(q));
    for (std::size_t i = 0; i < parts_a.size(); ++i)  // (d first in max(): a NaN plane leaves d)
      clear_a[i] = std::max(d, q - std::min(p, u.dot(pa * parts_a[i].center) + parts_a[i].radius) - slack);
    for (std::size_t j = 0; j < parts_b.size(); ++j)
      clear_b[j] = std::max(d, std::max(q, u.dot(pb * parts_b[j].center) - parts_b[j].radius) - p - slack);
    return true;
  }

  // Self item k's parts' motion bounds against the other link, for this segment: a's parts, then b's.
  const double* splitBounds(int k) {
    const Item& it = mc.items_[k];
    double* bound = ctx.split_bound.data() + ctx.split_slot[k];
    if (ctx.split_stamp[k] != ctx.segment) {
      const std::vector<int>& begin = mc.bodies_.parts_begin;
      const int na = static_cast<int>(it.ga->parts().size()), nb = static_cast<int>(it.gb->parts().size());
      for (int i = 0; i < na; ++i) bound[i] = mc.bound_.pair(begin[it.a] + i, it.b, ctx.dq.data());
      for (int j = 0; j < nb; ++j) bound[na + j] = mc.bound_.pair(it.a, begin[it.b] + j, ctx.dq.data());
      ctx.split_stamp[k] = ctx.segment;
    }
    return bound;
  }

  // How far from s a clearance d of item k reaches, either way. Beyond `want` nothing is asked; only short
  // of it does a self item look at its links' parts: where the near part lies close to the axes that turn
  // it, the far parts' larger clearances make up for their larger motion.
  double reach(int k, double d, double want) {
    const Item& it = mc.items_[k];
    const double* dq = ctx.dq.data();
    const Pose* poses = ctx.scene.poses.data();  // (at the parameter d was measured at)
    // The static bound first: where it reaches as far as asked, the reaches from the axes now are not needed.
    double h = d / ctx.bound[k];  // (∞ when the item does not move)
    if (!(h < want)) return h;
    if (it.b < 0) return std::max(h, mc.bound_.linkStep(it.a, dq, poses, d, ctx.obstacle_motion));
    h = std::max(h, mc.bound_.pairStep(it.a, it.b, dq, poses, d));
    if (h < want && split_item == k && splitClearances(k, d)) {
      const double* bound = splitBounds(k);
      const std::size_t na = it.ga->parts().size(), nb = it.gb->parts().size();
      double ha = INFINITY, hb = INFINITY;  // (a part that does not move relative to the other: ∞)
      for (std::size_t i = 0; i < na; ++i) ha = std::min(ha, clear_a[i] / bound[i]);
      for (std::size_t j = 0; j < nb; ++j) hb = std::min(hb, clear_b[j] / bound[na + j]);
      h = std::max(h, std::max(ha, hb));
    }
    return h;
  }

  // How far either way from s item k is clear, measured for the interval s ± half; −1 within contact.
  double first(int k, double s, double half) {
    CollisionReport report;
    const double d = measureItem(k, s, ctx.bound[k] * half, report);
    if (d > contactOf(k)) return reach(k, d, half);
    if (verdict_only && mc.items_[k].last <= mc.items_[k].first) found(s, report);
    return -1.0;
  }

  // A contact at s settles a verdict-only check (no parameter before it is known to be free).
  void found(double s, const CollisionReport& report) {
    hit = true;
    limit = s;
    ++contacts;
    clear_before = 0.0;
    r.report = report;
  }

  // Covers [a, b] ∩ [0, limit] for item k (all of [0, a) is covered already).
  void cover(int k, double a, double b, double witness) {
    const Item& it = mc.items_[k];
    const std::size_t base = ctx.intervals.size();
    ctx.intervals.push_back({a, b, witness});
    CollisionReport report;
    while (ctx.intervals.size() > base && !stop()) {
      const MotionContext::Interval iv = ctx.intervals.back();
      ctx.intervals.pop_back();
      const double hi = std::min(iv.b, limit);
      if (iv.a > hi || (hit && iv.a >= hi)) continue;
      const double m = 0.5 * (iv.a + hi);
      const double d = measureItem(k, m, ctx.bound[k] * 0.5 * (hi - iv.a), report);
      if (d <= contactOf(k)) {
        if (it.last > it.first) {  // a group within contact: its members take over here, exactly
          for (int member = it.first; member < it.last && !stop(); ++member) {
            ctx.bound[member] = mc.itemBound(mc.items_[member], ctx.dq.data(), ctx.obstacle_motion);
            cover(member, iv.a, hi, iv.witness);
          }
          continue;
        }
        if (verdict_only) {
          found(m, report);
          ctx.intervals.resize(base);
          return;
        }
        if (advance(k, iv.a, iv.witness, hi)) {
          ctx.intervals.resize(base);  // all to the right of the contact
          return;
        }
        continue;
      }
      const double rad = reach(k, d, std::max(m - iv.a, hi - m));
      if (m + rad < hi) ctx.intervals.push_back({m + rad, hi, m});
      if (m - rad > iv.a) ctx.intervals.push_back({iv.a, m - rad, iv.witness});
    }
    ctx.intervals.resize(base);
  }

  // Conservative advancement of item k from a (clear at `witness`) towards `until`: true when it meets a
  // contact there (which becomes the limit); false when [a, until] is clear.
  bool advance(int k, double a, double witness, double until) {
    CollisionReport report;
    double s = a, prev = std::max(witness, 0.0), prev_d = 0.0;  // the clearance measured at prev (0: none)
    while (!capped) {
      const double d = measureItem(k, s, ctx.bound[k] * (until - s), report);
      const double contact = contactOf(k);
      if (d <= contact) {
        if (!hit || s < limit) {
          limit = s;
          hit = true;
          ++contacts;
          // The last parameter known free: past prev, as long as the step's bound still leaves half the
          // contact distance. (Both reaches come from bounds convex in the step and 0 at 0: the motion
          // over a fraction λ of the step is at most λ·prev_d.)
          clear_before = prev_d > contact ? prev + (s - prev) * (1.0 - 0.5 * contact / prev_d) : prev;
          r.report = report;
        }
        return true;
      }
      prev = s;
      prev_d = d;
      s += reach(k, d, until - s);  // at least contactOf(k) / B > 0: the loop ends
      if (!(s < until)) return false;
    }
    return false;
  }
};

double MotionChecker::itemBound(const Item& it, const double* dq, double obstacle_motion) const noexcept {
  return it.b >= 0 ? bound_.pair(it.a, it.b, dq) : bound_.link(it.a, dq) + obstacle_motion;
}

MotionResult MotionChecker::certified(const double* q0, double t0, const double* q1, double t1, MotionContext& ctx,
                                      bool locate_contact) const noexcept {
  MotionResult r;
  const Scene& sc = *scene_;
  // q0's collisions are found by the items' coverage of the segment, except those no state changes.
  // (first_contact = last_valid = 0)
  if (!sc.validState(q0)) {
    r.report.kind = CollisionReport::Kind::Invalid;
    return r;
  }
  if (sc.staticCollision().kind != CollisionReport::Kind::None || rigid_collision_.kind != CollisionReport::Kind::None) {
    r.report = sc.staticCollision().kind != CollisionReport::Kind::None ? sc.staticCollision() : rigid_collision_;
    return r;
  }
  for (int i = 0; i < sc.dimension(); ++i) ctx.dq[i] = q1[i] - q0[i];
  for (const int k : quaternions_) {  // the change of the unit quaternions slerp runs between
    Eigen::Vector4d a, b;
    alignedUnit(q0 + k, q1 + k, a, b);
    for (int c = 0; c < 4; ++c) ctx.dq[k + c] = b[c] - a[c];
  }
  for (int i = 0; i < sc.dimension(); ++i)
    if (!std::isfinite(ctx.dq[i])) {
      r.report.kind = CollisionReport::Kind::Invalid;
      return r;
    }
  // The segment stays within bounds when both ends do (boxes are convex): an invalid end is reported
  // after the advancement has looked for an earlier contact.
  const bool end_invalid = !sc.validState(q1);

  const bool check_env = sc.effects().environment && !sc.environment().empty();
  const int n_items = check_env ? static_cast<int>(items_.size()) : env_begin_;
  // No warm start from other segments: a segment's verdict then depends on nothing but its ends (a planner's
  // threads, and a later re-check of its path, must agree even on pairs within the contact distance).
  for (SimplexCache& c : ctx.hull_cache) c = SimplexCache{};
  ++ctx.segment;  // (the part pairs' and obstacles' warm starts are emptied as their items first need them)
  // How far moving obstacles travel over the segment (per unit of s): it adds to every environment item's
  // motion; none unless the scene declares them.
  const bool timed = sc.effects().moving && sc.environment().hasMovingObstacles();
  if (!timed) t0 = t1 = 0.0;
  ctx.obstacle_motion = timed ? obstacle_speed_ * std::abs(t1 - t0) : 0.0;
  if (!std::isfinite(ctx.obstacle_motion) || !std::isfinite(t0)) {
    r.report.kind = CollisionReport::Kind::Invalid;
    return r;
  }
  // Members wait until their group comes within contact.
  for (int k = 0; k < n_items; ++k) {
    if (items_[k].group >= 0) continue;
    ctx.bound[k] = itemBound(items_[k], ctx.dq.data(), ctx.obstacle_motion);  // (0 when nothing moves: measured once)
    ctx.safe_until[k] = 0.0;
  }

  if (options_.mode == MotionMode::Cast) castAhead(q0, q1, t0, n_items, ctx, r);
  Sweep sweep{*this, ctx, r, q0, q1};
  sweep.t0 = t0, sweep.t1 = t1;
  sweep.verdict_only = !locate_contact;
  // The item that met the last contact goes first: a planner's next segment often meets it again, and a
  // contact found early bounds every other item's work.
  const int lead = ctx.lead >= 0 && ctx.lead < n_items && items_[ctx.lead].group < 0 ? ctx.lead : -1;
  const auto cover = [&](int k, double a, double b, double witness) {
    const int before = sweep.contacts;
    sweep.cover(k, a, b, witness);
    if (sweep.contacts > before) ctx.lead = k;
  };
  if (lead >= 0 && ctx.safe_until[lead] <= 1.0)
    cover(lead, ctx.safe_until[lead], 1.0, ctx.safe_until[lead] > 0.0 ? ctx.safe_until[lead] : -1.0);
  // Every other item is first measured in the middle of what is left, where one set of poses serves all.
  const double mid = 0.5 * sweep.limit;
  for (int k = 0; k < n_items && !sweep.stop(); ++k)
    if (k != lead && items_[k].group < 0 && ctx.safe_until[k] == 0.0) {
      const int before = sweep.contacts;
      ctx.first_reach[k] = sweep.first(k, mid, mid);
      if (sweep.contacts > before) ctx.lead = k;
    }
  for (int k = 0; k < n_items && !sweep.stop(); ++k) {
    if (k == lead || items_[k].group >= 0) continue;
    const double start = ctx.safe_until[k];  // 0, or where a shape cast says the item is clear until
    if (start > 1.0) continue;
    if (start > 0.0) {
      cover(k, start, 1.0, start);
    } else if (ctx.first_reach[k] < 0.0) {
      cover(k, 0.0, 1.0, -1.0);  // within contact in the middle: from the start, exactly
    } else {  // what the ball in the middle leaves, left first
      const double rad = ctx.first_reach[k];
      if (mid - rad > 0.0) cover(k, 0.0, mid - rad, -1.0);
      if (mid + rad < sweep.limit) cover(k, mid + rad, 1.0, mid);
    }
  }
  if (sweep.capped) {
    r.capped = true;
    r.first_contact = r.last_valid = 0.0;
    r.report = CollisionReport{};
    r.report.kind = CollisionReport::Kind::Invalid;
    return r;
  }
  // An end out of bounds: the segment is valid up to where it leaves them (q0 is within: boxes are convex).
  double exit = 1.0;
  if (end_invalid) {
    for (int i = 0; i < sc.dimension(); ++i) {
      const double lo = sc.lower(i) - kJointLimitTolerance, hi = sc.upper(i) + kJointLimitTolerance;
      if (q1[i] > hi && ctx.dq[i] > 0.0) exit = std::min(exit, (hi - q0[i]) / ctx.dq[i]);
      if (q1[i] < lo && ctx.dq[i] < 0.0) exit = std::min(exit, (lo - q0[i]) / ctx.dq[i]);
    }
    exit = std::clamp(exit, 0.0, 1.0);
  }
  if (sweep.hit && !(end_invalid && exit < sweep.limit)) {
    r.free = false;
    r.first_contact = sweep.limit;
    // The state at the contact is within contact_distance of touching: if it is still free, it is the last
    // valid one; otherwise the last parameter the contacting item is certified clear at. (Deciding costs a
    // full check of a state next to a contact, where the exact meshes decide: about a tenth of a UR5's
    // motion checks, so only for callers that want it.)
    r.last_valid = sweep.clear_before;
    if (locate_contact) {
      interpolate(q0, q1, sweep.limit, ctx.q.data());
      if (sc.isFree(ctx.q.data(), ctx.scene, nullptr, sweep.time(sweep.limit))) r.last_valid = sweep.limit;
    }
    return r;
  }
  if (end_invalid) {  // clear until the segment leaves its bounds
    r.first_contact = r.last_valid = exit;
    r.report = CollisionReport{};
    r.report.kind = CollisionReport::Kind::Invalid;
    return r;
  }
  r.free = true;
  r.report = CollisionReport{};
  return r;
}

}  // namespace clearway
