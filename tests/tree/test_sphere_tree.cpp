// The sphere tree: its leaf balls hold every triangle and every primitive (generated meshes, random
// primitives, the links of our robots and the shared ones); "apart" is only ever said where the brute-force
// reference finds the bodies apart; the nesting guard keeps a body inside a closed mesh from being called
// apart; and the rung does fire (a rung that never fires would pass the rest).
#include <clearway/body/link_geometry.h>
#include <clearway/body/robot_geometry.h>
#include <clearway/body/sphere_tree.h>
#include <clearway/load/robot_loader.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <variant>
#include <vector>

#include "shared_data.h"
#include "tree/mesh_reference.h"

namespace clearway {
namespace {

// True when the point lies in some leaf ball (rounding of the test's own norm allowed).
bool inLeaf(const SphereTree& tree, const Vec3& p) {
  for (const SphereTree::Node& n : tree.nodes())
    if (n.isLeaf() && (p - n.center).norm() <= n.radius * (1.0 + 1e-15)) return true;
  return false;
}

// Every triangle lies wholly in one leaf ball, every vertex in the root's; points of every primitive (support
// points in many directions, which with the centre span it) lie in leaf balls.
void expectEnclosed(const LinkGeometry& g, const std::string& what, std::mt19937_64& rng) {
  const SphereTree& tree = g.spheres();
  ASSERT_FALSE(tree.empty()) << what;
  const SphereTree::Node& root = tree.nodes()[0];
  for (const Triangle& t : g.triangles()) {
    bool held = false;
    for (const SphereTree::Node& n : tree.nodes()) {
      if (!n.isLeaf()) continue;
      bool all = true;
      for (const Vec3& v : t.v) all &= (v - n.center).norm() <= n.radius;
      if (all) {
        held = true;
        break;
      }
    }
    ASSERT_TRUE(held) << what << ": a triangle in no leaf ball";
    for (const Vec3& v : t.v) ASSERT_LE((v - root.center).norm(), root.radius) << what;
  }
  std::normal_distribution<double> normal;
  for (const LinkGeometry::Primitive& p : g.primitives()) {
    for (int k = 0; k < 300; ++k) {
      const Vec3 d(normal(rng), normal(rng), normal(rng));
      const double r = std::visit([](const auto& s) { return s.radius(); }, p.shape);
      const Vec3 core = std::visit([&](const auto& s) { return s.support(d); }, p.shape);
      const Vec3 point = p.pose * (core + r * d.normalized());  // a point of the shape's surface
      ASSERT_TRUE(inLeaf(tree, point)) << what << ": a primitive's surface point in no leaf ball";
      const Vec3 inside = p.pose * (0.5 * (core + std::visit([](const auto& s) { return s.center(); }, p.shape)));
      ASSERT_TRUE(inLeaf(tree, inside)) << what << ": a primitive's inner point in no leaf ball";
    }
  }
}

TEST(SphereTree, HoldsGeneratedMeshesAndPrimitives) {
  std::mt19937_64 rng(11);
  for (const TriangleMesh& m : {tree_ref::uvSphere(0.1, 10, 16), tree_ref::torus(0.12, 0.03, 20, 10),
                                tree_ref::gridBox(Vec3(0.15, 0.1, 0.002), 4), tree_ref::gridBox(Vec3(0.05, 0.08, 0.1), 2)}) {
    const LinkGeometry g(m);
    expectEnclosed(g, "generated mesh", rng);
    EXPECT_LE(g.spheres().leafCount(), 1 << SphereTree::kLevels);
  }
  // Random primitives of every kind, in random poses, several to a link.
  std::uniform_real_distribution<double> size(0.005, 0.3);
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<CollisionElement> elements(3);
    for (int k = 0; k < 3; ++k) {
      switch ((trial + k) % 5) {
        case 0: elements[k].primitive = Shape(Box(Vec3(size(rng), size(rng), 0.1 * size(rng)))); break;
        case 1: elements[k].primitive = Shape(Sphere(size(rng))); break;
        case 2: elements[k].primitive = Shape(Capsule(0.2 * size(rng), size(rng))); break;
        case 3: elements[k].primitive = Shape(Cylinder(size(rng), size(rng))); break;
        default: elements[k].primitive = Shape(Cone(size(rng), size(rng))); break;
      }
      elements[k].origin.R = tree_ref::randomRotation(rng);
      elements[k].origin.t = tree_ref::randomInBall(rng, 0.5);
    }
    expectEnclosed(LinkGeometry(elements, {}), "random primitives " + std::to_string(trial), rng);
  }
}

TEST(SphereTree, HoldsTheLinksOfRealRobots) {
  std::vector<std::string> urdfs{std::string(CLEARWAY_SOURCE_DIR) + "/robots/arm6/arm6.urdf",
                                 std::string(CLEARWAY_SOURCE_DIR) + "/robots/twin_arm/twin_arm.urdf"};
  for (const char* rel : {"robots/panda/panda.urdf", "robots/ur5/ur5.urdf"}) {
    CLEARWAY_REQUIRE_SHARED(rel);
    urdfs.push_back(test::sharedPath(rel));
  }
  std::mt19937_64 rng(5);
  for (const std::string& urdf : urdfs) {
    const RobotGeometry geometry(std::make_shared<const RobotModel>(loadRobot(urdf)));
    int leaves = 0;
    for (int i : geometry.geometricLinks()) {
      expectEnclosed(*geometry.link(i), urdf + " link " + geometry.model().link(i).name, rng);
      leaves += geometry.link(i)->spheres().leafCount();
    }
    std::printf("  %s: %d leaf balls over %zu links\n", urdf.c_str(), leaves, geometry.geometricLinks().size());
  }
}

// Random poses of generated solids and Panda links near each other: every pair the trees call apart (with
// the guard) is farther apart than the gap by brute force, and the rung clears a share of the pairs whose
// hulls overlap.
TEST(SphereTree, ApartOnlyWhereTheReferenceIsApart) {
  std::vector<TriangleMesh> meshes{tree_ref::uvSphere(0.1, 10, 16), tree_ref::torus(0.12, 0.03, 20, 10),
                                   tree_ref::gridBox(Vec3(0.05, 0.08, 0.1), 2)};
  if (!test::sharedPath("robots/panda/meshes/collision").empty()) {
    const std::string dir = test::sharedDir() + "/robots/panda/meshes/collision";
    for (const char* name : {"link5", "link7", "hand"}) meshes.push_back(loadMesh(dir + "/" + name + ".stl", Vec3::Ones()));
  } else if (test::sharedDataRequired()) {
    FAIL() << "the shared Panda meshes are missing";
  }
  std::vector<LinkGeometry> geoms;
  for (const TriangleMesh& m : meshes) geoms.emplace_back(m);
  const Tolerances tol;
  std::mt19937_64 rng(3);
  int apart = 0, guarded = 0, hulls_overlap_but_apart = 0, balls_overlap_but_apart = 0;
  for (std::size_t i = 0; i < meshes.size(); ++i)
    for (std::size_t j = i; j < meshes.size(); ++j) {
      const double reach = 0.9 * (tree_ref::meshRadius(meshes[i]) + tree_ref::meshRadius(meshes[j]));
      for (int k = 0; k < 40; ++k) {
        Pose pa, pb;
        pa.R = tree_ref::randomRotation(rng);
        pb.R = tree_ref::randomRotation(rng);
        pb.t = tree_ref::randomInBall(rng, reach);
        const double gap = k % 3 == 0 ? 0.01 : 0.0;
        const Pose b_in_a = pa.inverse() * pb;
        if (!sphereTreesApart(geoms[i].spheres(), geoms[j].spheres(), b_in_a, gap)) continue;
        const tree_ref::WorldMesh wa = tree_ref::place(meshes[i], pa), wb = tree_ref::place(meshes[j], pb);
        ASSERT_EQ(tree_ref::classify(wa, wb, gap, 1e-9), tree_ref::Verdict::Free)
            << "meshes " << i << " and " << j << " case " << k << ": trees apart, surfaces not";
        ++apart;
        if (mayNest(geoms[i], geoms[j], b_in_a, gap) || mayNest(geoms[j], geoms[i], b_in_a.inverse(), gap)) continue;
        ++guarded;
        EXPECT_EQ(tree_ref::containment(wa, wb), tree_ref::Verdict::Free) << i << " " << j << " " << k << ": nested";
        EXPECT_EQ(tree_ref::containment(wb, wa), tree_ref::Verdict::Free) << i << " " << j << " " << k << ": nested";
        SimplexCache cache;
        hulls_overlap_but_apart += gjkIntersect(geoms[i].hull(), pa, geoms[j].hull(), pb, tol, cache).intersecting;
        balls_overlap_but_apart += (pa * geoms[i].sphereCenter() - pb * geoms[j].sphereCenter()).norm() <=
                                   geoms[i].sphereRadius() + geoms[j].sphereRadius() + gap;
      }
    }
  std::printf("  %d poses apart by the trees (%d past the guard): %d with overlapping bounding balls, %d with "
              "overlapping hulls\n", apart, guarded, balls_overlap_but_apart, hulls_overlap_but_apart);
  EXPECT_GT(balls_overlap_but_apart, 20) << "the rung never clears what the bounding balls cannot";

  // Where a body is concave, the rung clears what the hull cannot: a pebble between a dumbbell's two ends.
  const LinkGeometry dumbbell(tree_ref::joined(tree_ref::uvSphere(0.04, 6, 10), tree_ref::gridBox(Vec3(0.03, 0.03, 0.03), 2),
                                               Vec3(0.2, 0.05, 0.0)));
  const LinkGeometry pebble(tree_ref::uvSphere(0.01, 6, 8));
  const Pose between = Pose::translation(Vec3(0.1, 0.025, 0.0));
  SimplexCache cache;
  EXPECT_TRUE(gjkIntersect(dumbbell.hull(), Pose(), pebble.hull(), between, tol, cache).intersecting);
  EXPECT_TRUE(sphereTreesApart(dumbbell.spheres(), pebble.spheres(), between, 0.0));
  EXPECT_FALSE(mayNest(dumbbell, pebble, between, 0.0));
  EXPECT_FALSE(mayNest(pebble, dumbbell, between.inverse(), 0.0));
  EXPECT_FALSE(meshesIntersect(dumbbell, Pose(), pebble, between, tol, GeometryMode::Mesh));
  EXPECT_TRUE(meshesIntersect(dumbbell, Pose(), pebble, between, tol, GeometryMode::Hull));
}

TEST(SphereTree, ApartFromShapesOnlyWhereTheyAre) {
  const LinkGeometry torus(tree_ref::torus(0.12, 0.03, 20, 10));
  const tree_ref::WorldMesh w = tree_ref::place(tree_ref::torus(0.12, 0.03, 20, 10), Pose::identity());
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> size(0.005, 0.1);
  int apart = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    Shape shape = Sphere(1.0);
    switch (trial % 5) {
      case 0: shape = Box(Vec3(size(rng), size(rng), size(rng))); break;
      case 1: shape = Sphere(size(rng)); break;
      case 2: shape = Capsule(size(rng), size(rng)); break;
      case 3: shape = Cylinder(size(rng), size(rng)); break;
      default: shape = Cone(size(rng), size(rng)); break;
    }
    Pose p;
    p.R = tree_ref::randomRotation(rng);
    p.t = tree_ref::randomInBall(rng, 0.25);
    if (!sphereTreeApartFrom(torus.spheres(), shape, p, 0.0)) continue;
    ++apart;
    // Every sampled point of the shape (surface and axis) is off the torus's surface by the reference.
    std::normal_distribution<double> normal;
    for (int k = 0; k < 20; ++k) {
      const Vec3 d(normal(rng), normal(rng), normal(rng));
      const double r = std::visit([](const auto& s) { return s.radius(); }, shape);
      const Vec3 q = p * (std::visit([&](const auto& s) { return s.support(d); }, shape) + r * d.normalized());
      double nearest = tree_ref::kInf;
      for (const tree_ref::Tri& t : w.tris) nearest = std::min(nearest, tree_ref::pointTriangle(q, t));
      ASSERT_GT(nearest, 0.0) << "trial " << trial;
    }
    // The exact test agrees (the shape is not in the tube: the torus is closed and the guard is the caller's).
    if (!shapeMayNest(torus, shape, p, 0.0))
      EXPECT_FALSE(shapeIntersectsLink(shape, p, torus, Pose::identity(), Tolerances{}, GeometryMode::Mesh)) << trial;
  }
  EXPECT_GT(apart, 100);
}

TEST(SphereTree, BodiesInsideClosedMeshesAreNotApart) {
  // A pebble in a closed box's middle: no ball of either meets the other's, but the guard sees it may nest,
  // and the exact test calls it a collision.
  const LinkGeometry box(tree_ref::gridBox(Vec3(0.2, 0.2, 0.2), 2));
  const LinkGeometry pebble(tree_ref::uvSphere(0.02, 6, 8));
  const Pose centre = Pose::identity();
  EXPECT_TRUE(sphereTreesApart(box.spheres(), pebble.spheres(), centre, 0.0));
  EXPECT_TRUE(mayNest(box, pebble, centre, 0.0));
  EXPECT_TRUE(meshesIntersect(box, Pose::identity(), pebble, centre, Tolerances{}, GeometryMode::Mesh));
  EXPECT_TRUE(shapeMayNest(box, Sphere(0.02), centre, 0.0));
  EXPECT_TRUE(shapeIntersectsLink(Sphere(0.02), centre, box, Pose::identity(), Tolerances{}, GeometryMode::Mesh));
  // Beside it: apart, and no nesting.
  const Pose beside = Pose::translation(Vec3(0.5, 0.0, 0.0));
  EXPECT_TRUE(sphereTreesApart(box.spheres(), pebble.spheres(), beside, 0.0));
  EXPECT_FALSE(mayNest(box, pebble, beside, 0.0));
  EXPECT_FALSE(mayNest(pebble, box, beside.inverse(), 0.0));
}

TEST(SphereTree, NotFiniteIsNeverApart) {
  const LinkGeometry a(tree_ref::uvSphere(0.1, 6, 8));
  Pose far = Pose::translation(Vec3(10.0, 0.0, 0.0));
  ASSERT_TRUE(sphereTreesApart(a.spheres(), a.spheres(), far, 0.0));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Pose bad = far;
  bad.t.y() = nan;
  EXPECT_FALSE(sphereTreesApart(a.spheres(), a.spheres(), bad, 0.0));
  EXPECT_FALSE(sphereTreeApartFrom(a.spheres(), Box(Vec3(0.1, 0.1, 0.1)), bad, 0.0));
  EXPECT_FALSE(sphereTreesApart(a.spheres(), a.spheres(), far, nan));
  EXPECT_FALSE(sphereTreesApart(SphereTree(), a.spheres(), far, 0.0));
  EXPECT_TRUE(mayNest(LinkGeometry(tree_ref::gridBox(Vec3(1, 1, 1), 1)), a, bad, 0.0));
  EXPECT_TRUE(std::isnan(pointShapeLowerBound(Box(Vec3(1, 1, 1)), Vec3(nan, 0, 0))) ||
              !(pointShapeLowerBound(Box(Vec3(1, 1, 1)), Vec3(nan, 0, 0)) > 0.0));
}

}  // namespace
}  // namespace clearway
