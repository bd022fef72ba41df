// Sampled mode: states at a fixed resolution, as OMPL's DiscreteMotionValidator (may tunnel).
#include <clearway/motion/motion.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "motion_detail.h"

namespace clearway {

MotionResult MotionChecker::sampled(const double* q0, double t0, const double* q1, double t1,
                                    motion_detail::Scratch& ctx) const noexcept {
  MotionResult r;
  const Scene& sc = *scene_;
  const auto time = [&](double s) { return t0 + s * (t1 - t0); };
  double len2 = 0.0;
  for (int i = 0; i < sc.dimension(); ++i) len2 += (q1[i] - q0[i]) * (q1[i] - q0[i]);
  // As OMPL's DiscreteMotionValidator: the ends, then the states in between at the resolution.
  const double len = std::sqrt(len2);
  // The step count in double first: len / resolution may exceed every int, and a length that overflows
  // (a change beyond 1e154) is beyond every cap, never one step from end to end.
  const double steps = std::isfinite(len) ? std::max(1.0, std::ceil(len / options_.resolution)) : HUGE_VAL;
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

}  // namespace clearway
