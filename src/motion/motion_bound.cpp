// MotionBound: the per-link and per-pair coefficients of the motion bound, static and from the axes now.
#include <clearway/motion/motion.h>

#include <clearway/detail/margins.h>
#include <clearway/serial.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "motion_detail.h"

namespace clearway {

using motion_detail::referenceState;

// ---- MotionBound --------------------------------------------------------------------------------------

struct MotionBound::Tables {
  Tables(const Scene& scene, const std::vector<MotionBound::Body>& bodies);
  double link(int link, const double* dq) const noexcept;
  double pair(int a, int b, const double* dq) const noexcept;
  // Paths of at most this many joints take pair()'s cheapest watching link; longer ones are watched from the fork.
  static constexpr std::size_t kMaxPath = 128;
  // Visits the joints on the path between a and b that could move them, in path order (a's side upwards,
  // then b's downwards), as visit(joint, reach to a, reach to b). False, visiting none, for a path longer than
  // kMaxPath.
  template <class F>
  bool forPath(int a, int b, F&& visit) const noexcept;
  // The cheapest split of the path's joints' costs: Σ_{k<i} cost_a[k] + Σ_{k≥i} cost_b[k], least over i.
  static double cheapestSplit(const double* cost_a, const double* cost_b, std::size_t n) noexcept;
  double linkStep(int link, const double* dq, const Pose* poses, double d, double extra) const noexcept;
  // The bound from the velocity field now (below linkStep): f(h) = h·speed + h²·accel/2.
  struct TwistBound {
    double speed = 0.0, accel = 0.0;
    bool valid = true;  // false when a joint that moves does not turn
    double solve(double d) const noexcept;  // the largest h with f(h) ≤ d
  };
  double pairStep(int a, int b, const double* dq, const Pose* poses, double d) const noexcept;
  bool translates(int a, int b, const double* dq) const noexcept;
  bool translates(int link, const double* dq) const noexcept;
  static constexpr double kSpin = MotionBound::kSpin;
  using Body = MotionBound::Body;

  // How many joints the chains of links a and b share (from the root): the index of the first that is not.
  std::size_t forkOf(int a, int b) const noexcept {
    std::size_t fork = 0;
    while (fork < chain_[a].size() && fork < chain_[b].size() && chain_[a][fork] == chain_[b][fork]) ++fork;
    return fork;
  }
  struct DynamicBound;
  using LinkTerms = MotionBound::LinkTerms;
  // Adds to f and t the joints of link's chain from index `from` on, in one walk of the chain.
  void addBounds(int link, std::size_t from, const double* dq, const Pose* poses, DynamicBound& f,
                 TwistBound& t) const noexcept;
  // The same walk's sums for the link alone, with room for at most `room` pieces (f's left).
  void linkTerms(int link, std::size_t from, const double* dq, const Pose* poses, int room,
                 LinkTerms& out) const noexcept;
  // A link's sums, from the cache where it holds them for these poses (id), else walked (and kept there).
  const LinkTerms& cachedTerms(int link, std::size_t from, const double* dq, const Pose* poses, int room,
                               MotionBound::StepCache& cache, std::uint64_t id) const noexcept;
  double pairStep(int a, int b, const double* dq, const Pose* poses, double d, MotionBound::StepCache& cache,
                  std::uint64_t id) const noexcept;

  int dim_ = 0, links_ = 0;
  // Names these tables for the caches made from them (by serial, not address: tables made after others
  // were freed may take their address).
  std::uint64_t serial_ = detail::nextSerial();
  std::vector<int> frame_;                        // per link: the link whose pose places it (a body's anchor)
  std::vector<double> link_coef_;                 // links × dim
  std::vector<double> link_coef_t_;               // the same, dim × links (MotionBound::links)
  std::vector<std::vector<int>> chain_;           // per link: the joints from the root, in order
  std::vector<std::vector<double>> prefix_;       // per link: running sum of step_ along its chain
  // Σ step_ over chain_[link][i + 1 .. j] (i = −1: from the start): a difference of the running sums where
  // they are finite; summed where an unbounded slide (a planar or floating joint without bounds) makes
  // them ∞, which a difference would turn into NaN.
  double offsets(int link, std::ptrdiff_t i, std::ptrdiff_t j) const noexcept {
    if (j <= i) return 0.0;
    const std::vector<double>& p = prefix_[link];
    if (std::isfinite(p[j])) return p[j] - (i >= 0 ? p[i] : 0.0);
    double sum = 0.0;
    for (std::ptrdiff_t m = i + 1; m <= j; ++m) sum += step_[chain_[link][m]];
    return sum;
  }
  std::vector<std::vector<double>> joint_reach_;  // per link: per joint of its chain, its reach to the link
  std::vector<double> radius_;                    // per link: farthest hull vertex from the link's origin
  std::vector<int> joint_var_;                    // per joint: the state entry that drives it, -1 if none
  // The arrays "per joint" below are per element: a joint of one variable is one element, a planar joint
  // three and a floating joint seven (see the constructor); chains list elements.
  enum class Kind : char { Revolute, Prismatic, Spin };
  std::vector<double> joint_mult_;                // per joint: |multiplier| of a mimic, kSpin for a spin, else 1
  std::vector<double> joint_sign_;                // per joint: the sign of a mimic's multiplier, else 1
  std::vector<char> kind_;                        // per joint: a Kind
  std::vector<int> joint_of_;                     // per joint: the robot's joint
  bool isSlide(int j) const noexcept { return kind_[j] == static_cast<char>(Kind::Prismatic); }
  std::vector<double> step_;                      // per joint: largest parent-to-child frame offset
  std::vector<Vec3> axis_;                        // per joint: unit axis in the joint (child link) frame
  std::vector<int> child_;                        // per joint: child link
  std::vector<Vec3> sphere_center_;               // per link: its bounding ball (link frame)
  std::vector<double> sphere_radius_;
  std::vector<double> exact_;  // links × joints: the link's farthest point from a revolute axis it is rigid with; else ∞
  double exactReach(int link, int joint) const noexcept { return exact_[static_cast<std::size_t>(link) * joint_var_.size() + joint]; }
};

MotionBound::Tables::Tables(const Scene& scene, const std::vector<Body>& bodies)
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
      joint_sign_.push_back(joint.isMimic() && joint.mimic.multiplier < 0.0 ? -1.0 : 1.0);
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
    return margins::roundedUp(r, hull ? radius_[link] + o.norm() : 0.0);
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
    const std::vector<int>& anchor = scene.rigidAnchors();  // (the same rigid bodies MotionChecker merges)
    for (int j = 0; j < joints; ++j) {
      const Joint& joint = model.joint(j);
      if (!still(j) || joint.parent_link < 0 || joint.child_link < 0) continue;
      // Held where the reference state has it (a held planar or floating joint has no limits to bound it).
      const double offset = relativePose(ctx.poses()[joint.parent_link], ctx.poses()[joint.child_link]).t.norm();
      for (const int e : elements_of[j]) step_[e] = e == elements_of[j].front() ? offset * (1.0 + margins::kRounding) : 0.0;
    }
    for (int e = 0; e < elements; ++e) {
      const Joint& joint = model.joint(joint_of_[e]);
      if (joint_var_[e] < 0 || kind_[e] != static_cast<char>(Kind::Revolute) || joint.child_link < 0 || joint.parent_link < 0)
        continue;
      const Pose& child = ctx.poses()[joint.child_link];  // the joint frame, turned by q about the axis
      const Vec3 point = child.t, dir = child.R * axis_[e];
      for (int l = 0; l < links_; ++l) {
        const int root = anchor[frame_[l]];
        if (root != anchor[joint.child_link] && root != anchor[joint.parent_link]) continue;
        const Pose& pose = ctx.poses()[frame_[l]];
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
      joint_reach_[i][k] = radius_[i] + offsets(i, static_cast<std::ptrdiff_t>(k), static_cast<std::ptrdiff_t>(n) - 1);
      joint_reach_[i][k] = std::min(joint_reach_[i][k], exactReach(i, chain_[i][k]));
    }
    for (std::size_t k = 0; k < n; ++k) {
      const int j = chain_[i][k];
      if (joint_var_[j] < 0 || joint_mult_[j] == 0.0) continue;  // (a mimic of multiplier 0 never moves)
      const double w = isSlide(j) ? 1.0 : joint_reach_[i][k];
      link_coef_[static_cast<std::size_t>(i) * dim_ + joint_var_[j]] += joint_mult_[j] * w;
    }
  }
  link_coef_t_.assign(link_coef_.size(), 0.0);
  for (int i = 0; i < links_; ++i)
    for (int v = 0; v < dim_; ++v)
      link_coef_t_[static_cast<std::size_t>(v) * links_ + i] = link_coef_[static_cast<std::size_t>(i) * dim_ + v];
}

bool MotionBound::Tables::translates(int a, int b, const double* dq) const noexcept {
  // Joints above the fork move both links alike; only the path between them matters.
  const std::size_t fork = forkOf(a, b);
  for (const int l : {a, b})
    for (std::size_t k = fork; k < chain_[l].size(); ++k) {
      const int j = chain_[l][k], v = joint_var_[j];
      if (v >= 0 && dq[v] != 0.0 && !isSlide(j)) return false;
    }
  return true;
}

bool MotionBound::Tables::translates(int link, const double* dq) const noexcept {
  for (const int j : chain_[link])
    if (joint_var_[j] >= 0 && dq[joint_var_[j]] != 0.0 && !isSlide(j)) return false;
  return true;
}

double MotionBound::Tables::link(int link, const double* dq) const noexcept {
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
struct MotionBound::Tables::DynamicBound {
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

// One link's terms of f and t: each sum its own, added to the pair's as a whole (so that a pair's bound is
// the same number whether its links' terms were walked now or kept from another pair at the same poses).
struct MotionBound::LinkTerms {
  double a = 0.0, c = 0.0, fixed = 0.0;  // DynamicBound's sums
  double cap[Tables::DynamicBound::kMax], gain[Tables::DynamicBound::kMax], excess[Tables::DynamicBound::kMax];
  int n = 0;
  double accel = 0.0, speed = 0.0;  // TwistBound's
  bool valid = true;
  // Empty again (the pieces' arrays need no clearing: only the first n count).
  void clear() noexcept { a = c = fixed = accel = speed = 0.0, n = 0, valid = true; }
  // Adds the terms to a pair's (or a link's) bounds.
  void addTo(Tables::DynamicBound& f, Tables::TwistBound& t) const noexcept {
    f.a += a, f.c += c, f.fixed += fixed;
    for (int i = 0; i < n; ++i) f.cap[f.n + i] = cap[i], f.gain[f.n + i] = gain[i], f.excess[f.n + i] = excess[i];
    f.n += n;
    t.valid = t.valid && valid;
    t.accel += accel;
    t.speed += speed;
  }
};

// The twist bound (TwistBound): the motion from the link's velocity field now, where the joints' speeds add
// as vectors, not as lengths. A revolute chain turns the link's points at w_k (the signed Δq_k) about axis k (unit u_k
// through o_k): dx/ds = Σ_k w_k·t_k with t_k = u_k × (x − o_k), a twist Ω × x + V, so on the link's ball (centre c,
// radius ρ) the speed now is at most v0 = |Ω × c + V| + |Ω|·ρ. Along the segment t_k turns with the frame
// of joint k (at most Σ_{j≤k} |w_j| radians per unit s) and changes inside it only as the joints below k
// move x, by at most Σ_{j>k} |w_j|·R_j; with |t_k| ≤ R_k (the static reach of the link from axis k),
// |d²x/ds²| ≤ A = Σ_k |w_k|·((Σ_{j≤k} |w_j|)·R_k + Σ_{j>k} |w_j|·R_j) anywhere. So no point moves farther than
// h·v0 + h²·A/2 for a step of h either way. Only for chains whose moving joints all turn (else not valid).
void MotionBound::Tables::addBounds(int link, std::size_t from, const double* dq, const Pose* poses, DynamicBound& f,
                                    TwistBound& t) const noexcept {
  LinkTerms terms;
  linkTerms(link, from, dq, poses, DynamicBound::kMax - f.n, terms);
  terms.addTo(f, t);
}

void MotionBound::Tables::linkTerms(int link, std::size_t from, const double* dq, const Pose* poses, int room,
                                    LinkTerms& f) const noexcept {
  const std::vector<int>& chain = chain_[link];
  const Vec3 center = poses[frame_[link]] * sphere_center_[link];
  const double rho = sphere_radius_[link];
  double after = 0.0;  // Σ w·R over the joints below k: γ_k
  // The twist: Ω, the field at the centre, A and the rounding's scale. A = Σ_k |w_k|·R_k·(|w_k| + 2·Σ_{j<k} |w_j|)
  // is summed here as Σ_k |w_k|·(|w_k|·R_k + 2·γ_k): terms ≥ 0 only, so an unbounded reach makes it ∞, never NaN.
  Vec3 omega = Vec3::Zero(), velocity = Vec3::Zero();
  double accel = 0.0, size = 0.0;
  for (std::size_t k = chain.size(); k-- > from;) {
    const int j = chain[k], v = joint_var_[j];
    if (v < 0 || dq[v] == 0.0 || joint_mult_[j] == 0.0) continue;  // (0·∞ would be NaN)
    const double w = joint_mult_[j] * std::abs(dq[v]);
    const double reach = isSlide(j) ? 1.0 : joint_reach_[link][k];
    if (kind_[j] != static_cast<char>(Kind::Revolute)) {  // slides, spins: static, and no twist
      f.a += w * reach;
      f.valid = false;
    } else {
      const Pose& frame = poses[child_[j]];
      const Vec3 u = frame.R * axis_[j], r = center - frame.t;
      const double now = std::min(reach, (r - r.dot(u) * u).norm() + rho);
      f.a += w * (f.n == room ? reach : now);
      if (f.n < room && now < reach && after > 0.0) {
        f.c += w * after;
        f.cap[f.n] = (reach - now) / after, f.gain[f.n] = w * after, f.excess[f.n] = w * (reach - now);
        ++f.n;
      }
      const double signed_w = joint_sign_[j] * w * (dq[v] < 0.0 ? -1.0 : 1.0);
      omega += signed_w * u;
      velocity += signed_w * u.cross(r);
      accel += w * (w * reach + 2.0 * after);
      size += w * (reach + rho);
    }
    after += w * reach;
  }
  f.fixed = after;
  f.accel = accel;
  // Rounding: the field's terms can cancel, so their sum's error is absolute, a few ulps of Σ |w_k|·(R_k + ρ)
  // at most; 1e-12 of it is far above.
  f.speed = velocity.norm() + omega.norm() * rho + margins::kRounding * size;
}

// A walk with room for `room` pieces that kept fewer than it allowed would be the same with any room above
// what it kept: the cap never bound. So an entry serves such rooms, or its own.
const MotionBound::LinkTerms& MotionBound::Tables::cachedTerms(int link, std::size_t from, const double* dq,
                                                               const Pose* poses, int room,
                                                               MotionBound::StepCache& cache,
                                                               std::uint64_t id) const noexcept {
  MotionBound::StepCache::Entry& e = cache.entries_[link];
  if (e.id == id && e.from == from && (e.room == room || (e.terms->n < e.room && e.terms->n < room))) return *e.terms;
  e.id = id, e.from = from, e.room = room;
  e.terms->clear();
  linkTerms(link, from, dq, poses, room, *e.terms);
  return *e.terms;
}

double MotionBound::Tables::linkStep(int link, const double* dq, const Pose* poses, double d, double extra) const noexcept {
  DynamicBound f;
  TwistBound t;
  addBounds(link, 0, dq, poses, f, t);
  f.a += extra, f.fixed += extra, t.speed += extra;  // (linear in h)
  return t.valid ? std::max(f.solve(d), t.solve(d)) : f.solve(d);
}

double MotionBound::Tables::TwistBound::solve(double d) const noexcept {
  if (!(d > 0.0)) return 0.0;
  // Rounding of the sums of products of metres and radians, and of the root below: relative, and far above it.
  constexpr double kMargin = margins::kBeyond;
  const double v0 = speed * kMargin, a = accel * kMargin;
  const double root = v0 + std::sqrt(v0 * v0 + 2.0 * a * d);
  if (!(root > 0.0)) return root == 0.0 ? INFINITY : 0.0;  // nothing moves; NaN proves nothing
  return 2.0 * d / root;
}

double MotionBound::Tables::pairStep(int a, int b, const double* dq, const Pose* poses, double d) const noexcept {
  // Watched from the fork: each link moves by the joints below it, from where their axes are now.
  const std::size_t fork = forkOf(a, b);
  DynamicBound f;
  TwistBound t;
  addBounds(a, fork, dq, poses, f, t);
  addBounds(b, fork, dq, poses, f, t);
  return t.valid ? std::max(f.solve(d), t.solve(d)) : f.solve(d);
}

double MotionBound::Tables::pairStep(int a, int b, const double* dq, const Pose* poses, double d,
                                     MotionBound::StepCache& cache, std::uint64_t id) const noexcept {
  const std::size_t fork = forkOf(a, b);
  DynamicBound f;
  TwistBound t;
  cachedTerms(a, fork, dq, poses, DynamicBound::kMax, cache, id).addTo(f, t);
  cachedTerms(b, fork, dq, poses, DynamicBound::kMax - f.n, cache, id).addTo(f, t);
  return t.valid ? std::max(f.solve(d), t.solve(d)) : f.solve(d);
}

template <class F>
bool MotionBound::Tables::forPath(int a, int b, F&& visit) const noexcept {
  // Joints shared by both chains move the pair rigidly. The others lie on the path a → fork → b, and
  // the pair may be watched from any link X on that path: the joints between a and X move a, the rest
  // move b. Each joint costs |Δq| times its reach to the link it moves (for a link above the joint, the
  // offsets up to the fork and down to that link); pair() takes the cheapest X, found in one sweep.
  const std::vector<int>& ca = chain_[a];
  const std::vector<int>& cb = chain_[b];
  const std::size_t na = ca.size(), nb = cb.size();
  const std::size_t fork = forkOf(a, b);
  if (na - fork + nb - fork > kMaxPath) return false;
  const std::ptrdiff_t shared = static_cast<std::ptrdiff_t>(fork) - 1;  // the last joint both chains share
  const double side_a = offsets(a, shared, static_cast<std::ptrdiff_t>(na) - 1);
  const double side_b = offsets(b, shared, static_cast<std::ptrdiff_t>(nb) - 1);
  const auto moving = [&](int j) { return joint_var_[j] >= 0 && joint_mult_[j] != 0.0; };  // (0·∞ would be NaN)
  for (std::size_t k = na; k-- > fork;) {
    if (!moving(ca[k])) continue;
    // From this joint up to the fork, then down to b.
    const double reach_b = radius_[b] + offsets(a, shared, static_cast<std::ptrdiff_t>(k)) + side_b;
    visit(ca[k], joint_reach_[a][k], std::min(reach_b, exactReach(b, ca[k])));
  }
  for (std::size_t k = fork; k < nb; ++k) {
    if (!moving(cb[k])) continue;
    const double reach_a = radius_[a] + offsets(b, shared, static_cast<std::ptrdiff_t>(k)) + side_a;
    visit(cb[k], std::min(reach_a, exactReach(a, cb[k])), joint_reach_[b][k]);
  }
  return true;
}

double MotionBound::Tables::cheapestSplit(const double* cost_a, const double* cost_b, std::size_t n) noexcept {
  // By a suffix sweep.
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

double MotionBound::Tables::pair(int a, int b, const double* dq) const noexcept {
  double cost_a[kMaxPath], cost_b[kMaxPath];
  std::size_t n = 0;
  const bool within = forPath(a, b, [&](int j, double reach_a, double reach_b) {
    const int v = joint_var_[j];
    if (dq[v] == 0.0) return;
    const double w = joint_mult_[j] * std::abs(dq[v]);
    cost_a[n] = (isSlide(j) ? 1.0 : reach_a) * w;
    cost_b[n] = (isSlide(j) ? 1.0 : reach_b) * w;
    ++n;
  });
  if (within) return cheapestSplit(cost_a, cost_b, n);
  // Beyond any real robot: watched from the fork.
  const std::size_t fork = forkOf(a, b);
  double bound = 0.0;
  for (int side = 0; side < 2; ++side) {
    const int l = side ? b : a;
    for (std::size_t k = fork; k < chain_[l].size(); ++k) {
      const int j = chain_[l][k], v = joint_var_[j];
      if (v >= 0 && dq[v] != 0.0 && joint_mult_[j] != 0.0)
        bound += joint_mult_[j] * std::abs(dq[v]) * (isSlide(j) ? 1.0 : joint_reach_[l][k]);
    }
  }
  return bound;
}


MotionBound::MotionBound(const Scene& scene, const std::vector<Body>& bodies)
    : t_(std::make_shared<const Tables>(scene, bodies)) {}
double MotionBound::link(int link, const double* dq) const noexcept { return t_->link(link, dq); }
double MotionBound::pair(int a, int b, const double* dq) const noexcept { return t_->pair(a, b, dq); }
void MotionBound::links(const double* dq, int count, double* out) const noexcept {
  // Tables::link's sums, state entry by entry over all bodies at once (link_coef_t_: contiguous per entry, so
  // the compiler's lanes do several bodies per step); entries that do not move are skipped, as link() does.
  const Tables& t = *t_;
  const int known = std::min(count, t.links_);
  std::fill(out, out + known, 0.0);
  std::fill(out + known, out + std::max(count, known), INFINITY);  // (no such body: no bound)
  for (int v = 0; v < t.dim_; ++v) {
    if (dq[v] == 0.0) continue;
    const double w = std::abs(dq[v]);
    const double* c = &t.link_coef_t_[static_cast<std::size_t>(v) * t.links_];
    for (int i = 0; i < known; ++i) out[i] += c[i] * w;
  }
}
MotionBound::PairPath MotionBound::path(int a, int b) const {
  PairPath p;
  p.a_ = a, p.b_ = b;
  const Tables& t = *t_;
  p.long_ = !t.forPath(a, b, [&](int j, double reach_a, double reach_b) {
    const bool slide = t.isSlide(j);
    p.joints_.push_back({t.joint_var_[j], t.joint_mult_[j], slide ? 1.0 : reach_a, slide ? 1.0 : reach_b});
  });
  return p;
}
double MotionBound::pair(const PairPath& path, const double* dq) const noexcept {
  if (path.long_) return t_->pair(path.a_, path.b_, dq);
  double cost_a[Tables::kMaxPath], cost_b[Tables::kMaxPath];
  std::size_t n = 0;
  for (const PairPath::Joint& j : path.joints_) {  // (as Tables::pair: the same products, the same sums)
    if (dq[j.var] == 0.0) continue;
    const double w = j.mult * std::abs(dq[j.var]);
    cost_a[n] = j.to_a * w;
    cost_b[n] = j.to_b * w;
    ++n;
  }
  return Tables::cheapestSplit(cost_a, cost_b, n);
}
double MotionBound::linkStep(int link, const double* dq, const Pose* poses, double d, double extra) const noexcept {
  return t_->linkStep(link, dq, poses, d, extra);
}
double MotionBound::pairStep(int a, int b, const double* dq, const Pose* poses, double d) const noexcept {
  return t_->pairStep(a, b, dq, poses, d);
}
double MotionBound::pairStep(int a, int b, const double* dq, const Pose* poses, double d, StepCache& cache,
                             std::uint64_t poses_id) const noexcept {
  if (cache.owner_ != t_->serial_) return t_->pairStep(a, b, dq, poses, d);  // (another robot's, or none's)
  return t_->pairStep(a, b, dq, poses, d, cache, poses_id);
}

MotionBound::StepCache MotionBound::makeStepCache() const {
  StepCache cache;
  cache.owner_ = t_->serial_;
  cache.entries_.resize(t_->links_);
  for (StepCache::Entry& e : cache.entries_) e.terms = std::make_shared<LinkTerms>();
  return cache;
}
bool MotionBound::linkTwist(int link, const double* dq, const Pose* poses, double& speed, double& accel) const noexcept {
  Tables::DynamicBound f;
  Tables::TwistBound t;
  t_->addBounds(link, 0, dq, poses, f, t);
  if (!t.valid) return false;
  speed = t.speed, accel = t.accel;
  return true;
}
bool MotionBound::translates(int a, int b, const double* dq) const noexcept { return t_->translates(a, b, dq); }
bool MotionBound::translates(int link, const double* dq) const noexcept { return t_->translates(link, dq); }
double MotionBound::linkCoefficient(int link, int v) const noexcept { return t_->link_coef_[link * t_->dim_ + v]; }

}  // namespace clearway
