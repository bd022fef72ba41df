#pragma once
// sin and cos of one joint angle, inline and without a libm call: about a third of libm's cost, and a
// form that lanes of angles can share later.
//
// For |x| ≤ 2^16, each result is within 2^-52 (two units of 2^-53) of the exact value, absolute; beyond
// it, and for NaN and ±∞, the values are libm's. Why the bound holds:
// - Reduction: x = k·π/2 + r with k the integer nearest x·2/π (|k| < 2^16) and π/2 = C1 + C2 + C3, where
//   C1 and C2 have 37 significant bits, so k·C1 and k·C2 are exact. x − k·C1 is exact (for |x| ≥ 1 it is
//   a multiple of ulp(x) no larger than |x|; for 1/2 ≤ |x| < 1, a multiple of 2^-53 below 1; below 1/2,
//   k = 0). Subtracting k·C2 keeps its error term (two-sum), so hi + lo = r within
//   |k|·(|π/2 − C1 − C2 − C3| + ulp(k·C3)) + ulp(lo) < 2^-100.
// - Polynomials: Taylor series of sin to r^17 and cos to r^18 on |r| ≤ π/4 (+ rounding); their remainders
//   are below 9e-20 = 2^-63. sin: hi + (hi·z·S(z) + lo·(1 − z/2)), z = hi²: the last addition rounds by at
//   most 2^-53·|sin| ≤ 0.71·2^-53; the tail (|tail| ≤ 0.08) is evaluated to within 6 roundings of itself,
//   ≤ 0.5·2^-53; terms of order lo² are below 2^-100. cos: w = 1 − z/2, its rounding error recovered
//   exactly as (1 − w) − z/2 (1 − w is exact by Sterbenz), plus z²·C(z) − hi·lo (|·| ≤ 0.016, to within
//   0.1·2^-53): ≤ 1.1·2^-53 with the last addition. Both stay below 2^-52; tests/kinematics measure it.
#include <cmath>

#if defined(__FAST_MATH__)
#error "sincos.h needs IEEE arithmetic: the reduction's exact steps break under -ffast-math"
#endif

namespace clearway::detail {

// The constants of sinCos, shared with its lanes (kinematic_lanes.cpp), which repeat its operations in its
// order: Highway's target-specific operations cannot be called from a template compiled for no target.
struct SinCosConstants {
  static constexpr double kTwoOverPi = 0x1.45f306dc9c883p-1;
  static constexpr double kC1 = 0x1.921fb54440000p+0, kC2 = 0x1.68c234c4c0000p-39, kC3 = 0x1.98a2e03707345p-77;
  static constexpr double kRound = 0x1.8p52;  // adding and subtracting it rounds |v| < 2^51 to an integer
  static constexpr double kRange = 0x1p16;    // beyond it (and for NaN): libm
  // Taylor coefficients: sin r = r + r·z·S(z), cos r = 1 − z/2 + z²·C(z), z = r².
  static constexpr double kS[8] = {-0x1.5555555555555p-3,  0x1.1111111111111p-7,  -0x1.a01a01a01a01ap-13,
                                   0x1.71de3a556c734p-19,  -0x1.ae64567f544e4p-26, 0x1.6124613a86d09p-33,
                                   -0x1.ae7f3e733b81fp-41, 0x1.952c77030ad4ap-49};
  static constexpr double kC[8] = {0x1.5555555555555p-5,   -0x1.6c16c16c16c17p-10, 0x1.a01a01a01a01ap-16,
                                   -0x1.27e4fb7789f5cp-22, 0x1.1eed8eff8d898p-29,  -0x1.93974a8c07c9dp-37,
                                   0x1.ae7f3e733b81fp-45,  -0x1.6827863b97d97p-53};
};

/// *s = sin x, *c = cos x, each within 2^-52 absolute for |x| ≤ 2^16 (libm's values beyond).
inline void sinCos(double x, double* s, double* c) noexcept {
  using K = SinCosConstants;
  if (!(std::abs(x) <= K::kRange)) {  // (NaN too)
    *s = std::sin(x);
    *c = std::cos(x);
    return;
  }
  const double k = (x * K::kTwoOverPi + K::kRound) - K::kRound;
  const double r1 = x - k * K::kC1;  // exact (above)
  const double p2 = k * K::kC2;      // exact
  // hi + lo = r1 − p2 − k·C3: two-sum of r1 and −p2 (|lo| ≤ ulp(hi)/2 + 2^-60).
  const double hi = r1 - p2;
  const double hv = hi - r1;
  const double lo = ((r1 - (hi - hv)) - (p2 + hv)) - k * K::kC3;
  // The polynomials in z = hi², by Estrin's scheme: each term is below 1/30 of the one before, so the sum keeps
  // the error of Horner's while its latency is half.
  const double z = hi * hi, z2 = z * z, z4 = z2 * z2;
  const auto estrin = [&](const double* a) {
    return (a[0] + z * a[1]) + z2 * (a[2] + z * a[3]) + z4 * ((a[4] + z * a[5]) + z2 * (a[6] + z * a[7]));
  };
  const double S = estrin(K::kS), C = estrin(K::kC);
  const double half_z = 0.5 * z;
  const double sin_r = hi + (hi * z * S + lo * (1.0 - half_z));
  const double w = 1.0 - half_z;
  const double cos_r = w + (((1.0 - w) - half_z) + (z * z * C - hi * lo));
  // The quadrant picks and signs by indexing, not branching: joint angles fall in every quadrant.
  const long long quadrant = static_cast<long long>(k);
  const double v[2] = {sin_r, cos_r};
  *s = v[quadrant & 1] * static_cast<double>(1 - (quadrant & 2));
  *c = v[(quadrant & 1) ^ 1] * static_cast<double>(1 - ((quadrant + 1) & 2));
}

}  // namespace clearway::detail
