// LinkGeometry: Mesh mode against brute force over all triangle pairs (tests/tree/mesh_reference.h, no
// tree, SAT or GJK in it) on random poses of generated meshes and of the Panda's link meshes; Hull mode
// never "free" where Mesh says "collision"; padding; touching; primitives; distances.
#include <clearway/load/mesh_loader.h>
#include <clearway/body/proximity.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "box_surface.h"
#include "shared_data.h"
#include "tree/mesh_reference.h"

namespace clearway {
namespace {

using tree_ref::Verdict;

constexpr double kBand = 1e-9;

struct Tally {
  int collide = 0, free = 0, band = 0, disagreements = 0, hull_only = 0;
};

Pose randomPoseNear(std::mt19937_64& rng, double reach) {
  Pose p;
  p.R = tree_ref::randomRotation(rng);
  p.t = tree_ref::randomInBall(rng, reach);
  return p;
}

enum class CaseKind { Random, NearContact, HullsOverlapMeshesApart };

// One random case: meshes a and b at random poses whose origins are within `reach`; Mesh mode against
// the reference, Hull mode against Mesh mode. Random: the poses as drawn. NearContact: b is moved along
// the normal of closest approach by 0.8 … 1.2 times the distance (from meshDistance; the reference then
// judges the result), so that the trees descend deep and most triangle pairs are close calls.
// HullsOverlapMeshesApart: drawn until the hulls overlap while meshDistance is positive, so that the
// exact stage has to prove "free" (for nearly convex meshes, most free poses end at the hull test).
void checkCase(const TriangleMesh& ma, const LinkGeometry& ga, const TriangleMesh& mb, const LinkGeometry& gb,
               std::mt19937_64& rng, double reach, double padding, Tally& tally, const std::string& what,
               CaseKind kind) {
  const Tolerances tol;
  Pose pa, pb;
  for (int draw = 0; draw < 100; ++draw) {
    pa = randomPoseNear(rng, 0.3 * reach);
    pb = randomPoseNear(rng, reach);
    pb.t += pa.t;
    if (kind != CaseKind::HullsOverlapMeshesApart) break;
    if (meshesIntersect(ga, pa, gb, pb, tol, GeometryMode::Hull, padding) &&
        !meshesIntersect(ga, pa, gb, pb, tol, GeometryMode::Mesh, padding))
      break;  // the selection uses the code under test; the reference still judges the case
  }
  if (kind == CaseKind::NearContact) {
    const DistanceResult d = meshDistance(ga, pa, gb, pb, tol, 0.2);  // a rough distance is enough here
    std::uniform_real_distribution<double> f(0.8, 1.2);
    if (d.distance > 0.0) pb.t -= (d.distance - padding) * f(rng) * d.normal;
  }
  const bool mesh = meshesIntersect(ga, pa, gb, pb, tol, GeometryMode::Mesh, padding);
  const bool hull = meshesIntersect(ga, pa, gb, pb, tol, GeometryMode::Hull, padding);
  EXPECT_TRUE(hull || !mesh) << what << ": hull says free where the mesh collides";
  if (hull && !mesh) ++tally.hull_only;
  const tree_ref::WorldMesh wa = tree_ref::place(ma, pa), wb = tree_ref::place(mb, pb);
  Verdict v = tree_ref::classify(wa, wb, padding, kBand);
  // Closed meshes are solids: surfaces apart, a piece of one may still lie inside the other (a Panda finger
  // drawn inside link3).
  if (v == Verdict::Free && tree_ref::closedMesh(mb)) v = tree_ref::containment(wa, wb);
  if (v == Verdict::Free && tree_ref::closedMesh(ma)) v = tree_ref::containment(wb, wa);
  switch (v) {
    case Verdict::Collide:
      ++tally.collide;
      if (!mesh) ++tally.disagreements;
      EXPECT_TRUE(mesh) << what << ": the reference finds a collision";
      break;
    case Verdict::Free:
      ++tally.free;
      if (mesh) ++tally.disagreements;
      EXPECT_FALSE(mesh) << what << ": the reference finds every triangle pair apart";
      break;
    case Verdict::Band:
      ++tally.band;
      break;
  }
  // The same pair seen from the other side.
  EXPECT_EQ(meshesIntersect(gb, pb, ga, pa, tol, GeometryMode::Mesh, padding), mesh) << what << ": not symmetric";
}

struct TestMesh {
  std::string name;
  TriangleMesh mesh;
};

std::vector<TestMesh> generatedMeshes() {
  return {{"sphere", tree_ref::uvSphere(0.1, 10, 16)},
          {"torus", tree_ref::torus(0.12, 0.03, 20, 10)},
          {"plate", tree_ref::gridBox(Vec3(0.15, 0.1, 0.002), 4)},
          {"box", tree_ref::gridBox(Vec3(0.05, 0.08, 0.1), 2)},
          {"dumbbell", tree_ref::joined(tree_ref::uvSphere(0.04, 6, 10), tree_ref::gridBox(Vec3(0.03, 0.03, 0.03), 2),
                                        Vec3(0.2, 0.05, 0.0))}};
}

void runRandomCases(const std::vector<TestMesh>& meshes, std::uint64_t seed, int cases_per_pair, double padding,
                    const TreeBuildOptions& options = {}) {
  std::vector<LinkGeometry> geoms;
  for (const auto& m : meshes) geoms.emplace_back(m.mesh, options);
  std::mt19937_64 rng(seed);
  Tally tally;
  int counter = 0;
  for (std::size_t i = 0; i < meshes.size(); ++i)
    for (std::size_t j = i; j < meshes.size(); ++j) {
      const double reach = tree_ref::meshRadius(meshes[i].mesh) + tree_ref::meshRadius(meshes[j].mesh);
      for (int c = 0; c < cases_per_pair; ++c)
        checkCase(meshes[i].mesh, geoms[i], meshes[j].mesh, geoms[j], rng, reach, padding, tally,
                  meshes[i].name + " vs " + meshes[j].name + " case " + std::to_string(c),
                  static_cast<CaseKind>(counter++ % 3));
    }
  const int total = tally.collide + tally.free + tally.band;
  std::printf("  %d cases: %d collide, %d free, %d in the band, %d hull-only collisions, %d disagreements\n", total,
              tally.collide, tally.free, tally.band, tally.hull_only, tally.disagreements);
  EXPECT_EQ(tally.disagreements, 0);
  EXPECT_LE(tally.band, total / 100) << "too many cases in the tolerance band to mean anything";
  EXPECT_GT(tally.collide, total / 10);
  EXPECT_GT(tally.free, total / 10);
  EXPECT_GT(tally.hull_only, total / 20) << "too few cases for the exact stage to prove free";
}

TEST(LinkGeometry, MeshModeMatchesBruteForceOnGeneratedMeshes) {
  runRandomCases(generatedMeshes(), 21, 30, 0.0);
}

TEST(LinkGeometry, MeshModeMatchesBruteForceForEverySplitAndLeafSize) {
  std::uint64_t seed = 40;
  for (const TreeSplit split : {TreeSplit::Median, TreeSplit::Sah})
    for (int leaf = 1; leaf <= AabbTree::kMaxLeafSize; ++leaf) {
      SCOPED_TRACE(testing::Message() << "split " << static_cast<int>(split) << " leaf " << leaf);
      runRandomCases({{"torus", tree_ref::torus(0.12, 0.03, 16, 8)}, {"plate", tree_ref::gridBox(Vec3(0.15, 0.1, 0.002), 3)}},
                     ++seed, 12, 0.0, {split, leaf});
    }
}

TEST(LinkGeometry, PaddingMatchesBruteForce) {
  runRandomCases(generatedMeshes(), 22, 12, 0.01);
  runRandomCases(generatedMeshes(), 23, 6, 0.05);
}

std::string pandaMeshDir() { return test::sharedDir() + "/robots/panda/meshes/collision"; }

std::vector<TestMesh> pandaMeshes() {
  std::vector<TestMesh> out;
  for (const char* name : {"link0", "link1", "link2", "link3", "link4", "link5", "link6", "link7", "hand", "finger"})
    out.push_back({name, loadMesh(pandaMeshDir() + "/" + name + ".stl", Vec3::Ones())});
  // Two links as one mesh: a hull with room between them, where only the triangles can say "free".
  out.push_back({"link3+link5", tree_ref::joined(out[3].mesh, out[5].mesh, Vec3(0.25, 0.0, 0.05))});
  out.push_back({"hand+finger", tree_ref::joined(out[8].mesh, out[9].mesh, Vec3(0.0, 0.04, 0.06))});
  return out;
}

TEST(LinkGeometry, MeshModeMatchesBruteForceOnPandaLinks) {
  CLEARWAY_REQUIRE_SHARED("robots/panda/meshes/collision");
  const std::vector<TestMesh> meshes = pandaMeshes();
  runRandomCases(meshes, 24, 3, 0.0);
  runRandomCases(meshes, 25, 1, 0.02);
}

// ---- Exact contact ---------------------------------------------------------------------------------------

TEST(LinkGeometry, TouchingCountsAndSurfacesInsideDoNot) {
  const TriangleMesh cube = tree_ref::gridBox(Vec3(0.5, 0.5, 0.5), 1);
  const LinkGeometry g(cube);
  const Tolerances tol;
  const Pose id = Pose::identity();
  // Faces coplanar and shared.
  EXPECT_TRUE(meshesIntersect(g, id, g, Pose::translation(Vec3(1, 0, 0)), tol, GeometryMode::Mesh));
  // Edge on edge, corner on corner.
  EXPECT_TRUE(meshesIntersect(g, id, g, Pose::translation(Vec3(1, 1, 0)), tol, GeometryMode::Mesh));
  EXPECT_TRUE(meshesIntersect(g, id, g, Pose::translation(Vec3(1, 1, 1)), tol, GeometryMode::Mesh));
  // Rotated 45° about z, its edge touching the face x = 0.5.
  const Pose rotated = Pose::fromQuaternion(0, 0, std::sin(tree_ref::kPi / 8), std::cos(tree_ref::kPi / 8), Vec3(0.5 + std::sqrt(0.5), 0.2, 0));
  EXPECT_TRUE(meshesIntersect(g, id, g, rotated, tol, GeometryMode::Mesh));
  // A micrometre apart: free, unless padded by more.
  EXPECT_FALSE(meshesIntersect(g, id, g, Pose::translation(Vec3(1 + 1e-6, 0, 0)), tol, GeometryMode::Mesh));
  EXPECT_FALSE(meshesIntersect(g, id, g, Pose::translation(Vec3(1 + 1e-6, 0.3, -0.2)), tol, GeometryMode::Hull));
  EXPECT_TRUE(meshesIntersect(g, id, g, Pose::translation(Vec3(1 + 1e-6, 0, 0)), tol, GeometryMode::Mesh, 1.1e-6));
  EXPECT_FALSE(meshesIntersect(g, id, g, Pose::translation(Vec3(1 + 1e-6, 0, 0)), tol, GeometryMode::Mesh, 0.9e-6));
  // A small cube inside a large one: surfaces apart, but a closed mesh is a solid, so they collide, in
  // either order, at distance 0 (and the parts' lower bound is 0).
  const LinkGeometry small(tree_ref::gridBox(Vec3(0.1, 0.1, 0.1), 1));
  const Pose inside = Pose::translation(Vec3(0.1, 0, 0));
  EXPECT_TRUE(meshesIntersect(g, id, small, inside, tol, GeometryMode::Mesh));
  EXPECT_TRUE(meshesIntersect(small, inside, g, id, tol, GeometryMode::Mesh));
  EXPECT_TRUE(meshesIntersect(g, id, small, inside, tol, GeometryMode::Hull));
  EXPECT_EQ(meshDistance(g, id, small, inside, tol).lower_bound, 0.0);
  EXPECT_EQ(meshDistance(small, inside, g, id, tol, 0.1, 0.01).lower_bound, 0.0);
  EXPECT_EQ(partsLowerBound(g, id, small, inside, tol, 1.0, 0.1), 0.0);
  EXPECT_EQ(partsLowerBound(small, inside, g, id, tol, 1.0, 0.1), 0.0);
  // Open (one triangle of the large cube's removed): a surface, free while the surfaces are apart.
  TriangleMesh open_cube = cube;
  open_cube.triangles.pop_back();
  const LinkGeometry open(open_cube);
  EXPECT_EQ(open.solidCount(), 0);
  EXPECT_EQ(g.solidCount(), 1);
  EXPECT_FALSE(meshesIntersect(open, id, small, inside, tol, GeometryMode::Mesh));
  EXPECT_NEAR(meshDistance(open, id, small, inside, tol).distance, 0.3, 1e-9);
  // Inside a torus's hole: outside its solid, so hull collision only.
  const LinkGeometry ring(tree_ref::torus(0.5, 0.1, 24, 12));
  EXPECT_FALSE(meshesIntersect(ring, id, small, id, tol, GeometryMode::Mesh));
  EXPECT_TRUE(meshesIntersect(ring, id, small, id, tol, GeometryMode::Hull));
  // Inside the torus's tube: a small ball in the solid ring.
  const LinkGeometry pebble(tree_ref::uvSphere(0.02, 6, 8));
  EXPECT_TRUE(meshesIntersect(ring, id, pebble, Pose::translation(Vec3(0.5, 0, 0)), tol, GeometryMode::Mesh));
  EXPECT_TRUE(shapeIntersectsLink(Sphere(0.02), Pose::translation(Vec3(0, 0.5, 0)), ring, id, tol, GeometryMode::Mesh));
  EXPECT_FALSE(shapeIntersectsLink(Sphere(0.02), id, ring, id, tol, GeometryMode::Mesh));
}

// A box surface of half size h about the origin with its (−, −, −) corner pulled out to `corner`: it touches
// a box of half size 0.5 there alone when `corner` is that box's corner. Outward triangles, or inward ones.
TriangleMesh pulledBox(double h, const Vec3& corner, bool inward) {
  TriangleMesh m = test::boxSurface(Vec3(h, h, h));
  m.vertices[0] = corner;
  if (inward)
    for (auto& t : m.triangles) std::swap(t[1], t[2]);
  return m;
}

// Issue 43: two nested closed shells sharing one corner were one piece, and its ray parity called the
// inner shell's inside outside. Whether a point is inside must not depend on whether the shells touch;
// the winding decides what lies between them (an inward inner shell bounds a cavity, which is empty).
TEST(LinkGeometry, NestedShellsAreSolidHoweverTheyTouch) {
  const Tolerances tol;
  const Pose id = Pose::identity();
  const TriangleMesh outer = test::boxSurface(Vec3(0.5, 0.5, 0.5));
  const LinkGeometry pebble(tree_ref::uvSphere(0.02, 6, 8));
  const Vec3 centre(0.02, 0.01, 0.0), wall(0.4, 0.35, 0.4), beyond(0.7, 0.0, 0.0);
  // Whether the pebble (a sphere mesh, and a sphere) placed at p collides with the link, and whether the
  // point itself lies inside it; all three must agree.
  const auto collides = [&](const LinkGeometry& g, const Vec3& p) {
    const bool mesh = meshesIntersect(g, id, pebble, Pose::translation(p), tol, GeometryMode::Mesh);
    const bool sphere = shapeIntersectsLink(Sphere(0.02), Pose::translation(p), g, id, tol, GeometryMode::Mesh);
    EXPECT_EQ(mesh, sphere) << p.transpose();
    EXPECT_EQ(mesh, g.containsPoint(p)) << p.transpose();
    return mesh;
  };
  for (const bool touching : {true, false}) {
    const Vec3 corner = touching ? Vec3(-0.5, -0.5, -0.5) : Vec3(-0.45, -0.45, -0.45);
    const std::string what = touching ? "sharing a corner" : "apart";
    // Both shells outward: the inner one's inside is inside both solids.
    const LinkGeometry twice(tree_ref::joined(outer, pulledBox(0.2, corner, false), Vec3::Zero()));
    EXPECT_EQ(twice.solidCount(), 2) << what;
    EXPECT_TRUE(collides(twice, centre)) << what;
    EXPECT_TRUE(collides(twice, wall)) << what;
    EXPECT_FALSE(collides(twice, beyond)) << what;
    // The inner shell inward: a thick-walled box. Its cavity is empty, its wall solid; no core in the cavity.
    const LinkGeometry hollow(tree_ref::joined(outer, pulledBox(0.2, corner, true), Vec3::Zero()));
    EXPECT_EQ(hollow.solidCount(), 2) << what;
    EXPECT_FALSE(collides(hollow, centre)) << what;
    EXPECT_TRUE(collides(hollow, wall)) << what;
    EXPECT_FALSE(collides(hollow, beyond)) << what;
    for (const LinkGeometry::Ball& c : hollow.cores()) EXPECT_TRUE(hollow.containsPoint(c.center)) << what;
    // The same box with every triangle turned (inward outer shell, outward inner one): the same solid.
    TriangleMesh inverted = tree_ref::joined(outer, pulledBox(0.2, corner, true), Vec3::Zero());
    for (auto& t : inverted.triangles) std::swap(t[1], t[2]);
    const LinkGeometry turned(inverted);
    EXPECT_FALSE(collides(turned, centre)) << what;
    EXPECT_TRUE(collides(turned, wall)) << what;
    EXPECT_FALSE(collides(turned, beyond)) << what;
  }
  // An inward shell that is no cavity: it crosses the outer surface (a part exported with its winding
  // turned). Where the two overlap, both call the point inside: never free by accident.
  TriangleMesh crossing = test::boxSurface(Vec3(0.2, 0.2, 0.2));
  for (auto& t : crossing.triangles) std::swap(t[1], t[2]);
  const LinkGeometry overlapping(tree_ref::joined(outer, crossing, Vec3(0.5, 0.0, 0.0)));
  EXPECT_TRUE(collides(overlapping, Vec3(0.4, 0.0, 0.0)));
  EXPECT_TRUE(collides(overlapping, Vec3(0.6, 0.0, 0.0)));
  EXPECT_TRUE(collides(overlapping, Vec3(0.0, 0.0, 0.0)));
  EXPECT_FALSE(collides(overlapping, Vec3(0.8, 0.0, 0.0)));
}

TEST(LinkGeometry, NeverFreeByAccident) {
  const LinkGeometry g(tree_ref::uvSphere(0.1, 6, 8));
  const Tolerances tol;
  Pose bad = Pose::translation(Vec3(10, 0, 0));
  bad.t.x() = NAN;
  EXPECT_TRUE(meshesIntersect(g, Pose::identity(), g, bad, tol, GeometryMode::Mesh));
  EXPECT_TRUE(meshesIntersect(g, Pose::identity(), g, Pose::translation(Vec3(10, 0, 0)), tol, GeometryMode::Mesh, NAN));
  EXPECT_TRUE(meshesIntersect(g, Pose::identity(), g, Pose::translation(Vec3(10, 0, 0)), tol, GeometryMode::Mesh, -1.0));
  EXPECT_TRUE(shapeIntersectsLink(Sphere(0.1), bad, g, Pose::identity(), tol, GeometryMode::Mesh));
  EXPECT_TRUE(isFailure(meshDistance(g, Pose::identity(), g, bad).status));
}

TEST(LinkGeometry, HullCacheCarriesTheSeparatingAxis) {
  const LinkGeometry g(tree_ref::torus(0.12, 0.03, 20, 10));
  const Tolerances tol;
  // A pose where the bounding spheres and the boxes of the hulls overlap but the hulls do not, so that
  // the query ends at the hull test.
  std::mt19937_64 rng(33);
  Pose start;
  for (int draw = 0;; ++draw) {
    ASSERT_LT(draw, 10000);
    start = randomPoseNear(rng, 0.3);
    const bool spheres = (start * g.sphereCenter() - g.sphereCenter()).norm() <= 2 * g.sphereRadius();
    const bool boxes = !detail::OrientedBoxTest(start, 0.0, 1.0).separated<false>(g.bounds(), g.bounds());
    if (spheres && boxes && !meshesIntersect(g, Pose::identity(), g, start, tol, GeometryMode::Hull)) break;
  }
  const Vec3 away = gjkDistance(g.hull(), Pose::identity(), g.hull(), start, tol).normal;
  SimplexCache cache;
  for (int i = 0; i < 20; ++i) {
    const Pose pb = Pose::translation(1e-4 * i * away) * start;  // drifting apart
    EXPECT_FALSE(meshesIntersect(g, Pose::identity(), g, pb, tol, GeometryMode::Mesh, 0.0, &cache));
    EXPECT_TRUE(cache.valid);
  }
}

// ---- Construction -----------------------------------------------------------------------------------------

TEST(LinkGeometry, SubnormalPrimitivesDoNotBreakTheHull) {
  // A sphere of radius 1e-310 (as a URDF once gave; the loader now refuses it) made the hull builder
  // read the first of no kept vertices. Whatever the hull is, it must be built and hold the shape.
  for (const double r : {1e-310, 1e-320, 1e-300}) {
    for (const Shape& shape : {Shape(Sphere(r)), Shape(Cylinder(r, r)), Shape(Capsule(r, r)), Shape(Box(Vec3::Constant(r)))}) {
      std::vector<CollisionElement> elements(1);
      elements[0].primitive = shape;
      const LinkGeometry g(elements, {});
      EXPECT_GE(g.hull().support(Vec3::UnitX()).x(), 0.0) << r;
      EXPECT_LE(g.hull().support(-Vec3::UnitX()).x(), 0.0) << r;
    }
  }
}

TEST(LinkGeometry, BuildsFromCollisionElements) {
  const std::vector<TriangleMesh> meshes{tree_ref::uvSphere(0.1, 6, 8), tree_ref::gridBox(Vec3(0.1, 0.2, 0.3), 1)};
  std::vector<CollisionElement> elements(3);
  elements[0].mesh = 1;
  elements[0].origin = Pose::fromQuaternion(0.3, 0.1, 0.2, 0.9, Vec3(0.5, 0, 0));
  elements[1].primitive = Shape(Cylinder(0.05, 0.2));
  elements[1].origin = Pose::fromQuaternion(0, 0.7, 0, 0.7, Vec3(0, 0.5, 0));
  elements[2].primitive = Shape(Sphere(0.07));
  elements[2].origin = Pose::translation(Vec3(0, 0, -0.4));
  const LinkGeometry g(elements, meshes);
  ASSERT_EQ(g.triangles().size(), meshes[1].triangles.size());
  ASSERT_EQ(g.primitives().size(), 2u);
  const auto& t0 = meshes[1].triangles[0];
  EXPECT_LT((g.triangles()[0].v[1] - elements[0].origin * meshes[1].vertices[t0[1]]).norm(), 1e-15);
  EXPECT_EQ(g.tree().itemCount(), static_cast<int>(meshes[1].triangles.size()));
  // The hull contains every element: along any direction its support reaches at least as far.
  std::mt19937_64 rng(30);
  std::normal_distribution<double> n;
  for (int k = 0; k < 500; ++k) {
    const Vec3 d = Vec3(n(rng), n(rng), n(rng)).normalized();
    const double reach = d.dot(g.hull().support(d));
    for (const Triangle& t : g.triangles())
      for (const Vec3& v : t.v) ASSERT_GE(reach, d.dot(v) - 1e-12);
    for (const auto& p : g.primitives()) {
      const double prim = std::visit(
          [&](const auto& s) { return d.dot(p.pose * s.support(p.pose.R.transpose() * d)) + s.radius(); }, p.shape);
      ASSERT_GE(reach, prim - 1e-12) << "primitive " << shapeTypeName(p.shape);
    }
  }
  EXPECT_TRUE(g.bounds().contains(elements[2].origin.t + Vec3(0, 0, -0.07)));

  EXPECT_THROW(LinkGeometry(std::vector<CollisionElement>{}, meshes), ShapeError);
  std::vector<CollisionElement> bad(1);
  bad[0].mesh = 5;
  EXPECT_THROW(LinkGeometry(bad, meshes), ShapeError);
  TriangleMesh broken = meshes[0];
  broken.triangles[3][1] = 9999;
  EXPECT_THROW(LinkGeometry{broken}, ShapeError);
  EXPECT_THROW(LinkGeometry{TriangleMesh{}}, ShapeError);
}

// ---- Primitives against links ------------------------------------------------------------------------------

// A sphere (solid) against a mesh (surface): collide iff some triangle is within the radius.
TEST(LinkGeometry, SpheresAndCapsulesAgainstMeshesMatchBruteForce) {
  const std::vector<TestMesh> meshes = generatedMeshes();
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> radius(0.005, 0.08), half(0.0, 0.1);
  const Tolerances tol;
  int collide = 0, free = 0;
  for (const TestMesh& m : meshes) {
    const LinkGeometry g(m.mesh);
    for (int c = 0; c < 40; ++c) {
      const Pose pl = randomPoseNear(rng, 0.5);
      Pose ps = randomPoseNear(rng, tree_ref::meshRadius(m.mesh) + 0.05);
      ps.t += pl.t;
      const double r = radius(rng), h = c % 2 ? half(rng) : 0.0;
      const Shape shape = h > 0.0 ? Shape(Capsule(r, h)) : Shape(Sphere(r));
      // The core segment as a degenerate triangle, in the world frame.
      const Vec3 p0 = ps * Vec3(0, 0, -h), p1 = ps * Vec3(0, 0, h);
      const tree_ref::WorldMesh w = tree_ref::place(m.mesh, pl);
      double d = tree_ref::kInf;
      const tree_ref::Box core{{std::min(p0.x(), p1.x()), std::min(p0.y(), p1.y()), std::min(p0.z(), p1.z())},
                               {std::max(p0.x(), p1.x()), std::max(p0.y(), p1.y()), std::max(p0.z(), p1.z())}};
      for (std::size_t k = 0; k < w.tris.size(); ++k) {
        const auto& t = w.tris[k];
        if (tree_ref::boxGap(core, w.boxes[k]) > std::min(d, r + kBand)) continue;  // cannot change the verdict
        const auto pr = tree_ref::comparePair(tree_ref::Tri{{p0, p1, p1}}, t);
        d = std::min(d, pr.margin >= 0.0 ? 0.0 : pr.dist);
      }
      // A closed mesh is a solid: a core wholly inside it collides.
      if (d > r + kBand && std::abs(tree_ref::windingNumber(p0, w)) > 0.75) d = 0.0;
      const bool got = shapeIntersectsLink(shape, ps, g, pl, tol, GeometryMode::Mesh);
      const bool hull = shapeIntersectsLink(shape, ps, g, pl, tol, GeometryMode::Hull);
      EXPECT_TRUE(hull || !got);
      if (d < r - kBand) {
        ++collide;
        EXPECT_TRUE(got) << m.name << " case " << c << " d " << d << " r " << r;
      } else if (d > r + kBand) {
        ++free;
        EXPECT_FALSE(got) << m.name << " case " << c << " d " << d << " r " << r;
      }
      // The sphere as a link's primitive gives the same answer through meshesIntersect.
      CollisionElement e;
      e.primitive = shape;
      const LinkGeometry prim({e}, {});
      EXPECT_EQ(meshesIntersect(prim, ps, g, pl, tol, GeometryMode::Mesh), got);
      EXPECT_EQ(meshesIntersect(g, pl, prim, ps, tol, GeometryMode::Mesh), got);
    }
  }
  EXPECT_GT(collide, 25);
  EXPECT_GT(free, 25);
}

// Boxes, cylinders and cones against meshes: shapeIntersectsLink first compares the shape's own box with
// the link's (oriented, 15 axes), so it must give the answer of the same primitive as a link, whose path
// compares it with each triangle and never with that box. Poses are drawn so that a third of the cases
// fall between the boxes' overlap and the shapes' contact, where only the later rungs decide.
TEST(LinkGeometry, OrientedBoxRungKeepsEveryVerdict) {
  const std::vector<TestMesh> meshes = generatedMeshes();
  std::mt19937_64 rng(37);
  std::uniform_real_distribution<double> size(0.005, 0.12), unit(0.0, 1.0);
  const Tolerances tol;
  int collide = 0, free = 0, boxes_overlap_but_free = 0;
  for (const TestMesh& m : meshes) {
    const LinkGeometry g(m.mesh);
    for (int c = 0; c < 400; ++c) {
      const double a = size(rng), b = size(rng), padding = c % 3 == 0 ? 0.02 * unit(rng) : 0.0;
      const Shape shape = c % 3 == 0 ? Shape(Box(Vec3(a, b, size(rng)))) : c % 3 == 1 ? Shape(Cylinder(a, b)) : Shape(Cone(a, b));
      // Centred near a vertex, at 0.4 to 1.4 times the shape's reach: mostly near contact.
      const Pose pl = randomPoseNear(rng, 0.5);
      const Vec3& v = m.mesh.vertices[static_cast<std::size_t>(unit(rng) * m.mesh.vertices.size()) % m.mesh.vertices.size()];
      Pose ps = randomPoseNear(rng, 0.0);
      ps.t = pl * v + tree_ref::randomInBall(rng, 1.0).normalized() * (0.4 + unit(rng)) * boundingRadius(shape);
      const bool got = shapeIntersectsLink(shape, ps, g, pl, tol, GeometryMode::Mesh, padding);
      CollisionElement e;
      e.primitive = shape;
      const LinkGeometry prim({e}, {});
      EXPECT_EQ(meshesIntersect(prim, ps, g, pl, tol, GeometryMode::Mesh, padding), got) << m.name << " case " << c;
      EXPECT_TRUE(shapeIntersectsLink(shape, ps, g, pl, tol, GeometryMode::Hull, padding) || !got);
      ++(got ? collide : free);
      const Pose shape_in_link = relativePose(pl, ps);
      std::visit(
          [&](const auto& s) {
            const Aabb box = placedBox(s, shape_in_link);  // the shape's world box, in the link's frame
            boxes_overlap_but_free += !got && overlaps(box.inflated(padding), g.bounds());
          },
          shape);
    }
  }
  EXPECT_GT(collide, 500);
  EXPECT_GT(free, 300);
  EXPECT_GT(boxes_overlap_but_free, 100);  // (a margin shrunk by 0.1 mm fails this test)
}

TEST(LinkGeometry, PrimitivesAgainstPrimitives) {
  std::vector<CollisionElement> ea(1), eb(1);
  ea[0].primitive = Shape(Box(Vec3(0.1, 0.1, 0.1)));
  eb[0].primitive = Shape(Sphere(0.05));
  eb[0].origin = Pose::translation(Vec3(0, 0, 0.2));
  const LinkGeometry a(ea, {}), b(eb, {});
  const Tolerances tol;
  // The sphere's centre is 0.2 above b's origin: touching the box's top face when b is at z = -0.05.
  EXPECT_TRUE(meshesIntersect(a, Pose::identity(), b, Pose::translation(Vec3(0, 0, -0.05)), tol, GeometryMode::Mesh));
  EXPECT_FALSE(meshesIntersect(a, Pose::identity(), b, Pose::translation(Vec3(0, 0, -0.049)), tol, GeometryMode::Mesh));
  EXPECT_TRUE(meshesIntersect(a, Pose::identity(), b, Pose::translation(Vec3(0, 0, -0.049)), tol, GeometryMode::Mesh, 0.0011));
  const DistanceResult d = meshDistance(a, Pose::identity(), b, Pose::translation(Vec3(0, 0, -0.04)));
  EXPECT_NEAR(d.distance, 0.01, 1e-9);
  EXPECT_LE(d.lower_bound, d.distance);
  EXPECT_NEAR(d.point_a.z(), 0.1, 1e-9);
  EXPECT_NEAR(d.point_b.z(), 0.11, 1e-9);
  EXPECT_NEAR(d.normal.z(), 1.0, 1e-9);
}

// ---- Distance ------------------------------------------------------------------------------------------------

TEST(LinkGeometry, DistanceMatchesBruteForce) {
  const std::vector<TestMesh> generated = generatedMeshes();
  std::vector<TestMesh> meshes{generated[0], generated[1], generated[4]};  // sphere, torus, dumbbell
  // The Panda's meshes join when present (and must be there when CI=true).
  if (std::filesystem::is_directory(pandaMeshDir()) || test::sharedDataRequired()) {
    const std::vector<TestMesh> panda = pandaMeshes();
    meshes.push_back(panda[3]);
    meshes.push_back(panda[8]);
  }
  std::mt19937_64 rng(32);
  const Tolerances tol;
  int zero = 0, positive = 0;
  // Without the shared Panda meshes there are 6 pairs instead of 15: more placements per pair keep the
  // counts below as meaningful.
  const int cases = meshes.size() < 5 ? 8 : 3;
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    const LinkGeometry ga(meshes[i].mesh);
    for (std::size_t j = i; j < meshes.size(); ++j) {
      const LinkGeometry gb(meshes[j].mesh);
      const double reach = 1.3 * (tree_ref::meshRadius(meshes[i].mesh) + tree_ref::meshRadius(meshes[j].mesh));
      // Warm starts carried from placement to placement, as a motion check carries them along a segment.
      std::vector<SimplexCache> warm_starts(ga.parts().size() * gb.parts().size());
      for (int c = 0; c < cases; ++c) {
        const Pose pa = randomPoseNear(rng, 0.2);
        Pose pb = randomPoseNear(rng, reach);
        pb.t += pa.t;
        const double ref = tree_ref::meshDistance(tree_ref::place(meshes[i].mesh, pa), tree_ref::place(meshes[j].mesh, pb));
        const DistanceResult d = meshDistance(ga, pa, gb, pb, tol);
        const std::string what = meshes[i].name + " vs " + meshes[j].name + " case " + std::to_string(c);
        ASSERT_FALSE(isFailure(d.status)) << what;
        EXPECT_LE(d.lower_bound, d.distance) << what;
        // The convex parts contain the meshes and lie inside the hulls: their bound sits between.
        ASSERT_GE(ga.parts().size(), 1u);
        ASSERT_LE(ga.parts().size(), static_cast<std::size_t>(LinkGeometry::kMaxParts));
        const double parts = partsLowerBound(ga, pa, gb, pb, tol, INFINITY, 0.25);
        EXPECT_LE(parts, ref + kBand) << what;
        EXPECT_GE(parts, 0.75 * gjkDistance(ga.hull(), pa, gb.hull(), pb, tol).lower_bound - kBand) << what;
        EXPECT_LE(partsLowerBound(ga, pa, gb, pb, tol, 0.5 * parts, 0.25), parts + kBand) << what;
        // Warm-started, the bound is as certified and as tight (each is within 25% of the parts' distance).
        const double warm = partsLowerBound(ga, pa, gb, pb, tol, INFINITY, 0.25, warm_starts.data());
        EXPECT_LE(warm, ref + kBand) << what;
        EXPECT_GE(warm, 0.75 * parts - kBand) << what;
        EXPECT_GE(parts, 0.75 * warm - kBand) << what;
        // Stopped at `enough` with warm starts, and never above the distance for a `enough` that is no number.
        EXPECT_LE(partsLowerBound(ga, pa, gb, pb, tol, 0.5 * parts, 0.25, warm_starts.data()), parts + kBand) << what;
        EXPECT_EQ(partsLowerBound(ga, pa, gb, pb, tol, std::nan(""), 0.25, warm_starts.data()), 0.0) << what;
        if (ref == 0.0) {
          ++zero;
          EXPECT_EQ(d.distance, 0.0) << what;
          continue;
        }
        ++positive;
        EXPECT_NEAR(d.distance, ref, 2e-6 * ref + kBand) << what;
        EXPECT_LE(d.lower_bound, ref + kBand) << what;
        EXPECT_GE(d.lower_bound, ref * (1 - 2e-6) - kBand) << what;
        // The witnesses are on the meshes, d apart.
        EXPECT_NEAR((d.point_b - d.point_a).norm(), d.distance, 1e-9) << what;
        EXPECT_NEAR(d.normal.dot(d.point_b - d.point_a), d.distance, 1e-9) << what;
        // Consistent with the boolean queries.
        EXPECT_FALSE(meshesIntersect(ga, pa, gb, pb, tol, GeometryMode::Mesh, 0.99 * ref)) << what;
        EXPECT_TRUE(meshesIntersect(ga, pa, gb, pb, tol, GeometryMode::Mesh, 1.01 * ref)) << what;
      }
    }
  }
  EXPECT_GT(zero, 5);
  EXPECT_GT(positive, 20);
}

// A fine mesh within millimetres of a coarse one (large triangles askew, whose boxes hold many of the fine
// mesh's), where the search prunes by triangles' planes as well as boxes: with a relative error and a
// cutoff, never above the brute-force distance for its bound, never more than the relative error above it
// for its distance, in both orders (each side's leaves bound the other's boxes).
TEST(LinkGeometry, DistanceNearFineMeshesMatchesBruteForce) {
  const TriangleMesh fine = tree_ref::uvSphere(0.05, 40, 80);                      // 6,320 triangles
  const TriangleMesh plate = tree_ref::gridBox(Vec3(0.2, 0.12, 0.03), 1);          // 12 large ones
  const TriangleMesh ring = tree_ref::torus(0.09, 0.025, 24, 12);
  const std::vector<std::pair<std::string, TriangleMesh>> meshes{{"plate", plate}, {"fine", fine}, {"ring", ring}};
  std::mt19937_64 rng(41);
  const Tolerances tol;
  constexpr double kRelative = 0.1, kCutoff = 0.003;
  int near = 0, cases = 0;
  for (const auto& [i, j] : std::vector<std::pair<int, int>>{{0, 1}, {1, 0}, {2, 1}, {1, 2}}) {
    const LinkGeometry ga(meshes[i].second), gb(meshes[j].second);
    const double reach = 1.2 * (tree_ref::meshRadius(meshes[i].second) + tree_ref::meshRadius(meshes[j].second));
    for (int c = 0; c < 14; ++c) {
      const Pose pa = randomPoseNear(rng, 0.2);
      Pose pb = randomPoseNear(rng, reach);
      pb.t += pa.t;
      // Moved along the normal of closest approach to 0 … 2.5 mm (the reference judges where it lands).
      const DistanceResult first = meshDistance(ga, pa, gb, pb, tol, 0.2);
      if (!(first.distance > 0.0)) continue;
      pb.t -= (first.distance - std::uniform_real_distribution<double>(0.0, 0.0025)(rng)) * first.normal;
      const double ref = tree_ref::meshDistance(tree_ref::place(meshes[i].second, pa), tree_ref::place(meshes[j].second, pb));
      const DistanceResult d = meshDistance(ga, pa, gb, pb, tol, kRelative, kCutoff);
      const std::string what = meshes[i].first + " vs " + meshes[j].first + " case " + std::to_string(c) +
                               ": reference " + std::to_string(ref);
      ++cases;
      ASSERT_FALSE(isFailure(d.status)) << what;
      EXPECT_LE(d.lower_bound, ref + kBand) << what;
      if (ref < kCutoff) {
        ++near;
        EXPECT_GE(d.distance, ref - kBand) << what;
        EXPECT_LE(d.distance, (1.0 + kRelative) * ref + kBand) << what;
      } else {
        EXPECT_GE(d.distance, kCutoff - kBand) << what;
      }
    }
  }
  EXPECT_GE(cases, 40);
  EXPECT_GE(near, 30) << cases;
}

}  // namespace
}  // namespace clearway
