// sin and cos over a vector of angles, per SIMD target: detail::sinCos (sincos.h) operation for operation, so
// bit for bit. Included after <hwy/highway.h> by each kernel compiled per target (foreach_target.h).
// (Highway's per-target include guard: the header is read once for each target.)
#if defined(CLEARWAY_KINEMATICS_SINCOS_LANES_INL_H_) == defined(HWY_TARGET_TOGGLE)
#ifdef CLEARWAY_KINEMATICS_SINCOS_LANES_INL_H_
#undef CLEARWAY_KINEMATICS_SINCOS_LANES_INL_H_
#else
#define CLEARWAY_KINEMATICS_SINCOS_LANES_INL_H_
#endif

#include <cmath>
#include <cstddef>

#include "kinematics/sincos.h"

#include <hwy/highway.h>

HWY_BEFORE_NAMESPACE();
namespace clearway {
namespace HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

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

}  // namespace HWY_NAMESPACE
}  // namespace clearway
HWY_AFTER_NAMESPACE();

#endif
