// ConvexHull: quickhull construction (exact counts, closed convex mesh, containment) and support
// queries against a brute-force scan of the input points.
#include <clearway/shape/convex_hull.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <utility>
#include <vector>

namespace clearway {
namespace {

// The largest |coordinate| of the input: the scale of every tolerance below.
double largestCoordinate(const std::vector<Vec3>& points) {
  double m = 0.0;
  for (const Vec3& p : points) m = std::max(m, p.cwiseAbs().maxCoeff());
  return m;
}

double bruteForceMax(const std::vector<Vec3>& points, const Vec3& d) {
  double best = -std::numeric_limits<double>::infinity();
  for (const Vec3& p : points) best = std::max(best, d.dot(p));
  return best;
}

bool isInputPoint(const std::vector<Vec3>& points, const Vec3& v) {
  return std::find(points.begin(), points.end(), v) != points.end();
}

// A closed, consistently oriented, convex triangle mesh that contains every input point:
// each directed edge once and its reverse once (so each edge is shared by exactly two triangles),
// Euler characteristic 2, every vertex used, and every input point on or behind every triangle's plane
// within tol; the centre strictly behind each plane (outward normals). The plane of a needle triangle
// is only known to ~2^-52·(longest edge)²/|normal| radians in floating point, so that much slack
// (times the point's distance) is added: it is negligible for well-shaped triangles.
void expectClosedConvexHull(const ConvexHull& hull, const std::vector<Vec3>& input, double tol) {
  const auto& v = hull.vertices();
  const auto& tris = hull.triangles();
  ASSERT_FALSE(tris.empty());
  std::map<std::pair<int, int>, int> directed;
  std::vector<int> used(v.size(), 0);
  for (const auto& t : tris) {
    for (int k = 0; k < 3; ++k) {
      ASSERT_GE(t[k], 0);
      ASSERT_LT(t[k], static_cast<int>(v.size()));
      ++directed[{t[k], t[(k + 1) % 3]}];
      used[t[k]] = 1;
    }
  }
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1) << "directed edge " << edge.first << "->" << edge.second;
    const auto it = directed.find({edge.second, edge.first});
    ASSERT_TRUE(it != directed.end()) << "edge " << edge.first << "-" << edge.second << " has one triangle";
  }
  for (std::size_t i = 0; i < v.size(); ++i) EXPECT_TRUE(used[i]) << "vertex " << i << " in no triangle";
  const long V = static_cast<long>(v.size()), E = static_cast<long>(directed.size()) / 2, F = static_cast<long>(tris.size());
  EXPECT_EQ(V - E + F, 2);

  for (const auto& t : tris) {
    const Vec3 n = (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]);
    ASSERT_GT(n.norm(), 0.0);
    const Vec3 u = n.normalized();
    const double longest = std::max({(v[t[1]] - v[t[0]]).norm(), (v[t[2]] - v[t[1]]).norm(), (v[t[0]] - v[t[2]]).norm()});
    const double angle_error = 8.0 * std::numeric_limits<double>::epsilon() * longest * longest / n.norm();
    if (angle_error < 1e-3) {
      EXPECT_LT(u.dot(hull.center() - v[t[0]]), 0.0);
    }
    for (const Vec3& p : input) {
      EXPECT_LE(u.dot(p - v[t[0]]), tol + angle_error * (p - v[t[0]]).norm()) << "triangle " << t[0] << " " << t[1] << " " << t[2];
    }
  }
  for (const Vec3& p : v) EXPECT_TRUE(isInputPoint(input, p));
}

// support(d)·d equals the brute-force maximum over the input within 1e-12 of the scale of the dot
// products (|d| · largest |coordinate|), for `count` random directions.
void expectExactSupport(const ConvexHull& hull, const std::vector<Vec3>& input, int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  const double scale = largestCoordinate(input);
  std::int32_t hint = -1;  // carried from one direction to the next, as GJK's warm starts are
  for (int i = 0; i < count; ++i) {
    Vec3 d(normal(rng), normal(rng), normal(rng));
    if (i % 7 == 0) d = Vec3(i % 2 ? 1.0 : -1.0, 0.0, 0.0);  // axis directions: ties on flat faces
    if (i % 11 == 0) d = Vec3(1.0, i % 2 ? -1.0 : 1.0, 1.0);  // the cube map's face and cell borders
    const Vec3 s = hull.support(d);
    ASSERT_NEAR(d.dot(s), bruteForceMax(input, d), 1e-12 * scale * d.norm()) << "direction " << d.transpose();
    ASSERT_TRUE(isInputPoint(hull.vertices(), s));
    const Vec3 warm = hull.support(d, hint);
    ASSERT_NEAR(d.dot(warm), bruteForceMax(input, d), 1e-12 * scale * d.norm()) << "direction " << d.transpose();
  }
}

std::vector<Vec3> cubeCorners(double h = 1.0) {
  std::vector<Vec3> c;
  for (int i = 0; i < 8; ++i) c.emplace_back(i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h);
  return c;
}

std::vector<Vec3> randomInBox(int n, std::uint64_t seed, const Vec3& half, const Vec3& offset = Vec3::Zero()) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3> p;
  for (int i = 0; i < n; ++i) p.push_back(offset + Vec3(u(rng), u(rng), u(rng)).cwiseProduct(half));
  return p;
}

std::vector<Vec3> randomOnSphere(int n, std::uint64_t seed, double radius = 1.0) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  std::vector<Vec3> p;
  while (static_cast<int>(p.size()) < n) {
    const Vec3 x(normal(rng), normal(rng), normal(rng));
    if (x.norm() > 1e-3) p.push_back(radius * x.normalized());
  }
  return p;
}

TEST(ConvexHull, CubeCornersGiveEightVerticesAndTwelveTriangles) {
  const auto corners = cubeCorners();
  const ConvexHull hull(corners);
  EXPECT_EQ(hull.vertices().size(), 8u);
  EXPECT_EQ(hull.triangles().size(), 12u);
  expectClosedConvexHull(hull, corners, 1e-15);
  EXPECT_NEAR(hull.center().norm(), 0.0, 1e-15);
  EXPECT_EQ(hull.support(Vec3(1, 2, 3)), Vec3(1, 1, 1));
  EXPECT_EQ(hull.support(Vec3(-1, 2, -3)), Vec3(-1, 1, -1));
  EXPECT_EQ(hull.radius(), 0.0);
}

TEST(ConvexHull, CubeWithInteriorFaceEdgeAndDuplicatePointsKeepsOnlyCorners) {
  std::vector<Vec3> points = cubeCorners();
  for (const Vec3& p : randomInBox(200, 1, Vec3(0.99, 0.99, 0.99))) points.push_back(p);
  for (int k = 0; k < 3; ++k) {
    for (const double s : {-1.0, 1.0}) {
      Vec3 c = Vec3::Zero();
      c[k] = s;
      points.push_back(c);  // face centre
      for (const double t : {-1.0, 1.0}) {
        Vec3 m = Vec3::Zero();  // edge midpoints
        m[k] = s;
        m[(k + 1) % 3] = t;
        points.push_back(m);
      }
    }
  }
  for (int i = 0; i < 8; ++i) points.push_back(points[i]);  // duplicated corners
  // Many orders: ties in the starting simplex and the farthest-point choice pick face and edge points.
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 40; ++trial) {
    std::shuffle(points.begin(), points.end(), rng);
    const ConvexHull hull(points);
    ASSERT_EQ(hull.vertices().size(), 8u) << "trial " << trial;
    EXPECT_EQ(hull.triangles().size(), 12u);
    for (const Vec3& v : hull.vertices()) EXPECT_EQ(v.cwiseAbs(), Vec3(1, 1, 1));
    expectClosedConvexHull(hull, points, 1e-15);
  }
}

TEST(ConvexHull, GridsOnCubeFacesKeepOnlyCorners) {
  std::vector<Vec3> points;
  const int n = 11;
  for (int k = 0; k < 3; ++k) {
    for (const double s : {-1.0, 1.0}) {
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          Vec3 p;
          p[k] = s;
          p[(k + 1) % 3] = -1.0 + 2.0 * i / (n - 1);
          p[(k + 2) % 3] = -1.0 + 2.0 * j / (n - 1);
          points.push_back(p);
        }
      }
    }
  }
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 10; ++trial) {
    const ConvexHull hull(points);
    ASSERT_EQ(hull.vertices().size(), 8u) << "trial " << trial;
    EXPECT_EQ(hull.triangles().size(), 12u);
    expectClosedConvexHull(hull, points, 1e-15);
    expectExactSupport(hull, points, 200, trial);
    std::shuffle(points.begin(), points.end(), rng);
  }
}

TEST(ConvexHull, RotatedCubeGridWithRoundingNoiseIsClosedConvexAndContainsAllPoints) {
  std::vector<Vec3> points;
  const int n = 21;
  for (int k = 0; k < 3; ++k) {
    for (const double s : {-1.0, 1.0}) {
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          Vec3 p;
          p[k] = s;
          p[(k + 1) % 3] = -1.0 + 2.0 * i / (n - 1);
          p[(k + 2) % 3] = -1.0 + 2.0 * j / (n - 1);
          points.push_back(p);
        }
      }
    }
  }
  const Mat3 R = Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  for (Vec3& p : points) p = R * p;  // rounding moves the face points off their planes by ~1e-16
  const ConvexHull hull(points);
  EXPECT_EQ(hull.vertices().size(), 8u);  // points within rounding noise of the faces and edges add none
  expectClosedConvexHull(hull, points, 1e-12);
  expectExactSupport(hull, points, 2000, 11);
}

TEST(ConvexHull, RandomPointsOnASphereAreAllVertices) {
  const int n = 500;
  const auto points = randomOnSphere(n, 42);
  const ConvexHull hull(points);
  EXPECT_EQ(hull.vertices().size(), static_cast<std::size_t>(n));
  EXPECT_EQ(hull.triangles().size(), static_cast<std::size_t>(2 * n - 4));
  expectClosedConvexHull(hull, points, 1e-14);
  expectExactSupport(hull, points, 2000, 5);
}

TEST(ConvexHull, Tetrahedron) {
  const std::vector<Vec3> points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const ConvexHull hull(points);
  EXPECT_EQ(hull.vertices().size(), 4u);
  EXPECT_EQ(hull.triangles().size(), 4u);
  expectClosedConvexHull(hull, points, 0.0);
  EXPECT_EQ(hull.center(), Vec3(0.25, 0.25, 0.25));
  EXPECT_EQ(hull.support(Vec3(-1, -1, -1)), Vec3(0, 0, 0));
  EXPECT_EQ(hull.support(Vec3(0, 0, 1)), Vec3(0, 0, 1));
}

TEST(ConvexHull, CoincidentPointsGiveOnePoint) {
  const std::vector<Vec3> points(5, Vec3(0.5, -2.0, 3.0));
  const ConvexHull hull(points);
  ASSERT_EQ(hull.vertices().size(), 1u);
  EXPECT_TRUE(hull.triangles().empty());
  EXPECT_EQ(hull.vertices()[0], Vec3(0.5, -2.0, 3.0));
  EXPECT_EQ(hull.support(Vec3(1, 1, 1)), Vec3(0.5, -2.0, 3.0));
  EXPECT_EQ(hull.center(), Vec3(0.5, -2.0, 3.0));
  const ConvexHull single({Vec3::Zero()});
  EXPECT_EQ(single.vertices().size(), 1u);
  EXPECT_EQ(single.support(Vec3(0, 0, 1)), Vec3::Zero());
}

TEST(ConvexHull, CollinearPointsGiveTheTwoEndpoints) {
  std::vector<Vec3> points;
  const Vec3 a(1, 2, 3), dir(0.25, -0.5, 1.0);
  for (int i = 0; i <= 20; ++i) points.push_back(a + (i % 10) * dir);  // duplicates and interior points
  points.push_back(a + 12.0 * dir);
  points.push_back(a - 3.0 * dir);
  const ConvexHull hull(points);
  ASSERT_EQ(hull.vertices().size(), 2u);
  EXPECT_TRUE(hull.triangles().empty());
  EXPECT_TRUE(isInputPoint(hull.vertices(), a + 12.0 * dir));
  EXPECT_TRUE(isInputPoint(hull.vertices(), a - 3.0 * dir));
  EXPECT_EQ(hull.support(dir), a + 12.0 * dir);
  EXPECT_EQ(hull.support(-dir), a - 3.0 * dir);
  expectExactSupport(hull, points, 500, 2);
}

TEST(ConvexHull, CoplanarPointsGiveThePolygonCorners) {
  // A square in z = 0.5 with interior, edge and duplicate points.
  std::vector<Vec3> points = {{-1, -1, 0.5}, {1, -1, 0.5}, {1, 1, 0.5}, {-1, 1, 0.5}, {0, -1, 0.5}, {1, 0.25, 0.5}};
  for (const Vec3& p : randomInBox(100, 9, Vec3(0.9, 0.9, 0.0), Vec3(0, 0, 0.5))) points.push_back(p);
  points.push_back(points[2]);
  const ConvexHull square(points);
  EXPECT_EQ(square.vertices().size(), 4u);
  EXPECT_TRUE(square.triangles().empty());
  for (const Vec3& v : square.vertices()) EXPECT_EQ(v.head<2>().cwiseAbs(), Eigen::Vector2d(1, 1));
  expectExactSupport(square, points, 500, 3);

  // A triangle in the tilted plane x + y + z = 1 (exact in binary): grid points on its edges and inside.
  std::vector<Vec3> tilted;
  for (int i = 0; i <= 8; ++i) {
    for (int j = 0; i + j <= 8; ++j) tilted.emplace_back(i / 8.0, j / 8.0, 1.0 - i / 8.0 - j / 8.0);
  }
  const ConvexHull triangle(tilted);
  EXPECT_EQ(triangle.vertices().size(), 3u);
  EXPECT_TRUE(triangle.triangles().empty());
  expectExactSupport(triangle, tilted, 500, 4);
}

TEST(ConvexHull, InvalidInputThrows) {
  EXPECT_THROW(ConvexHull(std::vector<Vec3>{}), ShapeError);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(ConvexHull({Vec3(0, 0, 0), Vec3(1, nan, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}), ShapeError);
  EXPECT_THROW(ConvexHull({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, -inf)}), ShapeError);
  try {
    ConvexHull({Vec3(0, 0, 0), Vec3(nan, 0, 0)});
    FAIL() << "no exception";
  } catch (const ShapeError& e) {
    EXPECT_NE(std::string(e.what()).find("convex hull"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("point 1"), std::string::npos) << e.what();
  }
}

TEST(ConvexHull, SupportMatchesBruteForceOnRandomHulls) {
  std::uint64_t seed = 100;
  for (const int n : {16, 64, 256, 2000}) {
    const auto in_box = randomInBox(n, ++seed, Vec3(1.0, 2.0, 0.5));
    const ConvexHull box_hull(in_box);
    expectClosedConvexHull(box_hull, in_box, 1e-14);
    expectExactSupport(box_hull, in_box, 3000, ++seed);

    const auto on_sphere = randomOnSphere(n, ++seed, 3.0);
    const ConvexHull sphere_hull(on_sphere);
    EXPECT_EQ(sphere_hull.vertices().size(), static_cast<std::size_t>(n));
    expectExactSupport(sphere_hull, on_sphere, 3000, ++seed);
  }
}

TEST(ConvexHull, FarFromTheOriginAndTiny) {
  const auto far = randomInBox(1000, 21, Vec3(1, 1, 1), Vec3(1e4, -1e4, 1e4));
  const ConvexHull far_hull(far);
  expectClosedConvexHull(far_hull, far, 1e-9);
  expectExactSupport(far_hull, far, 3000, 22);

  const auto far_sphere = randomOnSphere(1000, 23, 1.0);
  std::vector<Vec3> shifted;
  for (const Vec3& p : far_sphere) shifted.push_back(p + Vec3(1e4, 1e4, -1e4));
  const ConvexHull shifted_hull(shifted);
  expectClosedConvexHull(shifted_hull, shifted, 1e-9);
  expectExactSupport(shifted_hull, shifted, 3000, 24);

  const auto tiny = randomOnSphere(1000, 25, 1e-3);
  const ConvexHull tiny_hull(tiny);
  EXPECT_EQ(tiny_hull.vertices().size(), 1000u);
  expectClosedConvexHull(tiny_hull, tiny, 1e-17);
  expectExactSupport(tiny_hull, tiny, 3000, 26);
}

TEST(ConvexHull, ThinSliver) {
  // Points in a 1 × 1 × 1e-9 slab, tilted so that no coordinate is exactly shared.
  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(-1, 2, 0.5).normalized()).toRotationMatrix();
  std::vector<Vec3> points;
  for (const Vec3& p : randomInBox(3000, 31, Vec3(1, 1, 1e-9))) points.push_back(R * p);
  const ConvexHull hull(points);
  EXPECT_GE(hull.vertices().size(), 4u);
  expectClosedConvexHull(hull, points, 1e-12);
  expectExactSupport(hull, points, 3000, 32);
}

TEST(ConvexHull, NearlyCoplanarNoise) {
  // A flat disc of points with 1e-15 noise across its plane, plus one apex far above: most points sit
  // within the noise of the base plane.
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Mat3 R = Eigen::AngleAxisd(1.1, Vec3(3, -1, 2).normalized()).toRotationMatrix();
  std::vector<Vec3> points;
  for (int i = 0; i < 5000; ++i) {
    const Vec3 p(u(rng), u(rng), 1e-15 * u(rng));
    if (p.head<2>().norm() <= 1.0) points.push_back(R * p);
  }
  points.push_back(R * Vec3(0, 0, 1));
  const ConvexHull hull(points);
  expectClosedConvexHull(hull, points, 1e-12);
  expectExactSupport(hull, points, 3000, 42);
  // Only the noise: a nearly-flat disc, no apex.
  points.pop_back();
  const ConvexHull flat(points);
  expectExactSupport(flat, points, 3000, 43);
}

TEST(ConvexHull, DegenerateDirectionsDoNotHang) {
  const auto points = randomOnSphere(300, 51);
  const ConvexHull hull(points);
  ASSERT_GE(hull.vertices().size(), 24u);  // the hill-climbing path
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(isInputPoint(hull.vertices(), hull.support(Vec3(nan, nan, nan))));
  EXPECT_TRUE(isInputPoint(hull.vertices(), hull.support(Vec3(1, nan, 0))));
  EXPECT_TRUE(isInputPoint(hull.vertices(), hull.support(Vec3::Zero())));
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(isInputPoint(hull.vertices(), hull.support(Vec3(inf, 0, 0))));
}

}  // namespace
}  // namespace clearway
