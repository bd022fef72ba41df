// The slow paths of the orientation predicates: extended precision, then exact expansion arithmetic.
#include "shape/orientation.h"

#include <array>
#include <cassert>
#include <limits>

#if defined(__FAST_MATH__)
#error "orientation.cpp needs IEEE arithmetic: the exact predicates break under -ffast-math"
#endif

namespace clearway::orientation {
namespace {

// s + e == a + b exactly (Knuth's two-sum, no ordering of |a| and |b| needed).
inline void twoSum(double a, double b, double& s, double& e) {
  s = a + b;
  const double bv = s - a;
  const double av = s - bv;
  e = (a - av) + (b - bv);
}

// p + e == a · b exactly.
inline void twoProduct(double a, double b, double& p, double& e) {
  p = a * b;
  e = std::fma(a, b, -p);
}

// An exact sum of doubles kept as a nonoverlapping expansion: components in increasing magnitude,
// zeros dropped, so the sign of the sum is the sign of the last component.
class Expansion {
 public:
  void add(double b) {
    // Grow-expansion: carry b up through the components; each step is exact, and its rounding errors
    // become the new (smaller, nonoverlapping) components.
    double q = b;
    int m = 0;
    for (int i = 0; i < n_; ++i) {
      double s, e;
      twoSum(q, c_[i], s, e);
      q = s;
      if (e != 0.0) c_[m++] = e;
    }
    if (q != 0.0) c_[m++] = q;
    n_ = m;
    assert(n_ < static_cast<int>(c_.size()));
  }
  // Adds sign · x · y exactly.
  void addProduct(double sign, double x, double y) {
    double p, e;
    twoProduct(sign * x, y, p, e);
    add(e);
    add(p);
  }
  // Adds sign · x · y · z exactly.
  void addProduct(double sign, double x, double y, double z) {
    double p, e, p1, e1, p2, e2;
    twoProduct(y, z, p, e);
    twoProduct(sign * x, p, p1, e1);
    twoProduct(sign * x, e, p2, e2);
    add(e2);
    add(p2);
    add(e1);
    add(p1);
  }
  int sign() const { return n_ == 0 ? 0 : (c_[n_ - 1] > 0.0 ? 1 : -1); }

 private:
  std::array<double, 128> c_;  // ≤ 96 terms are ever added, and each add grows the length by ≤ 1
  int n_ = 0;
};

// Adds sign · x · (y × z) exactly.
void addTripleProduct(Expansion& ex, double sign, const Vec3& x, const Vec3& y, const Vec3& z) {
  ex.addProduct(sign, x[0], y[1], z[2]);
  ex.addProduct(-sign, x[0], y[2], z[1]);
  ex.addProduct(sign, x[1], y[2], z[0]);
  ex.addProduct(-sign, x[1], y[0], z[2]);
  ex.addProduct(sign, x[2], y[0], z[1]);
  ex.addProduct(-sign, x[2], y[1], z[0]);
}


int orientExact(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& q) {
  if (q == a || q == b || q == c) return 0;
  // Four points sharing a coordinate lie in an axis-aligned plane: the commonest exact zero (flat faces
  // of CAD parts), settled without expansions.
  for (int k = 0; k < 3; ++k) {
    if (a[k] == q[k] && b[k] == q[k] && c[k] == q[k]) return 0;
  }
  Vec3 ad, bd, cd;
  bool differences_exact = true;
  for (int k = 0; k < 3; ++k) {
    double e;
    twoSum(a[k], -q[k], ad[k], e);
    differences_exact = differences_exact && e == 0.0;
    twoSum(b[k], -q[k], bd[k], e);
    differences_exact = differences_exact && e == 0.0;
    twoSum(c[k], -q[k], cd[k], e);
    differences_exact = differences_exact && e == 0.0;
  }
  Expansion ex;
  if (differences_exact) {
    addTripleProduct(ex, 1.0, ad, cd, bd);
  } else {
    // Multilinearity: (a − q)·((c − q) × (b − q)) = [a,c,b] − [q,c,b] − [a,q,b] − [a,c,q].
    addTripleProduct(ex, 1.0, a, c, b);
    addTripleProduct(ex, -1.0, q, c, b);
    addTripleProduct(ex, -1.0, a, q, b);
    addTripleProduct(ex, -1.0, a, c, q);
  }
  return ex.sign();
}

// Where long double is x87 extended precision (64-bit significand), a second filter in it settles
// points within ~1e-16 of a plane (rounding noise) at a fraction of the cost of expansions.
constexpr bool kExtendedFilter = std::numeric_limits<long double>::digits == 64;

// The same evaluation and bound as orientFiltered, in long double; 0 when undecided.
int orientExtended(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& q) {
  using L = long double;
  const L ax = L(a.x()) - q.x(), ay = L(a.y()) - q.y(), az = L(a.z()) - q.z();
  const L bx = L(b.x()) - q.x(), by = L(b.y()) - q.y(), bz = L(b.z()) - q.z();
  const L cx = L(c.x()) - q.x(), cy = L(c.y()) - q.y(), cz = L(c.z()) - q.z();
  const L p0 = cy * bz, p1 = cz * by, p2 = cz * bx, p3 = cx * bz, p4 = cx * by, p5 = cy * bx;
  const L det = ax * (p0 - p1) + ay * (p2 - p3) + az * (p4 - p5);
  const L perm = std::abs(ax) * (std::abs(p0) + std::abs(p1)) + std::abs(ay) * (std::abs(p2) + std::abs(p3)) +
                 std::abs(az) * (std::abs(p4) + std::abs(p5));
  const L unit = std::numeric_limits<L>::epsilon() / 2;
  if (perm >= L(kMinPermanent) && std::abs(det) > 12 * unit * perm) return det > 0 ? 1 : -1;
  return 0;
}

}  // namespace

int orientUncertain(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& q) {
  if (kExtendedFilter) {
    if (const int sign = orientExtended(a, b, c, q); sign != 0) return sign;
  }
  return orientExact(a, b, c, q);
}

int orient2dSign(double ax, double ay, double bx, double by, double cx, double cy) {
  const double l = (ax - cx) * (by - cy), r = (ay - cy) * (bx - cx);
  const double det = l - r, perm = std::abs(l) + std::abs(r);
  // Differences, products and the subtraction: ≤ 4u·perm; 8u leaves room for the rounding of perm.
  if (perm >= kMinPermanent && std::abs(det) > 8.0 * kUnitRoundoff * perm) return det > 0.0 ? 1 : -1;
  if ((ax == bx && bx == cx) || (ay == by && by == cy)) return 0;  // on an axis-parallel line
  // [a,b] − [c,b] − [a,c], with [x,y] = x₀y₁ − x₁y₀.
  Expansion ex;
  ex.addProduct(1.0, ax, by);
  ex.addProduct(-1.0, ay, bx);
  ex.addProduct(-1.0, cx, by);
  ex.addProduct(1.0, cy, bx);
  ex.addProduct(-1.0, ax, cy);
  ex.addProduct(1.0, ay, cx);
  return ex.sign();
}

bool collinear(const Vec3& a, const Vec3& b, const Vec3& c) {
  for (int k = 0; k < 3; ++k) {
    const int u = (k + 1) % 3, v = (k + 2) % 3;
    if (orient2dSign(a[u], a[v], b[u], b[v], c[u], c[v]) != 0) return false;
  }
  return true;
}

}  // namespace clearway::orientation
