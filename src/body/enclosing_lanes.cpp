// EnclosingBalls::boundsApart in SIMD lanes, compiled once per target by Highway's foreach_target.h: the
// bounding-ball test of many link pairs at once, the first rung of every self-collision query.
#include <clearway/body/enclosing.h>
#include <clearway/detail/margins.h>

#include <algorithm>
#include <cstddef>
#include <limits>

#include "detail/simd_targets.h"
// Nor AVX2: its gathers made every state slower on a Xeon (box_panda, one state at a time: 3.8 µs with
// AVX2 lanes here, 3.35 µs with SSE4's, whose gathers are plain loads; the kinematics' AVX2 lanes gain).
#define HWY_DISABLED_TARGETS (CLEARWAY_LANES_DISABLED | HWY_AVX2)  // (before Highway's headers)
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "body/enclosing_lanes.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h
#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace clearway {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// ball = (x, y, z, r, |centre|) per link. Pair k is apart when |c_a − c_b|² > limit², limit = reach +
// band·(|c_a| + |c_b| + reach), reach = r_a + r_b + padding: apart()'s test. A NaN or an infinite radius
// compares false (never apart).
void BoundsApart(const double* x, const double* y, const double* z, const double* r, const double* norm,
                 const std::int64_t* a, const std::int64_t* b, const double* padding, int n, double band,
                 std::uint8_t* out) {
  const hn::ScalableTag<double> d;
  const hn::RebindToSigned<decltype(d)> di;
  using V = hn::Vec<decltype(d)>;
  const int L = static_cast<int>(hn::Lanes(d));
  const V vband = hn::Set(d, band);
  int k = 0;
  for (; k + L <= n; k += L) {
    const auto ia = hn::LoadU(di, a + k), ib = hn::LoadU(di, b + k);
    const V dx = hn::Sub(hn::GatherIndex(d, x, ia), hn::GatherIndex(d, x, ib));
    const V dy = hn::Sub(hn::GatherIndex(d, y, ia), hn::GatherIndex(d, y, ib));
    const V dz = hn::Sub(hn::GatherIndex(d, z, ia), hn::GatherIndex(d, z, ib));
    const V reach = hn::Add(hn::Add(hn::GatherIndex(d, r, ia), hn::GatherIndex(d, r, ib)), hn::LoadU(d, padding + k));
    const V sizes = hn::Add(hn::Add(hn::GatherIndex(d, norm, ia), hn::GatherIndex(d, norm, ib)), reach);
    const V limit = hn::Add(reach, hn::Mul(vband, sizes));
    const V dist2 = hn::Add(hn::Add(hn::Mul(dx, dx), hn::Mul(dy, dy)), hn::Mul(dz, dz));
    alignas(64) double apart[8];
    hn::StoreU(hn::IfThenElseZero(hn::Gt(dist2, hn::Mul(limit, limit)), hn::Set(d, 1.0)), d, apart);
    for (int l = 0; l < L; ++l) out[k + l] = apart[l] != 0.0;
  }
  for (; k < n; ++k) {  // the last few, one at a time, by the same formula
    const double ex = x[a[k]] - x[b[k]], ey = y[a[k]] - y[b[k]], ez = z[a[k]] - z[b[k]];
    const double reach = r[a[k]] + r[b[k]] + padding[k];
    const double limit = reach + band * (norm[a[k]] + norm[b[k]] + reach);
    out[k] = ex * ex + ey * ey + ez * ez > limit * limit;
  }
}

}  // namespace HWY_NAMESPACE
}  // namespace clearway
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace clearway {

HWY_EXPORT(BoundsApart);

void EnclosingBalls::boundsApart(const std::int64_t* a, const std::int64_t* b, const double* padding, int n,
                                 const Tolerances& tol, std::uint8_t* out) const noexcept {
  static_assert(HWY_MAX_BYTES / sizeof(double) <= 8, "the kernel's lane buffer holds 8 doubles");
  if (n <= 0) return;
  if (!poses_) {  // never placed: nothing proved
    std::fill(out, out + n, std::uint8_t{0});
    return;
  }
  const double band = margins::narrowBand(tol.gjk_absolute);
  HWY_DYNAMIC_DISPATCH(BoundsApart)(bound_x_.data(), bound_y_.data(), bound_z_.data(), bound_r_.data(),
                                    bound_norm_.data(), a, b, padding, n, band, out);
}

}  // namespace clearway
#endif  // HWY_ONCE
