// Cores (balls inside a link's solids): every core lies inside its solid, away from every triangle, on
// generated meshes, primitives and the links of real robots; overlapping cores are collisions the
// brute-force reference confirms; and they decide a real share of deep contacts (a layer that never
// fires would pass the first two).
#include <clearway/body/proximity.h>
#include <clearway/body/robot_geometry.h>
#include <clearway/load/robot_loader.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "body/panda_meshes.h"
#include "shared_data.h"
#include "tree/mesh_reference.h"

namespace clearway {
namespace {

// Every core: its centre has winding number ±1 in the link's triangles (the reference's own reading), and no triangle comes within its
// radius (brute force over all of them, no tree).
void expectCoresInside(const LinkGeometry& g, const std::string& what) {
  const tree_ref::WorldMesh w = tree_ref::placeTriangles(g.triangles());
  for (const LinkGeometry::Ball& c : g.cores()) {
    ASSERT_GT(c.radius, 0.0) << what;
    bool in_primitive = false;
    for (const LinkGeometry::Primitive& p : g.primitives()) {
      const Vec3 q = p.pose.inverse() * c.center;  // in the primitive's frame
      if (const Box* b = std::get_if<Box>(&p.shape)) in_primitive |= ((b->half - q.cwiseAbs()).array() >= c.radius).all();
      if (const Sphere* s = std::get_if<Sphere>(&p.shape)) in_primitive |= q.norm() + c.radius <= s->r * (1 + 1e-12);
      if (const Capsule* s = std::get_if<Capsule>(&p.shape))
        in_primitive |= Vec3(q.x(), q.y(), q.z() - std::clamp(q.z(), -s->h, s->h)).norm() + c.radius <= s->r * (1 + 1e-12);
      if (const Cylinder* s = std::get_if<Cylinder>(&p.shape))
        in_primitive |= std::hypot(q.x(), q.y()) + c.radius <= s->r * (1 + 1e-12) && std::abs(q.z()) + c.radius <= s->h * (1 + 1e-12);
    }
    if (in_primitive) continue;
    // (Above ¾, as the reference's containment reads it: open pieces beside a closed one add fractions.)
    EXPECT_GT(std::abs(tree_ref::windingNumber(c.center, w)), 0.75) << what << ": a core centre outside its solid";
    double nearest = tree_ref::kInf;
    for (const tree_ref::Tri& t : w.tris) nearest = std::min(nearest, tree_ref::pointTriangle(c.center, t));
    EXPECT_LT(c.radius, nearest) << what << ": a core crosses the surface";
  }
}

TEST(Cores, LieInsideGeneratedMeshes) {
  const std::vector<std::pair<std::string, TriangleMesh>> meshes = tree_ref::closedSamples();
  for (const auto& [name, mesh] : meshes) {
    const LinkGeometry g(mesh);
    EXPECT_FALSE(g.cores().empty()) << name << ": a closed mesh without cores";
    EXPECT_LE(static_cast<int>(g.cores().size()), LinkGeometry::kMaxCores);
    expectCoresInside(g, name);
  }
  // The sphere's largest core is most of it (a climb that found nothing would leave grid-sized balls).
  const LinkGeometry sphere(tree_ref::uvSphere(0.1, 10, 16));
  double largest = 0.0;
  for (const LinkGeometry::Ball& c : sphere.cores()) largest = std::max(largest, c.radius);
  EXPECT_GT(largest, 0.08);
  // An open mesh is a surface: no cores.
  TriangleMesh open = tree_ref::uvSphere(0.1, 10, 16);
  open.triangles.pop_back();
  EXPECT_TRUE(LinkGeometry(open).cores().empty());
}

TEST(Cores, LieInsidePrimitives) {
  std::vector<CollisionElement> elements(4);
  elements[0].primitive = Shape(Box(Vec3(0.3, 0.05, 0.1)));
  elements[0].origin = Pose::fromQuaternion(0.3, 0.1, 0.2, 0.9, Vec3(0.5, 0, 0));
  elements[1].primitive = Shape(Cylinder(0.05, 0.2));
  elements[1].origin = Pose::fromQuaternion(0, 0.7, 0, 0.7, Vec3(0, 0.5, 0));
  elements[2].primitive = Shape(Sphere(0.07));
  elements[2].origin = Pose::translation(Vec3(0, 0, -0.4));
  elements[3].primitive = Shape(Capsule(0.02, 0.3));
  elements[3].origin = Pose::translation(Vec3(1, 0, 0));
  const LinkGeometry g(elements, {});
  EXPECT_GE(g.cores().size(), 4u);
  expectCoresInside(g, "primitives");
}

TEST(Cores, LieInsideTheLinksOfRealRobots) {
  CLEARWAY_REQUIRE_SHARED_ARMS();
  for (const std::string& urdf : test::allArms()) {
    const RobotGeometry geometry(std::make_shared<const RobotModel>(loadRobot(urdf)));
    int with_cores = 0, solid = 0;
    for (int i : geometry.geometricLinks()) {
      const LinkGeometry& g = *geometry.link(i);
      solid += g.solidCount() > 0 || !g.primitives().empty();
      with_cores += !g.cores().empty();
      expectCoresInside(g, urdf + " link " + geometry.model().link(i).name);
    }
    std::printf("  %s: %d of %d solid links have cores\n", urdf.c_str(), with_cores, solid);
    EXPECT_GE(with_cores, solid * 3 / 4) << urdf;
  }
}

// Random poses of two Panda links (and of generated solids) drawn near each other: whenever their cores
// overlap, the reference sees crossing triangles or one body inside the other; and cores decide a fair
// share of the colliding poses.
TEST(Cores, OverlapOnlyWhereTheReferenceCollides) {
  std::vector<TriangleMesh> meshes{tree_ref::uvSphere(0.1, 10, 16), tree_ref::torus(0.12, 0.03, 20, 10),
                                   tree_ref::gridBox(Vec3(0.05, 0.08, 0.1), 2)};
  if (const std::string missing = test::addSharedPandaMeshes(meshes); !missing.empty()) FAIL() << missing;
  std::vector<LinkGeometry> geoms;
  for (const TriangleMesh& m : meshes) geoms.emplace_back(m);
  std::mt19937_64 rng(41);
  int overlaps = 0, collide = 0;
  for (std::size_t i = 0; i < meshes.size(); ++i)
    for (std::size_t j = i; j < meshes.size(); ++j) {
      const double reach = 0.6 * (tree_ref::meshRadius(meshes[i]) + tree_ref::meshRadius(meshes[j]));
      for (int k = 0; k < 40; ++k) {
        Pose pa, pb;
        pa.R = tree_ref::randomRotation(rng);
        pb.R = tree_ref::randomRotation(rng);
        pb.t = tree_ref::randomInBall(rng, reach);
        const tree_ref::WorldMesh wa = tree_ref::place(meshes[i], pa), wb = tree_ref::place(meshes[j], pb);
        tree_ref::Verdict v = tree_ref::classify(wa, wb, 0.0, 1e-9);
        if (v == tree_ref::Verdict::Free) {
          v = tree_ref::containment(wa, wb);
          if (v == tree_ref::Verdict::Free) v = tree_ref::containment(wb, wa);
        }
        const bool cores = coresOverlap(geoms[i], geoms[j], relativePose(pa, pb));
        collide += v == tree_ref::Verdict::Collide;
        overlaps += cores;
        if (cores) EXPECT_EQ(v, tree_ref::Verdict::Collide) << "meshes " << i << " and " << j << " case " << k;
        EXPECT_EQ(meshesIntersect(geoms[i], pa, geoms[j], pb, Tolerances{}, GeometryMode::Mesh) || v != tree_ref::Verdict::Collide, true);
      }
    }
  std::printf("  cores decide %d of %d colliding poses\n", overlaps, collide);
  // (Shallow contacts are settled by the cores that hug the surface, not by the largest.)
  EXPECT_GT(overlaps, collide * 3 / 4);
}

// The groups cover the cores in order, at most eight each, and each group's ball holds its cores.
TEST(Cores, GroupsHoldTheirCores) {
  std::vector<LinkGeometry> geoms;
  for (const auto& [name, mesh] : tree_ref::closedSamples()) geoms.emplace_back(mesh);
  for (const LinkGeometry& g : geoms) {
    int next = 0;
    for (const LinkGeometry::CoreGroup& group : g.coreGroups()) {
      EXPECT_EQ(group.first, next);
      EXPECT_GE(group.count, 1);
      EXPECT_LE(group.count, 8);
      for (int k = group.first; k < group.first + group.count; ++k) {
        const LinkGeometry::Ball& c = g.cores()[k];
        EXPECT_LE((c.center - group.center).norm() + c.radius, group.radius * (1 + 1e-12));
      }
      next = group.first + group.count;
    }
    EXPECT_EQ(next, static_cast<int>(g.cores().size()));
  }
}

// A mesh link dipping a few millimetres into a thin plate (a primitive link, whose inscribed balls lie far
// from the contact): a core of the mesh inside the plate settles the pair before the triangles.
TEST(Cores, ACoreInsideAnotherLinksPrimitiveSettlesThePair) {
  std::vector<CollisionElement> plate_element(1);
  plate_element[0].primitive = Shape(Box(Vec3(0.3, 0.3, 0.01)));
  const LinkGeometry plate(plate_element, {});
  const LinkGeometry ball(tree_ref::uvSphere(0.1, 24, 32));
  const Tolerances tol;
  int settled = 0;
  for (const double depth : {0.003, 0.006, 0.01}) {
    // Above the plate's face, away from its inscribed balls (on its x axis), sunk `depth` into it.
    const Pose above = Pose::translation(Vec3(0.05, 0.2, 0.01 + 0.1 - depth));
    const Screen s = screenMeshes(plate, Pose::identity(), ball, above, tol, GeometryMode::Mesh);
    EXPECT_NE(s, Screen::Apart) << depth;
    EXPECT_FALSE(coresOverlap(plate, ball, above)) << depth;  // (the inscribed balls are not what decides)
    settled += s == Screen::Touching;
    EXPECT_TRUE(meshesIntersect(plate, Pose::identity(), ball, above, tol, GeometryMode::Mesh)) << depth;
  }
  EXPECT_GE(settled, 2);
  // Just clear of the plate, nothing is settled as touching.
  EXPECT_NE(
      screenMeshes(plate, Pose::identity(), ball, Pose::translation(Vec3(0.05, 0.2, 0.111)), tol, GeometryMode::Mesh),
      Screen::Touching);
}

// A core inside a box, sphere or capsule obstacle is a collision; beside one it decides nothing.
TEST(Cores, MeetShapesOnlyWhenInside) {
  const LinkGeometry g(tree_ref::uvSphere(0.1, 10, 16));
  ASSERT_FALSE(g.cores().empty());
  const Vec3 c = g.cores().front().center;
  for (const Shape& s : {Shape(Box(Vec3(0.01, 0.01, 0.01))), Shape(Sphere(0.01)), Shape(Capsule(0.01, 0.05))}) {
    EXPECT_TRUE(coreMeetsShape(s, Pose::translation(c), g)) << shapeTypeName(s);
    EXPECT_FALSE(coreMeetsShape(s, Pose::translation(c + Vec3(0.2, 0, 0)), g)) << shapeTypeName(s);
    EXPECT_TRUE(shapeIntersectsLink(s, Pose::translation(c), g, Pose::identity(), Tolerances{}, GeometryMode::Mesh));
  }
  EXPECT_FALSE(coreMeetsShape(Shape(Cone(0.01, 0.01)), Pose::translation(c), g));  // undecided: false
}

}  // namespace
}  // namespace clearway
