// Numerically hard narrow-phase cases, one TEST per family. Each states its error bound; L is the size
// of the shapes involved (their largest half extent or radius) and "the band" is where gjkIntersect may
// answer either way: shapes within gjk_absolute·(size of A − B) = 1e-10·(size) of touching (gjk.h).
// Across all of them: no hang, no NaN, no failure status on finite input, and never a wrong boolean
// outside the band.
#include "narrowphase/reference.h"

#include <clearway/narrowphase/epa.h>
#include <clearway/narrowphase/gjk.h>
#include <clearway/narrowphase/ray_cast.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace clearway;

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

Pose posed(const Mat3& R, const Vec3& t) {
  Pose p;
  p.R = R;
  p.t = t;
  return p;
}

Mat3 rotation(double angle, const Vec3& axis) { return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix(); }

// A rotation with no special structure, applied to whole configurations so no test is axis-aligned only.
const Mat3 kTilt = rotation(0.7, Vec3(1, 2, 3));

bool isIntersecting(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb) {
  SimplexCache cache;
  const IntersectResult r = gjkIntersect(a, pa, b, pb, Tolerances{}, cache);
  EXPECT_FALSE(isFailure(r.status)) << statusName(r.status);
  return r.intersecting;
}

// Every field finite, status a certificate.
void expectSane(const DistanceResult& d) {
  EXPECT_FALSE(isFailure(d.status)) << statusName(d.status);
  EXPECT_TRUE(std::isfinite(d.distance) && std::isfinite(d.lower_bound) && d.point_a.allFinite() &&
              d.point_b.allFinite() && d.normal.allFinite());
  EXPECT_LE(d.lower_bound, d.distance);
}

void expectSane(const PenetrationResult& p) {
  EXPECT_FALSE(isFailure(p.status)) << statusName(p.status);
  EXPECT_TRUE(std::isfinite(p.depth) && std::isfinite(p.signed_distance) && p.point_a.allFinite() &&
              p.point_b.allFinite() && p.normal.allFinite());
  EXPECT_NEAR(p.normal.norm(), 1.0, 1e-12);
}

void expectSane(const CastResult& c) {
  EXPECT_FALSE(isFailure(c.status)) << statusName(c.status);
  EXPECT_TRUE(std::isfinite(c.t) && c.normal.allFinite() && c.point.allFinite());
}

// gjkDistance, checked for sanity, against an exact distance with an absolute bound; also the booleans:
// mayCollide() and gjkIntersect agree with `exact` when it is outside ±band.
void expectDistance(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb, double exact, double bound,
                    double band) {
  const DistanceResult d = gjkDistance(a, pa, b, pb);
  expectSane(d);
  EXPECT_NEAR(d.distance, std::max(exact, 0.0), bound) << "status " << statusName(d.status);
  EXPECT_LE(d.lower_bound, std::max(exact, 0.0) + bound);
  if (exact > band) {
    EXPECT_FALSE(d.mayCollide());
    EXPECT_FALSE(isIntersecting(a, pa, b, pb)) << "gap " << exact;
  } else if (exact < -band) {
    EXPECT_TRUE(d.mayCollide());
    EXPECT_TRUE(isIntersecting(a, pa, b, pb)) << "overlap " << -exact;
  }
}

std::vector<Vec3> boxCorners(const Vec3& h) {
  std::vector<Vec3> c;
  for (int i = 0; i < 8; ++i) c.emplace_back((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(), (i & 4) ? h.z() : -h.z());
  return c;
}

}  // namespace

// Two boxes face to face, gaps 1e-3 … 1e-9 of their size L, in a tilted frame, for L = 1e-2, 1, 1e2.
// Bound: |distance − gap| ≤ 1e-12·L (rounding of the inputs is ~1e-16·L); intersect false for every
// gap ≥ 1e-9·L (the band is ~3e-10·L); true at gap 0. The same with B as a ConvexHull of its corners.
TEST(HardCases, NearTouchingBoxes) {
  for (const double L : {1e-2, 1.0, 1e2}) {
    const Vec3 half_a = L * Vec3(1.0, 0.7, 0.4), half_b = L * Vec3(0.6, 0.5, 0.9);
    const Shape a = Box(half_a), b = Box(half_b), hull_b = ConvexHull(boxCorners(half_b));
    const Vec3 origin = L * Vec3(3.0, -1.0, 2.0);
    const Pose pa = posed(kTilt, origin);
    for (int k = 3; k <= 10; ++k) {
      const double gap = k == 10 ? 0.0 : L * std::pow(10.0, -k);
      SCOPED_TRACE("L " + std::to_string(L) + " gap " + std::to_string(gap));
      // Offset sideways so only parts of the faces overlap.
      const Pose pb = posed(kTilt, origin + kTilt * Vec3(half_a.x() + half_b.x() + gap, 0.3 * L, -0.2 * L));
      for (const Shape* sb : {&b, &hull_b}) {
        expectDistance(a, pa, *sb, pb, gap, 1e-12 * L, 1e-9 * L - 1e-15 * L);
        if (gap == 0.0) EXPECT_TRUE(isIntersecting(a, pa, *sb, pb));
        if (gap >= 1e-9 * L) EXPECT_FALSE(isIntersecting(a, pa, *sb, pb));
      }
    }
  }
}

// Near contact where the closest feature of A − B is an edge, not a face: a box's vertex over another
// box's edge (A turned 45° about x so its top edge runs along x; B turned so one vertex points straight
// down), and a segment's endpoint over another segment's interior (bare and as capsule cores). Everything
// else of B is higher and everything else of A lower, so the distance is the vertical gap. Gaps 1e-3 …
// 1e-9 in a tilted frame; then a triangle–segment pair found by the random tests. Bound: 1e-12 +
// gjk_relative·gap; intersect false for every gap ≥ 1e-9.
TEST(HardCases, NearTouchingVertexOverEdge) {
  const Shape cube = Box(Vec3(0.5, 0.5, 0.5));
  const Mat3 edge_up = rotation(M_PI / 4, Vec3::UnitX());
  const Mat3 vertex_down = rotation(std::atan(std::sqrt(2.0)), Vec3(1, -1, 0));
  const double top = std::sqrt(0.5);                             // A's top edge height
  const double below = -(vertex_down * Vec3(-0.5, -0.5, -0.5)).z();  // B's centre above its lowest vertex
  const Shape seg = Segment(Vec3(-1, 0, 0), Vec3(1, 0, 0));
  const Shape rising = Segment(Vec3(0, 0, 0), Vec3(0.5, 0.7, 1.0));  // lowest at its first endpoint
  const Shape cap_a = Capsule(0.25, 1.0), cap_b = Capsule(0.125, 0.5);
  const Mat3 along_x = rotation(M_PI / 2, Vec3::UnitY());        // capsule axis z → x
  for (int k = 3; k <= 9; ++k) {
    const double gap = std::pow(10.0, -k);
    SCOPED_TRACE("gap " + std::to_string(gap));
    const Vec3 vertex_at(0.1, 0.0, top + gap);
    // B's lowest vertex sits at vertex_at: its centre is that far above it (it points straight down).
    expectDistance(cube, posed(kTilt * edge_up, Vec3::Zero()), cube,
                   posed(kTilt * vertex_down, kTilt * (vertex_at + Vec3(0, 0, below))), gap, 1e-12 + 1e-6 * gap,
                   1e-9 - 1e-15);
    expectDistance(seg, posed(kTilt, Vec3(1, 2, 3)), rising, posed(kTilt, Vec3(1, 2, 3) + kTilt * Vec3(0.3, 0, gap)),
                   gap, 1e-12 + 1e-6 * gap, 1e-9 - 1e-15);
    // Capsules: A along x, B's axis rising from its lower end, which is 0.25 + 0.125 + gap above A's axis.
    const Mat3 tilt_b = rotation(0.6, Vec3(1, 1, 0));
    const Vec3 b_end = tilt_b * Vec3(0, 0, -0.5);
    expectDistance(cap_a, posed(kTilt * along_x, Vec3::Zero()), cap_b,
                   posed(kTilt * tilt_b, kTilt * (Vec3(0.3, 0, 0.375 + gap) - b_end)), gap, 1e-12 + 1e-6 * gap,
                   1e-9 - 1e-15);
  }
  // Found by RandomNarrowphase.NearContactPairs: a small triangle's vertex 2.06e-9 from a long segment.
  // GJK ended on an edge of A − B with v's along-edge rounding tilting the axis, and gjkIntersect called
  // the pair intersecting. Reference distance from reference.h (triangle–segment, exact features).
  const Shape tri = Triangle(Vec3(0.007729582154937284, 0.12986955404829928, -0.12424730845308646),
                             Vec3(-0.012643136516748086, 0.076988939615152338, 0.10891322400715837),
                             Vec3(-0.12647330868911755, 0.029200127155893301, 0.067926114537738919));
  const Pose pt = Pose::fromQuaternion(0.81270013651119388, 0.46270724426253651, -0.29001593159805433,
                                       0.20325170021667438,
                                       Vec3(-1.0810956790820823, -0.36683679202637276, 1.0012622076601365));
  const Vec3 s0(0.69305188002416462, 0.13642140277083115, 0.27619121544263647),
      s1(-0.62875183832107384, -0.37594104111981536, 0.24573119728679302);
  const Pose ps = Pose::fromQuaternion(
      0.6305088824798516, 0.25048566753642665, 0.71250645052896022, -0.17902524243095363,
      Vec3(-0.25287659314533051, -0.99844681143732317, 0.61953379342904547) +
          Vec3(-0.83946281872894146, 0.45533192348613266, 0.18493350640369377));
  const Triangle& t = std::get<Triangle>(tri);
  const double exact =
      ref::signedDistance(ref::meshFromTriangle(pt * t.v[0], pt * t.v[1], pt * t.v[2]), ref::meshFromSegment(ps * s0, ps * s1))
          .value;
  ASSERT_GT(exact, 1e-9);
  expectDistance(tri, pt, Segment(s0, s1), ps, exact, 1e-12 + 1e-6 * exact, 1e-9);
}

// Face–face contact of parallel faces (B turned about the common normal), exactly parallel edge–edge
// contact, and edges 1e-7 rad from parallel (turned about the vertical, and tilted out of the plane).
// Bound: 1e-12 absolute for face–face (unit-sized boxes); 1e-12 + gjk_relative·gap for edge–edge, where
// GJK may stop at its documented relative tolerance (observed: 5e-12 at a gap of 1e-3).
TEST(HardCases, ParallelFacesAndNearlyParallelEdges) {
  const Shape a = Box(Vec3(1, 1, 1)), b = Box(Vec3(0.5, 2, 0.3));
  for (const double gap : {1e-1, 1e-4, 1e-8, 0.0}) {
    SCOPED_TRACE("face-face gap " + std::to_string(gap));
    const Pose pb = posed(kTilt * rotation(0.3, Vec3::UnitX()), kTilt * Vec3(1.5 + gap, 0.4, -0.7));
    expectDistance(a, posed(kTilt, Vec3::Zero()), b, pb, gap, 1e-12, 1e-9);
  }
  // Boxes turned 45° about x: A's top edge and B's bottom edge run along x at heights √½ and z_b − √½.
  const Shape e = Box(Vec3(1, 0.5, 0.5));
  const Mat3 r45 = rotation(M_PI / 4, Vec3::UnitX());
  const double h = std::sqrt(0.5);
  for (const double gap : {1e-3, 1e-6, 1e-9}) {
    SCOPED_TRACE("edge-edge gap " + std::to_string(gap));
    // Exactly parallel (in exact arithmetic), overlapping along x by half their length.
    expectDistance(e, posed(r45, Vec3::Zero()), e, posed(r45, Vec3(1.0, 0, 2 * h + gap)), gap, 1e-12 + 1e-6 * gap, 1e-9);
    // Turned 1e-7 rad about z (the vertical): both edges stay horizontal and their projections cross at
    // x = y = 0, so the distance is still the height difference.
    const Pose turned = posed(rotation(1e-7, Vec3::UnitZ()) * r45, Vec3(0, 0, 2 * h + gap));
    expectDistance(e, posed(r45, Vec3::Zero()), e, turned, gap, 1e-12 + 1e-6 * gap, 1e-9);
  }
  // Tilted 1e-7 rad about y: B's edge dips at its x = +1 end by sin θ + √½·(cos θ − 1); that end lies over
  // A's edge (x = cos θ − √½ sin θ < 1), so the distance is the end's height above A's edge.
  const double theta = 1e-7;
  for (const double gap : {1e-6, 1e-5}) {
    const Pose tilted = posed(rotation(theta, Vec3::UnitY()) * r45, Vec3(0, 0, 2 * h + gap));
    const double exact = 2 * h + gap - (std::sin(theta) + h * std::cos(theta)) - h;
    expectDistance(e, posed(r45, Vec3::Zero()), e, tilted, exact, 1e-12 + 1e-6 * exact, 1e-9);
  }
}

// A vertex exactly on a face (and on an edge, and on a corner) of a box: exact binary coordinates, so the
// contact is exact. Bound: intersect true and distance ≤ 1e-15 (rounding only), EPA depth ≤ 1e-15.
TEST(HardCases, VertexExactlyOnFaceEdgeAndCorner) {
  const Shape box = Box(Vec3(0.5, 0.5, 0.5));
  // Both shapes share one pose, so the relative pose is exactly the identity (a quarter turn has exact entries).
  Mat3 quarter;
  quarter << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  for (const Pose& p : {Pose(), posed(quarter, Vec3(3, -2, 7))}) {
    for (const Vec3& contact : {Vec3(0.125, 0.25, 0.5), Vec3(0.5, 0.25, 0.5), Vec3(0.5, 0.5, 0.5)}) {
      SCOPED_TRACE("contact " + std::to_string(contact.x()) + " " + std::to_string(contact.y()));
      const Shape tetra = ConvexHull({contact, contact + Vec3(0.25, 0.5, 1), contact + Vec3(-0.5, 0.25, 1),
                                      contact + Vec3(0.25, -0.5, 1)});
      const Shape tri = Triangle(contact, contact + Vec3(0.75, 0.5, 1), contact + Vec3(-0.5, 0.75, 1));
      const Shape point_on_it = Point(contact);
      for (const Shape* s : {&tetra, &tri, &point_on_it}) {
        const DistanceResult d = gjkDistance(box, p, *s, p);
        expectSane(d);
        EXPECT_LE(d.distance, 1e-15) << shapeTypeName(*s);
        EXPECT_TRUE(d.mayCollide()) << shapeTypeName(*s) << " " << statusName(d.status) << " " << d.distance;
        EXPECT_TRUE(isIntersecting(box, p, *s, p)) << shapeTypeName(*s);
        const PenetrationResult pen = epaPenetration(box, p, *s, p);
        expectSane(pen);
        EXPECT_LE(pen.depth, 1e-15) << shapeTypeName(*s);
        EXPECT_LE(std::abs(pen.signed_distance), 1e-15) << shapeTypeName(*s);
      }
    }
  }
}

// A tiny box (half 1e-3) near a huge one (half 1e3), near a face and near a corner, in both argument
// orders. Bound: |distance − exact| ≤ 1e-12·1e3 = 1e-9 (rounding of the huge box's coordinates);
// booleans outside a band of 1e-9·1e3 (the band is ~1e-10·|A − B| ≈ 2e-7 here).
TEST(HardCases, SizeRatioOneToAMillion) {
  const Shape huge = Box(Vec3(1e3, 1e3, 1e3)), tiny = Box(Vec3(1e-3, 1e-3, 1e-3));
  const Pose pa = posed(kTilt, Vec3(10, 20, 30));
  for (const double gap : {1e-2, 1e-4, 1e-6, -1e-4}) {
    SCOPED_TRACE("gap " + std::to_string(gap));
    const Pose face = posed(kTilt, pa.t + kTilt * Vec3(1e3 + 1e-3 + gap, 3.7, -12.1));
    expectDistance(huge, pa, tiny, face, gap, 1e-9, 1e-6);
    expectDistance(tiny, face, huge, pa, gap, 1e-9, 1e-6);
    const double c = 1e3 + 1e-3 + gap;
    const Pose corner = posed(kTilt, pa.t + kTilt * Vec3(c, c, c));
    expectDistance(huge, pa, tiny, corner, gap > 0 ? std::sqrt(3.0) * gap : gap, 1e-9, 1e-6);
    if (gap < 0) {
      const PenetrationResult pen = epaPenetration(huge, pa, tiny, face);
      expectSane(pen);
      EXPECT_NEAR(pen.depth, -gap, 1e-9);
      EXPECT_NEAR((pen.normal - kTilt * Vec3::UnitX()).norm(), 0.0, 1e-6);
    }
  }
  // The tiny box turned 45° so a tiny edge faces the huge face.
  const Pose edge = posed(kTilt * rotation(M_PI / 4, Vec3::UnitZ()), pa.t + kTilt * Vec3(1e3 + std::sqrt(2.0) * 1e-3 + 1e-5, 0, 0));
  expectDistance(huge, pa, tiny, edge, 1e-5, 1e-9, 1e-6);
}

// Shapes 1e4 from the origin with gaps of 1e-6. Bound: 1e-9 absolute (the coordinates carry ~2e-12 of
// rounding). Boxes (tilted), spheres, capsules and hulls; a ray cast there too.
TEST(HardCases, FarFromTheOrigin) {
  const Vec3 far(1e4, -1e4, 1e4);
  const double gap = 1e-6;
  const Shape box = Box(Vec3(1, 0.5, 0.25));
  const Pose pa = posed(kTilt, far);
  expectDistance(box, pa, box, posed(kTilt, far + kTilt * Vec3(2 + gap, 0.2, 0.1)), gap, 1e-9, 1e-7);
  expectDistance(box, pa, box, posed(kTilt, far + kTilt * Vec3(0.3, 1 + gap, -0.1)), gap, 1e-9, 1e-7);
  const Shape s1 = Sphere(0.75), s2 = Sphere(0.5);
  const Vec3 u = Vec3(1, 2, 2) / 3.0;
  expectDistance(s1, Pose::translation(far), s2, Pose::translation(far + (1.25 + gap) * u), gap, 1e-9, 1e-7);
  const Shape cap = Capsule(0.25, 1.0);
  // Parallel capsules side by side; and crossed ones (along z and along x, one above the other).
  expectDistance(cap, Pose::translation(far), cap, Pose::translation(far + Vec3(0.5 + gap, 0, 0.3)), gap, 1e-9, 1e-7);
  expectDistance(cap, Pose::translation(far), cap, posed(rotation(M_PI / 2, Vec3::UnitY()), far + Vec3(0, 0.5 + gap, 0.2)),
                 gap, 1e-9, 1e-7);
  const Shape hull = ConvexHull(boxCorners(Vec3(1, 0.5, 0.25)));
  expectDistance(hull, pa, box, posed(kTilt, far + kTilt * Vec3(2 + gap, 0.2, 0.1)), gap, 1e-9, 1e-7);
  // A ray from 10 units away onto the tilted box's −x face: t = 9 − … within 1e-9 (unit direction).
  const Ray ray{far + kTilt * Vec3(-10, 0.1, 0.05), kTilt * Vec3(1, 0, 0), 100};
  const CastResult r = gjkRayCast(box, pa, ray);
  expectSane(r);
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.t, 9.0, 1e-9);
  EXPECT_LE(r.t, 9.0 + 1e-11);
  EXPECT_NEAR((r.normal + kTilt * Vec3::UnitX()).norm(), 0.0, 1e-9);
}

// Needle (one edge 1e-9 long) and sliver (a vertex 1e-9 off the opposite edge) triangles against
// triangles and boxes: parallel planes at a gap, crossing (overlapping), and random placements against
// the reference. Bound: 1e-12 absolute for the analytic gaps (unit sizes), gjk_relative·d + 1e-12 for
// random placements.
TEST(HardCases, NeedleAndSliverTriangles) {
  const Shape needle = Triangle(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1e-9, 0));
  const Shape sliver = Triangle(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 1e-9, 0));
  const Shape box = Box(Vec3(0.5, 0.5, 0.5));
  for (const Shape* t : {&needle, &sliver}) {
    for (const double gap : {1e-2, 1e-6, 1e-9}) {
      SCOPED_TRACE(std::string(t == &needle ? "needle" : "sliver") + " gap " + std::to_string(gap));
      // A second copy turned 90° about z, at height gap, crossing the first near (0.5, 0).
      const Pose above = posed(rotation(M_PI / 2, Vec3::UnitZ()), Vec3(0.5, -0.5, gap));
      expectDistance(*t, Pose(), *t, above, gap, 1e-12, 5e-10);
      // The box's bottom face at height gap above the triangle.
      expectDistance(*t, Pose(), box, Pose::translation(Vec3(0.6, 0.2, 0.5 + gap)), gap, 1e-12, 5e-10);
      // Tilted frame: the same configurations, rounding only.
      expectDistance(*t, posed(kTilt, Vec3::Zero()), box, posed(kTilt, kTilt * Vec3(0.6, 0.2, 0.5 + gap)), gap,
                     1e-12, 5e-10);
    }
    // Crossing: the box pierced by the triangle, and the triangle through a wall triangle in x = 0.5 (at
    // z = 0 the wall spans y ∈ [−0.5, 0.5]); the wall moved to x = 1 + 1e-6, past the tip, is 1e-6 away.
    EXPECT_TRUE(isIntersecting(*t, Pose(), box, Pose::translation(Vec3(0.5, 0, 0.1))));
    const Shape wall = Triangle(Vec3(0, -1, -1), Vec3(0, 1, -1), Vec3(0, 0, 1));
    EXPECT_TRUE(isIntersecting(*t, Pose(), wall, Pose::translation(Vec3(0.5, 0, 0))));
    EXPECT_TRUE(isIntersecting(wall, posed(kTilt, kTilt * Vec3(0.5, 0, 0)), *t, posed(kTilt, Vec3::Zero())));
    expectDistance(*t, Pose(), wall, Pose::translation(Vec3(1 + 1e-6, 0, 0)), 1e-6, 1e-12, 5e-10);
  }
  // Random placements of needles and slivers against each other, against the reference distance.
  std::mt19937_64 g(0x5117);
  std::uniform_real_distribution<double> u(-1, 1);
  int checked = 0;
  for (int i = 0; i < 400; ++i) {
    const Vec3 a0(u(g), u(g), u(g)), a1(u(g), u(g), u(g));
    const Vec3 b0(u(g), u(g), u(g)), b1(u(g), u(g), u(g));
    const Vec3 off_a = Vec3(u(g), u(g), u(g)).normalized() * std::pow(10.0, -3 - 7 * std::abs(u(g)));
    const Vec3 off_b = Vec3(u(g), u(g), u(g)).normalized() * std::pow(10.0, -3 - 7 * std::abs(u(g)));
    // Needle for even i (third vertex beside the second), sliver for odd i (beside the midpoint).
    const Vec3 a2 = (i % 2 ? 0.5 * (a0 + a1) : a1) + off_a, b2 = (i % 2 ? 0.5 * (b0 + b1) : b1) + off_b;
    const Shape ta = Triangle(a0, a1, a2), tb = Triangle(b0, b1, b2);
    const ref::Mesh ma = ref::meshFromTriangle(a0, a1, a2), mb = ref::meshFromTriangle(b0, b1, b2);
    const ref::Signed exact = ref::signedDistance(ma, mb);
    SCOPED_TRACE("random case " + std::to_string(i));
    if (exact.value > 1e-9) {
      ++checked;
      const DistanceResult d = gjkDistance(ta, Pose(), tb, Pose());
      expectSane(d);
      EXPECT_NEAR(d.distance, exact.value, 1e-6 * exact.value + 1e-12);
      EXPECT_FALSE(isIntersecting(ta, Pose(), tb, Pose()));
    } else if (exact.value < -1e-9) {
      EXPECT_TRUE(isIntersecting(ta, Pose(), tb, Pose()));
    }
  }
  EXPECT_GT(checked, 300);
}

// Convex hulls given duplicated, coplanar, collinear and interior points answer exactly as the shape
// they describe: a cube hull as the box, a flat square as a zero-height box, a line as a segment, one
// repeated point as a point. Bound: 1e-12 absolute against the box's own answers / the analytic gaps.
TEST(HardCases, DuplicatedAndCoplanarHullPoints) {
  std::vector<Vec3> pts;
  for (int rep = 0; rep < 3; ++rep)
    for (const Vec3& c : boxCorners(Vec3(0.5, 0.5, 0.5))) pts.push_back(c);
  for (int k = 0; k < 3; ++k) {
    Vec3 f = Vec3::Zero();
    f[k] = 0.5;
    pts.push_back(f);   // face centres
    pts.push_back(-f);
    Vec3 e = Vec3::Constant(0.5);
    e[k] = 0.0;
    pts.push_back(e);   // an edge midpoint
  }
  pts.push_back(Vec3(0.1, -0.2, 0.3));  // interior
  const Shape cube = ConvexHull(pts), box = Box(Vec3(0.5, 0.5, 0.5));
  const Shape other = Box(Vec3(0.3, 0.2, 0.4));
  for (const Vec3& t : {Vec3(1.2, 0.1, 0.2), Vec3(0.9, 0.8, 0.85), Vec3(0.6, 0.1, -0.2), Vec3(0.1, 0.1, 0.1)}) {
    const Pose pb = posed(rotation(0.4, Vec3(1, 1, 0)), t);
    const DistanceResult dh = gjkDistance(cube, Pose(), other, pb), db = gjkDistance(box, Pose(), other, pb);
    expectSane(dh);
    EXPECT_NEAR(dh.distance, db.distance, 1e-12);
    EXPECT_EQ(isIntersecting(cube, Pose(), other, pb), isIntersecting(box, Pose(), other, pb));
    const PenetrationResult ph = epaPenetration(cube, Pose(), other, pb), pbx = epaPenetration(box, Pose(), other, pb);
    expectSane(ph);
    EXPECT_NEAR(ph.signed_distance, pbx.signed_distance, 1e-9);
  }
  // Flat: a square at z = 0 given with duplicates, edge points and its centre; a box above it.
  std::vector<Vec3> square;
  for (int rep = 0; rep < 2; ++rep)
    for (const Vec3& c : {Vec3(-1, -1, 0), Vec3(1, -1, 0), Vec3(1, 1, 0), Vec3(-1, 1, 0), Vec3(0, 1, 0), Vec3(0, 0, 0)})
      square.push_back(c);
  const Shape flat = ConvexHull(square);
  for (const double gap : {1e-3, 1e-9}) {
    expectDistance(flat, Pose(), other, Pose::translation(Vec3(0.9, -0.5, 0.4 + gap)), gap, 1e-12, 5e-10);
    expectDistance(flat, posed(kTilt, Vec3(1, 2, 3)), Sphere(0.25), posed(kTilt, Vec3(1, 2, 3) + kTilt * Vec3(0.3, 0.2, -0.25 - gap)), gap,
                   1e-12, 5e-10);
  }
  EXPECT_TRUE(isIntersecting(flat, Pose(), other, Pose::translation(Vec3(0.9, -0.5, 0.3))));
  // Collinear points (a segment from x = −1 to 2) and a single repeated point.
  const Shape line = ConvexHull({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(2, 0, 0), Vec3(1, 0, 0)});
  expectDistance(line, Pose(), Sphere(0.5), Pose::translation(Vec3(2.5, 0.6, 0.8)), std::hypot(0.5, 0.6, 0.8) - 0.5, 1e-12, 1e-9);
  expectDistance(line, Pose(), Sphere(0.5), Pose::translation(Vec3(0.3, 0, 0.5 + 1e-9)), 1e-9, 1e-12, 5e-10);
  const Shape dot = ConvexHull({Vec3(0.25, 0.5, 1), Vec3(0.25, 0.5, 1), Vec3(0.25, 0.5, 1)});
  expectDistance(dot, Pose(), box, Pose::translation(Vec3(0.25, 0.5, 1.5 + 1e-9)), 1e-9, 1e-12, 5e-10);
  expectDistance(dot, Pose(), box, Pose::translation(Vec3(0.25, 0.5, 1.5)), 0.0, 1e-12, 5e-10);
  EXPECT_TRUE(isIntersecting(dot, Pose(), box, Pose::translation(Vec3(0.25, 0.5, 1.5))));
}

// Spheres exactly touching (centre distance exactly r_a + r_b along an axis) intersect; 1e-9·r apart
// they do not. Radii 1e-2 … 1e2. Bound: distance within 1e-12·r of the gap.
TEST(HardCases, TouchingSpheres) {
  for (const double r : {1e-2, 1.0, 1e2}) {
    const Shape a = Sphere(r), b = Sphere(0.5 * r);
    const Vec3 c(0.25 * r, -3 * r, 7 * r);
    for (int axis = 0; axis < 3; ++axis) {
      SCOPED_TRACE("r " + std::to_string(r) + " axis " + std::to_string(axis));
      const Vec3 e = Vec3::Unit(axis);
      const Pose pa = Pose::translation(c), touching = Pose::translation(c + 1.5 * r * e);
      EXPECT_TRUE(isIntersecting(a, pa, b, touching));
      const DistanceResult d = gjkDistance(a, pa, b, touching);
      expectSane(d);
      EXPECT_LE(d.distance, 1e-12 * r);
      EXPECT_TRUE(d.mayCollide());
      const Pose apart = Pose::translation(c + (1.5 * r + 1e-9 * r) * e);
      EXPECT_FALSE(isIntersecting(a, pa, b, apart));
      EXPECT_NEAR(gjkDistance(a, pa, b, apart).distance, 1e-9 * r, 1e-12 * r);
    }
    // Along a diagonal (|u| = 1 to rounding): the same booleans.
    const Vec3 u = Vec3(2, -3, 6) / 7.0;
    EXPECT_TRUE(isIntersecting(a, Pose::translation(c), b, Pose::translation(c + 1.5 * r * u)));
    EXPECT_FALSE(isIntersecting(a, Pose::translation(c), b, Pose::translation(c + (1.5 + 1e-9) * r * u)));
    // A sphere touching a box face, and one 1e-9·r off it.
    const Shape box = Box(Vec3(r, 2 * r, 3 * r));
    EXPECT_TRUE(isIntersecting(box, Pose::translation(c), a, Pose::translation(c + Vec3(2 * r, 0.5 * r, 0))));
    EXPECT_FALSE(isIntersecting(box, Pose::translation(c), a, Pose::translation(c + Vec3((2 + 1e-9) * r, 0.5 * r, 0))));
  }
}

// Rotations of 1e-7 rad: a cube tilted by θ about y over another cube. Its lowest point is an edge at
// height z_b − (sin θ + cos θ). Bound: 1e-12 + gjk_relative·gap (the documented relative tolerance; these
// near-parallel faces need not converge to rounding); at the exact touching height intersect is true,
// 1e-9 above it false.
TEST(HardCases, TinyRotations) {
  const Shape cube = Box(Vec3(1, 1, 1));
  const double theta = 1e-7;
  const Mat3 r = rotation(theta, Vec3::UnitY());
  const double drop = std::sin(theta) + std::cos(theta);
  // B is shifted by −0.2 in x so its lowest edge (at x = −0.2 + cos θ − sin θ) lies over A's top face.
  for (const double gap : {1e-3, 1e-6, 1e-8}) {
    const Pose pb = posed(r, Vec3(-0.2, 0.3, 1 + drop + gap));
    expectDistance(cube, Pose(), cube, pb, gap, 1e-12 + 1e-6 * gap, 1e-9);
  }
  EXPECT_TRUE(isIntersecting(cube, Pose(), cube, posed(r, Vec3(-0.2, 0.3, 1 + drop))));
  EXPECT_FALSE(isIntersecting(cube, Pose(), cube, posed(r, Vec3(-0.2, 0.3, 1 + drop + 1e-9))));
  // Both cubes turned by different tiny rotations in a tilted frame: faces 2e-7 rad from parallel.
  const Pose pa = posed(kTilt * rotation(-theta, Vec3::UnitX()), Vec3::Zero());
  const Pose pb = posed(kTilt * rotation(theta, Vec3::UnitX()), kTilt * Vec3(0, 0, 3));
  // Each cube's extreme height along the tilted z: sin θ + cos θ; the gap is 3 − 2(sin θ + cos θ).
  const double exact = 3 - 2 * (std::sin(theta) + std::cos(theta));
  expectDistance(cube, pa, cube, pb, exact, 1e-12 + 1e-6 * exact, 1e-9);
  // A 1e-7 rad rotation of a sphere or capsule changes nothing.
  const Shape cap = Capsule(0.5, 1.0);
  expectDistance(cap, posed(rotation(theta, Vec3::UnitX()), Vec3::Zero()), cap, Pose::translation(Vec3(1 + 1e-8, 0, 0)),
                 1e-8, 1e-12, 1e-9);
}

// Ray casts grazing an edge and a vertex of a box, starting inside, on the surface, with a zero
// direction. Semantics (ray_cast.h): the smallest t with the ray point in the closed solid, t a lower
// bound; a ray that touches the solid exactly is a hit. Bound: t within 1e-9 (unit box) where the
// contact is transversal; for grazes, t ≤ exact and the point at t within cast_relative·size of the box.
TEST(HardCases, RayGrazesStartsInsideOnSurfaceAndZeroDirection) {
  const Shape box = Box(Vec3(1, 1, 1));
  const Tolerances tol;
  for (const Pose& p : {Pose(), posed(kTilt, Vec3(2, -1, 0.5))}) {
    const auto ray = [&](const Vec3& o, const Vec3& d, double max_t) { return Ray{p * o, p.R * d, max_t}; };
    const auto pointOff = [&](const Ray& r, double t) {
      const Vec3 q = p.R.transpose() * (r.origin + t * r.direction - p.t);
      return (q - q.cwiseMax(Vec3(-1, -1, -1)).cwiseMin(Vec3(1, 1, 1))).norm();
    };
    // Along an edge (y = z = 1), through a vertex only, and along a face (y = 1): all touch the box.
    for (const Ray& graze : {ray(Vec3(-4, 1, 1), Vec3(1, 0, 0), 10), ray(Vec3(-2, 4, 1), Vec3(1, -1, 0), 10),
                             ray(Vec3(-4, 1, 0.3), Vec3(2, 0, 0), 10)}) {
      const CastResult r = gjkRayCast(box, p, graze);
      expectSane(r);
      EXPECT_TRUE(r.hit) << "a ray touching the box exactly was reported as a miss";
      const double exact = graze.direction.norm() > 1.5 ? 1.5 : 3.0;
      EXPECT_LE(r.t, exact + 1e-12);
      EXPECT_LE(pointOff(graze, r.t), 2 * tol.cast_relative * 6);
    }
    // The same rays moved 1e-4 outward miss; moved 1e-4 inward hit at the exact entry (transversal: 1e-9).
    EXPECT_FALSE(gjkRayCast(box, p, ray(Vec3(-4, 1 + 1e-4, 1), Vec3(1, 0, 0), 10)).hit);
    EXPECT_FALSE(gjkRayCast(box, p, ray(Vec3(-2, 4 + 1e-4, 1), Vec3(1, -1, 0), 10)).hit);
    const CastResult in = gjkRayCast(box, p, ray(Vec3(-4, 1 - 1e-4, 1 - 1e-4), Vec3(1, 0, 0), 10));
    ASSERT_TRUE(in.hit);
    EXPECT_NEAR(in.t, 3.0, 1e-9);
    EXPECT_LE(in.t, 3.0 + 1e-12);
    // Starting inside: t = 0, whatever the direction (even zero) or max_t (even 0).
    for (const Vec3& d : {Vec3(1, 0, 0), Vec3(0.3, -2, 5), Vec3(0, 0, 0)}) {
      for (const double max_t : {0.0, 1.0}) {
        const CastResult r = gjkRayCast(box, p, ray(Vec3(0.2, 0.3, -0.4), d, max_t));
        expectSane(r);
        EXPECT_TRUE(r.hit);
        EXPECT_EQ(r.t, 0.0);
      }
    }
    // Starting exactly on the surface (a face, an edge, a vertex), pointing out, along, in, or nowhere: t = 0.
    for (const Vec3& o : {Vec3(1, 0.25, -0.5), Vec3(1, 1, 0.5), Vec3(1, 1, 1)}) {
      for (const Vec3& d : {Vec3(1, 0, 0), Vec3(0, 0, 1), Vec3(-1, 0, 0), Vec3(0, 0, 0)}) {
        const CastResult r = gjkRayCast(box, p, ray(o, d, 5));
        expectSane(r);
        EXPECT_TRUE(r.hit) << "origin " << o.transpose() << " dir " << d.transpose();
        EXPECT_LE(r.t, 1e-12) << "origin " << o.transpose() << " dir " << d.transpose();
      }
    }
    // A zero direction from outside (beyond the cast band of 1e-6·size) never reaches the box.
    for (const Vec3& o : {Vec3(1 + 1e-4, 0, 0), Vec3(3, 3, 3)}) {
      const CastResult r = gjkRayCast(box, p, ray(o, Vec3::Zero(), 1e6));
      expectSane(r);
      EXPECT_FALSE(r.hit);
    }
  }
  // Tangent to a sphere: a hit (the ray touches it); t ≤ 5 and the point at t within the cast tolerance.
  const CastResult tangent = gjkRayCast(Sphere(1), Pose(), Ray{Vec3(-5, 1, 0), Vec3(1, 0, 0), 10});
  expectSane(tangent);
  EXPECT_TRUE(tangent.hit);
  EXPECT_LE(tangent.t, 5.0 + 1e-12);
  EXPECT_LE(std::hypot(-5 + tangent.t, 1.0) - 1.0, 2 * Tolerances{}.cast_relative * 6);
  EXPECT_FALSE(gjkRayCast(Sphere(1), Pose(), Ray{Vec3(-5, 1 + 1e-4, 0), Vec3(1, 0, 0), 10}).hit);
}

// Penetrations of 1e-8 between boxes (tilted), box–hull, sphere–box, capsule–box and sphere–sphere.
// Bound: EPA depth within 1e-10 of 1e-8, normal within 1e-6 rad of the face normal; intersect true.
TEST(HardCases, TinyPenetrations) {
  const double depth = 1e-8;
  const Shape a = Box(Vec3(1, 1, 1)), b = Box(Vec3(0.5, 0.7, 0.3));
  const Shape hull_b = ConvexHull(boxCorners(Vec3(0.5, 0.7, 0.3)));
  const Vec3 n = kTilt * Vec3::UnitX();
  const auto check = [&](const Shape& sa, const Pose& pa, const Shape& sb, const Pose& pb, const Vec3& normal) {
    const PenetrationResult p = epaPenetration(sa, pa, sb, pb);
    expectSane(p);
    EXPECT_NEAR(p.depth, depth, 1e-10) << shapeTypeName(sa) << "-" << shapeTypeName(sb) << " " << statusName(p.status);
    EXPECT_NEAR(p.signed_distance, -depth, 1e-10);
    EXPECT_NEAR((p.normal - normal).norm(), 0.0, 1e-6) << p.normal.transpose();
    EXPECT_TRUE(isIntersecting(sa, pa, sb, pb));
    const DistanceResult d = gjkDistance(sa, pa, sb, pb);
    expectSane(d);
    EXPECT_EQ(d.distance, 0.0);
    EXPECT_TRUE(d.mayCollide());
  };
  const Pose pa = posed(kTilt, Vec3(1, 2, 3));
  const Pose pb = posed(kTilt, pa.t + kTilt * Vec3(1.5 - depth, 0.2, -0.3));
  check(a, pa, b, pb, n);
  check(a, pa, hull_b, pb, n);
  check(a, pa, Sphere(0.4), posed(kTilt, pa.t + kTilt * Vec3(1.4 - depth, 0.2, -0.3)), n);
  check(a, pa, Capsule(0.4, 0.5), posed(kTilt, pa.t + kTilt * Vec3(1.4 - depth, 0.2, -0.3)), n);
  check(Sphere(0.75), Pose::translation(Vec3(1, 2, 3)), Sphere(0.5), Pose::translation(Vec3(1, 2, 3) + Vec3(1.25 - depth, 0, 0)),
        Vec3::UnitX());
}

// Centre-coincident pairs: depth is the analytic value, the normal finite and of unit length.
// Bound: 1e-12 (unit sizes; exact in principle, rounding only).
TEST(HardCases, CentreCoincidentShapes) {
  const auto check = [](const Shape& a, const Shape& b, const Pose& p, double exact) {
    const PenetrationResult r = epaPenetration(a, p, b, p);
    expectSane(r);
    EXPECT_NEAR(r.depth, exact, 1e-12) << shapeTypeName(a) << "-" << shapeTypeName(b) << " " << statusName(r.status);
    EXPECT_NEAR(r.signed_distance, -exact, 1e-12);
    // Moving B by depth along the normal (plus 1e-9) separates the pair.
    Pose out = p;
    out.t += r.normal * (r.depth + 1e-9);
    EXPECT_FALSE(isIntersecting(a, p, b, out)) << shapeTypeName(a) << "-" << shapeTypeName(b);
    EXPECT_TRUE(isIntersecting(a, p, b, p));
  };
  for (const Pose& p : {Pose(), posed(kTilt, Vec3(5, -6, 7))}) {
    check(Box(Vec3(1, 2, 3)), Box(Vec3(0.5, 0.5, 0.5)), p, 1.5);   // along x: 1 + 0.5
    check(Box(Vec3(1, 1, 1)), Box(Vec3(1, 1, 1)), p, 2.0);         // any face
    check(Box(Vec3(3, 2, 1)), Box(Vec3(1, 1, 0.25)), p, 1.25);     // along z
    check(Sphere(1.0), Sphere(0.5), p, 1.5);
    check(Sphere(1.0), Sphere(1.0), p, 2.0);
    check(Box(Vec3(1, 2, 3)), Sphere(0.5), p, 1.5);                // sphere inside: 1 + 0.5
    check(Capsule(0.5, 1.0), Capsule(0.25, 2.0), p, 0.75);         // coaxial: sideways by r_a + r_b
    check(Capsule(0.5, 1.0), Sphere(0.25), p, 0.75);
    check(Box(Vec3(1, 2, 3)), Capsule(0.25, 0.5), p, 1.25);        // capsule along z inside: 1 + 0.25 along x
    check(ConvexHull(boxCorners(Vec3(1, 2, 3))), Box(Vec3(0.5, 0.5, 0.5)), p, 1.5);
  }
  // Crossed capsules (z and x axes): the cores cross at the centre; sideways along y by r_a + r_b.
  const Pose crossed = posed(rotation(M_PI / 2, Vec3::UnitY()), Vec3::Zero());
  const PenetrationResult r = epaPenetration(Capsule(0.5, 1.0), Pose(), Capsule(0.25, 2.0), crossed);
  expectSane(r);
  EXPECT_NEAR(r.depth, 0.75, 1e-12);
  EXPECT_NEAR(std::abs(r.normal.y()), 1.0, 1e-12);
}

// Non-finite input: every query reports Status::InvalidInput with a result a caller treats as a
// collision. Shape constructors reject what test_primitives.cpp / test_convex_hull.cpp do not cover yet.
TEST(HardCases, BadInput) {
  const Shape box = Box(Vec3(1, 1, 1)), sphere = Sphere(0.5);
  const Pose ok = Pose::translation(Vec3(5, 0, 0));
  std::vector<Pose> bad;
  for (const double x : {kNaN, kInf, -kInf}) {
    bad.push_back(Pose::translation(Vec3(x, 0, 0)));
    Pose r;
    r.R(1, 2) = x;
    bad.push_back(r);
  }
  for (const Pose& b : bad) {
    for (int order = 0; order < 2; ++order) {
      const Pose& pa = order ? ok : b;
      const Pose& pb = order ? b : ok;
      const DistanceResult d = gjkDistance(box, pa, sphere, pb);
      EXPECT_EQ(d.status, Status::InvalidInput);
      EXPECT_TRUE(isFailure(d.status));
      EXPECT_TRUE(d.mayCollide());
      SimplexCache cache;
      const IntersectResult i = gjkIntersect(box, pa, sphere, pb, Tolerances{}, cache);
      EXPECT_EQ(i.status, Status::InvalidInput);
      EXPECT_TRUE(i.intersecting);
      EXPECT_FALSE(cache.valid);
      const PenetrationResult p = epaPenetration(box, pa, sphere, pb);
      EXPECT_EQ(p.status, Status::InvalidInput);
      EXPECT_TRUE(isFailure(p.status));
      const CastResult c = gjkShapeCast(box, pa, Vec3(1, 0, 0), sphere, pb, 1.0);
      EXPECT_EQ(c.status, Status::InvalidInput);
      EXPECT_TRUE(c.hit);
    }
    const CastResult r = gjkRayCast(box, b, Ray{Vec3(-5, 0, 0), Vec3(1, 0, 0), 10});
    EXPECT_EQ(r.status, Status::InvalidInput);
    EXPECT_TRUE(r.hit);
  }
  for (const double x : {kNaN, kInf, -kInf}) {
    for (const Ray& ray : {Ray{Vec3(x, 0, 0), Vec3(1, 0, 0), 10}, Ray{Vec3(-5, 0, 0), Vec3(1, x, 0), 10}}) {
      const CastResult r = gjkRayCast(box, Pose(), ray);
      EXPECT_EQ(r.status, Status::InvalidInput);
      EXPECT_TRUE(r.hit);
    }
    const CastResult c = gjkShapeCast(sphere, ok, Vec3(-1, 0, x), box, Pose(), 10);
    EXPECT_EQ(c.status, Status::InvalidInput);
    EXPECT_TRUE(c.hit);
  }
  for (const double max_t : {kNaN, -1.0}) {
    const CastResult r = gjkRayCast(box, Pose(), Ray{Vec3(-5, 0, 0), Vec3(1, 0, 0), max_t});
    EXPECT_EQ(r.status, Status::InvalidInput);
    EXPECT_TRUE(r.hit);
    const CastResult c = gjkShapeCast(sphere, ok, Vec3(-1, 0, 0), box, Pose(), max_t);
    EXPECT_EQ(c.status, Status::InvalidInput);
    EXPECT_TRUE(c.hit);
  }
  // Finite but overflowing magnitudes (squares reach infinity): any status, but never a NaN and never
  // "free" unless the answer is certified.
  for (const double big : {1e160, 1e300}) {
    const DistanceResult d = gjkDistance(box, Pose(), sphere, Pose::translation(Vec3(big, 0, 0)));
    EXPECT_FALSE(std::isnan(d.distance));
    if (!isFailure(d.status)) EXPECT_GT(d.distance, 0.0);
    SimplexCache cache;
    const IntersectResult i = gjkIntersect(box, Pose(), sphere, Pose::translation(Vec3(big, 0, 0)), Tolerances{}, cache);
    if (isFailure(i.status)) EXPECT_TRUE(i.intersecting);
    const CastResult c = gjkRayCast(box, Pose(), Ray{Vec3(-big, 0, 0), Vec3(big, 0, 0), 10});
    EXPECT_FALSE(std::isnan(c.t));
    if (!isFailure(c.status)) EXPECT_TRUE(c.hit);
  }
  // Constructors (the cases the shape tests do not already cover).
  EXPECT_THROW(Sphere{kInf}, ShapeError);
  EXPECT_THROW(Capsule(kNaN, 1.0), ShapeError);
  EXPECT_THROW(Capsule(0.0, 1.0), ShapeError);
  EXPECT_THROW(Capsule(-0.5, 1.0), ShapeError);
  EXPECT_THROW(Capsule(0.5, kInf), ShapeError);
  EXPECT_THROW(Capsule(0.5, kNaN), ShapeError);
  EXPECT_THROW(Cylinder(-1.0, 1.0), ShapeError);
  EXPECT_THROW(Cylinder(kInf, 1.0), ShapeError);
  EXPECT_THROW(Cylinder(1.0, kNaN), ShapeError);
  EXPECT_THROW(Cylinder(1.0, -1.0), ShapeError);
  EXPECT_THROW(Cone(kNaN, 1.0), ShapeError);
  EXPECT_THROW(Cone(0.0, 1.0), ShapeError);
  EXPECT_THROW(Cone(1.0, -1.0), ShapeError);
  EXPECT_THROW(Cone(1.0, kInf), ShapeError);
  EXPECT_THROW(Box(Vec3(kNaN, 1, 1)), ShapeError);
  EXPECT_THROW(Box(Vec3(1, 1, -kInf)), ShapeError);
  EXPECT_THROW(Point(Vec3(0, kInf, 0)), ShapeError);
  EXPECT_THROW(Segment(Vec3::Zero(), Vec3(kNaN, 0, 0)), ShapeError);
  EXPECT_THROW(Segment(Vec3(0, 0, -kInf), Vec3::Zero()), ShapeError);
  EXPECT_THROW(Triangle(Vec3::Zero(), Vec3::UnitX(), Vec3(0, kInf, 0)), ShapeError);
  EXPECT_THROW(ConvexHull({Vec3(kInf, 0, 0)}), ShapeError);
  // Zero-size shapes that are allowed stay usable: a flat box, a zero-length segment and capsule.
  EXPECT_NO_THROW(Box(Vec3(1, 0, 1)));
  EXPECT_NO_THROW(Segment(Vec3::Zero(), Vec3::Zero()));
  EXPECT_NEAR(gjkDistance(Capsule(0.5, 0.0), Pose(), Box(Vec3(1, 0, 1)), Pose::translation(Vec3(0, 2, 0))).distance, 1.5,
              1e-12);
}

// Issue 18, part 6: the families that were conservative but not exact.

namespace {
std::string num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", x);
  return buf;
}
}  // namespace

// A 1e-3 box on a 1e3 box (face on face in a tilted frame, and on an edge of it), and unit shapes of
// every curved kind, at gaps down to where the coordinates' own rounding is. The band of gjkIntersect
// is 1e-10 of the size of A − B, 2e-7 here, so gaps of 1e-7 … 1e-9 of the small box came out
// intersecting; a pair in the band now gets an exact look along GJK's last axes with a margin of the
// computation's rounding (gjk.h). Bound: separated for every gap ≥ 1e-10 (1e-7 of the small box,
// 1e-13 of the big one; its coordinates round at ~1e-13), intersecting at 0 and at −1e-10.
TEST(HardCases, SmallBoxOnABigOneAndCurvedShapesNearTouching) {
  const Shape huge = Box(Vec3(1e3, 1e3, 1e3)), tiny = Box(Vec3(1e-3, 1e-3, 1e-3));
  const Pose pa = posed(kTilt, Vec3(10, 20, 30));
  for (const double gap : {1e-4, 1e-6, 1e-8, 1e-9, 1e-10, 0.0, -1e-10}) {
    SCOPED_TRACE("gap " + num(gap));
    const Pose face = posed(kTilt, pa.t + kTilt * Vec3(1e3 + 1e-3 + gap, 3.7, -12.1));
    const Pose plain = Pose::translation(Vec3(0.3, -0.2, 1e3 + 1e-3 + gap));
    // The tiny box turned 45° about x, its edge down onto the big box's top face.
    const Pose edge = posed(rotation(M_PI / 4, Vec3::UnitX()), Vec3(-0.4, 0.25, 1e3 + std::sqrt(2.0) * 1e-3 + gap));
    const bool apart = gap > 0.0;
    EXPECT_EQ(isIntersecting(huge, pa, tiny, face), !apart);
    EXPECT_EQ(isIntersecting(tiny, face, huge, pa), !apart);
    EXPECT_EQ(isIntersecting(huge, Pose(), tiny, plain), !apart);
    if (gap != 0.0) {  // √2·1e-3 is not exact
      EXPECT_EQ(isIntersecting(huge, Pose(), tiny, edge), !apart);
    }
  }
  // Unit-sized curved shapes against a box face, at gaps of 1e-7 … 1e-9 of their size (and 0).
  for (const double L : {1e-2, 1.0, 1e2}) {
    const Shape box = Box(L * Vec3(1, 0.7, 0.4));
    const Shape cyl = Cylinder(0.5 * L, 0.8 * L), cone = Cone(0.6 * L, 0.7 * L), ball = Sphere(0.5 * L);
    const Pose pb = posed(kTilt, L * Vec3(3, -1, 2));
    for (int k = 7; k <= 10; ++k) {
      const double gap = k == 10 ? 0.0 : L * std::pow(10.0, -k);
      SCOPED_TRACE("L " + num(L) + " gap " + num(gap));
      const auto at = [&](const Mat3& R, double reach) { return posed(kTilt * R, pb.t + kTilt * Vec3(L + reach + gap, 0.1 * L, 0.1 * L)); };
      EXPECT_EQ(isIntersecting(box, pb, cyl, at(rotation(M_PI / 2, Vec3::UnitX()), 0.5 * L)), gap == 0.0);  // side
      EXPECT_EQ(isIntersecting(box, pb, cyl, at(rotation(M_PI / 2, Vec3::UnitY()), 0.8 * L)), gap == 0.0);  // cap
      EXPECT_EQ(isIntersecting(box, pb, cone, at(rotation(-M_PI / 2, Vec3::UnitY()), 0.7 * L)), gap == 0.0);  // apex
      EXPECT_EQ(isIntersecting(box, pb, ball, at(Mat3::Identity(), 0.5 * L)), gap == 0.0);
    }
  }
}

namespace {

// Stable roots of a·t² + 2b·t + c (a ≠ 0), in order; false when there are none.
bool quadraticRoots(double a, double b, double c, double& t0, double& t1) {
  const double disc = b * b - a * c;
  if (disc < 0.0) return false;
  const double q = -(b + std::copysign(std::sqrt(disc), b));
  t0 = q / a;
  t1 = q != 0.0 ? c / q : 0.0;
  if (t0 > t1) std::swap(t0, t1);
  return true;
}

// The first boundary point of a ray from outside a cylinder or cone (local frame): the smallest root on
// the lateral surface within the slab, or the crossing of a flat end within its disc. −1 on a miss.
double entryCylinderOrCone(bool cone, double r, double h, const Vec3& o, const Vec3& d) {
  double best = INFINITY;
  const double k = cone ? r / (2 * h) : 0.0;  // cone: ρ = k·(h − z)
  double t0, t1;
  const double a = d.x() * d.x() + d.y() * d.y() - k * k * d.z() * d.z();
  const double b = o.x() * d.x() + o.y() * d.y() + k * k * (h - o.z()) * d.z();
  const double c = o.x() * o.x() + o.y() * o.y() - (cone ? k * k * (h - o.z()) * (h - o.z()) : r * r);
  if (a != 0.0 && quadraticRoots(a, b, c, t0, t1)) {
    for (const double t : {t0, t1}) {
      const double z = o.z() + t * d.z();
      if (t >= 0.0 && std::abs(z) <= h && (!cone || h - z >= 0.0)) best = std::min(best, t);
    }
  }
  for (const double zc : cone ? std::vector<double>{-h} : std::vector<double>{-h, h}) {
    const double t = (zc - o.z()) / d.z();
    const Vec3 p = o + t * d;
    if (t >= 0.0 && std::hypot(p.x(), p.y()) <= r) best = std::min(best, t);
  }
  return std::isfinite(best) ? best : -1.0;
}

}  // namespace

// Rays passing a sphere or a capsule (its side and its end caps) 1e-6 … 1e-9 of its radius outside,
// and 1e-6 inside, in a tilted frame. The GJK cast counted a ray point within cast_relative (1e-6) of the
// shape as a hit; the cast now ends with conservative advancement on exact distances (ray_cast.h), which
// carries a passing ray beyond its closest approach, where a support plane proves the miss. Bound: a
// miss at every offset ≥ 1e-9·r outside (GJK's band is 1e-10 of the reach); inside, a hit with t a lower
// bound short of the analytic entry by at most that band over the incidence, √(2·1e-6) here.
TEST(HardCases, RaysTangentToSpheresAndCapsules) {
  for (const double r : {1e-2, 1.0, 1e2}) {
    const Pose p = posed(kTilt, r * Vec3(1, -2, 3));
    const Shape ball = Sphere(r), cap = Capsule(r, 2 * r);
    for (const double off : {1e-6, 1e-7, 1e-8, 1e-9, -1e-6}) {
      SCOPED_TRACE("r " + num(r) + " offset " + num(off));
      const double y = r * (1 + off);
      // Along x at height y: past the sphere, past the capsule's side, and past its upper end cap
      // (the cap's centre at z = 2r; the ray at z = 2r + y over its top, crossing along x).
      struct Case { const Shape* s; Vec3 o; double exact; };
      const double chord = off < 0 ? std::sqrt(r * r - y * y) : 0.0;
      for (const Case& c : {Case{&ball, Vec3(-5 * r, y, 0), 5 * r - chord}, Case{&cap, Vec3(-5 * r, y, 0.5 * r), 5 * r - chord},
                            Case{&cap, Vec3(-5 * r, 0, 2 * r + y), 5 * r - chord}}) {
        const Ray ray{p * c.o, p.R * Vec3(1, 0, 0), 10 * r};
        const CastResult hit = gjkRayCast(*c.s, p, ray);
        expectSane(hit);
        EXPECT_EQ(hit.hit, off < 0) << shapeTypeName(*c.s) << " t " << hit.t;
        if (off < 0 && hit.hit) {
          EXPECT_LE(hit.t, c.exact + 1e-12 * r);
          EXPECT_NEAR(hit.t, c.exact, 1e-10 * (6 * r) / std::sqrt(2e-6));
        }
      }
    }
  }
}

// Rays from outside onto cylinders and cones (side, flat ends, the cone's apex region) in a tilted frame,
// against the closed-form entry. The GJK cast stops once the ray point is within cast_relative of the
// shape, which left t short by up to ~3e-7 (1e-5 at low incidence); the conservative advancement that
// now ends every cast converges to GJK's rounding band. Bound, s = |origin − centre| + size: t never
// later than the entry (1e-12·s of slack for the reference's own rounding), and short of it by at most
// 2e-10·s/(|d|·incidence) for incidences ≥ 0.05.
TEST(HardCases, RayCastsAgainstCylindersAndCones) {
  std::mt19937_64 g(0xC0DE);
  std::uniform_real_distribution<double> u(-1, 1);
  double worst = 0.0;
  int checked = 0;
  for (int i = 0; i < 600; ++i) {
    const bool cone = i % 2;
    const double L = std::pow(10.0, 2 * u(g));
    const double r = L * (0.3 + 0.5 * std::abs(u(g))), h = L * (0.3 + 0.5 * std::abs(u(g)));
    const Shape s = cone ? Shape(Cone(r, h)) : Shape(Cylinder(r, h));
    const Vec3 o = 3 * L * Vec3(u(g), u(g), u(g)).normalized();
    const Vec3 d = (0.8 * Vec3(r * u(g), r * u(g), h * u(g)) - o) * std::pow(10.0, u(g));
    const double t = entryCylinderOrCone(cone, r, h, o, d);
    if (t <= 0.0) continue;
    // Incidence from the local normal at the entry point (side, end, or cone surface).
    // Incidence from the normal at the entry point; entries near a rim or the apex are left out.
    const Vec3 e = o + t * d;
    const double rho = std::hypot(e.x(), e.y());
    const bool on_end = std::abs(std::abs(e.z()) - h) < 1e-9 * L;
    if (on_end ? rho > 0.99 * r : (std::abs(std::abs(e.z()) - h) < 1e-2 * h || rho < 1e-2 * r)) continue;
    const Vec3 n = on_end ? Vec3(0, 0, e.z() > 0 ? 1 : -1) : Vec3(e.x() / rho, e.y() / rho, cone ? r / (2 * h) : 0.0).normalized();
    const double incidence = std::abs(n.dot(d.normalized()));
    if (incidence < 0.05) continue;
    const Pose p = posed(kTilt * rotation(u(g) * M_PI, Vec3(u(g), u(g), u(g))), L * Vec3(u(g), u(g), u(g)));
    const CastResult c = gjkRayCast(s, p, Ray{p * o, p.R * d, 2 * t});
    SCOPED_TRACE(std::string(shapeTypeName(s)) + " case " + std::to_string(i));
    expectSane(c);
    ASSERT_TRUE(c.hit);
    const double scale = o.norm() + r + h;
    EXPECT_LE(c.t, t + 1e-12 * scale / d.norm());
    const double err = (t - c.t) * d.norm() * incidence / scale;
    EXPECT_LE(err, 2e-10) << "o " << o.transpose() << " d " << d.transpose() << " r " << r << " h " << h << " t " << t << " got " << c.t;
    worst = std::max(worst, err);
    ++checked;
  }
  std::printf("[   stat   ] rays on cylinders and cones: %d checked, worst (t_exact - t)·|d|·incidence / s = %.3g\n",
              checked, worst);
  EXPECT_GT(checked, 200);
}

// A cylinder moving into a box face at incidences down to 1e-2 (a rim point leads), a cone moving apex
// first onto a cylinder's flat end, and a cone–cylinder cast that used to end at the default cap of 128
// iterations (found by random casts). The GJK cast's t was short by its stopping tolerance over the
// incidence (3.9e-7 of t here). Bound: t a lower bound within 1e-9/(|v|·incidence) of the analytic time
// (GJK's band, 1e-10 of a reach under 10, over the closing speed), status converged within the default
// cap; for the random cast, the shapes 1e-10 apart at t and apart just before.
TEST(HardCases, ShapeCastsOfCylindersAndCones) {
  const Shape box = Box(Vec3(1, 2, 2)), cyl = Cylinder(0.3, 0.5), cone = Cone(0.4, 0.3), post = Cylinder(1.0, 0.5);
  const Pose pb = posed(kTilt, Vec3(0.5, -1, 2));
  const Mat3 turn = rotation(0.4, Vec3(1, 2, 0));
  const Vec3 axis = turn * Vec3::UnitZ();
  // The cylinder's lowest x relative to its centre: its rim and half length along its axis.
  const double reach = 0.5 * std::abs(axis.x()) + 0.3 * std::sqrt(1 - axis.x() * axis.x());
  for (const double incidence : {1.0, 0.3, 0.1, 0.03, 0.01}) {
    SCOPED_TRACE("incidence " + num(incidence));
    // 0.5 from the face, arriving at y = 0.2 after sliding along it from y < 0 (|v| = 2).
    const double gap = 0.5, exact = gap / (2 * incidence);
    const Vec3 v = Vec3(-incidence, std::sqrt(1 - incidence * incidence), 0) * 2.0;
    const Vec3 start = Vec3(1 + reach, 0.2, -0.1) - exact * v;
    const double s = start.norm() + 3;
    const CastResult c = gjkShapeCast(cyl, posed(kTilt * turn, pb * start), kTilt * v, box, pb, 2 * exact);
    expectSane(c);
    ASSERT_TRUE(c.hit);
    EXPECT_EQ(c.status, Status::Converged);
    EXPECT_LE(c.t, exact + 1e-12 * s);
    EXPECT_NEAR(c.t, exact, 1e-9 / (2 * incidence)) << "short by " << (exact - c.t) / exact << " of t";
  }
  // The cone's apex points down (−z) onto the post's top at z = 0.5; it moves down and sideways.
  const Mat3 down = rotation(M_PI, Vec3::UnitX());
  for (const double slant : {0.0, 0.5, 2.0}) {
    SCOPED_TRACE("slant " + num(slant));
    const Vec3 start(0.1, -0.2, 0.5 + 0.3 + 0.7);  // apex 0.7 above the top
    const Vec3 v(slant * 0.1, 0.0, -1.0);
    const CastResult c = gjkShapeCast(cone, posed(kTilt * down, pb * start), kTilt * v, post, pb, 2.0);
    expectSane(c);
    ASSERT_TRUE(c.hit);
    EXPECT_EQ(c.status, Status::Converged);
    EXPECT_LE(c.iterations, Tolerances{}.cast_max_iterations);
    EXPECT_LE(c.t, 0.7 + 1e-12);
    EXPECT_NEAR(c.t, 0.7, 1e-9);
  }
  const Shape cone2 = Cone(0.5, 0.5), cyl2 = Cylinder(0.4, 0.6);
  const Pose pa = Pose::fromQuaternion(0.63629807155725171, -0.17807983445830003, 0.6888747860849691, 0.29810042903057871,
                                       Vec3(-0.66149603047524286, -2.2816384075322573, -1.1194353484664905));
  const Pose pc = Pose::fromQuaternion(0.45967652003772064, 0.0062438122309754667, -0.72102337467906008, 0.51844363714993691,
                                       Vec3(-0.04734353492221919, -0.29825723557258604, -0.23860962972421801));
  const Vec3 v(0.45143010279153795, 2.0066033448201916, 1.2035843288514627);
  const CastResult c = gjkShapeCast(cone2, pa, v, cyl2, pc, 2.0);
  expectSane(c);
  ASSERT_TRUE(c.hit);
  EXPECT_EQ(c.status, Status::Converged);
  const auto at = [&](double t) { return Pose{pa.R, pa.t + t * v}; };
  EXPECT_LE(gjkDistance(cone2, at(c.t), cyl2, pc).distance, 1e-10);
  EXPECT_GT(gjkDistance(cone2, at(c.t * (1 - 1e-8)), cyl2, pc).lower_bound, 0.0);
}

// One notion of contact: what gjkIntersect calls apart, gjkDistance proves apart (a certified lower bound
// above 0), at any gap down to the rounding, so that a state the validity checker accepts has a clearance
// a motion can start from. Faces, a vertex over an edge, triangles and curved shapes, sizes 1e-2 … 1e2,
// 1e3 m from the origin or at it; gaps 1e-9 … 1e-14 of the size and the last gap intersect calls apart
// (bisected). The lower bound never exceeds the gap (plus the inputs' rounding).
TEST(HardCases, WhatIntersectCallsApartDistanceProvesApart) {
  const Mat3 vertex_down = rotation(std::atan(std::sqrt(2.0)), Vec3(1, -1, 0));
  int pairs = 0, at_rounding = 0;
  for (const double L : {1e-2, 1.0, 1e2})
    for (const double far : {0.0, 1e3}) {
      const Vec3 origin = far * Vec3(0.6, -0.8, 0.3) + L * Vec3(0.3, 0.1, -0.2);
      struct Case {
        Shape a, b;
        Mat3 rb;  // B's turn
      };
      const std::vector<Case> cases = {
          {Box(Vec3(L, L, 0.5 * L)), Box(Vec3(0.5 * L, 0.5 * L, 0.5 * L)), Mat3::Identity()},
          {Box(Vec3(L, L, 0.5 * L)), Box(Vec3(0.5 * L, 0.5 * L, 0.5 * L)), vertex_down},
          {Triangle(Vec3(-L, -L, 0.5 * L), Vec3(L, -L, 0.5 * L), Vec3(0, L, 0.5 * L)),
           Triangle(Vec3(-L, 0, 0.2 * L), Vec3(L, 0.1 * L, -0.3 * L), Vec3(0.2 * L, -0.7 * L, -0.3 * L)), Mat3::Identity()},
          {Capsule(0.5 * L, L), Sphere(0.25 * L), Mat3::Identity()},
          {Cylinder(0.5 * L, 0.5 * L), Box(Vec3(0.2 * L, 0.3 * L, 0.4 * L)), vertex_down},
      };
      // How far a shape reaches along the unit u from its origin (its core's support plus its radius).
      const auto reach = [](const Shape& shape, const Vec3& u) {
        return std::visit([&](const auto& s) { return u.dot(s.support(u)) + s.radius(); }, shape);
      };
      for (const Case& c : cases) {
        // A's top at height 0 in the tilted frame; B's lowest point above it by the gap.
        const double top = reach(c.a, Vec3::UnitZ()), lo = reach(c.b, c.rb.transpose() * -Vec3::UnitZ());
        const Pose pa = posed(kTilt, origin - kTilt * Vec3(0, 0, top));
        const auto placed = [&](double gap) { return posed(kTilt * c.rb, origin + kTilt * Vec3(0, 0, lo + gap)); };
        std::vector<double> gaps;
        for (int k = 9; k <= 14; ++k) gaps.push_back(L * std::pow(10.0, -k));
        // The least gap intersect calls apart, to a relative 1e-3 (the band is ~1e-10 of A − B's size).
        double in = 0.0, out = 1e-9 * (L + far);
        ASSERT_FALSE(isIntersecting(c.a, pa, c.b, placed(out)));
        while (out - in > 1e-3 * out) {
          const double mid = 0.5 * (in + out);
          (isIntersecting(c.a, pa, c.b, placed(mid)) ? in : out) = mid;
        }
        gaps.push_back(out);
        for (const double gap : gaps) {
          const Pose pb = placed(gap);
          if (isIntersecting(c.a, pa, c.b, pb)) continue;
          ++pairs;
          at_rounding += gap == out;
          const DistanceResult d = gjkDistance(c.a, pa, c.b, pb);
          SCOPED_TRACE("L " + std::to_string(L) + " far " + std::to_string(far) + " gap " + std::to_string(gap));
          expectSane(d);
          EXPECT_GT(d.lower_bound, 0.0) << "intersect says apart, distance cannot prove it: " << statusName(d.status);
          // The gap as placed carries the rounding of the poses (~1e-16 of the coordinates).
          EXPECT_LE(d.lower_bound, gap + 1e-14 * (far + L));
        }
      }
    }
  std::printf("%d apart pairs, %d at the least gap intersect calls apart\n", pairs, at_rounding);
  EXPECT_EQ(at_rounding, 30);  // every case, size and place
}
