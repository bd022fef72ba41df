// ObstacleBoxes (obstacle_boxes.h): built once per version of a world's static obstacles; the ball test in
// SIMD lanes, compiled once per target by Highway's foreach_target.h, the target chosen at run time.
#include <clearway/environment/obstacle_boxes.h>
#include <clearway/detail/margins.h>

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "detail/simd_targets.h"
#define HWY_DISABLED_TARGETS CLEARWAY_LANES_DISABLED  // (before Highway's headers)
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "environment/obstacle_boxes.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace clearway {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// f: the boxes' fields (ObstacleBoxes::Field order), each `padded` long, a multiple of the lanes. Box k is
// clear when d² > limit², d the distance of u = Rᵀ(c − o) to [−h, h] and limit = reach + kRounding·(|c| +
// size): ballClear's test (the header's proof). A NaN compares false: never clear.
bool BallClear(const double* f, int padded, double cx, double cy, double cz, double reach, double center_norm) {
  const hn::ScalableTag<double> d;
  using V = hn::Vec<decltype(d)>;
  const auto field = [&](int k, int at) { return hn::LoadU(d, f + static_cast<std::ptrdiff_t>(k) * padded + at); };
  const V x = hn::Set(d, cx), y = hn::Set(d, cy), z = hn::Set(d, cz);
  const V vreach = hn::Set(d, reach), vnorm = hn::Set(d, center_norm), band = hn::Set(d, margins::kRounding);
  const V zero = hn::Zero(d);
  const int L = static_cast<int>(hn::Lanes(d));
  for (int at = 0; at < padded; at += L) {
    const V dx = hn::Sub(x, field(0, at)), dy = hn::Sub(y, field(1, at)), dz = hn::Sub(z, field(2, at));
    V dist2 = zero;
    for (int axis = 0; axis < 3; ++axis) {  // u_axis = (R's column axis) · (c − o), then its excess over h
      const int col = 3 + 3 * axis;
      const V u = hn::MulAdd(field(col, at), dx, hn::MulAdd(field(col + 1, at), dy, hn::Mul(field(col + 2, at), dz)));
      const V e = hn::Max(hn::Sub(hn::Abs(u), field(12 + axis, at)), zero);
      dist2 = hn::MulAdd(e, e, dist2);
    }
    const V limit = hn::MulAdd(band, hn::Add(vnorm, field(15, at)), vreach);
    if (!hn::AllTrue(d, hn::Gt(dist2, hn::Mul(limit, limit)))) return false;
  }
  return true;
}

}  // namespace HWY_NAMESPACE
}  // namespace clearway
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace clearway {

HWY_EXPORT(BallClear);

std::shared_ptr<const ObstacleBoxes> ObstacleBoxes::build(const std::vector<Placed>& boxes) {
  const int n = static_cast<int>(boxes.size());
  if (n == 0 || n > kMaxBoxes) return nullptr;
  for (const Placed& b : boxes) {
    if (!b.pose.isFinite() || b.box.isEmpty() || !b.box.min.allFinite() || !b.box.max.allFinite()) return nullptr;
    const Mat3 skew = b.pose.R.transpose() * b.pose.R - Mat3::Identity();
    if (!(skew.cwiseAbs().maxCoeff() <= kMaxSkew)) return nullptr;
  }
  constexpr int kWidest = 8;  // doubles in the widest lanes any target has (AVX-512 is disabled: 4 at most)
  static_assert(HWY_MAX_BYTES / sizeof(double) <= kWidest, "the padding covers the widest lanes");
  std::shared_ptr<ObstacleBoxes> out(new ObstacleBoxes());
  out->count_ = n;
  out->padded_ = (n + kWidest - 1) / kWidest * kWidest;
  out->soa_.assign(static_cast<std::size_t>(kFields) * out->padded_, 0.0);
  for (int k = 0; k < out->padded_; ++k) {
    const Placed& b = boxes[std::min(k, n - 1)];  // (the last box repeated: a lane of padding tests it again)
    const Vec3 local = b.box.center(), half = b.box.halfExtents();
    const Vec3 o = b.pose * local;
    double v[kFields];
    v[kOx] = o.x(), v[kOy] = o.y(), v[kOz] = o.z();
    for (int col = 0; col < 3; ++col)
      for (int row = 0; row < 3; ++row) v[kR00 + 3 * col + row] = b.pose.R(row, col);
    // (The box's centre and half extents round by a few ε of its corners: kRounding of |h| + |l| covers them.)
    v[kHx] = half.x(), v[kHy] = half.y(), v[kHz] = half.z();
    v[kSize] = o.norm() + half.norm() + local.norm() + b.pose.t.norm() + b.box.min.norm() + b.box.max.norm();
    for (int f = 0; f < kFields; ++f) out->soa_[static_cast<std::size_t>(f) * out->padded_ + k] = v[f];
  }
  return out;
}

bool ObstacleBoxes::ballClear(const Vec3& center, double radius, double slack) const noexcept {
  // (The reach rounds up for its own roundings; the centre's norm sizes the band with the box's size.)
  const double reach = margins::roundedUp(radius + slack, radius + slack);
  return HWY_DYNAMIC_DISPATCH(BallClear)(soa_.data(), padded_, center.x(), center.y(), center.z(), reach,
                                         center.norm());
}

}  // namespace clearway
#endif  // HWY_ONCE
