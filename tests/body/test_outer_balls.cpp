// Outer balls hold the whole link: every triangle (its corners, and random points of it) and every sampled
// point inside a closed mesh (the reference's winding number) lies in a ball, on generated meshes and on
// every link of our arms and the shared ones; and the check is one that fails, on the same balls shrunk by
// a grid step.
#include <clearway/body/outer_balls.h>
#include <clearway/body/robot_geometry.h>
#include <clearway/load/robot_loader.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "shared_data.h"
#include "tree/mesh_reference.h"

namespace clearway {
namespace {

bool held(const OuterBalls& o, const Vec3& p, double shrink = 0.0) {
  for (const OuterBalls::Group& g : o.groups) {
    if ((p - g.center).norm() > g.radius) continue;  // (no ball of the group can hold it)
    for (int i = g.first; i < g.first + g.count; ++i)
      if ((p - o.balls[i].center).norm() <= o.balls[i].radius - shrink) return true;
  }
  return false;
}

// Points of the link no ball holds (balls shrunk by `shrink`): every triangle's corners and centroid and
// `per_triangle` random points of it, then `inside` random points of the bounds the reference puts inside
// a closed mesh. Counts what it tried, too.
struct Loose {
  long surface = 0, loose_surface = 0, inside = 0, loose_inside = 0;
};
Loose sample(const LinkGeometry& g, const OuterBalls& o, int per_triangle, int inside, std::uint64_t seed,
             double shrink = 0.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Loose l;
  const auto check = [&](const Vec3& p) {
    ++l.surface;
    l.loose_surface += !held(o, p, shrink);
  };
  for (const Triangle& t : g.triangles()) {
    for (const Vec3& v : t.v) check(v);
    check((t.v[0] + t.v[1] + t.v[2]) / 3.0);
    for (int k = 0; k < per_triangle; ++k) {
      double a = u(rng), b = u(rng);
      if (a + b > 1.0) a = 1.0 - a, b = 1.0 - b;
      check(t.v[0] + a * (t.v[1] - t.v[0]) + b * (t.v[2] - t.v[0]));
    }
  }
  if (g.solidCount() == 0 || inside == 0) return l;
  const tree_ref::WorldMesh w = tree_ref::placeTriangles(g.triangles());
  for (int i = 0; i < inside; ++i) {
    const Vec3 p = tree_ref::randomInBox(rng, g.bounds());
    if (std::abs(tree_ref::windingNumber(p, w)) < 0.5) continue;
    ++l.inside;
    l.loose_inside += !held(o, p, shrink);
  }
  return l;
}

// Every ball lies in its group's ball, and the groups cover the balls in order, at most kGroupSize each.
void expectGroupsHoldTheirBalls(const OuterBalls& o, const std::string& what) {
  int next = 0;
  for (const OuterBalls::Group& g : o.groups) {
    EXPECT_EQ(g.first, next) << what;
    EXPECT_GE(g.count, 1) << what;
    EXPECT_LE(g.count, OuterBalls::kGroupSize) << what;
    for (int i = g.first; i < g.first + g.count; ++i)
      EXPECT_LE((o.balls[i].center - g.center).norm() + o.balls[i].radius, g.radius) << what << " ball " << i;
    next = g.first + g.count;
  }
  EXPECT_EQ(next, static_cast<int>(o.balls.size())) << what;
}

TEST(OuterBalls, HoldGeneratedMeshesAndFailShrunk) {
  std::vector<std::pair<std::string, TriangleMesh>> meshes = tree_ref::closedSamples();
  TriangleMesh open = tree_ref::gridBox(Vec3(0.1, 0.1, 0.1), 4);
  open.triangles.resize(open.triangles.size() / 2);  // half a box: a surface without an inside
  meshes.push_back({"open", open});
  meshes.push_back(
      {"far", tree_ref::joined(tree_ref::uvSphere(0.05, 8, 12), tree_ref::uvSphere(0.03, 6, 8), Vec3(0.0, 0.0, 0.3))});
  // (At 8 mm steps, as below: the plate's 2,438 balls at 4 mm take seconds to build, minutes sanitized.)
  OuterBallOptions options;
  options.step = 0.008;
  for (const auto& [name, mesh] : meshes) {
    const LinkGeometry g(mesh);
    const OuterBalls o = buildOuterBalls(g, options);
    ASSERT_TRUE(o.proven()) << name;
    expectGroupsHoldTheirBalls(o, name);
    // (Thin plates and open surfaces take thousands of balls at the default step: counted, not bounded.)
    std::printf("  %s: %zu balls, step %.1f mm\n", name.c_str(), o.balls.size(), o.cell * 1e3);
    for (const LinkGeometry::Ball& b : o.balls) EXPECT_LE(b.radius, g.sphereRadius() * 1.01) << name;
    const Loose l = sample(g, o, 20, 3000, 7);
    EXPECT_EQ(l.loose_surface, 0) << name << ": " << l.loose_surface << " of " << l.surface << " surface points";
    EXPECT_EQ(l.loose_inside, 0) << name << ": " << l.loose_inside << " of " << l.inside << " inside points";
    if (g.solidCount() > 0) EXPECT_GT(l.inside, 100) << name;
    // Shrunk by a step, the balls leave points out: the check above can fail.
    const Loose shrunk = sample(g, o, 20, 3000, 7, o.cell);
    EXPECT_GT(shrunk.loose_surface + shrunk.loose_inside, 0) << name;
  }
}

// The balls hug the link: on a sphere, none reaches more than three grid steps past its surface (a tight
// bound is what the sphere stage is for: a pair of links a few millimetres apart is settled by its balls).
TEST(OuterBalls, StayWithinAFewStepsOfASphere) {
  const double radius = 0.1;
  const LinkGeometry g(tree_ref::uvSphere(radius, 24, 48));
  const OuterBalls o = buildOuterBalls(g);
  ASSERT_TRUE(o.proven());
  double farthest = 0.0;
  for (const LinkGeometry::Ball& b : o.balls) farthest = std::max(farthest, b.center.norm() + b.radius);
  EXPECT_LE(farthest, radius + 3.0 * o.cell);
  EXPECT_GT(farthest, radius);
  std::printf("  a sphere of %.0f mm: %zu balls, %zu groups, step %.1f mm, reaching %.2f mm past it\n", radius * 1e3,
              o.balls.size(), o.groups.size(), o.cell * 1e3, (farthest - radius) * 1e3);
}

TEST(OuterBalls, ServeNoLinkWithPrimitivesOrBadOptions) {
  const std::vector<TriangleMesh> meshes{tree_ref::gridBox(Vec3(0.1, 0.2, 0.3), 1)};
  std::vector<CollisionElement> elements(2);
  elements[0].mesh = 0;
  elements[1].primitive = Shape(Sphere(0.07));
  EXPECT_FALSE(buildOuterBalls(LinkGeometry(elements, meshes)).proven());
  const LinkGeometry box(meshes[0]);
  EXPECT_TRUE(buildOuterBalls(box).proven());
  OuterBallOptions bad;
  bad.step = std::nan("");
  EXPECT_FALSE(buildOuterBalls(box, bad).proven());
  bad.step = -1.0;
  EXPECT_FALSE(buildOuterBalls(box, bad).proven());
  // Flat squares too wide for the grid at the default step (10 m: 19 million cells; 10,000 km: more cells
  // along a side than an int counts): not served, at once.
  for (const double side : {10.0, 1e7}) {
    TriangleMesh square;
    square.vertices = {Vec3(0, 0, 0), Vec3(side, 0, 0), Vec3(side, side, 0), Vec3(0, side, 0)};
    square.triangles = {{0, 1, 2}, {0, 2, 3}};
    EXPECT_FALSE(buildOuterBalls(LinkGeometry(square)).proven()) << side;
  }
}

TEST(OuterBalls, HoldEveryLinkOfRealRobots) {
  CLEARWAY_REQUIRE_SHARED_ARMS();
  // At 8 mm steps: the same proof as at the default 4 mm, built ten times faster (the Panda's 5.7 s at
  // 4 mm in an optimised build is minutes under the sanitizers; bench_outer_balls measures 4 mm).
  OuterBallOptions options;
  options.step = 0.008;
  for (const std::string& urdf : test::allArms()) {
    const RobotGeometry geometry(std::make_shared<const RobotModel>(loadRobot(urdf)));
    std::size_t balls = 0, links = 0;
    double step = 0.0;
    for (int i : geometry.geometricLinks()) {
      const LinkGeometry& g = *geometry.link(i);
      const std::string what = urdf + " link " + geometry.model().link(i).name;
      const OuterBalls o = buildOuterBalls(g, options);
      if (!g.primitives().empty()) {
        EXPECT_FALSE(o.proven()) << what;
        continue;
      }
      ASSERT_TRUE(o.proven()) << what;
      expectGroupsHoldTheirBalls(o, what);
      // (Fewer points on the links of 40,000 triangles: the winding number is brute force.)
      const int inside = std::clamp(static_cast<int>(2e6 / g.triangles().size()), 50, 500);
      const Loose l = sample(g, o, g.triangles().size() > 20000 ? 0 : 4, inside, i);
      EXPECT_EQ(l.loose_surface, 0) << what << ": " << l.loose_surface << " of " << l.surface;
      EXPECT_EQ(l.loose_inside, 0) << what << ": " << l.loose_inside << " of " << l.inside;
      balls += o.balls.size();
      ++links;
      step = std::max(step, o.cell);
    }
    std::printf("  %s: %zu links, %zu outer balls (steps up to %.1f mm)\n", urdf.c_str(), links, balls, step * 1e3);
  }
}

}  // namespace
}  // namespace clearway
