// The orientation predicates against exact integer arithmetic: coordinates are integers below 2^20
// scaled by 2^-21, so each determinant is an exact __int128, while the double evaluation rounds and must
// fall through to extended precision or expansions near zero.
#include "shape/orientation.h"

#include <gtest/gtest.h>

#include <array>
#include <random>

namespace clearway::orientation {
namespace {

using I = __int128;
using IVec = std::array<long long, 3>;

constexpr double kScale = 0x1p-21;

Vec3 toVec(const IVec& v) { return Vec3(v[0] * kScale, v[1] * kScale, v[2] * kScale); }

int sign(I x) { return x > 0 ? 1 : (x < 0 ? -1 : 0); }

// The exact sign of ((b − a) × (c − a)) · (q − a).
int exactOrient(const IVec& a, const IVec& b, const IVec& c, const IVec& q) {
  const I bx = b[0] - a[0], by = b[1] - a[1], bz = b[2] - a[2];
  const I cx = c[0] - a[0], cy = c[1] - a[1], cz = c[2] - a[2];
  const I qx = q[0] - a[0], qy = q[1] - a[1], qz = q[2] - a[2];
  return sign((by * cz - bz * cy) * qx + (bz * cx - bx * cz) * qy + (bx * cy - by * cx) * qz);
}

// The exact sign of (a − c) × (b − c) in the plane.
int exactOrient2d(long long ax, long long ay, long long bx, long long by, long long cx, long long cy) {
  return sign(I(ax - cx) * (by - cy) - I(ay - cy) * (bx - cx));
}

struct Points {
  std::mt19937_64 rng{20261127};
  std::uniform_int_distribution<long long> coordinate{-(1LL << 19), 1LL << 19};
  std::uniform_int_distribution<long long> small{-3, 3};

  IVec any() { return {coordinate(rng), coordinate(rng), coordinate(rng)}; }
  // a + i (b − a) + j (c − a) + a nudge of at most one unit per coordinate, kept in range.
  IVec nearPlane(const IVec& a, const IVec& b, const IVec& c) {
    IVec q;
    const long long i = small(rng), j = small(rng);
    for (int k = 0; k < 3; ++k) q[k] = a[k] + i * (b[k] - a[k]) + j * (c[k] - a[k]) + small(rng) / 3;
    return q;
  }
};

TEST(Orientation, SignIsExactOnAndNearPlanes) {
  Points points;
  std::uniform_int_distribution<long long> span{-(1LL << 18), 1LL << 18};
  std::array<long long, 30> fib{0, 1};
  for (std::size_t i = 2; i < fib.size(); ++i) fib[i] = fib[i - 1] + fib[i - 2];  // fib[28] = 317811
  std::uniform_int_distribution<long long> fib_index{24, 28};
  int zeros = 0, undecided = 0, nonzero_undecided = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    // A large triangle whose normal has one component ±1 (Cassini: F(n)² − F(n+1)·F(n−1) = ±1 for
    // Fibonacci numbers near 2^18): moving q by one unit along that axis changes the determinant by ±1,
    // while the products the filter bounds are ~2^55, so near the plane the double evaluation cannot
    // decide and the slow paths must.
    const int n = static_cast<int>(fib_index(points.rng)), axis = static_cast<int>(fib_index(points.rng) % 3);
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const IVec a = points.any();
    IVec b = a, c = a;
    b[axis] += span(points.rng);
    c[axis] += span(points.rng);
    b[u] += fib[n];
    b[v] += fib[n + 1];
    c[u] += fib[n - 1];
    c[v] += fib[n];
    IVec q;
    if (trial % 4 == 0) {
      q = points.any();
    } else {
      const long long i = points.small(points.rng) / 2, j = points.small(points.rng) / 2;  // −1, 0 or 1
      for (int d = 0; d < 3; ++d) q[d] = a[d] + i * (b[d] - a[d]) + j * (c[d] - a[d]);
      q[axis] += points.small(points.rng) / 3;  // −1, 0 or 1
    }
    const Vec3 va = toVec(a), vb = toVec(b), vc = toVec(c), vq = toVec(q);
    const int want = exactOrient(a, b, c, q);
    ASSERT_EQ(orientSign(va, vb, vc, vq), want) << "trial " << trial;
    const FilteredSign f = orientFiltered(va, vb, vc, vq);
    if (f.certain) {
      ASSERT_EQ(f.vol > 0.0 ? 1 : -1, want) << "the filter claimed a wrong sign, trial " << trial;
    } else {
      ++undecided;
      if (want != 0) ++nonzero_undecided;
    }
    if (want == 0) ++zeros;
  }
  // The cases must reach the slow paths, zero and nonzero alike, or the test proves little.
  EXPECT_GT(zeros, 1000);
  EXPECT_GT(undecided, 1000);
  EXPECT_GT(nonzero_undecided, 1000);
}

TEST(Orientation, PlanarSignAndCollinearityAreExact) {
  Points points;
  int zeros = 0, collinear_triples = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const IVec a = points.any();
    IVec d{};
    for (int k = 0; k < 3; ++k) d[k] = points.small(points.rng) * 131 + 1;
    const long long t = points.small(points.rng), s = points.small(points.rng);
    IVec b, c;
    for (int k = 0; k < 3; ++k) {
      b[k] = a[k] + t * d[k];
      c[k] = a[k] + s * d[k] + (trial % 3 == 0 ? points.small(points.rng) / 3 : 0);
    }
    const int want = exactOrient2d(a[0], a[1], b[0], b[1], c[0], c[1]);
    ASSERT_EQ(orient2dSign(a[0] * kScale, a[1] * kScale, b[0] * kScale, b[1] * kScale, c[0] * kScale, c[1] * kScale),
              want)
        << "trial " << trial;
    if (want == 0) ++zeros;
    bool on_line = true;
    for (int k = 0; k < 3; ++k) {
      const int u = (k + 1) % 3, v = (k + 2) % 3;
      on_line = on_line && exactOrient2d(a[u], a[v], b[u], b[v], c[u], c[v]) == 0;
    }
    ASSERT_EQ(collinear(toVec(a), toVec(b), toVec(c)), on_line) << "trial " << trial;
    if (on_line) ++collinear_triples;
  }
  EXPECT_GT(zeros, 1000);
  EXPECT_GT(collinear_triples, 1000);
}

}  // namespace
}  // namespace clearway::orientation
