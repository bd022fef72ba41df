// Narrow-phase queries against closed-form answers. Bounds: distances and times of impact within
// 1e-9 (the default relative tolerance 1e-6 applies to the gap between bounds, and these pairs
// converge to rounding), normals within 1e-6 rad.
#include <clearway/narrowphase/epa.h>
#include <clearway/narrowphase/gjk.h>
#include <clearway/narrowphase/ray_cast.h>

#include <gtest/gtest.h>

using namespace clearway;

namespace {
Pose at(double x, double y, double z) { return Pose::translation(Vec3(x, y, z)); }
Pose rotZ(double angle, const Vec3& t) {
  Pose p;
  p.R = Eigen::AngleAxisd(angle, Vec3::UnitZ()).toRotationMatrix();
  p.t = t;
  return p;
}
void expectVec(const Vec3& a, const Vec3& b, double tol) {
  EXPECT_NEAR((a - b).norm(), 0.0, tol) << "got " << a.transpose() << " expected " << b.transpose();
}
}  // namespace

TEST(Analytic, SphereSphereDistance) {
  const Shape a = Sphere(0.5), b = Sphere(0.25);
  const DistanceResult r = gjkDistance(a, at(1, 2, 3), b, at(1, 2, 5), Tolerances{});
  EXPECT_NEAR(r.distance, 2.0 - 0.75, 1e-12);
  EXPECT_LE(r.iterations, 2);
  expectVec(r.point_a, Vec3(1, 2, 3.5), 1e-12);
  expectVec(r.point_b, Vec3(1, 2, 4.75), 1e-12);
  expectVec(r.normal, Vec3::UnitZ(), 1e-12);
  EXPECT_FALSE(r.mayCollide());
}

TEST(Analytic, SphereBoxDistanceFaceEdgeVertex) {
  const Shape box = Box(Vec3(1, 2, 3)), s = Sphere(0.5);
  // Face region.
  DistanceResult r = gjkDistance(box, Pose(), s, at(3, 0, 0));
  EXPECT_NEAR(r.distance, 1.5, 1e-9);
  expectVec(r.normal, Vec3::UnitX(), 1e-9);
  // Edge region: nearest feature is the edge x = 1, y = 2.
  r = gjkDistance(box, Pose(), s, at(2, 3, 0));
  EXPECT_NEAR(r.distance, std::sqrt(2.0) - 0.5, 1e-9);
  expectVec(r.point_a, Vec3(1, 2, 0), 1e-9);
  // Vertex region.
  r = gjkDistance(box, Pose(), s, at(2, 3, 4));
  EXPECT_NEAR(r.distance, std::sqrt(3.0) - 0.5, 1e-9);
  expectVec(r.point_a, Vec3(1, 2, 3), 1e-9);
}

TEST(Analytic, BoxBoxFaceEdgeVertex) {
  const Shape a = Box(Vec3(0.5, 0.5, 0.5));
  // Face–face, offset sideways: distance is the axial gap.
  DistanceResult r = gjkDistance(a, Pose(), a, at(1.3, 0.2, -0.1));
  EXPECT_NEAR(r.distance, 0.3, 1e-9);
  expectVec(r.normal, Vec3::UnitX(), 1e-9);
  // Edge–face: B turned 45° about z presents a vertical face to A's vertical edge along the diagonal.
  r = gjkDistance(a, Pose(), a, rotZ(M_PI / 4, Vec3(2, 2, 0)));
  EXPECT_NEAR(r.distance, 2.0 * std::sqrt(2.0) - 0.5 - std::sqrt(0.5), 1e-9);
  // Edge–edge, crossed: A turned 45° about x (top edge along x), B turned 45° about y (bottom edge along y).
  const double h = 0.5 * std::sqrt(2.0);
  Pose pa, pb;
  pa.R = Eigen::AngleAxisd(M_PI / 4, Vec3::UnitX()).toRotationMatrix();
  pb.R = Eigen::AngleAxisd(M_PI / 4, Vec3::UnitY()).toRotationMatrix();
  pb.t = Vec3(0, 0, 2.0 * h + 0.125);
  r = gjkDistance(a, pa, a, pb);
  EXPECT_NEAR(r.distance, 0.125, 1e-9);
  expectVec(r.point_a, Vec3(0, 0, h), 1e-9);
  expectVec(r.point_b, Vec3(0, 0, h + 0.125), 1e-9);
  // Vertex–face: B is a box rotated so a vertex points down at A's top face.
  Pose p;
  p.R = (Eigen::AngleAxisd(std::atan(std::sqrt(2.0)), Vec3(1, -1, 0).normalized())).toRotationMatrix();
  const Vec3 corner = p.R * Vec3(-0.5, -0.5, -0.5);
  ASSERT_NEAR(corner.x(), 0.0, 1e-12);  // the rotation puts that corner straight below B's centre
  p.t = Vec3(0.1, -0.2, 0.5 + 0.25 - corner.z());
  r = gjkDistance(a, Pose(), a, p);
  EXPECT_NEAR(r.distance, 0.25, 1e-9);
  expectVec(r.point_b, Vec3(0.1, -0.2, 0.75), 1e-9);
}

TEST(Analytic, CapsuleCapsuleParallelAndSkew) {
  const Shape c = Capsule(0.1, 1.0);
  // Parallel axes 1 apart, overlapping in z: distance 1 − 0.2 whatever the z offset within overlap.
  DistanceResult r = gjkDistance(c, Pose(), c, at(1, 0, 0.7));
  EXPECT_NEAR(r.distance, 0.8, 1e-9);
  expectVec(r.normal, Vec3::UnitX(), 1e-9);
  // Skew axes: A along z, B along x at height 0 offset by y = 0.5 → closest points on the common normal.
  Pose px;
  px.R = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY()).toRotationMatrix();
  px.t = Vec3(0, 0.5, 0.3);
  r = gjkDistance(c, Pose(), c, px);
  EXPECT_NEAR(r.distance, 0.3, 1e-9);
  expectVec(r.point_a, Vec3(0, 0.1, 0.3), 1e-9);
  expectVec(r.point_b, Vec3(0, 0.4, 0.3), 1e-9);
}

TEST(Analytic, RaySphere) {
  // A curved surface converges to the tolerance, not to rounding: ask for 1e-12 to check exactness.
  Tolerances tight;
  tight.cast_relative = 1e-12;
  const Shape s = Sphere(1.0);
  Ray ray{Vec3(-5, 0.6, 0), Vec3(1, 0, 0), 100.0};
  const CastResult r = gjkRayCast(s, at(0, 0, 0), ray, tight);
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.t, 5.0 - 0.8, 1e-10);
  EXPECT_LE(r.t, 5.0 - 0.8);  // the cast's t is a lower bound on the time of impact
  expectVec(r.normal, Vec3(-0.8, 0.6, 0), 1e-9);
  expectVec(r.point, Vec3(-0.8, 0.6, 0), 1e-9);
  // At the default tolerance, t stays within cast_relative of the shape's size.
  EXPECT_NEAR(gjkRayCast(s, at(0, 0, 0), ray).t, 4.2, 1e-5);
  ray.origin = Vec3(-5, 1.01, 0);
  EXPECT_FALSE(gjkRayCast(s, at(0, 0, 0), ray).hit);
  ray.origin = Vec3(-5, 0, 0);
  ray.max_t = 3.9;
  EXPECT_FALSE(gjkRayCast(s, at(0, 0, 0), ray).hit);
}

TEST(Analytic, RayBox) {
  const Shape b = Box(Vec3(1, 1, 1));
  const Ray ray{Vec3(-3, 0.2, 0.9), Vec3(2, 0, 0), 10.0};
  const CastResult r = gjkRayCast(b, Pose(), ray);
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.t, 1.0, 1e-9);
  expectVec(r.normal, -Vec3::UnitX(), 1e-9);
  expectVec(r.point, Vec3(-1, 0.2, 0.9), 1e-9);
  // Rotated box: hit the face of a box turned 30° about z, ray along −y onto the top.
  const CastResult r2 = gjkRayCast(b, rotZ(M_PI / 6, Vec3(0, 0, 0)), Ray{Vec3(0, 0, 5), Vec3(0, 0, -1), 10.0});
  ASSERT_TRUE(r2.hit);
  EXPECT_NEAR(r2.t, 4.0, 1e-9);
  expectVec(r2.normal, Vec3::UnitZ(), 1e-9);
}

TEST(Analytic, ShapeCastSphereBox) {
  const Shape s = Sphere(0.5), b = Box(Vec3(1, 1, 1));
  const CastResult r = gjkShapeCast(s, at(-4, 0, 0), Vec3(1, 0, 0), b, Pose(), 10.0);
  ASSERT_TRUE(r.hit);
  EXPECT_NEAR(r.t, 2.5, 1e-6);
  expectVec(r.normal, -Vec3::UnitX(), 1e-6);
  expectVec(r.point, Vec3(-1, 0, 0), 1e-6);
  // Moving away never hits.
  EXPECT_FALSE(gjkShapeCast(s, at(-4, 0, 0), Vec3(-1, 0, 0), b, Pose(), 10.0).hit);
}

TEST(Analytic, PenetrationSphereSphereAndBoxBox) {
  const Shape s = Sphere(1.0);
  PenetrationResult r = epaPenetration(s, Pose(), s, at(0, 0, 1.5));
  EXPECT_NEAR(r.depth, 0.5, 1e-12);
  expectVec(r.normal, Vec3::UnitZ(), 1e-12);
  const Shape b = Box(Vec3(1, 1, 1));
  r = epaPenetration(b, Pose(), b, at(1.7, 0.3, -0.2));
  EXPECT_NEAR(r.depth, 0.3, 1e-9);
  EXPECT_NEAR(r.signed_distance, -0.3, 1e-9);
  expectVec(r.normal, Vec3::UnitX(), 1e-9);
  // Separated: the signed distance is the distance.
  r = epaPenetration(b, Pose(), b, at(2.5, 0, 0));
  EXPECT_NEAR(r.signed_distance, 0.5, 1e-9);
}

TEST(Analytic, IntersectUsesCachedAxis) {
  const Shape b = Box(Vec3(1, 1, 1));
  SimplexCache cache;
  const IntersectResult first = gjkIntersect(b, Pose(), b, at(2.5, 0.1, 0), Tolerances{}, cache);
  EXPECT_FALSE(first.intersecting);
  ASSERT_TRUE(cache.valid);
  const IntersectResult second = gjkIntersect(b, Pose(), b, at(2.49, 0.12, 0), Tolerances{}, cache);
  EXPECT_FALSE(second.intersecting);
  EXPECT_EQ(second.iterations, 1);
  EXPECT_TRUE(gjkIntersect(b, Pose(), b, at(1.99, 0.12, 0), Tolerances{}, cache).intersecting);
}
