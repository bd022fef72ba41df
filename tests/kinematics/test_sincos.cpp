// detail::sinCos against long double sinl/cosl (x87: 64-bit significands, so the reference errs by
// ~2^-64): within 2^-52 absolute wherever the fast path runs, libm's values beyond it.
#include "kinematics/sincos.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace clearway::detail {
namespace {

constexpr double kBound = 0x1p-52;

struct Worst {
  double error = 0.0, at = 0.0;
  int checked = 0;
};

// Checks one angle; returns false (and says where) when either value is off by more than the bound.
bool within(double x, Worst& worst) {
  double s, c;
  sinCos(x, &s, &c);
  const long double xs = x;
  const double es = static_cast<double>(std::fabs(static_cast<long double>(s) - std::sin(xs)));
  const double ec = static_cast<double>(std::fabs(static_cast<long double>(c) - std::cos(xs)));
  const double e = std::max(es, ec);
  ++worst.checked;
  if (e > worst.error) {
    worst.error = e;
    worst.at = x;
  }
  return e <= kBound;
}

TEST(SinCos, WithinTheBoundOnJointRanges) {
  if (std::numeric_limits<long double>::digits < 64) GTEST_SKIP() << "no extended long double for a reference";
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> joint(-2.0 * M_PI, 2.0 * M_PI), wide(-0x1p16, 0x1p16);
  std::uniform_real_distribution<double> tiny_exponent(-60.0, 0.0);
  Worst worst;
  for (int i = 0; i < 1000000; ++i) ASSERT_TRUE(within(joint(rng), worst)) << "x = " << std::hexfloat << worst.at;
  for (int i = 0; i < 200000; ++i) ASSERT_TRUE(within(wide(rng), worst)) << "x = " << std::hexfloat << worst.at;
  for (int i = 0; i < 100000; ++i) {  // small angles, both signs
    const double x = std::ldexp(1.0, static_cast<int>(tiny_exponent(rng))) * (1.0 + joint(rng) / 8.0);
    ASSERT_TRUE(within(x, worst)) << "x = " << std::hexfloat << worst.at;
  }
  std::printf("max error %.3g = %.3f units of 2^-53 at x = %a over %d angles\n", worst.error, worst.error / 0x1p-53,
              worst.at, worst.checked);
}

TEST(SinCos, WithinTheBoundNearMultiplesOfHalfPi) {
  if (std::numeric_limits<long double>::digits < 64) GTEST_SKIP() << "no extended long double for a reference";
  // The doubles around k·π/2, where the reduction cancels most bits, and around the quadrant boundaries
  // (k + 1/2)·π/2, where k may round either way, for every k the fast path reaches and then some.
  const long double half_pi = 1.5707963267948966192313216916397514L;
  Worst worst;
  for (long k = -41800; k <= 41800; ++k) {
    for (const long double at : {k * half_pi, (k + 0.5L) * half_pi}) {
      double x = static_cast<double>(at);
      for (int step = 0; step < 3; ++step) x = std::nextafter(x, -INFINITY);
      for (int step = 0; step < 7; ++step, x = std::nextafter(x, INFINITY)) {
        ASSERT_TRUE(within(x, worst)) << "x = " << std::hexfloat << x << " (k = " << k << ")";
      }
    }
  }
  EXPECT_GT(worst.checked, 1000000);
  std::printf("max error %.3g = %.3f units of 2^-53 at x = %a over %d angles\n", worst.error, worst.error / 0x1p-53,
              worst.at, worst.checked);
}

TEST(SinCos, LibmBeyondTheFastRangeAndForNonFinite) {
  for (const double x : {0x1p16 + 1.0, -1e6, 1e300, -0x1p60}) {
    double s, c;
    sinCos(x, &s, &c);
    EXPECT_EQ(s, std::sin(x)) << x;
    EXPECT_EQ(c, std::cos(x)) << x;
  }
  for (const double x : {std::numeric_limits<double>::quiet_NaN(), double(INFINITY), -double(INFINITY)}) {
    double s = 0.0, c = 0.0;
    sinCos(x, &s, &c);
    EXPECT_TRUE(std::isnan(s) && std::isnan(c)) << x;
  }
  double s, c;
  sinCos(0.0, &s, &c);
  EXPECT_EQ(s, 0.0);
  EXPECT_EQ(c, 1.0);
}

}  // namespace
}  // namespace clearway::detail
