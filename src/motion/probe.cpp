// The probe: a few states of a segment checked before any item is swept, so that a colliding segment
// usually ends after a state check or two instead of the items' distance measurements within contact
// (which climb to the exact meshes and measure both ends).
#include "motion_detail.h"

namespace clearway::motion_detail {

namespace {
// The parameters, in the order a fresh context checks them: the end first, then coarse to fine. RRTConnect
// checks the state it extends to only on its goal tree, so on its start tree the end often collides itself
// (on the shared problems, putting the end before 0.5, 0.25 and 0.75 took 1 to 16% off the motion checks of
// the same runs; dropping 0.25 then was no better within the noise, and worse for segments whose ends are
// both free). With each state checked in full, probing {1, 1/2} alone took 1.4% off the Panda's and added
// 2.1% to the UR5's instructions on the VAMP bench's 2,000 segments of box_*_0001: not worth a change.
constexpr double kAt[kProbes] = {1.0, 0.5, 0.25, 0.75};
// The probe runs while it finds a collision on at least this share of the segments it looks at: below it,
// the state checks cost free segments more than they save colliding ones (measured on the shared
// problems: a probe costs about a tenth of a colliding segment's sweep). It also runs on every eighth
// segment it would skip, so that the share it sees follows the caller's segments.
constexpr double kWorthwhile = 0.125;
constexpr int kRecheck = 8;
constexpr double kAverage = 1.0 / 16;  // the moving average's weight of the newest segment
// The decay of each state's count of first collisions per probe: it follows the planner's segments over
// the last few dozen probes.
constexpr double kHitDecay = 1.0 - 1.0 / 32;
}  // namespace

bool probeCollides(const MotionChecker& checker, const double* q0, double t0, const double* q1, double t1,
                   Scratch& ctx, MotionResult& r) noexcept {
  if (ctx.probe_rate < kWorthwhile && ++ctx.probe_skipped < kRecheck) return false;
  ctx.probe_skipped = 0;
  // The states that collided first most often lately go first (ties in kAt's order): which of them a
  // planner's colliding segments meet depends on the robot and the scene (on the shared problems the
  // middle for the Panda, the end for the UR5), and each state checked before the colliding one costs a
  // full check of its obstacles.
  int order[kProbes];
  for (int k = 0; k < kProbes; ++k) {
    int at = k;
    for (; at > 0 && ctx.probe_hits[order[at - 1]] < ctx.probe_hits[k]; --at) order[at] = order[at - 1];
    order[at] = k;
  }
  // Each in full, in that order, until one collides (Scene::anyCollides).
  const int dim = checker.scene().dimension();
  double times[kProbes];
  for (int k = 0; k < kProbes; ++k) {
    const double s = kAt[order[k]];
    checker.interpolate(q0, q1, s, ctx.probe_states.data() + static_cast<std::ptrdiff_t>(k) * dim);
    times[k] = t0 + s * (t1 - t0);
  }
  const int hit = checker.scene().anyCollides(ctx.probe_states.data(), kProbes, ctx.scene, &r.report, times);
  const bool found = hit >= 0;
  r.steps += found ? hit + 1 : kProbes;  // (the states after a colliding one are not checked)
  for (double& h : ctx.probe_hits) h *= kHitDecay;
  if (found) {
    r.free = false;
    r.first_contact = kAt[order[hit]];  // (verdict only: a contact, not necessarily the first)
    r.last_valid = 0.0;
    ctx.probe_hits[order[hit]] += 1.0;
  }
  ctx.probe_rate += kAverage * ((found ? 1.0 : 0.0) - ctx.probe_rate);
  return found;
}

bool stateCollides(const MotionChecker& checker, const double* q0, const double* q1, double s, double t, Scratch& ctx,
                   CollisionReport& report) noexcept {
  checker.interpolate(q0, q1, s, ctx.q.data());
  CollisionReport found;
  if (checker.scene().isFree(ctx.q.data(), ctx.scene, &found, t)) return false;
  report = found;
  return true;
}

}  // namespace clearway::motion_detail
