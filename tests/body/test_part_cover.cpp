// The parts' balls hold the inside of closed meshes: ballsHoldSolids proves only ball sets that hold the
// solid (hand-made sets on a cube, random sets on generated meshes, checked by the reference's winding
// number), and every link of our arms and the shared robots gets a proven margin, its sampled inside
// points all within a part's grown ball.
#include <clearway/body/link_geometry.h>
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

using Balls = std::vector<LinkGeometry::Ball>;

// How many of `samples` random points of the link's bounds that the reference puts inside a closed mesh
// lie in no ball grown by margin (and how many were inside at all).
struct Sampled {
  int inside = 0, loose = 0;
};
Sampled sampleInside(const LinkGeometry& g, const Balls& balls, double margin, int samples, std::uint64_t seed) {
  const tree_ref::WorldMesh w = tree_ref::placeTriangles(g.triangles());
  std::mt19937_64 rng(seed);
  Sampled s;
  for (int i = 0; i < samples; ++i) {
    const Vec3 p = tree_ref::randomInBox(rng, g.bounds());
    if (std::abs(tree_ref::windingNumber(p, w)) < 0.5) continue;
    ++s.inside;
    bool held = false;
    for (const LinkGeometry::Ball& ball : balls) held |= (p - ball.center).norm() <= ball.radius + margin;
    s.loose += !held;
  }
  return s;
}

Balls partBalls(const LinkGeometry& g) {
  Balls balls;
  for (const LinkGeometry::Part& p : g.parts()) balls.push_back({p.center, p.radius});
  return balls;
}

TEST(PartCover, ProvesOnlyBallsThatHoldTheCube) {
  const LinkGeometry cube(tree_ref::gridBox(Vec3(1, 1, 1), 4));
  ASSERT_EQ(cube.solidCount(), 1);
  const double m = 1e-3;
  // One ball around it all; the eight octants' balls (tangent at the corners: the margin settles those).
  EXPECT_TRUE(cube.ballsHoldSolids({{Vec3::Zero(), std::sqrt(3.0)}}, m));
  Balls octants;
  for (int k = 0; k < 8; ++k)
    octants.push_back({Vec3(k & 1 ? 0.5 : -0.5, k & 2 ? 0.5 : -0.5, k & 4 ? 0.5 : -0.5), std::sqrt(0.75)});
  EXPECT_TRUE(cube.ballsHoldSolids(octants, m));
  // Not without a margin (the proof cannot end at the corners), nor with a non-finite one.
  EXPECT_FALSE(cube.ballsHoldSolids(octants, 0.0));
  EXPECT_FALSE(cube.ballsHoldSolids(octants, std::nan("")));
  EXPECT_FALSE(cube.ballsHoldSolids(octants, std::numeric_limits<double>::infinity()));
  // The margin counts as stated: balls 0.4 margins short of the octants' corners are proven (the bottom
  // cells reach half a margin past a ball's boundary), 3 margins short refused (the corners stick out).
  Balls short_by = octants;
  for (LinkGeometry::Ball& b : short_by) b.radius = std::sqrt(0.75) - 0.4 * m;
  EXPECT_TRUE(cube.ballsHoldSolids(short_by, m));
  for (LinkGeometry::Ball& b : short_by) b.radius = std::sqrt(0.75) - 3.0 * m;
  EXPECT_FALSE(cube.ballsHoldSolids(short_by, m));
  // One octant missing leaves a corner of the cube held by nothing.
  Balls seven(octants.begin() + 1, octants.end());
  EXPECT_FALSE(cube.ballsHoldSolids(seven, m));
  EXPECT_GT(sampleInside(cube, seven, m, 4000, 1).loose, 0);
  // Balls along the surface hold every face but not the middle: the inside a body can lie in untouched.
  Balls skin;
  for (int axis = 0; axis < 3; ++axis)
    for (double side : {-1.0, 1.0})
      for (int i = 0; i <= 8; ++i)
        for (int j = 0; j <= 8; ++j) {
          Vec3 c;
          c[axis] = side;
          c[(axis + 1) % 3] = -1.0 + 0.25 * i;
          c[(axis + 2) % 3] = -1.0 + 0.25 * j;
          skin.push_back({c, 0.25});
        }
  EXPECT_FALSE(cube.ballsHoldSolids(skin, m));
  EXPECT_GT(sampleInside(cube, skin, m, 4000, 2).loose, 0);
  // No balls: nothing held. An open mesh has no inside: any balls do.
  EXPECT_FALSE(cube.ballsHoldSolids({}, m));
  TriangleMesh open = tree_ref::gridBox(Vec3(1, 1, 1), 4);
  open.triangles.pop_back();
  const LinkGeometry shell(open);
  EXPECT_EQ(shell.solidCount(), 0);
  EXPECT_TRUE(shell.ballsHoldSolids({}, m));
  EXPECT_EQ(shell.partBallMargin(), 0.0);
}

// Random ball sets near the parts' own (radii shrunk or grown, centres moved): every set proven holds every
// sampled inside point, and both answers occur (a proof that always refused would pass the first).
TEST(PartCover, EveryProvenSetHoldsTheSampledInside) {
  const std::vector<std::pair<std::string, TriangleMesh>> meshes = tree_ref::closedSamples();
  std::mt19937_64 rng(11);
  int proven = 0, refused = 0;
  for (const auto& [name, mesh] : meshes) {
    const LinkGeometry g(mesh);
    ASSERT_GT(g.solidCount(), 0) << name;
    const Balls parts = partBalls(g);
    for (int trial = 0; trial < 30; ++trial) {
      Balls balls = parts;
      for (LinkGeometry::Ball& b : balls) {
        b.radius *= std::uniform_real_distribution<double>(0.92, 1.12)(rng);
        b.center += tree_ref::randomInBall(rng, 0.03 * b.radius);
      }
      const double margin = g.sphereRadius() * (trial % 2 ? 1e-3 : 2e-2);
      if (!g.ballsHoldSolids(balls, margin)) {
        ++refused;
        continue;
      }
      ++proven;
      const Sampled s = sampleInside(g, balls, margin, 1500, 100 + trial);
      EXPECT_EQ(s.loose, 0) << name << " trial " << trial << ": proven, but " << s.loose << " of " << s.inside
                            << " inside points lie in no ball";
    }
  }
  std::printf("  %d ball sets proven, %d refused\n", proven, refused);
  EXPECT_GT(proven, 10);
  EXPECT_GT(refused, 10);
}

TEST(PartCover, EveryLinkOfRealRobotsHasAProvenMargin) {
  CLEARWAY_REQUIRE_SHARED_ARMS();
  for (const std::string& urdf : test::allArms()) {
    const RobotGeometry geometry(std::make_shared<const RobotModel>(loadRobot(urdf)));
    int solid = 0;
    for (int i : geometry.geometricLinks()) {
      const LinkGeometry& g = *geometry.link(i);
      const std::string what = urdf + " link " + geometry.model().link(i).name;
      if (g.solidCount() == 0) {
        EXPECT_EQ(g.partBallMargin(), 0.0) << what;
        continue;
      }
      ++solid;
      // Proven, and small: at most 1/1024 of the link's bounding ball.
      ASSERT_TRUE(std::isfinite(g.partBallMargin())) << what << ": no proof that the parts' balls hold it";
      EXPECT_LE(g.partBallMargin(), g.sphereRadius() / 1000.0) << what;
      // (Fewer samples on the links of 40,000 triangles: the winding number is brute force.)
      const int samples = std::clamp(static_cast<int>(4e6 / g.triangles().size()), 100, 1000);
      const Sampled s = sampleInside(g, partBalls(g), g.partBallMargin(), samples, i);
      EXPECT_EQ(s.loose, 0) << what << ": " << s.loose << " of " << s.inside << " inside points in no part's ball";
    }
    std::printf("  %s: %d links with closed meshes, all proven\n", urdf.c_str(), solid);
  }
}

}  // namespace
}  // namespace clearway
