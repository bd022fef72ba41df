// The soundness margins (detail/margins.h) keep their values: each was argued once, and a change must be
// deliberate. Each is also checked against what it claims to cover, on the worst inputs we can build.
#include <clearway/detail/margins.h>
#include <clearway/math.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace clearway {
namespace {

TEST(Margins, KeepTheirValues) {
  EXPECT_EQ(margins::kUlp, std::ldexp(1.0, -52));
  EXPECT_EQ(margins::kRounding, 1e-12);
  EXPECT_EQ(margins::kSlack, 1e-9);
  EXPECT_EQ(margins::kBeyond, 1.0 + 1e-9);
  EXPECT_EQ(margins::roundedUp(2.0, 3.0), 2.0 * (1.0 + 1e-12) + 3e-12);
  EXPECT_EQ(margins::narrowBand(1e-10), 1e-10);
  EXPECT_EQ(margins::narrowBand(0.0), 64.0 * std::numeric_limits<double>::epsilon());
  EXPECT_EQ(margins::placedRounding(1.0, 2.0), 48.0 * std::numeric_limits<double>::epsilon());
  EXPECT_EQ(margins::boxRounding(4.0), 64.0 * std::numeric_limits<double>::epsilon());
  static_assert(margins::kBeyond > 1.0 && margins::kRounding < margins::kSlack, "the order the proofs use");
}

// placedRounding holds the rounding of R·c + t: computed in double against long double, for rotations
// and points of every scale, the error never reaches half the margin.
TEST(Margins, PlacedRoundingHoldsThePlacementsRounding) {
  if (std::numeric_limits<long double>::digits <= std::numeric_limits<double>::digits)
    GTEST_SKIP() << "long double is no wider than double here: no exact reference to measure the rounding";
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0), e(-30.0, 30.0);
  double worst = 0.0;
  for (int i = 0; i < 200000; ++i) {
    const Eigen::Quaterniond q(u(rng), u(rng), u(rng), u(rng));
    if (q.norm() < 1e-3) continue;
    const Mat3 R = q.normalized().toRotationMatrix();
    const Vec3 c = std::pow(10.0, e(rng) / 10.0) * Vec3(u(rng), u(rng), u(rng));
    const Vec3 t = std::pow(10.0, e(rng) / 10.0) * Vec3(u(rng), u(rng), u(rng));
    const Vec3 placed = R * c + t;
    long double err2 = 0.0L;
    for (int k = 0; k < 3; ++k) {
      long double exact = static_cast<long double>(t[k]);
      for (int j = 0; j < 3; ++j) exact += static_cast<long double>(R(k, j)) * static_cast<long double>(c[j]);
      const long double d = static_cast<long double>(placed[k]) - exact;
      err2 += d * d;
    }
    const double ratio = static_cast<double>(std::sqrt(err2)) / margins::placedRounding(c.norm(), t.norm());
    worst = std::max(worst, ratio);
  }
  EXPECT_LT(worst, 0.5) << "the placement's rounding against its margin";
}

}  // namespace
}  // namespace clearway
