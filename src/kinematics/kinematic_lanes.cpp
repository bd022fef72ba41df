// Compiled once per SIMD target by Highway's foreach_target.h; the kernel below must therefore stay free
// of anything that differs between targets except the vector width.
#include <clearway/kinematics/forward_kinematics.h>
#include <clearway/kinematics/kinematic_lanes.h>

#include <cmath>
#include <cstddef>

#include "kinematics/pose_lanes.h"

#include "detail/simd_targets.h"
#define HWY_DISABLED_TARGETS CLEARWAY_LANES_DISABLED  // (before Highway's headers)
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "kinematics/kinematic_lanes.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

#include "kinematics/sincos_lanes-inl.h"

HWY_BEFORE_NAMESPACE();
namespace clearway {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

std::size_t LaneCount() { return hn::Lanes(hn::ScalableTag<double>()); }
const char* TargetName() { return hwy::TargetName(HWY_TARGET); }

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

// One state's links (links[k] for k < count, or first + k when links is null), each after its parent: a
// column of a pose's R, or its t, is one vector of four lanes (rows 0..2 and a spare), the sines and
// cosines four joints at a time, every operation computeLinkPose's in its order, so the poses are its own
// bit for bit. Targets with fewer than four lanes of doubles (SSE4, the portable ones) gain nothing by it
// and take computeLinkPose itself.
template <class D>
void ComputeLinks(D d, const RobotModel& model, const double* q, Pose* poses, const int* links, int first, int count) {
  using Kind = detail::KinematicStep::Kind;
  using V = hn::Vec<D>;
  constexpr int kBlock = 32;            // links per pass: their columns stay in `cols` for their children
  alignas(32) double cols[kBlock][16];  // per link of the pass: R's three columns, then t, four doubles each
  alignas(32) double value[kBlock + 4], sine[kBlock + 4], cosine[kBlock + 4];
  const auto link = [&](int k) { return links ? links[k] : first + k; };
  for (int begin = 0; begin < count; begin += kBlock) {
    const int end = count - begin < kBlock ? count : begin + kBlock;
    int turns = 0;
    for (int k = begin; k < end; ++k) {
      const detail::KinematicStep& st = model.kinematicStep(link(k));
      if (st.kind == Kind::TurnZ || st.kind == Kind::Turn) value[turns++] = st.value(q);
    }
    for (int j = turns; j < turns + 4; ++j) value[j] = 0.0;  // (the last vector's spare lanes)
    for (int j = 0; j < turns; j += 4) SinCosLanes(d, value + j, sine + j, cosine + j);
    int turn = 0;
    for (int k = begin; k < end; ++k) {
      const int i = link(k);
      const detail::KinematicStep& st = model.kinematicStep(i);
      double* out = cols[k - begin];
      Pose& pose = poses[i];
      if (st.kind == Kind::Other) {  // planar and floating joints: the scalar step
        computeLinkPose(model, q, poses, i);
        for (int c = 0; c < 3; ++c)
          for (int r = 0; r < 3; ++r) out[4 * c + r] = pose.R.data()[3 * c + r];
        for (int r = 0; r < 3; ++r) out[12 + r] = pose.t[r];
        continue;
      }
      // The parent's columns: where this pass computed it, from `cols`; else from its pose (the load of t
      // reads the next pose's first double into the spare lane: parent < i, so that pose exists).
      const double* from = nullptr;
      if (!links) {  // (a range: the parent's place in it is known)
        const int j = st.parent - first;
        if (j >= begin) from = cols[j - begin];
      } else {
        for (int j = k - 1; j >= begin && !from; --j)
          if (links[j] == st.parent) from = cols[j - begin];
      }
      V P0, P1, P2, Pt;
      if (from) {
        P0 = hn::Load(d, from), P1 = hn::Load(d, from + 4), P2 = hn::Load(d, from + 8), Pt = hn::Load(d, from + 12);
      } else {
        const Pose& p = poses[st.parent];
        P0 = hn::LoadU(d, p.R.data()), P1 = hn::LoadU(d, p.R.data() + 3), P2 = hn::LoadU(d, p.R.data() + 6);
        Pt = hn::LoadU(d, p.t.data());
      }
      // parent · origin, as computeLinkPose's place(): M = P·O; t = P·(origin.t + shift) + parent.t.
      const double* O = st.origin.R.data();
      const auto column = [&](int c) HWY_ATTR {
        return hn::Add(hn::Add(hn::Mul(P0, hn::Set(d, O[3 * c])), hn::Mul(P1, hn::Set(d, O[3 * c + 1]))),
                       hn::Mul(P2, hn::Set(d, O[3 * c + 2])));
      };
      const V M0 = column(0), M1 = column(1), M2 = column(2);
      double o[3];
      if (st.kind == Kind::Slide) {
        const double v = st.value(q);
        for (int r = 0; r < 3; ++r) o[r] = st.origin.t[r] + v * st.axis[r];
      } else {
        for (int r = 0; r < 3; ++r) o[r] = st.origin.t[r] + 0.0;  // (the scalar adds a zero shift)
      }
      const V T = hn::Add(
          hn::Add(hn::Add(hn::Mul(P0, hn::Set(d, o[0])), hn::Mul(P1, hn::Set(d, o[1]))), hn::Mul(P2, hn::Set(d, o[2]))),
          Pt);
      V R0 = M0, R1 = M1, R2 = M2;
      if (st.kind == Kind::TurnZ) {  // only M's first two columns turn
        const V c = hn::Set(d, cosine[turn]), s = hn::Set(d, sine[turn] * st.axis_sign);
        ++turn;
        R0 = hn::Add(hn::Mul(c, M0), hn::Mul(s, M1));
        R1 = hn::Sub(hn::Mul(c, M1), hn::Mul(s, M0));
      } else if (st.kind == Kind::Turn) {  // M·Rot(u) = c·M + s·M[u]× + (1 − c)·(M u) uᵀ
        const double cv = cosine[turn];
        const V c = hn::Set(d, cv), s = hn::Set(d, sine[turn]);
        ++turn;
        const V ux = hn::Set(d, st.axis[0]), uy = hn::Set(d, st.axis[1]), uz = hn::Set(d, st.axis[2]);
        const V w = hn::Mul(hn::Set(d, 1.0 - cv), hn::Add(hn::Add(hn::Mul(M0, ux), hn::Mul(M1, uy)), hn::Mul(M2, uz)));
        R0 = hn::Add(hn::Add(hn::Mul(c, M0), hn::Mul(s, hn::Sub(hn::Mul(uz, M1), hn::Mul(uy, M2)))), hn::Mul(ux, w));
        R1 = hn::Add(hn::Add(hn::Mul(c, M1), hn::Mul(s, hn::Sub(hn::Mul(ux, M2), hn::Mul(uz, M0)))), hn::Mul(uy, w));
        R2 = hn::Add(hn::Add(hn::Mul(c, M2), hn::Mul(s, hn::Sub(hn::Mul(uy, M0), hn::Mul(ux, M1)))), hn::Mul(uz, w));
      }
      hn::Store(R0, d, out), hn::Store(R1, d, out + 4), hn::Store(R2, d, out + 8), hn::Store(T, d, out + 12);
      // Into the pose: each column's spare lane lands on the next column's first double, overwritten by the
      // next store; t's three by hand (a fourth would write past the pose).
      double* R = pose.R.data();
      hn::StoreU(R0, d, R), hn::StoreU(R1, d, R + 3), hn::StoreU(R2, d, R + 6);
      pose.t[0] = out[12], pose.t[1] = out[13], pose.t[2] = out[14];
    }
  }
}

void ComputeOne(const RobotModel& model, const double* q, Pose* poses, const int* links, int first, int count) {
  const hn::CappedTag<double, 4> d;
  if (hn::MaxLanes(d) < 4) {
    for (int k = 0; k < count; ++k) computeLinkPose(model, q, poses, links ? links[k] : first + k);
    return;
  }
  ComputeLinks(d, model, q, poses, links, first, count);
}

}  // namespace HWY_NAMESPACE
}  // namespace clearway
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace clearway {

HWY_EXPORT(LaneCount);
HWY_EXPORT(TargetName);
HWY_EXPORT(ComputePass);
HWY_EXPORT(ComputeOne);

namespace detail {

void computeLinksInLanes(const RobotModel& model, const double* q, Pose* poses, const int* links, int first,
                         int count) noexcept {
  HWY_DYNAMIC_DISPATCH(ComputeOne)(model, q, poses, links, first, count);
}

}  // namespace detail

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
