// Randomized property tests of GJK distance / intersection, EPA, the ray cast and the shape cast
// against the independent reference of reference.h (triangle–triangle distances, SAT, slab clipping;
// no support mappings). Fixed seeds (std::mt19937_64), so every run sees the same cases.
//
// The bounds, from the documented semantics (tolerances.h, gjk.h, epa.h, ray_cast.h), with
//   s      = |t_b − t_a| + size_a + size_b (the size of the Minkowski difference A − B: the scale GJK's
//            absolute tolerances are relative to), and
//   tiny   = 1e-12 · (largest world coordinate): rounding of the inputs and of the world transforms.
// * distance (disjoint): lower_bound ≤ ref + tiny, ref ≤ distance + tiny, and
//   distance − ref ≤ gjk_relative · (ref + r_a + r_b) + tiny: GJK's relative tolerance applies to the
//   distance of the *cores* (ref + r_a + r_b; equal to ref for polytopes).
//   Within gjk_absolute·s of contact a "Touching" exit may report 0 (tolerances.h: below rounding the
//   distance is 0), so there the lower side and the witness gap get 2·gjk_absolute·s of slack.
// * distance (overlapping): distance ≤ 2·gjk_absolute·s.
// * witnesses: point_a within tiny of A, point_b of B, | |point_a − point_b| − distance | ≤ 4·tiny.
// * booleans (gjkIntersect, cold and warm cache, and mayCollide): must agree with the reference
//   whenever |signed distance| > band = 1e-8·s (1e-9·s in NearContactPairs). Inside the band either
//   answer is allowed: gjkIntersect counts shapes within gjk_absolute·max‖y‖ ≤ 1e-10·s as intersecting.
// * EPA depth: |depth − ref depth| ≤ max(epa, gjk)_relative · (ref depth + r_a + r_b) + tiny; moving B by
//   (depth·(1 + 1e-6) + 1e-9·s)·normal separates (reference and gjkIntersect), by 0.99·depth does not.
// * casts: t ≤ t_ref + tiny (t is a certified lower bound); the point (or A) at t is within
//   2·cast_relative·s of the target; hit/miss agrees with the reference when it is robust to moving every
//   face plane by δ = 1e-5·s in or out.
#include "narrowphase/reference.h"

#include <clearway/narrowphase/epa.h>
#include <clearway/narrowphase/gjk.h>
#include <clearway/narrowphase/ray_cast.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <sstream>
#include <string>
#include <vector>

using namespace clearway;

namespace {

using Rng = std::mt19937_64;

double uniform(Rng& g, double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(g); }
double logUniform(Rng& g, double lo, double hi) { return std::exp(uniform(g, std::log(lo), std::log(hi))); }
int uniformInt(Rng& g, int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(g); }

Vec3 unitVector(Rng& g) {
  std::normal_distribution<double> n;
  for (;;) {
    const Vec3 v(n(g), n(g), n(g));
    if (v.norm() > 1e-3) return v.normalized();
  }
}

Mat3 randomRotation(Rng& g) {
  std::normal_distribution<double> n;
  return Eigen::Quaterniond(n(g), n(g), n(g), n(g)).normalized().toRotationMatrix();
}

Vec3 inBall(Rng& g, double radius) { return unitVector(g) * radius * std::cbrt(uniform(g, 0.0, 1.0)); }

// 4–20 points in a ball of the given radius, squashed along each axis by a random factor in [0.2, 1].
std::vector<Vec3> randomCloud(Rng& g, double radius) {
  const int n = uniformInt(g, 4, 20);
  const Vec3 squash(uniform(g, 0.2, 1.0), uniform(g, 0.2, 1.0), uniform(g, 0.2, 1.0));
  std::vector<Vec3> pts;
  for (int i = 0; i < n; ++i) pts.push_back(inBall(g, radius).cwiseProduct(squash));
  return pts;
}

// Tracks the largest value of an error measure, printed at the end of a test.
struct Stat {
  const char* name;
  int count = 0;
  double max = 0.0;
  void add(double e) {
    ++count;
    if (e > max || std::isnan(e)) max = e;
  }
};

void print(const std::vector<const Stat*>& stats) {
  for (const Stat* s : stats) std::printf("[   stat   ] %-48s %6d cases, max %.3g\n", s->name, s->count, s->max);
}

// Stop a randomized loop after a handful of failing cases instead of flooding the log.
bool tooManyFailures() {
  return ::testing::UnitTest::GetInstance()->current_test_info()->result()->total_part_count() > 30;
}

std::string str(const Vec3& v) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "(%.17g, %.17g, %.17g)", v.x(), v.y(), v.z());
  return buf;
}

std::string str(const Pose& p) {
  const Eigen::Quaterniond q(p.R);
  char buf[256];
  std::snprintf(buf, sizeof buf, "quat(x,y,z,w)=(%.17g, %.17g, %.17g, %.17g) t=%s", q.x(), q.y(), q.z(), q.w(),
                str(p.t).c_str());
  return buf;
}

// ---- Bodies: a library Shape with its reference geometry -------------------------------------------

enum class Kind { Box, Sphere, Capsule, Cylinder, Cone, Triangle, Segment, Hull };
constexpr Kind kAllKinds[] = {Kind::Box,      Kind::Sphere,  Kind::Capsule, Kind::Cylinder,
                              Kind::Cone,     Kind::Triangle, Kind::Segment, Kind::Hull};
const char* kindName(Kind k) {
  static const char* names[] = {"box", "sphere", "capsule", "cylinder", "cone", "triangle", "segment", "hull"};
  return names[static_cast<int>(k)];
}

// Curved solids are bracketed by the prisms / pyramids over regular 32-gons inscribed in and
// circumscribed about their circles (radial gap 1 − cos(π/32) ≈ 4.8e-3 of the radius).
constexpr int kPolygonSides = 32;

struct Body {
  Kind kind;
  Shape shape;
  Pose pose;
  ref::Mesh inner, outer;  // the polytope core; for a cylinder or cone, polytopes inside and around it
  double radius = 0.0;     // the core's sweep radius (sphere, capsule)
  double size = 0.0;       // bounding radius about pose.t
  bool exact = true;       // inner == outer
  double r = 0.0, h = 0.0; // cylinder / cone parameters
  std::string text;        // the construction, to reproduce a failing case
};

double meshSize(const ref::Mesh& m, const Vec3& c) {
  double s = 0.0;
  for (const Vec3& v : m.verts) s = std::max(s, (v - c).norm());
  return s;
}

Body makeBody(Kind kind, double size, const Pose& pose, Rng& g) {
  Body b{kind, Point(), pose, {}, {}, 0.0, 0.0, true, 0.0, 0.0, ""};
  std::ostringstream text;
  text.precision(17);
  text << kindName(kind) << " pose " << str(pose) << " ";
  switch (kind) {
    case Kind::Box: {
      const Vec3 half = size * Vec3(uniform(g, 0.2, 0.6), uniform(g, 0.2, 0.6), uniform(g, 0.2, 0.6));
      b.shape = Box(half);
      b.inner = ref::meshFromBox(half, pose);
      text << "half " << str(half);
      break;
    }
    case Kind::Sphere:
      b.shape = Sphere(size);
      b.radius = size;
      b.inner = ref::meshFromPoint(pose.t);
      text << "r " << size;
      break;
    case Kind::Capsule:
      b.r = size * uniform(g, 0.2, 0.5);
      b.h = size * uniform(g, 0.1, 0.6);
      b.shape = Capsule(b.r, b.h);
      b.radius = b.r;
      b.inner = ref::meshFromSegment(pose * Vec3(0, 0, -b.h), pose * Vec3(0, 0, b.h));
      text << "r " << b.r << " h " << b.h;
      break;
    case Kind::Cylinder:
    case Kind::Cone:
      b.r = size * uniform(g, 0.3, 0.7);
      b.h = size * uniform(g, 0.2, 0.7);
      if (kind == Kind::Cylinder) {
        b.shape = Cylinder(b.r, b.h);
        b.inner = ref::meshFromCylinder(b.r, b.h, kPolygonSides, false, pose);
        b.outer = ref::meshFromCylinder(b.r, b.h, kPolygonSides, true, pose);
      } else {
        b.shape = Cone(b.r, b.h);
        b.inner = ref::meshFromCone(b.r, b.h, kPolygonSides, false, pose);
        b.outer = ref::meshFromCone(b.r, b.h, kPolygonSides, true, pose);
      }
      b.exact = false;
      text << "r " << b.r << " h " << b.h;
      break;
    case Kind::Triangle: {
      const Vec3 p0 = inBall(g, size), p1 = inBall(g, size), p2 = inBall(g, size);
      b.shape = Triangle(p0, p1, p2);
      b.inner = ref::meshFromTriangle(pose * p0, pose * p1, pose * p2);
      text << str(p0) << " " << str(p1) << " " << str(p2);
      break;
    }
    case Kind::Segment: {
      const Vec3 p0 = inBall(g, size), p1 = inBall(g, size);
      b.shape = Segment(p0, p1);
      b.inner = ref::meshFromSegment(pose * p0, pose * p1);
      text << str(p0) << " " << str(p1);
      break;
    }
    case Kind::Hull: {
      const std::vector<Vec3> pts = randomCloud(g, size);
      const ConvexHull hull(pts);
      b.inner = ref::meshFromHull(hull, pose);
      b.shape = hull;
      text << "points";
      for (const Vec3& p : pts) text << " " << str(p);
      break;
    }
  }
  if (b.exact) b.outer = b.inner;
  b.size = meshSize(b.outer, pose.t) + b.radius;
  b.text = text.str();
  return b;
}

Body moved(const Body& b, const Vec3& delta) {
  Body m = b;
  m.pose.t += delta;
  m.inner = ref::translated(b.inner, delta);
  m.outer = ref::translated(b.outer, delta);
  m.text += " moved by " + str(delta);
  return m;
}

// Distance from a point to the body (0 inside): exact for polytope cores, analytic in the meridian
// half-plane for cylinders and cones (solids of revolution).
double pointDistance(const Body& b, const Vec3& p) {
  if (b.exact) return std::max(0.0, ref::pointDistance(b.inner, p) - b.radius);
  const Vec3 q = b.pose.R.transpose() * (p - b.pose.t);
  const double rho = std::hypot(q.x(), q.y());
  if (b.kind == Kind::Cylinder) return std::hypot(std::max(0.0, rho - b.r), std::max(0.0, std::abs(q.z()) - b.h));
  const Vec3 x(rho, q.z(), 0.0);
  return (ref::closestOnTriangle(x, Vec3(0, -b.h, 0), Vec3(b.r, -b.h, 0), Vec3(0, b.h, 0)) - x).norm();
}

// The true signed distance of a pair lies in [lo, hi] (equal for exact bodies): inclusion-monotone.
struct Bracket {
  double lo, hi;
};

Bracket signedBracket(const Body& a, const Body& b) {
  const double rsum = a.radius + b.radius;
  const double hi = ref::signedDistance(a.inner, b.inner).value - rsum;
  if (a.exact && b.exact) return {hi, hi};
  return {ref::signedDistance(a.outer, b.outer).value - rsum, hi};
}

// Scales of a pair (see the header comment).
struct Scales {
  double s, tiny, band;
};

Scales scalesOf(const Body& a, const Body& b) {
  const double s = (b.pose.t - a.pose.t).norm() + a.size + b.size;
  const double world = std::max(a.pose.t.norm(), b.pose.t.norm()) + a.size + b.size;
  return {s, 1e-12 * world, 1e-8 * s};
}

bool finite(const DistanceResult& d) {
  return std::isfinite(d.distance) && std::isfinite(d.lower_bound) && d.point_a.allFinite() && d.point_b.allFinite() &&
         d.normal.allFinite();
}

// The statistics a pair check feeds.
struct PairStats {
  Stat dist_rel{"distance: |d - ref| / ref (exact pairs)"};
  Stat dist_abs{"distance: |d - ref| / s (exact pairs)"};
  Stat bracket{"distance: outside [lo, hi] / s (curved pairs)"};
  Stat lower{"lower_bound - ref, / s"};
  Stat witness{"witness: distance to own shape / s"};
  Stat witness_gap{"witness: ||pa - pb| - distance| / s"};
  Stat overlap_dist{"overlapping: reported distance / s"};
  Stat epa_rel{"EPA: |depth - ref| / (ref + r_a + r_b)"};
  Stat epa_sep{"EPA: ref signed distance after moving out, / s"};
  int disjoint = 0, overlapping = 0, in_band = 0;
  void print() const {
    ::print({&dist_rel, &dist_abs, &bracket, &lower, &witness, &witness_gap, &overlap_dist, &epa_rel, &epa_sep});
    std::printf("[   stat   ] pairs: %d disjoint, %d overlapping, %d inside the band\n", disjoint, overlapping, in_band);
  }
};


// One pair against the reference: distance, witnesses, booleans (outside ±band_factor·s), EPA.
void checkPair(const Body& a, const Body& b, const Tolerances& tol, PairStats& st, double band_factor = 1e-8) {
  SCOPED_TRACE("A: " + a.text + "\nB: " + b.text);
  const Bracket ref = signedBracket(a, b);
  const auto [s, tiny, default_band] = scalesOf(a, b);
  const double band = band_factor * s;
  const double rsum = a.radius + b.radius;
  // A "Touching" exit reports 0 for cores within gjk_absolute·max‖y‖ ≤ gjk_absolute·s of each other.
  const double touch = 2 * tol.gjk_absolute * s;

  const DistanceResult d = gjkDistance(a.shape, a.pose, b.shape, b.pose, tol);
  ASSERT_FALSE(isFailure(d.status)) << statusName(d.status);
  ASSERT_TRUE(finite(d));
  EXPECT_LE(d.lower_bound, d.distance);
  SimplexCache cold;
  const IntersectResult hit = gjkIntersect(a.shape, a.pose, b.shape, b.pose, tol, cold);
  ASSERT_FALSE(isFailure(hit.status)) << statusName(hit.status);

  // Witnesses lie on their shapes, and their gap is the reported distance.
  const double wa = pointDistance(a, d.point_a), wb = pointDistance(b, d.point_b);
  EXPECT_LE(wa, tiny) << "point_a " << str(d.point_a) << " is off A";
  EXPECT_LE(wb, tiny) << "point_b " << str(d.point_b) << " is off B";
  st.witness.add(std::max(wa, wb) / s);

  if (ref.lo > 0.0) {
    // Disjoint: the reported bounds bracket the reference (the lower side may drop to 0 by "Touching"
    // only within gjk_absolute·s of contact).
    EXPECT_LE(d.lower_bound, ref.hi + tiny);
    EXPECT_GE(d.distance, ref.lo - tiny - (ref.lo <= touch ? touch : 0.0)) << statusName(d.status);
    EXPECT_LE(d.distance, ref.hi + tol.gjk_relative * (ref.hi + rsum) + tiny) << "ref " << ref.hi;
    const double gap = std::abs((d.point_b - d.point_a).norm() - d.distance);
    EXPECT_LE(gap, 4 * tiny + (ref.lo <= touch ? touch : 0.0));
    st.witness_gap.add(gap / s);
    st.lower.add((d.lower_bound - ref.hi) / s);
    if (a.exact && b.exact) {
      st.dist_rel.add(std::abs(d.distance - ref.hi) / ref.hi);
      st.dist_abs.add(std::abs(d.distance - ref.hi) / s);
    } else {
      st.bracket.add(std::max({0.0, ref.lo - d.distance, d.distance - ref.hi}) / s);
    }
  }
  if (ref.lo > band) {
    ++st.disjoint;
    EXPECT_FALSE(d.mayCollide());
    EXPECT_FALSE(hit.intersecting) << "ref distance " << ref.lo;
    EXPECT_NEAR(d.normal.norm(), 1.0, 1e-9);
    EXPECT_GT(d.normal.dot(d.point_b - d.point_a), 0.0);
  } else if (ref.hi < -band) {
    ++st.overlapping;
    EXPECT_LE(d.distance, touch) << "ref depth " << -ref.hi;
    EXPECT_TRUE(d.mayCollide()) << statusName(d.status) << " distance " << d.distance << ", ref depth " << -ref.hi;
    EXPECT_TRUE(hit.intersecting) << "ref depth " << -ref.hi;
    st.overlap_dist.add(d.distance / s);
  } else {
    ++st.in_band;
  }

  // EPA: depth against the reference, then move B out along the normal.
  const PenetrationResult p = epaPenetration(a.shape, a.pose, b.shape, b.pose, tol);
  ASSERT_FALSE(isFailure(p.status)) << statusName(p.status);
  ASSERT_TRUE(std::isfinite(p.depth) && std::isfinite(p.signed_distance) && p.normal.allFinite());
  EXPECT_NEAR(p.normal.norm(), 1.0, 1e-9);
  const double epa_tol = std::max(tol.epa_relative, tol.gjk_relative) * (std::abs(ref.hi) + rsum) + tiny;
  if (ref.lo > band) {
    EXPECT_GE(p.signed_distance, ref.lo - epa_tol);
    EXPECT_LE(p.signed_distance, ref.hi + epa_tol);
  } else if (ref.hi < -band) {
    EXPECT_GE(p.depth, -ref.hi - epa_tol) << "ref depth " << -ref.hi;
    EXPECT_LE(p.depth, -ref.lo + epa_tol) << "ref depth " << -ref.lo;
    if (a.exact && b.exact) {
      st.epa_rel.add(std::abs(p.depth + ref.hi) / (-ref.hi + rsum));
      const Body out = moved(b, p.normal * (p.depth * (1 + 1e-6) + 1e-9 * s));
      const double after = signedBracket(a, out).hi;
      EXPECT_GE(after, -tiny) << "moving B by depth " << p.depth << " along " << str(p.normal) << " leaves an overlap";
      st.epa_sep.add(std::max(0.0, -after) / s);
      SimplexCache c1;
      EXPECT_FALSE(gjkIntersect(a.shape, a.pose, out.shape, out.pose, tol, c1).intersecting)
          << "moved out by depth " << p.depth << " (1 + 1e-6) + 1e-9·s; ref distance now " << after;
      const Body in = moved(b, p.normal * (0.99 * p.depth));
      EXPECT_LT(signedBracket(a, in).hi, 0.0);
      SimplexCache c2;
      EXPECT_TRUE(gjkIntersect(a.shape, a.pose, in.shape, in.pose, tol, c2).intersecting);
    }
  }
}

// A random pose: rotation uniform, translation within `reach` of the origin.
Pose randomPose(Rng& g, double reach) {
  Pose p;
  p.R = randomRotation(g);
  p.t = inBall(g, reach);
  return p;
}

// B's pose for A's: a random direction at k·(size_a + size_b) from A's centre, k ∈ [0.1, 1.5].
Pose partnerPose(Rng& g, const Body& a, double size_b) {
  Pose p;
  p.R = randomRotation(g);
  p.t = a.pose.t + unitVector(g) * uniform(g, 0.1, 1.5) * (a.size + size_b);
  return p;
}

}  // namespace

// The reference checks itself first: its de-duplicated feature search equals the brute-force minimum
// over triangle pairs of triangleTriangle, and SAT, the slab ray clip and the SAT cast clip give the
// closed-form answers for boxes.
TEST(RandomNarrowphase, ReferenceSelfCheck) {
  Rng g(0x5E1Full);
  for (int i = 0; i < 40; ++i) {
    const Body a = makeBody(Kind::Hull, 1.0, randomPose(g, 1.0), g);
    const Body b = makeBody(i % 2 ? Kind::Hull : Kind::Triangle, 1.0, partnerPose(g, a, 1.0), g);
    double brute = INFINITY;
    for (const auto& s : a.inner.tris)
      for (const auto& t : b.inner.tris) brute = std::min(brute, ref::triangleTriangle(s, t).dist2);
    EXPECT_NEAR(std::sqrt(ref::featureDistance(a.inner, b.inner).dist2), std::sqrt(brute), 1e-14) << i;
  }
  // Unit cubes: apart by 0.5 along x (distance 0.5), corner to corner (√3·0.5), overlapping by 0.25.
  const ref::Mesh cube = ref::meshFromBox(Vec3(1, 1, 1), Pose());
  EXPECT_NEAR(ref::signedDistance(cube, ref::meshFromBox(Vec3(1, 1, 1), Pose::translation(Vec3(2.5, 0.3, -0.2)))).value, 0.5, 1e-15);
  EXPECT_NEAR(ref::signedDistance(cube, ref::meshFromBox(Vec3(1, 1, 1), Pose::translation(Vec3(2.5, 2.5, 2.5)))).value,
              std::sqrt(3.0) * 0.5, 1e-15);
  EXPECT_NEAR(ref::signedDistance(cube, ref::meshFromBox(Vec3(1, 1, 1), Pose::translation(Vec3(0.3, 1.75, 0.1)))).value, -0.25, 1e-15);
  const ref::Slab ray = ref::raySlab(cube, Vec3(-3, 0.5, 0.5), Vec3(2, 0, 0), 10);
  EXPECT_TRUE(ray.hit);
  EXPECT_DOUBLE_EQ(ray.t_enter, 1.0);
  EXPECT_DOUBLE_EQ(ray.t_exit, 2.0);
  EXPECT_FALSE(ref::raySlab(cube, Vec3(-3, 1.5, 0.5), Vec3(1, 0, 0), 10).hit);
  const ref::Mesh moving = ref::meshFromBox(Vec3(0.5, 0.5, 0.5), Pose::translation(Vec3(-5, 0.2, 0)));
  const ref::Slab cast = ref::castSlab(moving, Vec3(1, 0, 0), cube, 10, ref::satAxes(moving, cube));
  EXPECT_TRUE(cast.hit);
  EXPECT_DOUBLE_EQ(cast.t_enter, 3.5);
}

// Convex hulls of 4–20 random points, sizes 1e-2 … 1e2 (independently, so ratios reach 1e4).
TEST(RandomNarrowphase, HullPairsDistanceIntersectEpa) {
  Rng g(0xC1EA5A7ull);
  const Tolerances tol;
  PairStats st;
  constexpr int kCases = 1000;
  for (int i = 0; i < kCases && !tooManyFailures(); ++i) {
    SCOPED_TRACE("case " + std::to_string(i));
    const double sa = logUniform(g, 1e-2, 1e2), sb = logUniform(g, 1e-2, 1e2);
    const Body a = makeBody(Kind::Hull, sa, randomPose(g, 3.0 * std::max(sa, sb)), g);
    const Body b = makeBody(Kind::Hull, sb, partnerPose(g, a, sb), g);
    checkPair(a, b, tol, st);
  }
  st.print();
}

// Every ordered pair of box, sphere, capsule, cylinder, cone, triangle, segment and hull.
TEST(RandomNarrowphase, PrimitivePairsDistanceIntersectEpa) {
  Rng g(0xB0C5ull);
  const Tolerances tol;
  PairStats st;
  constexpr int kCasesPerPair = 12;
  for (const Kind ka : kAllKinds) {
    for (const Kind kb : kAllKinds) {
      for (int i = 0; i < kCasesPerPair && !tooManyFailures(); ++i) {
        SCOPED_TRACE(std::string(kindName(ka)) + "-" + kindName(kb) + " case " + std::to_string(i));
        const double sa = logUniform(g, 1e-2, 1e2), sb = sa * logUniform(g, 0.1, 10.0);
        const Body a = makeBody(ka, sa, randomPose(g, 3.0 * std::max(sa, sb)), g);
        const Body b = makeBody(kb, sb, partnerPose(g, a, sb), g);
        checkPair(a, b, tol, st);
      }
    }
  }
  st.print();
}

// Closed-form references where they are simple: sphere–sphere, sphere–box (clamping), capsule–capsule
// (segment–segment distance). Bound: 1e-12 · (largest coordinate): these converge to rounding.
TEST(RandomNarrowphase, AnalyticPairs) {
  Rng g(0xA7A1ull);
  const Tolerances tol;
  Stat err{"analytic: |distance - exact| / s"};
  for (int i = 0; i < 600 && !tooManyFailures(); ++i) {
    SCOPED_TRACE("case " + std::to_string(i));
    const double size = logUniform(g, 1e-2, 1e2);
    Pose pa, pb;
    pa.R = randomRotation(g);
    pa.t = inBall(g, 3 * size);
    pb.R = randomRotation(g);
    pb.t = pa.t + inBall(g, 3 * size);
    const double s = (pb.t - pa.t).norm() + 4 * size;
    const double tiny = 1e-12 * (std::max(pa.t.norm(), pb.t.norm()) + 4 * size);
    double exact = 0.0;
    DistanceResult d;
    switch (i % 3) {
      case 0: {
        const double ra = size * uniform(g, 0.1, 1), rb = size * uniform(g, 0.1, 1);
        exact = (pb.t - pa.t).norm() - ra - rb;
        d = gjkDistance(Sphere(ra), pa, Sphere(rb), pb, tol);
        break;
      }
      case 1: {
        // Sphere centre clamped to the box in the box's frame.
        const Vec3 half = size * Vec3(uniform(g, 0.1, 1), uniform(g, 0.1, 1), uniform(g, 0.1, 1));
        const double r = size * uniform(g, 0.1, 1);
        const Vec3 c = pa.R.transpose() * (pb.t - pa.t);
        const Vec3 clamped = c.cwiseMax(-half).cwiseMin(half);
        if (clamped == c) continue;  // centre inside: not a distance case
        exact = (c - clamped).norm() - r;
        d = gjkDistance(Box(half), pa, Sphere(r), pb, tol);
        break;
      }
      default: {
        const double ra = size * uniform(g, 0.05, 0.3), rb = size * uniform(g, 0.05, 0.3);
        const double ha = size * uniform(g, 0, 1), hb = size * uniform(g, 0, 1);
        const ref::Closest c = ref::segmentSegment(pa * Vec3(0, 0, -ha), pa * Vec3(0, 0, ha), pb * Vec3(0, 0, -hb),
                                                   pb * Vec3(0, 0, hb));
        exact = std::sqrt(c.dist2) - ra - rb;
        d = gjkDistance(Capsule(ra, ha), pa, Capsule(rb, hb), pb, tol);
        break;
      }
    }
    ASSERT_FALSE(isFailure(d.status));
    if (exact > 1e-8 * s) {
      EXPECT_NEAR(d.distance, exact, tiny) << "kind " << i % 3;
      err.add(std::abs(d.distance - exact) / s);
    } else if (exact < -1e-8 * s) {
      EXPECT_EQ(d.distance, 0.0);
      EXPECT_TRUE(d.mayCollide());
    }
  }
  print({&err});
}

// Pairs of exact shapes (box, sphere, capsule, triangle, segment, hull) moved along the reference's
// closest-pair direction to a gap of 10^-k·s, or past contact by that much, k = 3 … 9 (translating B
// along that direction changes the distance by exactly the translation). Band here: 1e-9·s, ten times
// gjkIntersect's own (gjk_absolute·max‖y‖ ≤ 1e-10·s).
TEST(RandomNarrowphase, NearContactPairs) {
  Rng g(0x2EA7ull);
  const Tolerances tol;
  PairStats st;
  constexpr Kind kinds[] = {Kind::Box, Kind::Sphere, Kind::Capsule, Kind::Triangle, Kind::Segment, Kind::Hull};
  int made = 0;
  for (int i = 0; made < 700 && i < 5000 && !tooManyFailures(); ++i) {
    const Kind ka = kinds[uniformInt(g, 0, 5)], kb = kinds[uniformInt(g, 0, 5)];
    const double sa = logUniform(g, 1e-2, 1e2), sb = sa * logUniform(g, 0.1, 10.0);
    const Body a = makeBody(ka, sa, randomPose(g, 3.0 * std::max(sa, sb)), g);
    const Body b = makeBody(kb, sb, partnerPose(g, a, sb), g);
    const ref::Signed core = ref::signedDistance(a.inner, b.inner);
    if (!(core.value > 0.0)) continue;  // the closest pair of disjoint cores gives the direction
    ++made;
    SCOPED_TRACE("case " + std::to_string(i));
    const Vec3 u = (core.closest.q - core.closest.p).normalized();
    const double s = scalesOf(a, b).s;
    const double target = (made % 3 ? 1.0 : -1.0) * s * std::pow(10.0, -uniformInt(g, 3, 9));
    const Body near = moved(b, (target - (core.value - a.radius - b.radius)) * u);
    checkPair(a, near, tol, st, 1e-9);
  }
  EXPECT_EQ(made, 700);
  st.print();
}

// Two hulls: a0 still, b0 moving smoothly (translation along a line that passes through A, slow
// rotation) as u runs over [0, 1].
struct SmoothMotion {
  double sa, sb;  // (drawn first: the order of the draws makes the sequence)
  Body a0, b0;
  Vec3 start, axis;
  Mat3 r0;
  explicit SmoothMotion(Rng& g)
      : sa(logUniform(g, 1e-2, 1e2)),
        sb(sa * logUniform(g, 0.2, 5.0)),
        a0(makeBody(Kind::Hull, sa, randomPose(g, 3 * sa), g)),
        b0(makeBody(Kind::Hull, sb, Pose(), g)),
        start(unitVector(g) * (1.6 * (a0.size + b0.size)) + inBall(g, 0.3 * (a0.size + b0.size))),
        axis(unitVector(g)),
        r0(randomRotation(g)) {}
  const ConvexHull& hullA() const { return std::get<ConvexHull>(a0.shape); }
  const ConvexHull& hullB() const { return std::get<ConvexHull>(b0.shape); }
  // B at u, with its reference mesh.
  Body b(double u) const {
    Body b = b0;
    b.pose.R = Eigen::AngleAxisd(0.8 * u, axis).toRotationMatrix() * r0;
    b.pose.t = a0.pose.t + (1.0 - 2.0 * u) * start;
    b.inner = b.outer = ref::meshFromHull(hullB(), b.pose);
    return b;
  }
};

// A pair moving smoothly, with one SimplexCache reused over the sequence: the warm answer equals the
// cold one and the reference.
TEST(RandomNarrowphase, WarmCacheAlongSmoothMotion) {
  Rng g(0x3A53ull);
  const Tolerances tol;
  int steps = 0, warm_iterations = 0, cold_iterations = 0, checked = 0;
  for (int seq = 0; seq < 30 && !tooManyFailures(); ++seq) {
    const SmoothMotion m(g);
    const Body& a0 = m.a0;
    SimplexCache cache;
    constexpr int kSteps = 40;
    for (int k = 0; k <= kSteps; ++k) {
      SCOPED_TRACE("sequence " + std::to_string(seq) + " step " + std::to_string(k));
      const Body b = m.b(static_cast<double>(k) / kSteps);
      const Bracket ref = signedBracket(a0, b);
      const Scales sc = scalesOf(a0, b);
      const IntersectResult warm = gjkIntersect(a0.shape, a0.pose, b.shape, b.pose, tol, cache);
      SimplexCache fresh;
      const IntersectResult cold = gjkIntersect(a0.shape, a0.pose, b.shape, b.pose, tol, fresh);
      ASSERT_FALSE(isFailure(warm.status));
      ++steps;
      warm_iterations += warm.iterations;
      cold_iterations += cold.iterations;
      if (std::abs(ref.hi) > sc.band) {
        ++checked;
        EXPECT_EQ(warm.intersecting, ref.hi < 0.0) << "ref signed distance " << ref.hi << " (" << a0.text << ")";
        EXPECT_EQ(cold.intersecting, ref.hi < 0.0) << "ref signed distance " << ref.hi;
      }
    }
  }
  std::printf("[   stat   ] warm cache: %d steps (%d outside the band), mean iterations warm %.2f, cold %.2f\n", steps,
              checked, double(warm_iterations) / steps, double(cold_iterations) / steps);
}

// gjkLowerBound along the same kind of motion, its cache warm from step to step (and stale at the
// start): never above the reference distance, and either at least `enough` or within the relative
// error of the distance (hulls have no radius, so the cores' relative error is the distance's).
TEST(RandomNarrowphase, LowerBoundAlongSmoothMotion) {
  Rng g(0x10BDull);
  const Tolerances tol;
  int steps = 0, stopped_early = 0;
  for (int seq = 0; seq < 40 && !tooManyFailures(); ++seq) {
    const SmoothMotion m(g);
    const Body &a0 = m.a0, &b0 = m.b0;
    SimplexCache cache;
    cache.axis = unitVector(g);  // stale: from some other pair
    cache.valid = true;
    constexpr int kSteps = 40;
    for (int k = 0; k <= kSteps; ++k) {
      SCOPED_TRACE("sequence " + std::to_string(seq) + " step " + std::to_string(k));
      const Body b = m.b(static_cast<double>(k) / kSteps);
      const Bracket ref = signedBracket(a0, b);
      const Scales sc = scalesOf(a0, b);
      const double enough = k % 3 == 0 ? INFINITY : logUniform(g, 1e-3, 1.0) * (a0.size + b0.size);
      const double relative = k % 2 ? 0.25 : 1e-3;
      const double lower = gjkLowerBound(m.hullA(), a0.pose, m.hullB(), b.pose, tol, cache, enough, relative);
      ++steps;
      EXPECT_GE(lower, 0.0);
      EXPECT_LE(lower, std::max(ref.hi, 0.0) + sc.tiny) << "ref " << ref.lo << " … " << ref.hi;
      if (ref.lo > sc.band) {
        stopped_early += lower >= enough;
        EXPECT_GE(lower, std::min(enough, (1.0 - relative) * ref.lo) - sc.band) << "ref " << ref.lo << ", enough " << enough;
      }
    }
  }
  std::printf("[   stat   ] lower bounds: %d steps, %d stopped at `enough`\n", steps, stopped_early);
  EXPECT_GT(stopped_early, 20);
}

// Rays against hulls and boxes (slab clipping) and spheres (the quadratic), from outside and inside.
TEST(RandomNarrowphase, RayCastAgainstSlabs) {
  Rng g(0x5AB5ull);
  const Tolerances tol;
  Stat lower{"ray: (t - t_ref)·|d| / s  (must be <= tiny)"};
  Stat gap{"ray: distance of the hit point to the shape / s"};
  Stat square{"ray: (t_ref - t)·|d|·incidence / s"};
  int hits = 0, misses = 0, ambiguous = 0;
  for (int i = 0; i < 2400 && !tooManyFailures(); ++i) {
    SCOPED_TRACE("case " + std::to_string(i));
    const double size = logUniform(g, 1e-2, 1e2);
    const int kind = i % 3;
    const Body body = makeBody(kind == 0 ? Kind::Hull : kind == 1 ? Kind::Box : Kind::Sphere, size,
                               randomPose(g, 3 * size), g);
    const Vec3 c = body.pose.t;
    const Vec3 origin = c + unitVector(g) * body.size * uniform(g, 0.1, 3.0);
    const Vec3 target = c + inBall(g, 1.3 * body.size);
    const Vec3 dir = (target - origin) * logUniform(g, 1e-2, 1e2);
    const double max_t = (target - origin).norm() / dir.norm() * uniform(g, 0.3, 2.0);
    const Ray ray{origin, dir, max_t};
    SCOPED_TRACE(body.text + "\nray origin " + str(origin) + " dir " + str(dir) + " max_t " + std::to_string(max_t));
    const double s = (origin - c).norm() + body.size;
    const double tiny = 1e-12 * (origin.norm() + c.norm() + body.size);
    const double delta = 1e-5 * s;

    // Reference: [t_enter, t_exit] of the exact shape, and of it pushed out / pulled in by δ.
    ref::Slab exact, grown, shrunk;
    if (body.kind == Kind::Sphere) {
      const auto solve = [&](double r) {
        ref::Slab sl;
        const Vec3 m = origin - c;
        const double a = dir.squaredNorm(), b = m.dot(dir), cc = m.squaredNorm() - r * r;
        const double disc = b * b - a * cc;
        if (disc < 0.0) return sl;
        const double root = std::sqrt(disc);
        // Stable roots: the one with the larger magnitude first, the other from the product c/a.
        const double q = -(b + std::copysign(root, b));
        double t0 = q / a, t1 = q != 0.0 ? cc / q : 0.0;
        if (t0 > t1) std::swap(t0, t1);
        sl.t_enter = std::max(0.0, t0);
        sl.t_exit = std::min(max_t, t1);
        sl.hit = sl.t_enter <= sl.t_exit;
        if (t0 > 0.0) sl.incidence = std::abs((origin + t0 * dir - c).normalized().dot(dir.normalized()));
        return sl;
      };
      exact = solve(body.radius);
      grown = solve(body.radius + delta);
      shrunk = solve(std::max(0.0, body.radius - delta));
    } else {
      exact = ref::raySlab(body.inner, origin, dir, max_t);
      grown = ref::raySlab(body.inner, origin, dir, max_t, delta);
      shrunk = ref::raySlab(body.inner, origin, dir, max_t, -delta);
    }
    const CastResult r = gjkRayCast(body.shape, body.pose, ray, tol);
    ASSERT_FALSE(isFailure(r.status)) << statusName(r.status);
    ASSERT_TRUE(std::isfinite(r.t) && r.normal.allFinite() && r.point.allFinite());
    if (shrunk.hit) EXPECT_TRUE(r.hit) << "a robust hit at " << exact.t_enter << " was missed";
    if (!grown.hit) EXPECT_FALSE(r.hit) << "a robust miss was reported as a hit at " << r.t;
    if (shrunk.hit) ++hits;
    else if (!grown.hit) ++misses;
    else ++ambiguous;
    if (!r.hit) continue;
    EXPECT_GE(r.t, 0.0);
    EXPECT_LE(r.t, max_t);
    const Vec3 x = origin + r.t * dir;
    const double dist = pointDistance(body, x);
    EXPECT_LE(dist, 2 * tol.cast_relative * s + tiny) << "t " << r.t;
    gap.add(dist / s);
    if (exact.hit) {
      EXPECT_LE(r.t, exact.t_enter + tiny / dir.norm()) << "t is not a lower bound";
      lower.add((r.t - exact.t_enter) * dir.norm() / s);
      if (exact.t_enter > 0.0) square.add((exact.t_enter - r.t) * dir.norm() * exact.incidence / s);
    }
    if (r.t > 0.0) {
      EXPECT_NEAR(r.normal.norm(), 1.0, 1e-9);
      EXPECT_LE(r.normal.dot(dir), 1e-9 * dir.norm()) << "normal " << str(r.normal) << " faces away from the ray";
    }
  }
  print({&lower, &gap, &square});
  std::printf("[   stat   ] rays: %d robust hits, %d robust misses, %d inside the band\n", hits, misses, ambiguous);
}

// Loose cast tolerances (cast_relative = 1e-3, 1e-2) on curved shapes, where the cast converges to the
// tolerance rather than to rounding: never a failure status (an early stop once left runs capped), hit
// or miss as the bracketing polytopes say when robust to δ = 2·cast_relative·s, t no later than the
// inscribed polytope's entry (the true entry is between the two), the point / A at t within the band.
TEST(RandomNarrowphase, CastsAtLooseTolerances) {
  Rng g(0x100Eull);
  Stat gap{"loose: distance at t / (cast_relative * s)"};
  int hits = 0, misses = 0;
  for (int i = 0; i < 400 && !tooManyFailures(); ++i) {
    SCOPED_TRACE("case " + std::to_string(i));
    Tolerances tol;
    tol.cast_relative = i % 2 ? 1e-2 : 1e-3;
    const double size = logUniform(g, 1e-2, 1e2);
    const Body body = makeBody(i % 4 < 2 ? Kind::Cylinder : Kind::Cone, size, randomPose(g, 3 * size), g);
    const Vec3 c = body.pose.t;
    const double tiny = 1e-12 * (c.norm() + 4 * body.size);
    if (i % 8 < 4) {
      // A ray.
      const Vec3 origin = c + unitVector(g) * body.size * uniform(g, 1.0, 3.0);
      const Vec3 target = c + inBall(g, 1.3 * body.size);
      const Vec3 dir = (target - origin) * logUniform(g, 1e-1, 1e1);
      const double max_t = (target - origin).norm() / dir.norm() * uniform(g, 0.3, 2.0);
      SCOPED_TRACE(body.text + "\nray origin " + str(origin) + " dir " + str(dir) + " max_t " + std::to_string(max_t));
      const double s = (origin - c).norm() + body.size, delta = 2 * tol.cast_relative * s;
      const CastResult r = gjkRayCast(body.shape, body.pose, Ray{origin, dir, max_t}, tol);
      ASSERT_FALSE(isFailure(r.status)) << statusName(r.status) << " after " << r.iterations << " iterations";
      ASSERT_TRUE(std::isfinite(r.t));
      const ref::Slab inner = ref::raySlab(body.inner, origin, dir, max_t);
      if (ref::raySlab(body.inner, origin, dir, max_t, -delta).hit) { ++hits; EXPECT_TRUE(r.hit); }
      if (!ref::raySlab(body.outer, origin, dir, max_t, delta).hit) { ++misses; EXPECT_FALSE(r.hit); }
      if (!r.hit) continue;
      if (inner.hit) EXPECT_LE(r.t, inner.t_enter + tiny / dir.norm());
      const double dist = pointDistance(body, origin + r.t * dir);
      EXPECT_LE(dist, 2 * tol.cast_relative * s + tiny);
      gap.add(dist / (tol.cast_relative * s));
    } else {
      // The curved body moving into a box.
      const Body box = makeBody(Kind::Box, size * logUniform(g, 0.3, 3.0), randomPose(g, 3 * size), g);
      const Vec3 start = box.pose.t + unitVector(g) * (body.size + box.size) * uniform(g, 1.0, 3.0);
      const Body a = moved(body, start - c);
      const Vec3 target = box.pose.t + inBall(g, 1.2 * box.size);
      const Vec3 v = (target - start) * logUniform(g, 1e-1, 1e1);
      const double max_t = (target - start).norm() / v.norm() * uniform(g, 0.3, 2.0);
      SCOPED_TRACE("A: " + a.text + "\nB: " + box.text + "\nvelocity " + str(v) + " max_t " + std::to_string(max_t));
      const double s = (start - box.pose.t).norm() + a.size + box.size, delta = 2 * tol.cast_relative * s;
      const CastResult r = gjkShapeCast(a.shape, a.pose, v, box.shape, box.pose, max_t, tol);
      ASSERT_FALSE(isFailure(r.status)) << statusName(r.status) << " after " << r.iterations << " iterations";
      ASSERT_TRUE(std::isfinite(r.t));
      const std::vector<Vec3> in_axes = ref::satAxes(a.inner, box.inner), out_axes = ref::satAxes(a.outer, box.inner);
      const ref::Slab inner = ref::castSlab(a.inner, v, box.inner, max_t, in_axes);
      if (ref::castSlab(a.inner, v, box.inner, max_t, in_axes, -delta).hit) { ++hits; EXPECT_TRUE(r.hit); }
      if (!ref::castSlab(a.outer, v, box.inner, max_t, out_axes, delta).hit) { ++misses; EXPECT_FALSE(r.hit); }
      if (!r.hit) continue;
      if (inner.hit) EXPECT_LE(r.t, inner.t_enter + tiny / v.norm());
      const double dist = std::max(0.0, ref::signedDistance(ref::translated(a.inner, r.t * v), box.inner).value);
      EXPECT_LE(dist, 2 * tol.cast_relative * s + 5e-3 * a.size);  // + the inscribed polytope's radial gap (≤ 4.8e-3·r)
    }
  }
  print({&gap});
  std::printf("[   stat   ] loose casts: %d robust hits, %d robust misses of 400\n", hits, misses);
}

// A (hull or box) translating into B (hull or box): the time of first contact against the SAT slabs.
TEST(RandomNarrowphase, ShapeCastAgainstSlabs) {
  Rng g(0xCA57ull);
  const Tolerances tol;
  Stat lower{"cast: (t - t_ref)·|v| / s  (must be <= tiny)"};
  Stat gap{"cast: ref distance of A at t / s"};
  Stat before{"cast: overlap of A at t·(1 - 1e-6) / s"};
  int hits = 0, misses = 0, ambiguous = 0, entered = 0;
  for (int i = 0; i < 700 && !tooManyFailures(); ++i) {
    SCOPED_TRACE("case " + std::to_string(i));
    const double sa = logUniform(g, 1e-2, 1e2), sb = sa * logUniform(g, 0.1, 10.0);
    const Body b = makeBody(i % 2 ? Kind::Hull : Kind::Box, sb, randomPose(g, 3 * sb), g);
    // A starts apart from B (most of the time) and heads at a random point near B.
    Pose pa;
    pa.R = randomRotation(g);
    pa.t = b.pose.t + unitVector(g) * (sa + b.size) * uniform(g, 0.5, 3.0);
    const Body a = makeBody(i % 3 ? Kind::Hull : Kind::Box, sa, pa, g);
    const Vec3 target = b.pose.t + inBall(g, 1.2 * b.size);
    const Vec3 v = (target - pa.t) * logUniform(g, 1e-2, 1e2);
    const double max_t = (target - pa.t).norm() / v.norm() * uniform(g, 0.3, 2.0);
    SCOPED_TRACE("A: " + a.text + "\nB: " + b.text + "\nvelocity " + str(v) + " max_t " + std::to_string(max_t));
    const double s = (pa.t - b.pose.t).norm() + a.size + b.size;
    const double tiny = 1e-12 * (pa.t.norm() + b.pose.t.norm() + a.size + b.size);
    const double delta = 1e-5 * s;
    const std::vector<Vec3> axes = ref::satAxes(a.inner, b.inner);
    const ref::Slab exact = ref::castSlab(a.inner, v, b.inner, max_t, axes);
    const ref::Slab grown = ref::castSlab(a.inner, v, b.inner, max_t, axes, delta);
    const ref::Slab shrunk = ref::castSlab(a.inner, v, b.inner, max_t, axes, -delta);

    const CastResult r = gjkShapeCast(a.shape, pa, v, b.shape, b.pose, max_t, tol);
    ASSERT_FALSE(isFailure(r.status)) << statusName(r.status);
    ASSERT_TRUE(std::isfinite(r.t) && r.normal.allFinite() && r.point.allFinite());
    if (shrunk.hit) EXPECT_TRUE(r.hit) << "a robust hit at " << exact.t_enter << " was missed";
    if (!grown.hit) EXPECT_FALSE(r.hit) << "a robust miss was reported as a hit at " << r.t;
    if (shrunk.hit) ++hits;
    else if (!grown.hit) ++misses;
    else ++ambiguous;
    if (!r.hit) continue;
    EXPECT_LE(r.t, max_t);
    if (exact.hit) {
      EXPECT_LE(r.t, exact.t_enter + tiny / v.norm()) << "t is not a lower bound";
      lower.add((r.t - exact.t_enter) * v.norm() / s);
    }
    // At t, A is within the cast tolerance of B; just before t, A and B are apart.
    const double at_t = ref::signedDistance(ref::translated(a.inner, r.t * v), b.inner).value;
    EXPECT_LE(at_t, 2 * tol.cast_relative * s + tiny);
    gap.add(std::max(0.0, at_t) / s);
    if (r.t > 0.0) {
      const double at_before = ref::signedDistance(ref::translated(a.inner, r.t * (1 - 1e-6) * v), b.inner).value;
      EXPECT_GE(at_before, -tiny) << "A already overlaps B before t = " << r.t;
      before.add(std::max(0.0, -at_before) / s);
      // After t + tol (tol covers the cast tolerance at this incidence), A has entered B.
      if (exact.hit && exact.incidence >= 0.05) {
        const double t_in = r.t + 4 * tol.cast_relative * s / (v.norm() * exact.incidence);
        if (t_in < exact.t_exit) {
          ++entered;
          EXPECT_LE(ref::signedDistance(ref::translated(a.inner, t_in * v), b.inner).value, tiny)
              << "A is still apart from B at t + tol = " << t_in;
        }
      }
    }
  }
  print({&lower, &gap, &before});
  std::printf("[   stat   ] casts: %d robust hits (%d checked inside after t + tol), %d robust misses, %d in the band\n",
              hits, entered, misses, ambiguous);
}
