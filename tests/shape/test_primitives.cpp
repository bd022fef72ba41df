#include <clearway/shape/shape.h>

#include <gtest/gtest.h>

using namespace clearway;

TEST(Primitives, InvalidParametersThrowWithReason) {
  EXPECT_THROW(Sphere(0.0), ShapeError);
  EXPECT_THROW(Sphere(-1.0), ShapeError);
  EXPECT_THROW(Sphere(std::nan("")), ShapeError);
  EXPECT_THROW(Capsule(0.1, -1.0), ShapeError);
  EXPECT_THROW(Cylinder(0.0, 1.0), ShapeError);
  EXPECT_THROW(Cone(1.0, 0.0), ShapeError);
  EXPECT_THROW(Box(Vec3(1, -1, 1)), ShapeError);
  EXPECT_THROW(Box(Vec3(1, INFINITY, 1)), ShapeError);
  EXPECT_THROW(Triangle(Vec3::Zero(), Vec3(NAN, 0, 0), Vec3::UnitY()), ShapeError);
  try {
    Sphere s(-2.0);
    FAIL() << "no throw";
  } catch (const ShapeError& e) {
    EXPECT_NE(std::string(e.what()).find("sphere: radius"), std::string::npos) << e.what();
  }
}

TEST(Primitives, SupportPointsAreExtreme) {
  // Each support point must maximise d·x over the shape: compare with dense surface samples.
  const Cylinder cyl(0.5, 1.0);
  const Cone cone(0.5, 1.0);
  for (int k = 0; k < 200; ++k) {
    const Vec3 d(std::cos(k * 0.37) * std::sin(k * 0.11 + 0.3), std::sin(k * 0.37) * std::sin(k * 0.11 + 0.3),
                 std::cos(k * 0.11 + 0.3));
    double best_cyl = -INFINITY, best_cone = -INFINITY;
    for (int i = 0; i < 720; ++i) {
      const double a = i * M_PI / 360.0;
      const Vec3 rim(0.5 * std::cos(a), 0.5 * std::sin(a), 0.0);
      best_cyl = std::max({best_cyl, d.dot(rim + Vec3(0, 0, 1)), d.dot(rim - Vec3(0, 0, 1))});
      best_cone = std::max({best_cone, d.dot(rim - Vec3(0, 0, 1)), d.z()});
    }
    EXPECT_GE(d.dot(cyl.support(d)) + 1e-5, best_cyl);
    EXPECT_LE(d.dot(cyl.support(d)), best_cyl + 1e-5);
    EXPECT_GE(d.dot(cone.support(d)) + 1e-5, best_cone);
    EXPECT_LE(d.dot(cone.support(d)), best_cone + 1e-5);
  }
}
