// Certified mode: conservative advancement of every item over the segment (see motion.h), with Cast
// mode's shape casts ahead of it.
#include <clearway/motion/motion.h>

#include <clearway/body/proximity.h>
#include <clearway/detail/margins.h>
#include <clearway/kinematics/forward_kinematics.h>
#include <clearway/narrowphase/gjk.h>
#include <clearway/narrowphase/ray_cast.h>

#include <algorithm>
#include <iterator>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "motion_detail.h"

namespace clearway {

using motion_detail::alignedUnit;

void MotionChecker::castAhead(const double* q0, const double* q1, double t0, int n_items, motion_detail::Scratch& ctx,
                              MotionResult& r) const noexcept {
  const Scene& sc = *scene_;
  const Tolerances& tol = sc.options().tolerances;
  const double contact = options_.contact_distance;
  bool posed = false;
  for (int k = 0; k < n_items; ++k) {
    const Item& it = items_[k];
    if (it.group >= 0) continue;  // its group's coverage decides where it starts
    if (ctx.safe_until[k] != 0.0 || ctx.settled[k] != 0) continue;  // (a table or the rake settled some of it)
    const bool self = it.b >= 0;
    if (!self && ctx.obstacle_motion > 0.0) continue;  // (the cast holds obstacles still, where they are at t0)
    if (self ? !bound_.translates(it.a, it.b, ctx.dq.data()) : !bound_.translates(it.a, ctx.dq.data())) continue;
    if (!posed) {  // both ends' poses, once: the end's kept aside, the start's left in the scene context
      sc.computePoses(q1, ctx.scene);
      ctx.end_poses = ctx.scene.poses();
      sc.computePoses(q0, ctx.scene);
      posed = true;
    }
    const std::vector<Pose>& start = ctx.scene.poses();
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
      const CastQuery q{end[it.frame_a].t - start[it.frame_a].t, it.padding + contact, 1.0};
      first = sc.environment().linkCast(*it.ga, start[it.frame_a], tol, q,
                                        {t0, nullptr, nullptr, &ctx.scene.counters().environment});
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
  // Once the convex bounds are within contact, how far (in contact distances) the exact geometry is
  // measured: near fine meshes, a search farther out visits a great many triangles.
  static constexpr double kNear = 8.0;

  const MotionChecker& mc;
  motion_detail::Scratch& ctx;
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
  // The rake may place its finer levels' balls in lanes (the segment within the bounds the lanes were made
  // for), and the lane of the piece it is testing (−1: placed one piece at a time).
  bool points_in_lanes = false;
  int lane = -1;
  bool stop() const noexcept { return capped || (verdict_only && hit); }
  // The cap on distance queries reached, or the caller's stop condition true (asked every 256 queries).
  bool overBudget() const noexcept {
    if (r.distance_queries >= mc.options_.max_queries) return true;
    if ((r.distance_queries & 255) != 0 || !mc.options_.stop) return false;
    try {
      return mc.options_.stop();
    } catch (...) {  // (a condition that throws: stopping is the answer that is never wrong)
      return true;
    }
  }
  // The parameter each pose slot holds (−1: none), the steps they were placed at, the slot last placed or
  // looked up, and the slot the next new parameter takes (the one placed longest ago).
  double slot_s[motion_detail::Scratch::kPoseSlots];
  std::uint64_t slot_step[motion_detail::Scratch::kPoseSlots] = {};
  int slot = 0, next_slot = 0;
  // The last measurement's self item whose hulls' GJK axis separates them (splitClearances), −1: none.
  static constexpr std::size_t kSplit = 8;
  int split_item = -1;
  double clear_a[kSplit], clear_b[kSplit];

  Sweep(const MotionChecker& checker, motion_detail::Scratch& c, MotionResult& result, const double* from, const double* to)
      : mc(checker), ctx(c), r(result), q0(from), q1(to) {
    for (std::vector<Pose>& p : ctx.poses) p[0] = Pose::identity();
    std::fill(std::begin(slot_s), std::end(slot_s), -1.0);
  }

  // The time at parameter s.
  double time(double s) const noexcept { return t0 + s * (t1 - t0); }

  // The link's pose (and its ancestors') at parameter s, in the slot that holds s (placed there if none
  // does), which becomes `slot`.
  const Pose& pose(double s, int link) {
    if (s != slot_s[slot]) {
      int k = 0;
      while (k < motion_detail::Scratch::kPoseSlots && slot_s[k] != s) ++k;
      if (k == motion_detail::Scratch::kPoseSlots) {
        k = next_slot;
        next_slot = (next_slot + 1) % motion_detail::Scratch::kPoseSlots;
        mc.interpolate(q0, q1, s, ctx.q.data());
        const std::vector<int>& group = mc.scene_->groupVariables();
        for (std::size_t i = 0; i < group.size(); ++i) ctx.full_q[k][group[i]] = ctx.q[i];
        slot_step[k] = ++ctx.step_stamp;
        slot_s[k] = s;
        ++r.steps;
      }
      slot = k;
    }
    const RobotModel& model = mc.scene_->robot();
    Pose* poses = ctx.poses[slot].data();
    std::uint64_t* stamp = ctx.pose_stamp[slot].data();
    for (int l = link; l > 0 && stamp[l] != slot_step[slot]; l = model.parentLink(l)) {
      ctx.pose_path.push_back(l);
      stamp[l] = slot_step[slot];
    }
    if (!ctx.pose_path.empty()) {  // (root first)
      std::reverse(ctx.pose_path.begin(), ctx.pose_path.end());
      computeLinkPoses(model, ctx.full_q[slot].data(), poses, ctx.pose_path.data(),
                       static_cast<int>(ctx.pose_path.size()));
      ctx.pose_path.clear();
    }
    return poses[link];
  }

  // The poses of the parameter last measured at (its item's links and their ancestors placed).
  const Pose* measuredPoses() const noexcept { return ctx.poses[slot].data(); }

  // Where to measure [a, b]: its midpoint; but for a checker of many items, the coarsest dyadic fraction
  // in its middle half (the nearest such to the midpoint), so that items whose intervals differ share
  // parameters and so poses (the dual arm's 562 items: 16% fewer instructions per free segment, 10% per
  // colliding one). Not for a few items, which share little: there it moved the Panda's colliding segments
  // onto the quarters the probe had checked already, 6-10% dearer. The midpoint when the interval is too
  // narrow for a fraction of 2^-40.
  static constexpr std::size_t kAlignedItems = 64;
  double measuringPoint(double a, double b) const noexcept {
    const double w = b - a, lo = a + 0.25 * w, hi = b - 0.25 * w, mid = 0.5 * (a + b);
    if (mc.items_.size() <= kAlignedItems) return mid;
    for (double step = 0.5; step >= 0x1p-40 && w > 0.0; step *= 0.5) {  // (≤ 40 halvings: the loop ends)
      const double first = std::ceil(lo / step) * step;                 // (exact: step is a power of two)
      if (!(first <= hi)) continue;
      const double last = std::floor(hi / step) * step;
      return std::clamp(std::round(mid / step) * step, first, last);
    }
    return mid;
  }

  // Item k's motion bound for this segment (MotionChecker::itemBound), computed when first asked: the rake
  // settles most of a many-link robot's far pairs by their bodies' own motions (body_bound), and their
  // paths' bounds, a walk each, are then never needed (our dual arm: 595 self items every segment).
  double boundOf(int k) const noexcept {  // (ctx is a reference: the cache is the scratch's)
    if (ctx.bound_stamp[k] != ctx.segment) {
      ctx.bound[k] = mc.itemBound(k, ctx.dq.data(), ctx.obstacle_motion);
      ctx.bound_stamp[k] = ctx.segment;
    }
    return ctx.bound[k];
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

  // Item k's contact distance at s on this segment: contact_distance, or near an end closer than twice
  // that, half the end's clearance growing by kContactGrowth of the item's motion bound per unit of s
  // away from it (motion.h).
  double contactOf(int k, double s) const noexcept {
    const double c = mc.options_.contact_distance;
    if (ctx.contact_stamp[k] != ctx.segment) return c;
    const std::array<double, 2>& e = ctx.contact[k];
    if (!(e[0] < c) && !(e[1] < c)) return c;
    const double g = kContactGrowth * boundOf(k);  // (∞ for an unbounded motion: c away from the ends)
    const auto grown = [&](double end, double ds) { return ds > 0.0 ? end + g * ds : end; };
    return std::min({c, grown(e[0], s), grown(e[1], 1.0 - s)});
  }

  // measure(), and when item k first comes within contact on this segment, its ends' clearances: an end
  // closer than twice the contact distance lowers the item's contact distance near it (contactOf; never
  // to 0: an end that touches keeps it), and s is measured again. A state the validity checker accepts
  // can then be left. The loops still end, each ball being at least contactOf / B wide, and near an end
  // the balls grow geometrically (by about 2·kContactGrowth each), so an end a nanometre from contact
  // costs a few hundred measurements, not a crawl of contact-sized steps along the obstacle.
  double measureItem(int k, double s, double need, CollisionReport& report) {
    const double d = measure(k, s, need, report);
    if (!(d <= contactOf(k, s)) || ctx.contact_stamp[k] == ctx.segment) return d;
    const double c = mc.options_.contact_distance;
    ctx.contact_stamp[k] = ctx.segment;
    ctx.contact[k] = {c, c};
    const Item& it = mc.items_[k];
    if (it.last > it.first) return d;  // a group's members decide, each with its own ends
    // Only the verdict asked, and the state at s collides: the segment is not free whatever the ends'
    // clearances (a colliding state is within every contact distance), and the state check costs far less
    // than measuring the ends near contact, which climbs to their triangles.
    if (verdict_only && stateCollides(s, report)) return d;
    const double e0 = endClearance(k, 0.0);
    if (!(e0 > 0.0)) return d;  // an end that touches: every contact distance keeps it
    const double e1 = endClearance(k, 1.0);
    if (!(e1 > 0.0)) return d;
    if (!(0.5 * std::min(e0, e1) < c)) return d;
    ctx.contact[k] = {std::min(c, 0.5 * e0), std::min(c, 0.5 * e1)};
    return measure(k, s, need, report);
  }

  // True when the state at s collides as the validity checker sees it (then `report` says what).
  bool stateCollides(double s, CollisionReport& report) {
    ++r.steps;  // (the check places the scene context's poses, not the slots')
    return motion_detail::stateCollides(mc, q0, q1, s, time(s), ctx, report);
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
    if (overBudget()) capped = true;
    const Pose pa = pose(s, it.frame_a);
    double d;
    BoundQuery q;  // (no warm starts: an end's clearance must not depend on what was measured before)
    q.enough = cutoff;
    q.relative = relative;
    q.mode = exact ? GeometryMode::Mesh : GeometryMode::Hull;
    if (it.b >= 0) {
      d = BodyPair(*it.ga, *it.gb).lowerBound(pa, pose(s, it.frame_b), tol, q);
    } else {
      d = sc.environment().lowerBound(*it.ga, pa, tol, q,
                                      {time(s), nullptr, nullptr, &ctx.scene.counters().environment});
    }
    return d - it.padding;
  }

  // A certified lower bound on item k's clearance at s (padding removed), computed only as far as `need`
  // (beyond it, the answer only has to say so). A contact fills `report`.
  double measure(int k, double s, double need, CollisionReport& report) {
    const Scene& sc = *mc.scene_;
    const Tolerances& tol = sc.options().tolerances;
    const double contact = contactOf(k, s), relative = mc.options_.distance_relative_error;
    // Below the scene's contact distance (an end of the segment is that near), only distances decide: an
    // intersection test within it would count the narrow phase's band as contact.
    const bool lowered = contact < mc.options_.contact_distance;
    const bool exact = sc.options().mode != GeometryMode::Hull;
    const Item& it = mc.items_[k];
    const bool head = it.last > it.first;  // a group stops at the merged hulls: its members decide the rest
    ++r.distance_queries;
    split_item = -1;
    need = std::max(need, 2.0 * contact);  // a clearance must exceed the contact distance to count
    // The ladder (body/proximity.h), climbed only while within contact: a clearance beyond it is all a ball
    // needs. A group stops at its merged hulls; its members decide the rest.
    BoundQuery q;
    q.enough = need + it.padding;
    q.relative = relative;
    q.mode = exact && !head ? GeometryMode::Mesh : GeometryMode::Hull;
    q.climb = it.padding + contact;
    q.within = lowered ? -1.0 : it.padding + contact;
    q.near = it.padding + kNear * contact;
    const Pose pa = pose(s, it.frame_a);
    double d;
    if (it.b >= 0) {
      const Pose& pb = pose(s, it.frame_b);
      if (ctx.pair_stamp[k] != ctx.segment) {  // (its first measurement on this segment: no warm start)
        ctx.pairs[k].forget();
        ctx.pair_stamp[k] = ctx.segment;
      }
      d = ctx.pairs[k].lowerBound(pa, pb, tol, q) - it.padding;
      // (The hulls' last GJK axis, this measurement's or an earlier one's, where the hulls cleared it. Not in
      // Hull mode: the parts hold the triangles, not all of the hull that decides there.)
      if (d > contact && ctx.pairs[k].lastRung() <= Rung::Hulls && exact) split_item = k;
      if (d <= contact && !head) {
        report = CollisionReport{};
        report.kind = CollisionReport::Kind::Self;
        report.link = it.a;
        report.other_link = it.b;
      }
    } else {
      const double t = time(s);  // where moving obstacles are
      const int e = k - mc.env_begin_;
      // (A context made for another version of the environment has blocks of another size: no warm starts.)
      SimplexCache* warm = ctx.warm_obstacles == sc.environment().staticCount()
                               ? warmStarts(ctx.env_cache, ctx.env_slot[e], ctx.env_stamp[e], ctx.warm_obstacles)
                               : nullptr;
      EnvironmentHit hit;  // the item the bound came from: within contact when d is
      d = sc.environment().lowerBound(*it.ga, pa, tol, q, {t, warm, &hit, &ctx.scene.counters().environment}) -
          it.padding;
      if (d <= contact && !head) {
        report = CollisionReport{};
        report.kind = CollisionReport::Kind::Environment;
        report.link = it.a;
        report.hit = hit;
      }
    }
    if (overBudget()) capped = true;
    return d;
  }

  // Self item k's parts' clearances from the other link, from the hulls' separating plane: any unit u gives,
  // for a part of A whose points reach at most P_i along u and a B whose points start at Q, a clearance of
  // at least Q − P_i (the last GJK axis makes it tight for the nearest part); never below d, the hulls'.
  // False when there is no axis or too many parts.
  bool splitClearances(int k, double d) {
    const Item& it = mc.items_[k];
    const SimplexCache& cache = ctx.pairs[k].hullAxis();
    const std::vector<LinkGeometry::Part>& parts_a = it.ga->parts();
    const std::vector<LinkGeometry::Part>& parts_b = it.gb->parts();
    if (!cache.valid || parts_a.size() > kSplit || parts_b.size() > kSplit) return false;
    const Pose& pa = measuredPoses()[it.frame_a];
    const Pose& pb = measuredPoses()[it.frame_b];
    const Vec3 u_a = -cache.axis.normalized();  // A towards B, in A's frame
    const Vec3 u = pa.R * u_a, u_b = pb.R.transpose() * u;
    if (!u.allFinite()) return false;
    std::int32_t hint_a = cache.hint_a, hint_b = cache.hint_b;
    const double p = u.dot(pa.t) + u_a.dot(it.ga->hull().support(u_a, hint_a));
    const double q = u.dot(pb.t) + u_b.dot(it.gb->hull().support(-u_b, hint_b));
    // Rounding: each term is a dot product of coordinates of a few metres at most.
    const double slack = it.padding + margins::kRounding * (1.0 + std::abs(p) + std::abs(q));
    for (std::size_t i = 0; i < parts_a.size(); ++i)  // (d first in max(): a NaN plane leaves d)
      clear_a[i] = std::max(d, q - std::min(p, u.dot(pa * parts_a[i].center) + parts_a[i].radius) - slack);
    for (std::size_t j = 0; j < parts_b.size(); ++j)
      clear_b[j] = std::max(d, std::max(q, u.dot(pb * parts_b[j].center) - parts_b[j].radius) - p - slack);
    return true;
  }

  // Self item k's parts' motion bounds against the other link, for this segment: a's parts, then b's.
  const double* splitBounds(int k) {
    double* bound = ctx.split_bound.data() + ctx.split_slot[k];
    if (ctx.split_stamp[k] != ctx.segment) {
      const std::vector<MotionBound::PairPath>& paths = mc.split_paths_[k];
      for (std::size_t i = 0; i < paths.size(); ++i) bound[i] = mc.bound_.pair(paths[i], ctx.dq.data());
      ctx.split_stamp[k] = ctx.segment;
    }
    return bound;
  }

  // A ball keeps back kHeldBack of its reach: over the rest, the item's motion uses at most 1 − kHeldBack of
  // the clearance d measured at its centre (the bounds are convex in the step and 0 at 0), so every point
  // it covers stays kHeldBack·d clear. That is the margin a segment certified free reports
  // (MotionResult::margin). A measurement asks for kAskMore of what its ball must reach, so that the share
  // held back does not leave a sliver to measure again.
  static constexpr double kHeldBack = 0x1p-12;
  static constexpr double kAskMore = 1.0 + 0x1p-11;
  double min_clear = INFINITY;  // the least clearance a ball was formed from

  // The clearance item k's ball must have to reach `width` either way, as a measurement asks for it.
  double asked(int k, double width) const noexcept { return boundOf(k) * width * kAskMore; }

  // How far from s a clearance d of item k reaches, either way, with kHeldBack of it kept back. Beyond
  // `want` nothing is asked.
  double reach(int k, double d, double want) {
    min_clear = std::min(min_clear, d);
    return fullReach(k, d, want * kAskMore) * (1.0 - kHeldBack);
  }

  // reach() before the share kept back. Only short of `want` does a self item look at its links' parts:
  // where the near part lies close to the axes that turn it, the far parts' larger clearances make up for
  // their larger motion.
  double fullReach(int k, double d, double want) {
    const Item& it = mc.items_[k];
    const double* dq = ctx.dq.data();
    const Pose* poses = measuredPoses();  // (at the parameter d was measured at)
    // The static bound first: where it reaches as far as asked, the reaches from the axes now are not needed.
    double h = d / boundOf(k);                              // (∞ when the item does not move)
    if (std::isnan(h)) h = d == INFINITY ? INFINITY : 0.0;  // (∞ / ∞: nothing near, and an unbounded motion)
    if (!(h < want)) return h;
    if (it.b < 0) return std::max(h, mc.bound_.linkStep(it.a, dq, poses, d, ctx.obstacle_motion));
    // (With many items, pairs share links and parameters, and so the walks of their links' chains.)
    h = std::max(h, mc.items_.size() > kAlignedItems
                        ? mc.bound_.pairStep(it.a, it.b, dq, poses, d, ctx.step_cache, slot_step[slot])
                        : mc.bound_.pairStep(it.a, it.b, dq, poses, d));
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
    const double d = measureItem(k, s, asked(k, half), report);
    if (d > contactOf(k, s)) return reach(k, d, half);
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

  // Covers [a, b] ∩ [0, limit] for item k (all of [0, a) is covered already, except for a verdict, which
  // needs no order: any contact settles it).
  void cover(int k, double a, double b, double witness) {
    const Item& it = mc.items_[k];
    const std::size_t base = ctx.intervals.size();
    ctx.intervals.push_back({a, b, witness});
    CollisionReport report;
    while (ctx.intervals.size() > base && !stop()) {
      const motion_detail::Scratch::Interval iv = ctx.intervals.back();
      ctx.intervals.pop_back();
      double m = 0.0, hi = 0.0;
      if (measureOnce(k, iv, ctx.intervals, m, hi, report) != Measured::Contact) continue;
      if (it.last > it.first) {  // a group within contact: its members take over here, exactly
        for (int member = it.first; member < it.last && !stop(); ++member) cover(member, iv.a, hi, iv.witness);
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
    }
    ctx.intervals.resize(base);
  }

  // One step of covering item k: interval iv, cut at the limit, measured at its measuring point m (up to
  // hi, its end within the limit). Within contact there: Contact. Else Clear, and what the ball there
  // leaves of iv pushed on `stack`, the left part on top. Skipped (nothing measured) past the limit.
  enum class Measured { Skipped, Clear, Contact };
  Measured measureOnce(int k, const motion_detail::Scratch::Interval& iv,
                       std::vector<motion_detail::Scratch::Interval>& stack, double& m, double& hi,
                       CollisionReport& report) {
    hi = std::min(iv.b, limit);
    if (iv.a > hi || (hit && iv.a >= hi)) return Measured::Skipped;
    m = measuringPoint(iv.a, hi);
    const double d = measureItem(k, m, asked(k, std::max(m - iv.a, hi - m)), report);
    if (d <= contactOf(k, m)) return Measured::Contact;
    const double rad = reach(k, d, std::max(m - iv.a, hi - m));
    // Left first (popped first), so that advancement starts clear of everything before it. A verdict
    // keeps each item's order (its turns, coverInTurns, take its intervals as cover() does): then it
    // measures what the located check measures until a contact, so the two agree even where the contact
    // distance grows along the segment (near an end), where another order's balls could miss a
    // measurement within it that this order makes.
    if (m + rad < hi) stack.push_back({m + rad, hi, m});
    if (m - rad > iv.a) stack.push_back({iv.a, m - rad, iv.witness});
    return Measured::Clear;
  }

  // A verdict's covers of many items, in turns: each item's intervals on a stack of its own (cover's), one
  // measurement an item a turn, so that the item within contact is met after a few measurements of every
  // item, not after all of those before it (a shortcut past a shelf: a finger kept 2–9 mm from a board for
  // thirty measurements before the next finger, through the board, was measured at all). Each item measures
  // what cover() would, in the same order: a free segment costs the same. queue() adds an interval, under
  // those queued before (cover() covers them one after another, each in full); coverInTurns() covers them
  // all, or stops at the first contact.
  void queue(int k, double a, double b, double witness) {
    std::vector<motion_detail::Scratch::Interval>& stack = ctx.turn_stacks[k];
    if (stack.empty()) ctx.turns.push_back(k);
    stack.insert(stack.begin(), {a, b, witness});
  }
  void coverInTurns() {
    while (ctx.turn_head < ctx.turns.size() && !stop()) {
      const int k = ctx.turns[ctx.turn_head++];
      takeTurn(k);
      if (!ctx.turn_stacks[k].empty()) ctx.turns.push_back(k);
      if (ctx.turn_head >= 1024 && 2 * ctx.turn_head >= ctx.turns.size()) {  // (the turns taken: dropped)
        ctx.turns.erase(ctx.turns.begin(), ctx.turns.begin() + static_cast<std::ptrdiff_t>(ctx.turn_head));
        ctx.turn_head = 0;
      }
    }
    for (std::size_t i = ctx.turn_head; i < ctx.turns.size(); ++i) ctx.turn_stacks[ctx.turns[i]].clear();
    ctx.turns.clear();
    ctx.turn_head = 0;
  }
  // Item k's turn: one measurement of cover()'s loop (a group within contact hands the interval to its
  // members, which take turns of their own).
  void takeTurn(int k) {
    const Item& it = mc.items_[k];
    std::vector<motion_detail::Scratch::Interval>& stack = ctx.turn_stacks[k];
    CollisionReport report;
    while (!stack.empty() && !stop()) {
      const motion_detail::Scratch::Interval iv = stack.back();
      stack.pop_back();
      double m = 0.0, hi = 0.0;
      const Measured measured = measureOnce(k, iv, stack, m, hi, report);
      if (measured == Measured::Skipped) continue;
      if (measured == Measured::Contact && it.last > it.first) {
        for (int member = it.first; member < it.last; ++member) queue(member, iv.a, hi, iv.witness);
      } else if (measured == Measured::Contact) {
        found(m, report);
        ctx.lead = it.group >= 0 ? it.group : k;
        stack.clear();
      }
      return;
    }
  }

  // Conservative advancement of item k from a (clear at `witness`) towards `until`: true when it meets a
  // contact there (which becomes the limit); false when [a, until] is clear.
  bool advance(int k, double a, double witness, double until) {
    CollisionReport report;
    double s = a, prev = std::max(witness, 0.0), prev_d = 0.0;  // the clearance measured at prev (0: none)
    while (!capped) {
      const double d = measureItem(k, s, asked(k, until - s), report);
      if (d <= contactOf(k, s)) {
        if (!hit || s < limit) {
          limit = s;
          hit = true;
          ++contacts;
          // The last parameter known free: past prev, as long as the step's bound still leaves half the
          // contact distance. (Both reaches come from bounds convex in the step and 0 at 0: the motion
          // over a fraction λ of the step is at most λ·prev_d.)
          const double contact = contactOf(k, prev);  // (prev_d was beyond it)
          clear_before = prev_d > contact ? prev + (s - prev) * (1.0 - 0.5 * contact / prev_d) : prev;
          r.report = report;
        }
        return true;
      }
      prev = s;
      prev_d = d;
      s += reach(k, d, until - s);  // at least contactOf(k, s) / B > 0: the loop ends
      if (!(s < until)) return false;
    }
    return false;
  }

  // ---- The rake: bounding balls on pieces of the segment, before any distance is measured ----
  // Piece [m − h, m + h] is settled for item k when, at m, its bodies' bounding balls are farther apart (for
  // the environment: farther from the obstacles' boxes) than padding + contact_distance + B·h, B the item's
  // motion bound: over the piece neither body moves more than B·h relative to the other, so the clearance
  // stays beyond contact_distance, the largest contactOf can be. Pieces split from the whole segment to
  // sixteenths, and only while the balls at the middle clear the contact distance: an item whose balls meet
  // there is near, and is left to the distances (one test spent). A piece costs one subtraction and a
  // squared norm where a measurement costs a ladder of GJKs; the whole segment's one pose serves every item,
  // and a finer level's balls are placed for all its pieces at once in float lanes (placeInLanes). Where
  // a slender self pair's balls leave a piece, its hulls' boxes, apart by the same reach, may settle it.
  static constexpr int kRakeLevels = motion_detail::Scratch::kRakeLevels;
  static constexpr int kRakePieces = 1 << (kRakeLevels - 1);  // the finest pieces: bits of ctx.settled[k]
  using Bits = motion_detail::Scratch::RakeBits;
  static constexpr Bits kRakeAll = static_cast<Bits>((1u << kRakePieces) - 1u);
  static_assert(kRakePieces <= 8 * sizeof(Bits), "settled pieces are bits of RakeBits");

  enum class Raked { Settled, Halve, Near };
  // Body `body`'s bounding ball at the rake's current piece (placed once per piece: bodies share items),
  // grown by the rounding of its placed centre and of its radius (margins.h).
  // At a level placed in lanes (lane ≥ 0), its centre is the lanes' and the radius grows by their error bound.
  const motion_detail::Scratch::RakeBall& rakeBall(int body, int frame, const LinkGeometry& g, double s) {
    motion_detail::Scratch::RakeBall& b = ctx.rake_balls[body];
    if (b.piece != ctx.rake_piece || b.geometry != &g) {  // (an index names one geometry; checked, not assumed)
      const int k = lane >= 0 ? mc.rake_point_[body] : -1;
      if (k >= 0 && mc.rake_point_geometry_[body] == &g) {
        constexpr int L = PointLanes::kLanes;  // (lanes of L pieces each, a pass after another)
        const float* x = ctx.rake_xyz.data() + 3 * (mc.rake_points_.size() * (lane / L) + k) * L + lane % L;
        b.center = Vec3(x[0], x[L], x[2 * L]);
        b.radius = g.sphereRadius() * (1.0 + margins::kRounding) + mc.rake_points_.error(k);
      } else {
        const Pose& p = pose(s, frame);
        b.center = p * g.sphereCenter();
        b.radius = g.sphereRadius() * (1.0 + margins::kRounding) +
                   margins::placedRounding(g.sphereCenter().norm(), p.t.norm());
      }
      b.norm = b.center.norm();
      b.piece = ctx.rake_piece;
      b.geometry = &g;
    }
    return b;
  }
  // Whether self item `it`'s hulls' boxes, as oriented boxes, are farther apart than `reach` (beyond their own
  // band) at s: tighter than the balls for slender links (a forearm beside the base). (Out of line: the rake's
  // test stays as compact for the items that never ask it.)
  [[gnu::noinline]] bool boxesApartAt(const Item& it, double s, double reach) {
    const Pose pa = pose(s, it.frame_a);
    const Pose b_in_a = relativePose(pa, pose(s, it.frame_b));
    return b_in_a.isFinite() && boxesApart(*it.ga, *it.gb, b_in_a, mc.scene_->options().tolerances, reach);
  }
  // Whether item k's bounding balls at s settle the piece s ± half: apart (for the environment: clear of the
  // obstacles' and the map's boxes, Environment::ballClear) by more than padding + contact + B·half; else,
  // unless `last` (no halves follow), whether they are by more than padding + contact (the piece's halves
  // may be), or near.
  Raked rakeTest(int k, double s, double half, bool last, bool loose_tried = false) {
    const Item& it = mc.items_[k];
    const Scene& sc = *mc.scene_;
    const Tolerances& tol = sc.options().tolerances;
    const double contact = it.padding + mc.options_.contact_distance;
    const motion_detail::Scratch::RakeBall& a = rakeBall(it.a, it.frame_a, *it.ga, s);
    if (it.b >= 0) {
      const motion_detail::Scratch::RakeBall& b = rakeBall(it.b, it.frame_b, *it.gb, s);
      // |ca − cb| beyond both radii, the padding, the contact distance and (to settle) the motion, with the
      // narrow phase's band (as BodyPair's first rung) and the rounding of the squares and sums added.
      const double band = margins::narrowBand(tol.gjk_absolute) + margins::kRounding;
      const double d2 = (a.center - b.center).squaredNorm();
      const auto test = [&](double motion) {
        const double near =
            a.radius + b.radius + contact + band * (a.norm + b.norm + a.radius + b.radius + contact + motion);
        const double far = near + motion;
        return d2 > far * far ? Raked::Settled : d2 > near * near ? Raked::Halve : Raked::Near;
      };
      // Until the pair's bound is known, the bodies' own motions: their sum bounds the pair's (the cheapest
      // split of the same joints' terms between the two) and costs two loads where the pair's walks its path;
      // it settles most far pairs (one arm against the other).
      if (!loose_tried && ctx.bound_stamp[k] != ctx.segment) {
        const double loose = (ctx.body_bound[it.a] + ctx.body_bound[it.b]) * half;
        if (loose < INFINITY && test(loose) == Raked::Settled) return Raked::Settled;
      }
      const double motion = boundOf(k) * half;
      if (!(motion < INFINITY)) return Raked::Near;  // (∞ or NaN: nothing is settled)
      const Raked t = test(motion);
      return t == Raked::Settled || !it.boxes || !boxesApartAt(it, s, contact + motion) ? t : Raked::Settled;
    }
    const double motion = boundOf(k) * half;
    if (!(motion < INFINITY)) return Raked::Near;
    const Environment& env = sc.environment();
    if (ctx.obstacle_motion > 0.0) return Raked::Near;
    const double grown = (a.radius + motion) * margins::kBeyond;
    const double slack = env.linkSlack(contact, a.center.cwiseAbs().maxCoeff() + grown, tol);
    if (env.ballClear(a.center, grown, slack)) return Raked::Settled;
    return !last && env.ballClear(a.center, a.radius, slack) ? Raked::Halve : Raked::Near;
  }

  // rakeTest's first test, by the bodies' own motions, of every self item at once in SIMD lanes, at the piece
  // s ± half: each body's bounding ball grown by how far it moves over the piece (body_bound·half), the pair
  // padded by its padding and the contact distance (the rows'), beyond the same band. rakeTest's bound, by the
  // same formula summed in another order (the band's kRounding holds the difference); an item apart here is
  // settled over the piece, the others go to rakeTest. Fills ctx.rake_apart (per pair of mc.rake_rows_).
  void rakeInLanes(double s, double half) {
    for (const MotionChecker::RakeBody& body : mc.rake_bodies_) {
      const motion_detail::Scratch::RakeBall& b = rakeBall(body.body, body.frame, *body.geometry, s);
      const int i = body.body;
      ctx.rake_x[i] = b.center.x(), ctx.rake_y[i] = b.center.y(), ctx.rake_z[i] = b.center.z();
      ctx.rake_r[i] = b.radius + ctx.body_bound[i] * half;  // (∞ or NaN: never apart)
      ctx.rake_norm[i] = b.norm;
    }
    const double band = margins::narrowBand(mc.scene_->options().tolerances.gjk_absolute) + margins::kRounding;
    mc.rake_rows_.apart(ctx.rake_x.data(), ctx.rake_y.data(), ctx.rake_z.data(), ctx.rake_r.data(),
                        ctx.rake_norm.data(), band, ctx.rake_apart.data());
  }
  // The bodies' ball centres at the middle of each of the level's `pieces` pieces (of width 2·half), in float
  // lanes: one pass where each piece's poses cost a pass of double kinematics. (Not for the whole segment:
  // its one piece's poses serve the first measurement, in its middle, too.)
  void placeInLanes(int pieces, double half) {
    constexpr int L = PointLanes::kLanes;
    const std::vector<int>& group = mc.scene_->groupVariables();
    const double* q[L];
    for (int first = 0; first < pieces; first += L) {
      const int n = std::min(L, pieces - first);
      for (int l = 0; l < n; ++l) {
        mc.interpolate(q0, q1, (2 * (first + l) + 1) * half, ctx.q.data());
        std::vector<double>& full = ctx.rake_lane_q[l];
        for (std::size_t i = 0; i < group.size(); ++i) full[group[i]] = ctx.q[i];
        q[l] = full.data();
      }
      const std::size_t pass = static_cast<std::size_t>(3 * mc.rake_points_.size() * L) * (first / L);
      mc.rake_points_.compute(q, n, ctx.rake_xyz.data() + pass, ctx.rake_lane_scratch.data());
    }
  }

  // Self items due at the first piece from which the lanes pay: they place every body's ball and test every
  // pair, a few operations each (our dual arm's 500-odd pairs: 2.3% fewer instructions per free segment; the
  // Panda's and UR5's few due pairs would gain nothing).
  static constexpr int kLanesFrom = 32;

  // Fills ctx.settled for items [0, n_items) whose coverage starts at 0 (not the groups' members), level by
  // level, each piece's items at once (one set of poses).
  void rake(int n_items) {
    std::vector<int>& due = ctx.rake_items;
    std::vector<int>& next = ctx.rake_items_next;
    due.clear();
    for (int k = 0; k < n_items; ++k) {
      ctx.settled[k] = 0;
      ctx.rake_now[k] = 1;
      if (mc.items_[k].group < 0 && ctx.safe_until[k] == 0.0) due.push_back(k);
    }
    // The levels tested: the whole segment, quarters, sixteenths (their balls placed in lanes: eighths in
    // between, or thirty-seconds after, cost more than the distance queries they save). Halves settled too
    // little to pay for their poses (free motions: 2% fewer instructions without them on the shared Panda, 1%
    // on the UR5); the finest level only, too much of a segment left in short runs (50% more).
    static constexpr int kLevels[] = {0, 2, kRakeLevels - 1};
    constexpr int kSteps = sizeof(kLevels) / sizeof(kLevels[0]);
    for (int step = 0; step < kSteps && !due.empty(); ++step) {
      const int level = kLevels[step];
      const int pieces = 1 << level, width = kRakePieces / pieces;  // (width in finest pieces)
      const double half = 0.5 / pieces;
      const bool last = step + 1 == kSteps;
      const int span = last ? 1 : 1 << (kLevels[step + 1] - level);  // the next step's pieces per piece
      next.clear();
      for (const int k : due) ctx.rake_next[k] = 0;
      bool lanes = false;
      if (step == 0 && mc.rake_rows_.size() >= kLanesFrom) {  // (the first piece: every due item tests it)
        int self = 0;
        for (const int k : due) self += mc.rake_pair_[k] >= 0;
        lanes = self >= kLanesFrom;
      }
      const bool placed = points_in_lanes && step > 0;
      if (placed) placeInLanes(pieces, half);
      for (int p = 0; p < pieces; ++p) {
        const double m = (2 * p + 1) * half;  // (exact: dyadic)
        ++ctx.rake_piece;
        lane = placed ? p : -1;
        if (lanes) rakeInLanes(m, half);
        for (const int k : due) {
          if (!(ctx.rake_now[k] >> p & 1u)) continue;
          const int pair = lanes ? mc.rake_pair_[k] : -1;
          const Raked t = pair >= 0 && ctx.rake_apart[pair] ? Raked::Settled : rakeTest(k, m, half, last, pair >= 0);
          if (t == Raked::Settled) {
            ctx.settled[k] |= static_cast<Bits>(((1u << width) - 1u) << (p * width));
          } else if (t == Raked::Halve && !last) {
            if (ctx.rake_next[k] == 0) next.push_back(k);
            ctx.rake_next[k] |= static_cast<Bits>(((1u << span) - 1u) << (span * p));
          }
        }
      }
      lane = -1;
      for (const int k : next) ctx.rake_now[k] = ctx.rake_next[k];
      std::swap(due, next);
    }
    for (int k = 0; k < n_items; ++k)
      if (ctx.settled[k] == kRakeAll) ctx.safe_until[k] = 2.0;  // (beyond 1: covered)
  }

  // Covers what the rake left of item k: each run of pieces it did not settle, left first (a run after a
  // settled piece starts where the item is certified clear).
  template <class Cover>
  static void coverUnsettled(int k, Bits settled, Cover&& cover) {
    for (int i = 0; i < kRakePieces;) {
      if (settled >> i & 1u) {
        ++i;
        continue;
      }
      int j = i;
      while (j < kRakePieces && !(settled >> j & 1u)) ++j;
      const double a = static_cast<double>(i) / kRakePieces, b = static_cast<double>(j) / kRakePieces;
      cover(k, a, b, i > 0 ? a : -1.0);
      i = j;
    }
  }
};

double MotionChecker::itemBound(int k, const double* dq, double obstacle_motion) const noexcept {
  return items_[k].b >= 0 ? bound_.pair(paths_[k], dq) : bound_.link(items_[k].a, dq) + obstacle_motion;
}

MotionResult MotionChecker::certified(const double* q0, double t0, const double* q1, double t1, motion_detail::Scratch& ctx,
                                      bool locate_contact) const noexcept {
  MotionResult r;
  const Scene& sc = *scene_;
  // q0's collisions are found by the items' coverage of the segment, except those no state changes.
  // (first_contact = last_valid = 0)
  if (!sc.validState(q0)) {
    r.report.kind = CollisionReport::Kind::Invalid;
    return r;
  }
  if (sc.staticCollision().kind != CollisionReport::Kind::None) {
    r.report = sc.staticCollision();
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
  // threads, and a later re-check of its path, must agree even on pairs within the contact distance). The
  // pairs' and the obstacles' warm starts are emptied as their items are first measured (pair_stamp).
  ++ctx.segment;
  // How far moving obstacles travel over the segment (per unit of s): it adds to every environment item's
  // motion; none unless the scene declares them.
  const bool timed = sc.effects().moving && sc.environment().hasMovingObstacles();
  if (!timed) t0 = t1 = 0.0;
  ctx.obstacle_motion = timed ? obstacle_speed_ * std::abs(t1 - t0) : 0.0;
  if (!std::isfinite(ctx.obstacle_motion) || !std::isfinite(t0)) {
    r.report.kind = CollisionReport::Kind::Invalid;
    return r;
  }
  if (!locate_contact && motion_detail::probeCollides(*this, q0, t0, q1, t1, ctx, r)) return r;
  // (After the probe: a segment it settles needs no bounds.) Members wait until their group comes within contact.
  // (Their motion bounds are computed as the sweep first asks: Sweep::boundOf.)
  for (int k = 0; k < n_items; ++k)
    if (items_[k].group < 0) ctx.safe_until[k] = 0.0;
  if (options_.rake) bound_.links(ctx.dq.data(), static_cast<int>(ctx.body_bound.size()), ctx.body_bound.data());
  // Self items whose tables prove them apart along the whole segment are not swept.
  bool ends_set = false;
  for (int k = 0; k < std::min(n_items, env_begin_); ++k) {
    if (item_tables_[k].empty() || items_[k].group >= 0) continue;
    if (!ends_set) {
      const std::vector<int>& group = sc.groupVariables();
      for (int e = 0; e < 2; ++e) {
        ctx.ends[e] = ctx.scene.jointValues();  // (the variables outside the group at their held values)
        for (std::size_t i = 0; i < group.size(); ++i) ctx.ends[e][group[i]] = (e ? q1 : q0)[i];
      }
      ends_set = true;
    }
    bool apart = true;
    for (const auto& t : item_tables_[k]) apart = apart && t->freeAlong(ctx.ends[0].data(), ctx.ends[1].data());
    if (apart) ctx.safe_until[k] = 2.0;  // (beyond 1: covered)
  }
  Sweep sweep{*this, ctx, r, q0, q1};
  sweep.t0 = t0, sweep.t1 = t1;
  sweep.verdict_only = !locate_contact;
  sweep.points_in_lanes = rake_points_.serves() && !end_invalid && quaternions_.empty();
  // The item that met the last contact goes first: a planner's next segment often meets it again, and a
  // contact found early bounds every other item's work.
  const int lead = ctx.lead >= 0 && ctx.lead < n_items && items_[ctx.lead].group < 0 ? ctx.lead : -1;
  // (A verdict covers the items after the lead in turns, Sweep::coverInTurns. The lead goes first in full:
  // in turns with the others, a planner's colliding motions cost more queries where the lead meets the
  // contact again after a long cover, bookshelf_small_panda's shortcuts 18.5 a motion against 31.8.)
  bool in_turns = false;
  const auto cover = [&](int k, double a, double b, double witness) {
    if (in_turns) return sweep.queue(k, a, b, witness);
    const int before = sweep.contacts;
    sweep.cover(k, a, b, witness);
    if (sweep.contacts > before) ctx.lead = k;
  };
  // The bounding balls settle the pieces of the segment they can before any distance is measured.
  if (options_.rake) {
    sweep.rake(n_items);
  } else {
    std::fill(ctx.settled.begin(), ctx.settled.begin() + n_items, 0);
  }
  if (options_.mode == MotionMode::Cast) castAhead(q0, q1, t0, n_items, ctx, r);
  if (lead >= 0 && ctx.settled[lead] != 0 && ctx.safe_until[lead] <= 1.0) {
    Sweep::coverUnsettled(lead, ctx.settled[lead], cover);
  } else if (lead >= 0 && ctx.safe_until[lead] <= 1.0) {
    cover(lead, ctx.safe_until[lead], 1.0, ctx.safe_until[lead] > 0.0 ? ctx.safe_until[lead] : -1.0);
  }
  // The other items with work left, in order: not a group's members (their group decides when they are
  // covered), nor those the tables, the rake or a cast cleared whole (most of a many-link robot's).
  in_turns = sweep.verdict_only;
  std::vector<int>& live = ctx.live;  // (room for every item: makeContext)
  live.clear();
  for (int k = 0; k < n_items; ++k)
    if (k != lead && items_[k].group < 0 && ctx.safe_until[k] <= 1.0) live.push_back(k);
  // An item the rake left whole is first measured in the middle of what is left, where one set of poses serves
  // all.
  const double mid = 0.5 * sweep.limit;
  for (const int k : live) {
    if (sweep.stop()) break;
    if (ctx.safe_until[k] == 0.0 && ctx.settled[k] == 0) {
      const int before = sweep.contacts;
      ctx.first_reach[k] = sweep.first(k, mid, mid);
      if (sweep.contacts > before) ctx.lead = k;
    }
  }
  for (const int k : live) {
    if (sweep.stop()) break;
    const double start = ctx.safe_until[k];  // 0, or where a shape cast says the item is clear until
    if (ctx.settled[k] != 0) {
      Sweep::coverUnsettled(k, ctx.settled[k], cover);
    } else if (start > 0.0) {
      cover(k, start, 1.0, start);
    } else if (ctx.first_reach[k] < 0.0) {
      cover(k, 0.0, 1.0, -1.0);  // within contact in the middle: from the start, exactly
    } else {                     // what the ball in the middle leaves, left first
      const double rad = ctx.first_reach[k];
      if (mid - rad > 0.0) cover(k, 0.0, mid - rad, -1.0);  // (in every mode: see Sweep::cover)
      if (mid + rad < sweep.limit) cover(k, mid + rad, 1.0, mid);
    }
  }
  if (in_turns) sweep.coverInTurns();
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
      const double lo = sc.validLower(i), hi = sc.validUpper(i);
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
  // The rake, the tables and the casts leave every item they settle beyond the contact distance; the balls,
  // a share of their clearance (Sweep::kHeldBack; half of it, for the roundings of the bounds and steps).
  const double held = 0.5 * Sweep::kHeldBack * sweep.min_clear;
  r.margin = timed ? 0.0 : std::min(options_.contact_distance, held);
  return r;
}


}  // namespace clearway
