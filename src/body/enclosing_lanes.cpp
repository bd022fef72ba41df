// EnclosingBalls::boundsApart in SIMD lanes, compiled once per target by Highway's foreach_target.h: the
// bounding-ball test of many link pairs at once, the first rung of every self-collision query. The pairs lie
// in runs (BoundsRows): one first link's ball against the next few links' balls as they lie in memory, so the
// lanes load them with no gather and store their verdicts with no scatter.
#include <clearway/body/enclosing.h>
#include <clearway/detail/margins.h>

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "detail/simd_targets.h"
#define HWY_DISABLED_TARGETS CLEARWAY_LANES_DISABLED  // (before Highway's headers)
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "body/enclosing_lanes.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace clearway {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// ball = (x, y, z, r, |centre|) per link. Pair k is apart when |c_a − c_b|² > limit², limit = reach +
// band·(|c_a| + |c_b| + reach), reach = r_a + r_b + padding: apart()'s test, operation for operation. A NaN or
// an infinite radius compares false (never apart). Each step of lanes tests row.a against L second links side
// by side and stores their L verdicts as bytes at once: a row's last step writes past it, into the rows that
// follow (rows in order of their first pair), which write theirs after, or into out's spare bytes.
void RowsApart(const double* x, const double* y, const double* z, const double* r, const double* norm,
               const BoundsRows::Row* rows, int row_count, const double* padding, double band, std::uint8_t* out) {
  const hn::ScalableTag<double> d;
  const hn::RebindToUnsigned<decltype(d)> du;
  const hn::Rebind<std::uint8_t, decltype(d)> du8;  // a byte per lane
  using V = hn::Vec<decltype(d)>;
  constexpr int L = static_cast<int>(hn::MaxLanes(d));
  static_assert(L <= BoundsRows::kSpare, "a step writes past a row");
  const V vband = hn::Set(d, band);
  for (int i = 0; i < row_count; ++i) {
    const int a = rows[i].a, lo = rows[i].lo, first = rows[i].first, count = rows[i].count;
    const V ax = hn::Set(d, x[a]), ay = hn::Set(d, y[a]), az = hn::Set(d, z[a]);
    const V ar = hn::Set(d, r[a]), anorm = hn::Set(d, norm[a]);
    for (int j = 0; j < count; j += L) {
      const int b = lo + j;
      const V dx = hn::Sub(ax, hn::LoadU(d, x + b));
      const V dy = hn::Sub(ay, hn::LoadU(d, y + b));
      const V dz = hn::Sub(az, hn::LoadU(d, z + b));
      const V reach = hn::Add(hn::Add(ar, hn::LoadU(d, r + b)), hn::LoadU(d, padding + first + j));
      const V sizes = hn::Add(hn::Add(anorm, hn::LoadU(d, norm + b)), reach);
      const V limit = hn::Add(reach, hn::Mul(vband, sizes));
      const V dist2 = hn::Add(hn::Add(hn::Mul(dx, dx), hn::Mul(dy, dy)), hn::Mul(dz, dz));
      const auto ones = hn::ShiftRight<63>(hn::BitCast(du, hn::VecFromMask(d, hn::Gt(dist2, hn::Mul(limit, limit)))));
      const auto bytes = hn::TruncateTo(du8, ones);
      hn::StoreU(bytes, du8, out + first + j);
    }
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace clearway
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace clearway {

HWY_EXPORT(RowsApart);

BoundsRows::BoundsRows(const std::vector<std::int64_t>& a, const std::vector<std::int64_t>& b,
                       const std::vector<double>& padding, int link_count)
    : pairs_(static_cast<int>(a.size())), link_count_(link_count) {
  const std::size_t n = a.size();
  if (b.size() != n || padding.size() != n || link_count < 0)
    throw std::invalid_argument("BoundsRows: " + std::to_string(n) + " first links, " + std::to_string(b.size()) +
                                " second links and " + std::to_string(padding.size()) + " paddings");
  for (std::size_t k = 0; k < n; ++k)
    if (a[k] < 0 || a[k] >= link_count || b[k] < 0 || b[k] >= link_count || a[k] == b[k])
      throw std::invalid_argument("BoundsRows: pair " + std::to_string(k) + " (" + std::to_string(a[k]) + ", " +
                                  std::to_string(b[k]) + ") is not two links of " + std::to_string(link_count));
  for (std::size_t s = 0; s < n;) {  // a run continues while the next pair is the next second link
    std::size_t t = s + 1;
    while (t < n && a[t] == a[s] && b[t] == b[t - 1] + 1) ++t;
    rows_.push_back({static_cast<int>(a[s]), static_cast<int>(b[s]), static_cast<int>(s), static_cast<int>(t - s)});
    s = t;
  }
  padding_ = padding;
  padding_.resize(n + kSpare, 0.0);
}

void BoundsRows::apart(const double* x, const double* y, const double* z, const double* r, const double* norm,
                       double band, std::uint8_t* out) const noexcept {
  static_assert(HWY_MAX_BYTES / sizeof(double) <= kSpare, "a step of lanes reads past its run");
  if (pairs_ == 0) return;
  HWY_DYNAMIC_DISPATCH(RowsApart)
  (x, y, z, r, norm, rows_.data(), static_cast<int>(rows_.size()), padding_.data(), band, out);
}

void EnclosingBalls::boundsApart(const BoundsRows& pairs, const Tolerances& tol, std::uint8_t* out) const noexcept {
  const int n = pairs.size();
  if (n == 0) return;
  if (!poses_ || !geometry_ || pairs.linkCount() != static_cast<int>(links_.size())) {  // nothing proved
    std::fill(out, out + n, std::uint8_t{0});
    return;
  }
  pairs.apart(bound_x_.data(), bound_y_.data(), bound_z_.data(), bound_r_.data(), bound_norm_.data(),
              margins::narrowBand(tol.gjk_absolute), out);
}

}  // namespace clearway
#endif  // HWY_ONCE
