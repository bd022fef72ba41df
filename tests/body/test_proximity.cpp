// BodyPair (body/proximity.h): the ladder's bound never exceeds the brute-force distance of
// tests/tree/mesh_reference.h, `within` decides as the reference does, Hull mode is never tighter than
// Mesh mode, forgetting the warm starts gives a fresh pair's answers bit for bit, a distance with a cutoff
// is meshDistance's, a link against a convex shape answers as the shape queries, a cast never passes the
// first contact, and bad input is never "far"; partsApart holds each part to its own need.
#include <clearway/body/proximity.h>
#include <clearway/tree/aabb_tree.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "body/panda_meshes.h"
#include "tree/mesh_reference.h"

namespace clearway {
namespace {

constexpr double kBand = 1e-9;

Pose randomPose(std::mt19937_64& rng, double reach) {
  Pose p;
  p.R = tree_ref::randomRotation(rng);
  p.t = tree_ref::randomInBall(rng, reach);
  return p;
}

struct Named {
  std::string name;
  TriangleMesh mesh;
};

std::vector<Named> meshes() {
  return {{"sphere", tree_ref::uvSphere(0.1, 10, 16)},
          {"torus", tree_ref::torus(0.12, 0.03, 20, 10)},
          {"plate", tree_ref::gridBox(Vec3(0.15, 0.1, 0.002), 4)},
          {"dumbbell", tree_ref::joined(tree_ref::uvSphere(0.04, 6, 10), tree_ref::gridBox(Vec3(0.03, 0.03, 0.03), 2),
                                        Vec3(0.2, 0.05, 0.0))}};
}

// A measurement `within` a contact distance (1 cm), as the motion checker asks it.
BoundQuery nearQuery() {
  BoundQuery near;
  near.relative = 0.1;
  near.within = 0.01;
  near.climb = 0.01;
  return near;
}

// `within` a contact distance: the bound is 0 exactly when the reference distance is that near (outside the
// band), and beyond it, compared with ≤, otherwise; counts which it was.
void expectWithin(BodyPair& pair, const Pose& pa, const Pose& pb, const Tolerances& tol, double ref,
                  const std::string& what, int& hits, int& clear) {
  const BoundQuery near = nearQuery();
  const double w = pair.lowerBound(pa, pb, tol, near);
  if (ref < near.within - kBand) {
    EXPECT_EQ(w, 0.0) << what;
    ++hits;
  } else if (ref > near.within + kBand) {
    EXPECT_GT(w, near.within) << what << ": beyond `within` must compare beyond it";
    EXPECT_LE(w, ref + kBand) << what;
    ++clear;
  }
}

TEST(BodyPair, LadderBoundsTheBruteForceDistance) {
  const std::vector<Named> m = meshes();
  std::vector<LinkGeometry> g;
  for (const Named& n : m) g.emplace_back(n.mesh);
  const Tolerances tol;
  std::mt19937_64 rng(7);
  int exact = 0, within_hits = 0, within_clear = 0, cut_short = 0, cases = 0;
  for (std::size_t i = 0; i < m.size(); ++i) {
    for (std::size_t j = i; j < m.size(); ++j) {
      BodyPair pair(g[i], g[j]);  // warm starts carried from case to case, as along a segment
      const double reach = 1.2 * (tree_ref::meshRadius(m[i].mesh) + tree_ref::meshRadius(m[j].mesh));
      for (int c = 0; c < 12; ++c, ++cases) {
        const Pose pa = randomPose(rng, 0.1);
        Pose pb = randomPose(rng, reach);
        pb.t += pa.t;
        const std::string what = m[i].name + " vs " + m[j].name + " case " + std::to_string(c);
        const double ref = tree_ref::meshDistance(tree_ref::place(m[i].mesh, pa), tree_ref::place(m[j].mesh, pb));
        BoundQuery q;
        q.relative = 0.1;
        const double full = pair.lowerBound(pa, pb, tol, q);  // climbs to the triangles unless a rung reaches ∞
        EXPECT_LE(full, ref + kBand) << what;
        EXPECT_GE(full, ref / 1.1 - kBand) << what;
        if (pair.lastRung() == Rung::Exact) ++exact;
        // Asked only as far as `enough`: still a bound, and at least min(enough, the distance / 1.1).
        q.enough = 0.5 * ref;
        const double part = pair.lowerBound(pa, pb, tol, q);
        EXPECT_LE(part, ref + kBand) << what;
        EXPECT_GE(part, std::min(q.enough, ref / 1.1) - kBand) << what;
        // Hull mode stops at the hulls: never tighter than the exact answer.
        BoundQuery hull = q;
        hull.mode = GeometryMode::Hull;
        hull.enough = std::numeric_limits<double>::infinity();
        EXPECT_LE(pair.lowerBound(pa, pb, tol, hull), ref + kBand) << what;
        // `within` a contact distance: 0 exactly when the reference is that near (outside the band).
        expectWithin(pair, pa, pb, tol, ref, what, within_hits, within_clear);
        // The warm starts only speed it up: forgotten, the answers are a fresh pair's, bit for bit.
        pair.forget();
        BodyPair fresh(g[i], g[j]);
        EXPECT_EQ(pair.lowerBound(pa, pb, tol, nearQuery()), fresh.lowerBound(pa, pb, tol, nearQuery())) << what;
        EXPECT_EQ(pair.intersects(pa, pb, tol, {0.01, GeometryMode::Mesh}),
                  meshesIntersect(g[i], pa, g[j], pb, tol, GeometryMode::Mesh, 0.01))
            << what;
        const DistanceResult d = pair.distance(pa, pb, tol, {});
        EXPECT_NEAR(d.distance, ref, 1e-7) << what;
        // A finite cutoff: bodies at least that far apart answer it (the convex rungs, warm, may say so
        // before any triangle), nearer ones meshDistance's distance to the digit.
        DistanceQuery cut;
        cut.cutoff = 0.5 * ref;
        if (ref > kBand) {
          EXPECT_EQ(pair.distance(pa, pb, tol, cut).distance, cut.cutoff) << what;
          if (pair.lastRung() != Rung::Exact) ++cut_short;
        }
        cut.cutoff = 2.0 * ref + 0.01;
        EXPECT_EQ(pair.distance(pa, pb, tol, cut).distance,
                  meshDistance(g[i], pa, g[j], pb, tol, 0.0, cut.cutoff).distance)
            << what;
        // Hull mode: the hulls' distance, one GJK, certified never beyond the exact one; cut off likewise.
        DistanceQuery hulls;
        hulls.mode = GeometryMode::Hull;
        const DistanceResult h = pair.distance(pa, pb, tol, hulls);
        EXPECT_EQ(h.distance, gjkDistance(g[i].hull(), pa, g[j].hull(), pb, tol).distance) << what;
        EXPECT_LE(h.lower_bound, ref + kBand) << what;
        EXPECT_EQ(pair.lastRung(), Rung::Hulls) << what;
        hulls.cutoff = 0.5 * h.distance;
        if (h.distance > kBand) EXPECT_EQ(pair.distance(pa, pb, tol, hulls).distance, hulls.cutoff) << what;
      }
    }
  }
  std::printf("  %d cases: %d reached the triangles, %d within 1 cm, %d beyond, %d cut off before the triangles\n",
              cases, exact, within_hits, within_clear, cut_short);
  EXPECT_GT(exact, cases / 10);
  EXPECT_GT(within_hits, cases / 10);
  EXPECT_GT(within_clear, cases / 10);
  EXPECT_GT(cut_short, cases / 4) << "the convex rungs should answer most distances cut off at half";
}

// The screen and the exact rung together answer as intersects() does, in both modes and with padding; the
// screen settles some pairs each way and leaves some to the triangles (else the split would test nothing).
// The screen's two halves answer as the screen: the cheap rungs settle some pairs each way (the cores prove
// contacts) and leave some to the hulls, whose half settles some each way.
TEST(BodyPair, ScreenThenTrianglesAnswerAsIntersects) {
  const std::vector<Named> m = meshes();
  std::vector<LinkGeometry> g;
  for (const Named& n : m) g.emplace_back(n.mesh);
  const Tolerances tol;
  std::mt19937_64 rng(17);
  int counts[3] = {0, 0, 0}, cheap_counts[3] = {0, 0, 0}, dear_counts[3] = {0, 0, 0};
  for (std::size_t i = 0; i < m.size(); ++i)
    for (std::size_t j = i; j < m.size(); ++j) {
      BodyPair split(g[i], g[j]), whole(g[i], g[j]), halves(g[i], g[j]);
      const double reach = 0.9 * (tree_ref::meshRadius(m[i].mesh) + tree_ref::meshRadius(m[j].mesh));
      for (int c = 0; c < 60; ++c) {
        const Pose pa = randomPose(rng, 0.1);
        Pose pb = randomPose(rng, reach);
        pb.t += pa.t;
        for (GeometryMode mode : {GeometryMode::Mesh, GeometryMode::Hull}) {
          const IntersectQuery q{c % 4 == 0 ? 0.01 : 0.0, mode};
          const Screen s = split.screen(pa, pb, tol, q);
          if (mode == GeometryMode::Mesh) ++counts[static_cast<int>(s)];
          const Screen cheap = halves.screenCheap(pa, pb, tol, q);
          const Screen dear = cheap == Screen::Unsure ? halves.screenDear(pa, pb, tol, q) : cheap;
          EXPECT_EQ(dear, s) << m[i].name << " vs " << m[j].name << " case " << c;
          if (mode == GeometryMode::Mesh) {
            ++cheap_counts[static_cast<int>(cheap)];
            if (cheap == Screen::Unsure) ++dear_counts[static_cast<int>(dear)];
          }
          if (mode == GeometryMode::Hull) EXPECT_NE(s, Screen::Unsure);
          const bool answer = s == Screen::Unsure ? split.intersectsExactly(pa, pb, tol, q.padding) : s == Screen::Touching;
          EXPECT_EQ(answer, whole.intersects(pa, pb, tol, q)) << m[i].name << " vs " << m[j].name << " case " << c;
        }
      }
    }
  std::printf("  Mesh mode: %d apart, %d touching, %d left to the triangles by the screen\n", counts[0], counts[1], counts[2]);
  std::printf("  its cheap half: %d apart, %d touching, %d left to the hulls; the hulls' half: %d apart, %d touching\n",
              cheap_counts[0], cheap_counts[1], cheap_counts[2], dear_counts[0], dear_counts[1]);
  EXPECT_GT(counts[0], 0);
  EXPECT_GT(counts[1], 0);
  EXPECT_GT(counts[2], 0);
  for (int k = 0; k < 3; ++k) EXPECT_GT(cheap_counts[k], 0) << "the cheap half, verdict " << k;
  EXPECT_GT(dear_counts[0], 0);
}

// A fine mesh (past 4096 triangles) whose hull and cores leave a pair unsettled is screened by its convex
// parts before the triangle search: a ball in a ring's hole is apart without a triangle visited, a bead
// inside the ring's tube is not (the solids meet), and the screen never calls apart what the brute-force
// distance does not.
TEST(BodyPair, FineMeshesAreScreenedByTheirParts) {
  const TriangleMesh ring = tree_ref::torus(0.12, 0.03, 100, 50), ball_mesh = tree_ref::uvSphere(0.02, 6, 10);
  const LinkGeometry a(ring), ball(ball_mesh), bead(tree_ref::uvSphere(0.01, 6, 10));
  ASSERT_GT(a.triangles().size(), 4096u);
  ASSERT_GT(a.parts().size(), 1u);
  const Tolerances tol;
  EXPECT_EQ(screenMeshes(a, Pose(), ball, Pose(), tol, GeometryMode::Mesh, 0.0), Screen::Apart);
  EXPECT_EQ(screenMeshes(a, Pose(), ball, Pose(), tol, GeometryMode::Hull, 0.0), Screen::Touching);
  const Pose in_tube = Pose::translation(Vec3(0.12, 0.0, 0.0));
  EXPECT_NE(screenMeshes(a, Pose(), bead, in_tube, tol, GeometryMode::Mesh, 0.0), Screen::Apart);
  EXPECT_TRUE(meshesIntersect(a, Pose(), bead, in_tube, tol, GeometryMode::Mesh, 0.0));
  std::mt19937_64 rng(23);
  int apart = 0;
  for (int c = 0; c < 60; ++c) {
    const Pose pb = randomPose(rng, 0.17);
    const double padding = c % 4 == 0 ? 0.01 : 0.0;
    if (screenMeshes(a, Pose(), ball, pb, tol, GeometryMode::Mesh, padding) != Screen::Apart) continue;
    ++apart;
    EXPECT_GT(tree_ref::meshDistance(tree_ref::place(ring, Pose()), tree_ref::place(ball_mesh, pb)), padding - kBand)
        << "case " << c;
    const Vec3 o = pb.t;  // (the ball's centre: apart, it lies outside the tube)
    EXPECT_GT(std::hypot(std::hypot(o.x(), o.y()) - 0.12, o.z()), 0.03) << "case " << c;
  }
  std::printf("  %d of 60 poses near the ring screened apart\n", apart);
  EXPECT_GT(apart, 0);
}

// The convex side (a link against an obstacle's primitive or a voxel's box) answers as the shape queries it
// climbs to: intersects is shapeIntersectsLink's answer, the screen and the exact rung together the same,
// the bound never exceeds shapeLinkDistance's distance and is tight within the relative error, `within`
// decides as the distance does, the parts' rung is certified, distance is shapeLinkDistance's (A and B
// exchanged), forgetting gives a fresh pair's answers bit for bit, and a shape inside a closed mesh is 0 away.
TEST(BodyPair, ConvexSideAnswersAsTheShapeQueries) {
  const std::vector<Named> m = meshes();
  std::vector<LinkGeometry> g;
  for (const Named& n : m) g.emplace_back(n.mesh);
  const std::vector<std::pair<std::string, Shape>> shapes = {
      {"box", Box(Vec3(0.05, 0.02, 0.08))},
      {"sphere", Sphere(0.03)},
      {"capsule", Capsule(0.02, 0.05)},
      {"cylinder", Cylinder(0.04, 0.03)},
      {"hull", ConvexHull({Vec3(0, 0, 0), Vec3(0.06, 0, 0), Vec3(0, 0.05, 0), Vec3(0, 0, 0.07), Vec3(0.03, 0.03, 0.03)})}};
  const Tolerances tol;
  std::mt19937_64 rng(29);
  int cases = 0, exact = 0, within_hits = 0, within_clear = 0, touching = 0;
  for (std::size_t i = 0; i < m.size(); ++i) {
    for (const auto& [name, shape] : shapes) {
      BodyPair pair(g[i], shape);  // warm starts carried from case to case, as along a segment
      SimplexCache kept;  // a hull warm start the caller keeps
      const double reach = 1.2 * (tree_ref::meshRadius(m[i].mesh) + boundingRadius(shape));
      for (int c = 0; c < 24; ++c, ++cases) {
        const Pose pa = randomPose(rng, 0.1);
        Pose pb = randomPose(rng, reach);
        pb.t += pa.t;
        const std::string what = m[i].name + " vs " + name + " case " + std::to_string(c);
        const DistanceResult truth = shapeLinkDistance(shape, pb, g[i], pa, tol);
        ASSERT_FALSE(isFailure(truth.status)) << what;
        const double ref = truth.distance;
        for (GeometryMode mode : {GeometryMode::Mesh, GeometryMode::Hull}) {
          const IntersectQuery iq{c % 3 == 0 ? 0.01 : 0.0, mode};
          const bool answer = shapeIntersectsLink(shape, pb, g[i], pa, tol, mode, iq.padding);
          EXPECT_EQ(pair.intersects(pa, pb, tol, iq), answer) << what;
          const Screen sc = pair.screen(pa, pb, tol, iq);
          EXPECT_EQ(sc == Screen::Unsure ? pair.intersectsExactly(pa, pb, tol, iq.padding) : sc == Screen::Touching, answer)
              << what;
          if (mode == GeometryMode::Mesh && answer) ++touching;
        }
        BoundQuery q;
        q.relative = 0.1;
        const double full = pair.lowerBound(pa, pb, tol, q);
        EXPECT_LE(full, ref + kBand) << what;
        EXPECT_GE(full, ref / 1.1 - kBand) << what;
        if (pair.lastRung() == Rung::Exact) ++exact;
        kept = SimplexCache{};  // cold both: where the warm start lives changes nothing
        EXPECT_EQ(BodyPair(g[i], shape, &kept).lowerBound(pa, pb, tol, q), BodyPair(g[i], shape).lowerBound(pa, pb, tol, q))
            << what;
        q.enough = 0.5 * ref;
        const double part = pair.lowerBound(pa, pb, tol, q);
        EXPECT_LE(part, ref + kBand) << what;
        EXPECT_GE(part, std::min(q.enough, ref / 1.1) - kBand) << what;
        BoundQuery rungs;
        rungs.climb = INFINITY;
        for (Rung top : {Rung::Hulls, Rung::Parts}) {
          rungs.top = top;
          EXPECT_LE(pair.lowerBound(pa, pb, tol, rungs), ref + kBand) << what;
          EXPECT_LE(pair.lastRung(), top) << what;
        }
        expectWithin(pair, pa, pb, tol, ref, what, within_hits, within_clear);
        pair.forget();
        BodyPair fresh(g[i], shape);
        EXPECT_EQ(pair.lowerBound(pa, pb, tol, nearQuery()), fresh.lowerBound(pa, pb, tol, nearQuery())) << what;
        const DistanceResult d = pair.distance(pa, pb, tol, {});
        EXPECT_EQ(d.distance, ref) << what;
        EXPECT_EQ(d.point_a, truth.point_b) << what << ": A is the link";
        DistanceQuery cut;
        cut.cutoff = 0.5 * ref;
        if (ref > kBand) EXPECT_EQ(pair.distance(pa, pb, tol, cut).distance, cut.cutoff) << what;
        DistanceQuery hulls;
        hulls.mode = GeometryMode::Hull;
        const DistanceResult hull =
            std::visit([&](const auto& s) { return gjkDistance(g[i].hull(), pa, s, pb, tol); }, shape);
        EXPECT_EQ(pair.distance(pa, pb, tol, hulls).distance, hull.distance) << what;
        EXPECT_LE(hull.lower_bound, ref + kBand) << what;
        const double depth = pair.penetration(pa, pb, tol, 0.0);
        EXPECT_GE(depth, 0.0) << what;
      }
    }
  }
  std::printf("  %d cases: %d reached the exact geometry, %d touching, %d within 1 cm, %d beyond\n", cases, exact,
              touching, within_hits, within_clear);
  EXPECT_GT(exact, cases / 10);
  EXPECT_GT(touching, cases / 10);
  EXPECT_GT(within_hits, cases / 10);
  EXPECT_GT(within_clear, cases / 10);
  // A small box inside the closed sphere: the solid holds it, 0 apart on every rung from the parts up.
  const Shape pebble = Box(Vec3(0.01, 0.01, 0.01));
  BodyPair inside(g[0], pebble);
  BoundQuery parts;
  parts.top = Rung::Parts;
  parts.climb = INFINITY;
  EXPECT_EQ(inside.lowerBound(Pose(), Pose(), tol, parts), 0.0);
  EXPECT_EQ(inside.lowerBound(Pose(), Pose(), tol, {}), 0.0);
  EXPECT_TRUE(inside.intersects(Pose(), Pose(), tol, {}));
  Pose bad;
  bad.t.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(inside.lowerBound(Pose(), bad, tol, {}), 0.0);
  EXPECT_TRUE(inside.intersects(bad, Pose(), tol, {}));
}

// Links of one primitive each (a URDF of boxes, spheres, cylinders and capsules) are their primitives: the
// ladder measures them by their own GJK, exact where the hulls (circumscribed polytopes) stop short, and the
// screen decides them. Every answer is the exact one: the screen's verdict is the triangles' rung's, the bound
// never exceeds the distance (meshDistance, the primitives' GJK) and is within the relative error of it (skins
// included: two capsules' cores far apart under thick skins),
// `within` decides as the exact rung does, and Hull mode still answers for the hulls. Seen failing with the
// second primitive left unplaced by its link's pose.
TEST(BodyPair, LinksOfOnePrimitiveAreMeasuredAsThePrimitives) {
  const std::vector<std::pair<std::string, Shape>> shapes = {{"box", Box(Vec3(0.05, 0.02, 0.08))},
                                                             {"sphere", Sphere(0.03)},
                                                             {"capsule", Capsule(0.02, 0.05)},
                                                             {"cylinder", Cylinder(0.04, 0.03)}};
  std::mt19937_64 rng(31);
  std::vector<LinkGeometry> g;
  for (const auto& [name, shape] : shapes) {
    CollisionElement e;
    e.primitive = shape;
    e.origin = randomPose(rng, 0.05);  // (an element off the link's origin, as URDF <origin> places it)
    g.emplace_back(std::vector<CollisionElement>{e}, std::vector<TriangleMesh>{});
    ASSERT_NE(g.back().solePrimitive(), nullptr) << name;
  }
  EXPECT_EQ(LinkGeometry(tree_ref::uvSphere(0.1, 6, 8)).solePrimitive(), nullptr);
  const Tolerances tol;
  int cases = 0, touching = 0, within_hits = 0, within_clear = 0, tighter = 0;
  for (std::size_t i = 0; i < g.size(); ++i)
    for (std::size_t j = 0; j < g.size(); ++j) {
      BodyPair pair(g[i], g[j]);  // warm starts carried from case to case, as along a segment
      for (int c = 0; c < 40; ++c, ++cases) {
        const Pose pa = randomPose(rng, 0.5);
        Pose pb = randomPose(rng, 0.15);
        pb.t += pa.t;
        const std::string what = shapes[i].first + " vs " + shapes[j].first + " case " + std::to_string(c);
        const DistanceResult truth = meshDistance(g[i], pa, g[j], pb, tol, 0.0, INFINITY);
        ASSERT_FALSE(isFailure(truth.status)) << what;
        const double ref = truth.distance;
        const IntersectQuery iq{c % 3 == 0 ? 0.01 : 0.0, GeometryMode::Mesh};
        const bool exact = meshesIntersectExactly(g[i], pa, g[j], pb, tol, iq.padding);
        const Screen s = pair.screen(pa, pb, tol, iq);
        EXPECT_NE(s, Screen::Unsure) << what;
        EXPECT_EQ(s == Screen::Touching, exact) << what;
        touching += exact;
        BoundQuery q;
        q.relative = 0.1;
        const double bound = pair.lowerBound(pa, pb, tol, q);
        EXPECT_EQ(pair.lastRung(), Rung::Exact) << what;  // (nothing is enough: past the balls)
        EXPECT_LE(bound, ref + kBand) << what;
        EXPECT_GE(bound, ref * (1.0 - q.relative) - kBand) << what;
        BoundQuery hulls;
        hulls.mode = GeometryMode::Hull;
        const double hull = pair.lowerBound(pa, pb, tol, hulls);
        EXPECT_LE(hull, ref + kBand) << what;
        BoundQuery exact_q;
        const double full = pair.lowerBound(pa, pb, tol, exact_q);
        if (full > hull + 1e-6) ++tighter;
        expectWithin(pair, pa, pb, tol, ref, what, within_hits, within_clear);
      }
    }
  std::printf("  %d cases: %d touching, %d within 1 cm, %d beyond; tighter than the hulls in %d\n", cases, touching,
              within_hits, within_clear, tighter);
  EXPECT_GT(touching, cases / 10);
  EXPECT_GT(within_hits, cases / 10);
  EXPECT_GT(within_clear, cases / 10);
  EXPECT_GT(tighter, cases / 10);
}

// A cast: the link's hull, grown by a margin, translating against a convex shape or another link held still.
// Where it reports no contact before s, the grown hulls are apart at every sampled s' < s (a certified lower
// bound on the first contact); where it reports a hit within reach, they touch there (within the band);
// bad input is a hit at 0.
TEST(BodyPair, CastBoundsTheFirstContact) {
  const std::vector<Named> m = meshes();
  std::vector<LinkGeometry> g;
  for (const Named& n : m) g.emplace_back(n.mesh);
  const Shape box = Box(Vec3(0.05, 0.1, 0.02));
  const Tolerances tol;
  std::mt19937_64 rng(41);
  int hits = 0, clear = 0;
  for (std::size_t i = 0; i < m.size(); ++i) {
    for (int c = 0; c < 40; ++c) {
      const bool links = c % 2 == 1;
      const BodyPair pair = links ? BodyPair(g[i], g[(i + 1) % g.size()]) : BodyPair(g[i], box);
      const Pose pa = randomPose(rng, 0.1);
      const Pose pb = randomPose(rng, 0.3);
      CastQuery q;
      q.velocity = (pb.t - pa.t) + tree_ref::randomInBall(rng, 0.2);
      q.margin = c % 3 == 0 ? 0.01 : 0.0;
      q.max_s = 1.5;
      const std::string what = m[i].name + (links ? " vs the next mesh" : " vs a box") + " case " + std::to_string(c);
      const CastResult r = pair.cast(pa, pb, tol, q);
      ASSERT_FALSE(isFailure(r.status)) << what;
      const double first = r.hit ? r.t : q.max_s;
      // The hulls grown by the margin, A moved by s·velocity: apart before the first contact.
      const auto gap = [&](double s) {
        const Pose moved = Pose::translation(s * q.velocity) * pa;
        return links ? gjkDistance(g[i].hull(), moved, g[(i + 1) % g.size()].hull(), pb, tol).distance - q.margin
                     : std::visit([&](const auto& b) { return gjkDistance(g[i].hull(), moved, b, pb, tol).distance; }, box) -
                           q.margin;
      };
      if (first > 0.0)  // (s strictly before the first contact)
        for (int k = 0; k < 16; ++k) EXPECT_GT(gap(first * k / 16.0 * (1.0 - 1e-6)), -1e-9) << what << " sample " << k;
      if (r.hit && r.t > 0.0) {
        EXPECT_LT(gap(r.t), 1e-5) << what << ": a hit touches";
        ++hits;
      } else if (!r.hit) {
        ++clear;
      }
    }
  }
  std::printf("  %d casts hit, %d clear\n", hits, clear);
  EXPECT_GT(hits, 20);
  EXPECT_GT(clear, 10);
  Pose bad;
  bad.t.x() = std::numeric_limits<double>::quiet_NaN();
  CastQuery q;
  q.velocity = Vec3(1, 0, 0);
  const BodyPair pair(g[0], box);
  EXPECT_TRUE(pair.cast(bad, Pose::translation(Vec3(5, 0, 0)), tol, q).hit);
  q.margin = -1.0;
  EXPECT_TRUE(pair.cast(Pose(), Pose::translation(Vec3(5, 0, 0)), tol, q).hit);
}

TEST(BodyPair, PenetrationBoundsTheOverlap) {
  // Two unit-ish boxes (closed meshes) overlapping by a known depth along x: their hulls are the boxes.
  const LinkGeometry a(tree_ref::gridBox(Vec3(0.1, 0.1, 0.1), 2)), b(tree_ref::gridBox(Vec3(0.05, 0.05, 0.05), 2));
  const BodyPair pair(a, b);
  const Tolerances tol;
  EXPECT_NEAR(pair.penetration(Pose(), Pose::translation(Vec3(0.13, 0, 0)), tol), 0.02, 1e-9);
  EXPECT_NEAR(pair.penetration(Pose(), Pose::translation(Vec3(0.13, 0, 0)), tol, 0.01), 0.03, 1e-9);
  EXPECT_EQ(pair.penetration(Pose(), Pose::translation(Vec3(0.5, 0, 0)), tol), 0.0);
  EXPECT_NEAR(pair.penetration(Pose(), Pose::translation(Vec3(0.16, 0, 0)), tol, 0.02), 0.01, 1e-9)
      << "padding counts as overlap: 1 cm apart, padded by 2";
  Pose bad;
  bad.t.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(std::isnan(pair.penetration(Pose(), bad, tol)));
  EXPECT_TRUE(std::isnan(pair.penetration(Pose(), Pose(), tol, -1.0)));
}

TEST(BodyPair, FarBodiesStopAtTheBalls) {
  const LinkGeometry a(tree_ref::uvSphere(0.1, 8, 12)), b(tree_ref::gridBox(Vec3(0.15, 0.1, 0.002), 2));
  BodyPair pair(a, b);
  const Tolerances tol;
  BoundQuery q;
  q.enough = 0.5;
  EXPECT_GE(pair.lowerBound(Pose(), Pose::translation(Vec3(2, 0, 0)), tol, q), 0.5);
  EXPECT_EQ(pair.lastRung(), Rung::Balls);
  // A plate 0.098 above the sphere: the balls overlap, the hulls are apart by more than asked.
  q.enough = 0.04;
  const double d = pair.lowerBound(Pose(), Pose::translation(Vec3(0, 0, 0.2)), tol, q);
  EXPECT_GE(d, 0.04);
  EXPECT_EQ(pair.lastRung(), Rung::Hulls);
}

TEST(BodyPair, NeverFarByAccident) {
  const LinkGeometry a(tree_ref::uvSphere(0.1, 8, 12)), b(tree_ref::gridBox(Vec3(0.1, 0.1, 0.1), 2));
  BodyPair pair(a, b);
  const Tolerances tol;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Pose bad = Pose::translation(Vec3(5, 0, 0));
  bad.t.x() = nan;
  EXPECT_EQ(pair.lowerBound(Pose(), bad, tol, {}), 0.0);
  EXPECT_EQ(pair.lowerBound(bad, Pose(), tol, {}), 0.0);
  EXPECT_TRUE(pair.intersects(Pose(), bad, tol, {}));
  EXPECT_TRUE(pair.intersects(Pose(), Pose::translation(Vec3(5, 0, 0)), tol, {nan, GeometryMode::Mesh}));
  BoundQuery q;
  q.enough = nan;  // a NaN request climbs every rung and still answers a bound
  EXPECT_LE(pair.lowerBound(Pose(), Pose::translation(Vec3(0.5, 0, 0)), tol, q), 0.3 + kBand);
  // A box wholly inside the closed sphere: a solid, so 0 apart.
  const LinkGeometry small(tree_ref::gridBox(Vec3(0.01, 0.01, 0.01), 1));
  BodyPair inside(a, small);
  EXPECT_EQ(inside.lowerBound(Pose(), Pose(), tol, {}), 0.0);
  // A distance with a cutoff: a bad pose or cutoff is a failure, and a body inside a solid is 0 away, not cut off.
  DistanceQuery cut;
  cut.cutoff = 0.05;
  EXPECT_TRUE(pair.distance(Pose(), bad, tol, cut).mayCollide());
  EXPECT_EQ(inside.distance(Pose(), Pose(), tol, cut).distance, 0.0);
  cut.cutoff = nan;
  EXPECT_TRUE(pair.distance(Pose(), Pose::translation(Vec3(5, 0, 0)), tol, cut).mayCollide());
}

// Two meshes that touch: the triangle search (forEachOverlapDeeperFirst, the node pairs that overlap most
// first) meets a pair of triangles that touch after fewer pairs than plain depth first, summed over random
// colliding poses of Panda links and generated meshes (the order changes no answer: the tests above).
TEST(BodyPair, TheTriangleSearchMeetsATouchingPairSooner) {
  std::vector<TriangleMesh> meshes{tree_ref::uvSphere(0.1, 10, 16), tree_ref::torus(0.12, 0.03, 20, 10)};
  if (const std::string missing = test::addSharedPandaMeshes(meshes); !missing.empty()) FAIL() << missing;
  std::vector<LinkGeometry> geoms;
  for (const TriangleMesh& m : meshes) geoms.emplace_back(m);
  std::mt19937_64 rng(43);
  long plain_visits = 0, deeper_visits = 0;
  int touching = 0;
  for (std::size_t i = 0; i < geoms.size(); ++i)
    for (std::size_t j = i; j < geoms.size(); ++j)
      for (int k = 0; k < 60; ++k) {
        Pose pa, pb;
        pa.R = tree_ref::randomRotation(rng);
        pb.R = tree_ref::randomRotation(rng);
        pb.t = tree_ref::randomInBall(rng, 0.6 * (geoms[i].boundingRadius() + geoms[j].boundingRadius()));
        const Pose b_in_a = relativePose(pa, pb);
        const auto visits = [&](auto&& search) {
          long n = 0;
          const bool found = search(geoms[i].tree(), geoms[j].tree(), b_in_a, [&](std::int32_t x, std::int32_t y) {
            ++n;
            return trianglesTouch(geoms[i], pa, geoms[j], pb, TrianglePair{x, y}, Tolerances{}, 0.0);
          });
          return found ? n : -1L;
        };
        const long plain = visits([](auto&&... args) { return forEachOverlap(args...); });
        const long deeper = visits([](auto&&... args) { return forEachOverlapDeeperFirst(args...); });
        ASSERT_EQ(plain < 0, deeper < 0) << "meshes " << i << " and " << j << " case " << k;
        if (plain < 0) continue;
        ++touching;
        plain_visits += plain;
        deeper_visits += deeper;
      }
  ASSERT_GT(touching, 100);
  std::printf("  %d touching poses: %.1f triangle pairs before the first that touches depth first, %.1f deeper first\n",
              touching, double(plain_visits) / touching, double(deeper_visits) / touching);
  EXPECT_LT(deeper_visits, plain_visits);
}

// partsApart: each of b's parts is held to its own need (a far part may move farther than a near one), a
// true answer never claims more than the brute-force distance, a link inside a closed mesh is never apart,
// and bad input is never apart.
TEST(PartsApart, EachPartAgainstItsOwnNeed) {
  const Tolerances tol;
  // A dumbbell: a ball at the origin and a cube 0.2 along x. A plate 0.05 beyond the cube's far face (and
  // ~0.2 from the ball): the cube's parts may move 0.04, the ball's 0.15, but the cube's not 0.06.
  const TriangleMesh dumbbell = tree_ref::joined(tree_ref::uvSphere(0.04, 6, 10),
                                                 tree_ref::gridBox(Vec3(0.03, 0.03, 0.03), 2), Vec3(0.2, 0.0, 0.0));
  const LinkGeometry b(dumbbell), a(tree_ref::gridBox(Vec3(0.002, 0.1, 0.1), 2));
  ASSERT_GE(b.parts().size(), 2u);
  const Pose plate = Pose::translation(Vec3(0.2 + 0.03 + 0.05 + 0.002, 0.0, 0.0));
  const auto needs = [&](double near, double far) {
    std::vector<double> need;
    for (const LinkGeometry::Part& p : b.parts()) need.push_back(p.center.x() > 0.1 ? near : far);
    return need;
  };
  EXPECT_TRUE(partsApart(a, plate, b, Pose(), tol, needs(0.04, 0.15).data()));
  EXPECT_FALSE(partsApart(a, plate, b, Pose(), tol, needs(0.06, 0.15).data()));
  EXPECT_FALSE(partsApart(a, plate, b, Pose(), tol, needs(0.04, 0.3).data()));
  int first = -1;  // the pair too near is remembered, and the next query starts from it
  EXPECT_FALSE(partsApart(a, plate, b, Pose(), tol, needs(0.06, 0.15).data(), &first));
  EXPECT_GE(first, 0);
  EXPECT_TRUE(partsApart(a, plate, b, Pose(), tol, needs(0.04, 0.15).data(), &first));

  // Random poses: apart at x means the meshes are at least x apart.
  const std::vector<Named> m = meshes();
  std::mt19937_64 rng(21);
  int apart = 0, cases = 0;
  for (const Named& na : m) {
    for (const Named& nb : m) {
      const LinkGeometry ga(na.mesh), gb(nb.mesh);
      const double reach = 1.2 * (tree_ref::meshRadius(na.mesh) + tree_ref::meshRadius(nb.mesh));
      for (int c = 0; c < 10; ++c, ++cases) {
        const Pose pa = randomPose(rng, 0.1);
        Pose pb = randomPose(rng, reach);
        pb.t += pa.t;
        const double ref = tree_ref::meshDistance(tree_ref::place(na.mesh, pa), tree_ref::place(nb.mesh, pb));
        const double x = std::uniform_real_distribution<double>(0.0, 0.05)(rng);
        const std::vector<double> need(gb.parts().size(), x);
        if (partsApart(ga, pa, gb, pb, tol, need.data())) {
          ++apart;
          EXPECT_GE(ref, x - kBand) << na.name << " vs " << nb.name << " case " << c;
        }
      }
    }
  }
  std::printf("  %d of %d random cases apart\n", apart, cases);
  EXPECT_GT(apart, cases / 4);

  // Inside a closed mesh: the surfaces are far apart, the solids are not.
  const LinkGeometry ball(tree_ref::uvSphere(0.3, 10, 16)), cube(tree_ref::gridBox(Vec3(0.01, 0.01, 0.01), 1));
  const std::vector<double> zero(cube.parts().size(), 0.0), one(ball.parts().size(), 0.0);
  EXPECT_FALSE(partsApart(ball, Pose(), cube, Pose(), tol, zero.data()));
  EXPECT_FALSE(partsApart(cube, Pose(), ball, Pose(), tol, one.data()));
  // Bad input.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> bad = needs(0.04, 0.15);
  bad.back() = nan;
  EXPECT_FALSE(partsApart(a, plate, b, Pose(), tol, bad.data()));
  bad.back() = -1.0;
  EXPECT_FALSE(partsApart(a, plate, b, Pose(), tol, bad.data()));
  Pose broken = plate;
  broken.t.y() = nan;
  EXPECT_FALSE(partsApart(a, broken, b, Pose(), tol, needs(0.0, 0.0).data()));
}

}  // namespace
}  // namespace clearway
