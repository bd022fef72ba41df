// Compiled once per SIMD target by Highway's foreach_target.h (the kernel), the rest once (HWY_ONCE).
#include <clearway/kinematics/point_lanes.h>

#include <clearway/detail/margins.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>

#include "detail/simd_targets.h"
#define HWY_DISABLED_TARGETS CLEARWAY_LANES_DISABLED  // (before Highway's headers)
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "kinematics/point_lanes.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "kinematics/sincos_lanes-inl.h"

HWY_BEFORE_NAMESPACE();
namespace clearway {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// One pass over the steps: each link's R (column-major) and t as 12 rows of kLanes floats in `rows` (slot 0
// the root's identity), the sines and cosines in doubles (sinCos's lanes), then every point.
void PlacePoints(const PointLanes::Step* steps, int n_steps, const int* point_slot, const float* point_p, int n_points,
                 const double* const* q, int n, float* xyz, float* rows) {
  using Kind = detail::KinematicStep::Kind;
  constexpr int L = PointLanes::kLanes;
  const hn::ScalableTag<float> df;
  const hn::ScalableTag<double> dd;
  using V = hn::Vec<decltype(df)>;
  const int nf = static_cast<int>(hn::Lanes(df)), nd = static_cast<int>(hn::Lanes(dd));
  const auto row = [&](int slot, int k) { return rows + (12 * slot + k) * L; };
  for (int k = 0; k < 12; ++k) std::fill(row(0, k), row(0, k) + L, k < 9 && k % 4 == 0 ? 1.0f : 0.0f);
  alignas(64) double value[L], sine[L], cosine[L];
  alignas(64) float c32[L], s32[L], v32[L];
  for (int s = 0; s < n_steps; ++s) {
    const PointLanes::Step& st = steps[s];
    const Kind kind = static_cast<Kind>(st.kind);
    const bool turns = kind == Kind::TurnZ || kind == Kind::Turn;
    if (turns || kind == Kind::Slide) {
      for (int l = 0; l < L; ++l) value[l] = st.step->value(q[l < n ? l : n - 1]);
      if (turns) {
        for (int l = 0; l < L; l += nd) SinCosLanes(dd, value + l, sine + l, cosine + l);
        for (int l = 0; l < L; ++l) {
          c32[l] = static_cast<float>(cosine[l]);
          s32[l] = static_cast<float>(sine[l]) * st.axis_sign;
        }
      } else {
        // (Clamped into float's range, where converting is defined: such a value is outside the lanes'
        // bound anyway, whose positions are then meaningless but never undefined.)
        for (int l = 0; l < L; ++l) v32[l] = static_cast<float>(std::clamp(value[l], -1e38, 1e38));
      }
    }
    const int p = st.parent_slot, me = s + 1;
    for (int l = 0; l < L; l += nf) {
      V P[12], M[9];
      for (int k = 0; k < 12; ++k) P[k] = hn::LoadU(df, row(p, k) + l);
      if (st.turned) {
        for (int col = 0; col < 3; ++col)
          for (int r = 0; r < 3; ++r)
            M[3 * col + r] = hn::MulAdd(
                P[6 + r], hn::Set(df, st.O[3 * col + 2]),
                hn::MulAdd(P[3 + r], hn::Set(df, st.O[3 * col + 1]), hn::Mul(P[r], hn::Set(df, st.O[3 * col]))));
      } else {
        for (int k = 0; k < 9; ++k) M[k] = P[k];
      }
      V o[3];
      if (kind == Kind::Slide) {
        const V v = hn::LoadU(df, v32 + l);
        for (int k = 0; k < 3; ++k) o[k] = hn::MulAdd(v, hn::Set(df, st.axis[k]), hn::Set(df, st.origin[k]));
      } else {
        for (int k = 0; k < 3; ++k) o[k] = hn::Set(df, st.origin[k]);
      }
      for (int r = 0; r < 3; ++r)
        hn::StoreU(hn::MulAdd(P[6 + r], o[2], hn::MulAdd(P[3 + r], o[1], hn::MulAdd(P[r], o[0], P[9 + r]))), df,
                   row(me, 9 + r) + l);
      if (kind == Kind::TurnZ) {  // only M's first two columns turn
        const V c = hn::LoadU(df, c32 + l), sn = hn::LoadU(df, s32 + l);
        for (int r = 0; r < 3; ++r) {
          hn::StoreU(hn::MulAdd(sn, M[3 + r], hn::Mul(c, M[r])), df, row(me, r) + l);
          hn::StoreU(hn::NegMulAdd(sn, M[r], hn::Mul(c, M[3 + r])), df, row(me, 3 + r) + l);
          hn::StoreU(M[6 + r], df, row(me, 6 + r) + l);
        }
      } else if (kind == Kind::Turn) {  // M·Rot(u) = c·M + s·M[u]× + (1 − c)·(M u) uᵀ
        const V c = hn::LoadU(df, c32 + l), sn = hn::LoadU(df, s32 + l);
        const V ux = hn::Set(df, st.axis[0]), uy = hn::Set(df, st.axis[1]), uz = hn::Set(df, st.axis[2]);
        const V one_c = hn::Sub(hn::Set(df, 1.0f), c);
        for (int r = 0; r < 3; ++r) {
          const V w = hn::Mul(one_c, hn::MulAdd(M[6 + r], uz, hn::MulAdd(M[3 + r], uy, hn::Mul(M[r], ux))));
          const V a = hn::Sub(hn::Mul(uz, M[3 + r]), hn::Mul(uy, M[6 + r]));
          const V b = hn::Sub(hn::Mul(ux, M[6 + r]), hn::Mul(uz, M[r]));
          const V e = hn::Sub(hn::Mul(uy, M[r]), hn::Mul(ux, M[3 + r]));
          hn::StoreU(hn::MulAdd(ux, w, hn::MulAdd(sn, a, hn::Mul(c, M[r]))), df, row(me, r) + l);
          hn::StoreU(hn::MulAdd(uy, w, hn::MulAdd(sn, b, hn::Mul(c, M[3 + r]))), df, row(me, 3 + r) + l);
          hn::StoreU(hn::MulAdd(uz, w, hn::MulAdd(sn, e, hn::Mul(c, M[6 + r]))), df, row(me, 6 + r) + l);
        }
      } else {  // Fixed, Slide: the placement is the pose
        for (int k = 0; k < 9; ++k) hn::StoreU(M[k], df, row(me, k) + l);
      }
    }
  }
  for (int k = 0; k < n_points; ++k) {
    const int slot = point_slot[k];
    const float* p = point_p + 3 * k;
    for (int l = 0; l < L; l += nf) {
      for (int r = 0; r < 3; ++r) {
        const V x = hn::MulAdd(hn::LoadU(df, row(slot, 6 + r) + l), hn::Set(df, p[2]),
                               hn::MulAdd(hn::LoadU(df, row(slot, 3 + r) + l), hn::Set(df, p[1]),
                                          hn::MulAdd(hn::LoadU(df, row(slot, r) + l), hn::Set(df, p[0]),
                                                     hn::LoadU(df, row(slot, 9 + r) + l))));
        hn::StoreU(x, df, xyz + (3 * k + r) * L + l);
      }
    }
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace clearway
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace clearway {

HWY_EXPORT(PlacePoints);

namespace {

// The error recursion of point_lanes.h at unit roundoff u (and δ = 2u for sin and cos).
struct Rounding {
  double u;
  double gamma(int n) const noexcept { return n * u / (1.0 - n * u); }
};

}  // namespace

PointLanes::PointLanes(const RobotModel& model, std::vector<Point> points, const std::vector<double>& most)
    : points_(std::move(points)) {
  static_assert(HWY_MAX_BYTES / sizeof(float) <= kLanes, "a target wider than the lanes");
  using Kind = detail::KinematicStep::Kind;
  const int links = model.linkCount();
  // The links on the points' chains, in topological order (parents before children).
  std::vector<char> needed(static_cast<std::size_t>(links), 0);
  for (const Point& pt : points_) {
    if (pt.link < 0 || pt.link >= links || !pt.p.allFinite()) return;
    for (int l = pt.link; l > 0 && !needed[l]; l = model.parentLink(l)) needed[l] = 1;
  }
  std::vector<int> slot(static_cast<std::size_t>(links), -1);
  slot[0] = 0;
  const double root3 = std::sqrt(3.0);
  // Per slot: e, ε and T at float's rounding, and at double's (the double poses' own error).
  const Rounding rf{0x1p-24}, rd{0x1p-53};
  struct Bound {
    double e = 0.0, eps = 0.0;
  };
  std::vector<Bound> bf(1), bd(1);
  std::vector<double> reach(1, 0.0);
  const auto stepBound = [&](const Rounding& rnd, const Bound& parent, double t_parent, bool turned, Kind kind,
                             double o_norm) {
    const double u = rnd.u, delta = 2.0 * u;
    Bound b;
    const double m =
        turned ? parent.e * (1.0 + root3 * u) + root3 * u + rnd.gamma(3) * (root3 + parent.e) * root3 * (1.0 + u)
               : parent.e;
    const double o_hat = o_norm * (1.0 + 5.0 * u);
    b.eps = parent.eps + parent.e * o_hat + 5.0 * u * o_norm +
            rnd.gamma(4) * ((root3 + parent.e) * o_hat + t_parent + parent.eps);
    if (kind == Kind::TurnZ)
      b.e = m * (1.0 + 2.0 * delta) + 2.0 * delta + rnd.gamma(2) * std::sqrt(2.0) * (root3 + m) * (1.0 + 2.0 * delta);
    else if (kind == Kind::Turn)
      b.e = m * (1.0 + 6.0 * delta + 6.0 * u) + 6.0 * delta + 6.0 * u + 18.0 * rnd.gamma(10) * (1.0 + m);
    else
      b.e = m;
    return b;
  };
  for (int l = 1; l < links; ++l) {
    if (!needed[l]) continue;
    const detail::KinematicStep& st = model.kinematicStep(l);
    if (st.kind == Kind::Other || st.kind == Kind::Root || st.parent < 0 || slot[st.parent] < 0) return;
    double o_norm = st.origin.t.norm();
    if (st.kind == Kind::Slide) {
      const double q_most =
          st.variable >= 0 && st.variable < static_cast<int>(most.size()) ? most[st.variable] : INFINITY;
      // (Widened: the values a caller interpolates between two within the bound round by an ulp or so.)
      const double v = margins::roundedUp(std::abs(st.multiplier) * q_most + std::abs(st.offset), 0.0);
      if (!std::isfinite(v)) return;
      o_norm += v;
    }
    const int parent = slot[st.parent];
    // (Before any value is rounded to float: one beyond float's range would not convert.)
    if (!(reach[parent] + o_norm <= kMaxReach) || !st.origin.R.allFinite() || !st.axis.allFinite()) return;
    Step s{};
    s.parent_slot = parent;
    s.kind = static_cast<int>(st.kind);
    s.turned = st.origin.R != Mat3::Identity();
    for (int k = 0; k < 9; ++k) s.O[k] = static_cast<float>(st.origin.R.data()[k]);
    for (int k = 0; k < 3; ++k) {
      s.origin[k] = static_cast<float>(st.origin.t[k]);
      s.axis[k] = static_cast<float>(st.axis[k]);
    }
    s.axis_sign = static_cast<float>(st.axis_sign);
    s.step = &st;
    bf.push_back(stepBound(rf, bf[parent], reach[parent], s.turned, st.kind, o_norm));
    bd.push_back(stepBound(rd, bd[parent], reach[parent], s.turned, st.kind, o_norm));
    reach.push_back(reach[parent] + o_norm);
    slot[l] = static_cast<int>(steps_.size()) + 1;
    steps_.push_back(s);
  }
  for (const Point& pt : points_) {
    const int sl = slot[pt.link];
    point_slot_.push_back(sl);
    const double p = pt.p.norm();
    double total = 0.0;
    for (const auto& [rnd, bounds] : {std::pair{rf, &bf}, std::pair{rd, &bd}}) {
      const Bound& b = (*bounds)[static_cast<std::size_t>(sl)];
      const double u = rnd.u, p_hat = p * (1.0 + u);
      total += b.e * p_hat + u * p + rnd.gamma(4) * ((root3 + b.e) * p_hat + reach[sl] + b.eps) + b.eps;
    }
    if (!(p + reach[sl] <= kMaxReach) || !(2.0 * total < kMaxError)) {
      error_.clear();
      return;
    }
    error_.push_back(2.0 * total);
    for (int k = 0; k < 3; ++k) point_p_.push_back(static_cast<float>(pt.p[k]));
  }
  serves_ = true;
}

void PointLanes::compute(const double* const* q, int n, float* xyz, float* scratch) const noexcept {
  if (!serves_ || n <= 0) return;
  HWY_DYNAMIC_DISPATCH(PlacePoints)
  (steps_.data(), static_cast<int>(steps_.size()), point_slot_.data(), point_p_.data(), size(), q,
   n < kLanes ? n : kLanes, xyz, scratch);
}

}  // namespace clearway
#endif  // HWY_ONCE
