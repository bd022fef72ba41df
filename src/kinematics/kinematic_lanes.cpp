// Compiled once per SIMD target by Highway's foreach_target.h; the kernel below must therefore stay free
// of anything that differs between targets except the vector width.
#include <clearway/kinematics/forward_kinematics.h>
#include <clearway/kinematics/kinematic_lanes.h>

#include <cmath>
#include <cstddef>

#include "kinematics/sincos.h"

#include "detail/simd_targets.h"
#define HWY_DISABLED_TARGETS CLEARWAY_LANES_DISABLED  // (before Highway's headers)
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "kinematics/kinematic_lanes.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace clearway {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

std::size_t LaneCount() { return hn::Lanes(hn::ScalableTag<double>()); }
const char* TargetName() { return hwy::TargetName(HWY_TARGET); }

// detail::sinCos over a vector of angles, operation for operation (so bit for bit); lanes beyond its range
// (or NaN) take libm's values, as there.
template <class D>
void SinCosLanes(D d, const double* x, double* s, double* c) {
  using K = detail::SinCosConstants;
  using V = hn::Vec<D>;
  const hn::RebindToSigned<D> di;
  const V v = hn::LoadU(d, x);
  const V k = hn::Sub(hn::Add(hn::Mul(v, hn::Set(d, K::kTwoOverPi)), hn::Set(d, K::kRound)), hn::Set(d, K::kRound));
  const V r1 = hn::Sub(v, hn::Mul(k, hn::Set(d, K::kC1)));
  const V p2 = hn::Mul(k, hn::Set(d, K::kC2));
  const V hi = hn::Sub(r1, p2);
  const V hv = hn::Sub(hi, r1);
  const V lo = hn::Sub(hn::Sub(hn::Sub(r1, hn::Sub(hi, hv)), hn::Add(p2, hv)), hn::Mul(k, hn::Set(d, K::kC3)));
  const V z = hn::Mul(hi, hi), z2 = hn::Mul(z, z), z4 = hn::Mul(z2, z2);
  const auto term = [&](const double* a, int i) HWY_ATTR {  // a[i] + z·a[i+1]
    return hn::Add(hn::Set(d, a[i]), hn::Mul(z, hn::Set(d, a[i + 1])));
  };
  const auto estrin = [&](const double* a) HWY_ATTR {
    return hn::Add(hn::Add(term(a, 0), hn::Mul(z2, term(a, 2))),
                   hn::Mul(z4, hn::Add(term(a, 4), hn::Mul(z2, term(a, 6)))));
  };
  const V S = estrin(K::kS), C = estrin(K::kC);
  const V one = hn::Set(d, 1.0);
  const V half_z = hn::Mul(hn::Set(d, 0.5), z);
  const V sin_r = hn::Add(hi, hn::Add(hn::Mul(hn::Mul(hi, z), S), hn::Mul(lo, hn::Sub(one, half_z))));
  const V w = hn::Sub(one, half_z);
  const V cos_r = hn::Add(w, hn::Add(hn::Sub(hn::Sub(one, w), half_z), hn::Sub(hn::Mul(hn::Mul(z, z), C), hn::Mul(hi, lo))));
  // The quadrant's low bits: k + 1.5·2^52 holds 2^51 + k in its low bits, exactly, as two's complement would.
  const auto bits = hn::BitCast(di, hn::Add(k, hn::Set(d, K::kRound)));
  const auto bit = [&](decltype(bits) b, long long m) HWY_ATTR {
    return hn::RebindMask(d, hn::Eq(hn::And(b, hn::Set(di, m)), hn::Set(di, m)));
  };
  const auto odd = bit(bits, 1);
  const V minus = hn::Set(d, -1.0);
  hn::StoreU(hn::Mul(hn::IfThenElse(odd, cos_r, sin_r), hn::IfThenElse(bit(bits, 2), minus, one)), d, s);
  hn::StoreU(hn::Mul(hn::IfThenElse(odd, sin_r, cos_r), hn::IfThenElse(bit(hn::Add(bits, hn::Set(di, 1)), 2), minus, one)),
             d, c);
  if (!hn::AllTrue(d, hn::Le(hn::Abs(v), hn::Set(d, K::kRange))))
    for (std::size_t l = 0; l < hn::Lanes(d); ++l)
      if (!(std::abs(x[l]) <= K::kRange)) {
        s[l] = std::sin(x[l]);
        c[l] = std::cos(x[l]);
      }
}

// One pass: n ≤ LaneCount() states, each link's 12 doubles a row of `rows` (stride kMaxLanes). Lanes at
// and beyond n repeat state n − 1 and are never written out.
void ComputePass(const RobotModel& model, const double* const* q, int n, Pose* const* poses, double* rows) {
  using Kind = detail::KinematicStep::Kind;
  constexpr int kStride = KinematicLanes::kMaxLanes;
  const hn::ScalableTag<double> d;
  using V = hn::Vec<decltype(d)>;
  const int L = static_cast<int>(hn::Lanes(d));
  const auto lane = [&](int l) { return q[l < n ? l : n - 1]; };
  const auto row = [&](int link, int k) { return rows + (12 * link + k) * kStride; };
  const auto store = [&](int link) {  // the link's rows out to each state's poses (column-major R, then t)
    for (int l = 0; l < n; ++l) {
      double* R = poses[l][link].R.data();
      double* t = poses[l][link].t.data();
      for (int k = 0; k < 9; ++k) R[k] = row(link, k)[l];
      for (int k = 0; k < 3; ++k) t[k] = row(link, 9 + k)[l];
    }
  };
  for (int k = 0; k < 12; ++k) hn::StoreU(hn::Set(d, k < 9 && k % 4 == 0 ? 1.0 : 0.0), d, row(0, k));
  store(0);

  alignas(64) double value[kStride] = {}, cosine[kStride] = {}, sine[kStride] = {};
  for (int i = 1; i < model.linkCount(); ++i) {
    const detail::KinematicStep& st = model.kinematicStep(i);
    if (st.kind == Kind::Other) {  // planar and floating joints: each state by the scalar step
      for (int l = 0; l < n; ++l) {
        computeLinkPose(model, q[l], poses[l], i);
        const Pose& p = poses[l][i];
        for (int k = 0; k < 9; ++k) row(i, k)[l] = p.R.data()[k];
        for (int k = 0; k < 3; ++k) row(i, 9 + k)[l] = p.t[k];
      }
      continue;
    }
    V P[12];
    for (int k = 0; k < 12; ++k) P[k] = hn::LoadU(d, row(st.parent, k));
    const double* O = st.origin.R.data();
    const bool turns = st.kind == Kind::TurnZ || st.kind == Kind::Turn;
    if (turns || st.kind == Kind::Slide)
      for (int l = 0; l < L; ++l) value[l] = st.value(lane(l));
    if (turns)
      SinCosLanes(d, value, sine, cosine);

    // parent · origin, as computeLinkPose's place(): M = P·O; t = P·(origin.t + shift) + parent.t.
    V M[9], o[3];
    for (int col = 0; col < 3; ++col)
      for (int r = 0; r < 3; ++r)
        M[3 * col + r] = hn::Add(hn::Add(hn::Mul(P[r], hn::Set(d, O[3 * col])), hn::Mul(P[3 + r], hn::Set(d, O[3 * col + 1]))),
                                 hn::Mul(P[6 + r], hn::Set(d, O[3 * col + 2])));
    if (st.kind == Kind::Slide) {
      const V v = hn::LoadU(d, value);
      for (int k = 0; k < 3; ++k) o[k] = hn::Add(hn::Set(d, st.origin.t[k]), hn::Mul(v, hn::Set(d, st.axis[k])));
    } else {
      for (int k = 0; k < 3; ++k) o[k] = hn::Set(d, st.origin.t[k] + 0.0);  // the scalar adds a zero shift
    }
    for (int r = 0; r < 3; ++r)
      hn::StoreU(hn::Add(hn::Add(hn::Add(hn::Mul(P[r], o[0]), hn::Mul(P[3 + r], o[1])), hn::Mul(P[6 + r], o[2])), P[9 + r]),
                 d, row(i, 9 + r));

    if (st.kind == Kind::TurnZ) {  // only M's first two columns turn
      for (int l = 0; l < L; ++l) sine[l] *= st.axis_sign;
      const V c = hn::LoadU(d, cosine), s = hn::LoadU(d, sine);
      for (int r = 0; r < 3; ++r) {
        hn::StoreU(hn::Add(hn::Mul(c, M[r]), hn::Mul(s, M[3 + r])), d, row(i, r));
        hn::StoreU(hn::Sub(hn::Mul(c, M[3 + r]), hn::Mul(s, M[r])), d, row(i, 3 + r));
        hn::StoreU(M[6 + r], d, row(i, 6 + r));
      }
    } else if (st.kind == Kind::Turn) {  // M·Rot(u) = c·M + s·M[u]× + (1 − c)·(M u) uᵀ
      const V c = hn::LoadU(d, cosine), s = hn::LoadU(d, sine);
      const V ux = hn::Set(d, st.axis[0]), uy = hn::Set(d, st.axis[1]), uz = hn::Set(d, st.axis[2]);
      const V one_c = hn::Sub(hn::Set(d, 1.0), c);
      for (int r = 0; r < 3; ++r) {
        const V w = hn::Mul(one_c, hn::Add(hn::Add(hn::Mul(M[r], ux), hn::Mul(M[3 + r], uy)), hn::Mul(M[6 + r], uz)));
        hn::StoreU(hn::Add(hn::Add(hn::Mul(c, M[r]), hn::Mul(s, hn::Sub(hn::Mul(uz, M[3 + r]), hn::Mul(uy, M[6 + r])))),
                           hn::Mul(ux, w)),
                   d, row(i, r));
        hn::StoreU(hn::Add(hn::Add(hn::Mul(c, M[3 + r]), hn::Mul(s, hn::Sub(hn::Mul(ux, M[6 + r]), hn::Mul(uz, M[r])))),
                           hn::Mul(uy, w)),
                   d, row(i, 3 + r));
        hn::StoreU(hn::Add(hn::Add(hn::Mul(c, M[6 + r]), hn::Mul(s, hn::Sub(hn::Mul(uy, M[r]), hn::Mul(ux, M[3 + r])))),
                           hn::Mul(uz, w)),
                   d, row(i, 6 + r));
      }
    } else {  // Fixed, Slide: the placement is the pose
      for (int k = 0; k < 9; ++k) hn::StoreU(M[k], d, row(i, k));
    }
    store(i);
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace clearway
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace clearway {

HWY_EXPORT(LaneCount);
HWY_EXPORT(TargetName);
HWY_EXPORT(ComputePass);

KinematicLanes::KinematicLanes(const RobotModel& model)
    : model_(&model), lanes_(static_cast<std::size_t>(12 * model.linkCount() * kMaxLanes), 0.0) {
  static_assert(HWY_MAX_BYTES / sizeof(double) <= kMaxLanes, "a target wider than the scratch");
}

int KinematicLanes::width() noexcept { return static_cast<int>(HWY_DYNAMIC_DISPATCH(LaneCount)()); }

const char* KinematicLanes::targetName() noexcept { return HWY_DYNAMIC_DISPATCH(TargetName)(); }

// (Highway's list is inline: here it is this file's, without the targets disabled above.)
std::vector<std::int64_t> KinematicLanes::targets() { return hwy::SupportedAndGeneratedTargets(); }

void KinematicLanes::compute(const double* const* q, int n, Pose* const* poses) noexcept {
  if (n <= 0 || model_->linkCount() == 0) return;
  const int w = width();
  for (int first = 0; first < n; first += w) {
    const int count = n - first < w ? n - first : w;
    HWY_DYNAMIC_DISPATCH(ComputePass)(*model_, q + first, count, poses + first, lanes_.data());
  }
}

}  // namespace clearway
#endif  // HWY_ONCE
