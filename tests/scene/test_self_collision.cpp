// Self-collision: the filter, an analytic robot built in code, and the Panda and UR5 against brute
// force over triangle pairs on random configurations.
#include <clearway/kinematics/forward_kinematics.h>
#include <clearway/body/proximity.h>
#include <clearway/load/robot_loader.h>
#include <clearway/scene/scene.h>
#include <clearway/scene/self_collision.h>

#include "load/robot_files.h"
#include "scene/scissors.h"
#include "scene_cache.h"
#include "shared_data.h"
#include "tree/mesh_reference.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <thread>

namespace clearway {
namespace {

// 2D reference: do the rectangles [x0, x1] × [−w, w] (base) and the arm's [0.2, 1.0] × [−a, a] turned
// by θ intersect? Separating axis theorem over the 4 edge normals, in plain trigonometry.
bool rectanglesMeet(double theta, double half_arm_width) {
  const double c = std::cos(theta), s = std::sin(theta);
  auto corners = [&](bool arm) {
    std::vector<std::pair<double, double>> p;
    if (!arm) return std::vector<std::pair<double, double>>{{0.5, -0.05}, {1.5, -0.05}, {1.5, 0.05}, {0.5, 0.05}};
    for (auto [x, y] : {std::pair{0.2, -half_arm_width}, {1.0, -half_arm_width}, {1.0, half_arm_width}, {0.2, half_arm_width}})
      p.emplace_back(c * x - s * y, s * x + c * y);
    return p;
  };
  const auto a = corners(false), b = corners(true);
  const std::pair<double, double> axes[4] = {{1, 0}, {0, 1}, {c, s}, {-s, c}};
  for (const auto& [ux, uy] : axes) {
    double amin = 1e9, amax = -1e9, bmin = 1e9, bmax = -1e9;
    for (auto [x, y] : a) amin = std::min(amin, ux * x + uy * y), amax = std::max(amax, ux * x + uy * y);
    for (auto [x, y] : b) bmin = std::min(bmin, ux * x + uy * y), bmax = std::max(bmax, ux * x + uy * y);
    if (amax < bmin || bmax < amin) return false;
  }
  return true;
}

TEST(CollisionFilter, AdjacentSrdfAndGeometryless) {
  const auto model = test::scissors();
  CollisionFilter f(*model);
  EXPECT_FALSE(f.enabled(0, 1));
  EXPECT_EQ(f.reason(0, 1), "Adjacent");
  EXPECT_FALSE(f.enabled(1, 2));
  EXPECT_TRUE(f.enabled(0, 2));
  EXPECT_EQ(f.reason(0, 2), "");
  f.disable(2, 0, "allowed by scene");
  EXPECT_FALSE(f.enabled(0, 2));
  EXPECT_EQ(f.reason(0, 2), "allowed by scene");
  EXPECT_TRUE(f.enabledPairs().empty());
  EXPECT_THROW(f.disable(0, 0, "x"), std::out_of_range);
  EXPECT_THROW(f.disable(0, 7, "x"), std::out_of_range);
}

TEST(CollisionFilter, PandaHonoursSrdf) {
  CLEARWAY_SHARED_ROBOT_OR_SKIP(urdf, "panda/panda.urdf");
  const RobotModel panda = loadRobot(urdf, test::sharedRobot("panda/panda.srdf"));
  const CollisionFilter f(panda);
  ASSERT_FALSE(panda.disabledCollisions().empty());
  for (const DisabledCollision& d : panda.disabledCollisions()) EXPECT_FALSE(f.enabled(d.link_a, d.link_b));
  for (const auto& [a, b] : adjacentLinkPairs(panda)) EXPECT_EQ(f.reason(a, b), "Adjacent");
  // panda_link0 has no joint to panda_link2, and the SRDF does not disable... whatever it says, every
  // enabled pair has geometry on both sides.
  for (const auto& [a, b] : f.enabledPairs()) {
    EXPECT_FALSE(panda.link(a).collisions.empty());
    EXPECT_FALSE(panda.link(b).collisions.empty());
  }
}

TEST(SelfCollision, ScissorsMatchesTheAnalyticAnswer) {
  const auto model = test::scissors();
  auto geometry = std::make_shared<const RobotGeometry>(model);
  const SelfCollision checker(geometry, CollisionFilter(*model));
  ASSERT_EQ(checker.pairs().size(), 1u);
  SelfCollisionContext ctx = checker.makeContext();
  std::vector<Pose> poses(3);
  int collide = 0, free = 0;
  for (int i = 0; i <= 3600; ++i) {
    const double theta = -M_PI + 2 * M_PI * i / 3600.0;
    // Stay away from the exact touching angle, where rounding may decide.
    bool near_boundary = false;
    for (double d : {-1e-7, 1e-7}) near_boundary |= rectanglesMeet(theta + d, 0.05) != rectanglesMeet(theta, 0.05);
    if (near_boundary) continue;
    computeLinkPoses(*model, &theta, poses.data());
    const bool expected = rectanglesMeet(theta, 0.05);
    EXPECT_EQ(checker.firstCollision(poses.data(), ctx) != nullptr, expected) << "theta " << theta;
    // A default-made context (no warm starts, no balls, no room) answers the same; so does a moved-from one.
    SelfCollisionContext none;
    EXPECT_EQ(checker.firstCollision(poses.data(), none) != nullptr, expected) << "theta " << theta;
    SelfCollisionContext taken = std::move(none);
    EXPECT_EQ(checker.firstCollision(poses.data(), none) != nullptr, expected)
        << "theta " << theta;  // NOLINT(bugprone-use-after-move)
    (expected ? collide : free)++;
  }
  EXPECT_GT(collide, 50);
  EXPECT_GT(free, 2000);
  EXPECT_EQ(ctx.pairTests(), collide + free) << "one pair tested per query";
}

// A state uniform in the scene's bounds (unbounded joints: ±π), into q.
void uniformState(const Scene& scene, std::mt19937& rng, std::vector<double>& q) {
  for (int v = 0; v < scene.dimension(); ++v) {
    const double lo = std::max(scene.validLower(v), -M_PI), hi = std::min(scene.validUpper(v), M_PI);
    q[v] = std::uniform_real_distribution<double>(lo, hi)(rng);
  }
}

// The loop over pairs eight at a time (a context of this checker, with its tables' verdicts and the balls'
// kept) gives the plain loop's verdict (a context of a checker of other pairs, which keeps neither), state by
// state: our dual arm and the shared UR5, whose pair tables and hundreds of pairs span many steps of eight.
// (Which pair they name may differ: each context tries its own last hit first.)
TEST(SelfCollision, EightPairsAtATimeAsOneByOne) {
  std::mt19937 rng(41);
  const auto check = [&](const std::string& file) {
    const auto scene = test::loadScene(file);
    const SelfCollision& checker = scene->selfCollision();
    ASSERT_GT(checker.pairs().size(), 16u) << file;
    CollisionFilter fewer = scene->filter();
    fewer.disable(checker.pairs()[0].a, checker.pairs()[0].b, "test");
    const SelfCollision other(scene->geometryPtr(), fewer, checker.options());
    ASSERT_NE(other.pairs().size(), checker.pairs().size());
    SelfCollisionContext kept = checker.makeContext(), plain = other.makeContext();
    SceneContext placed = scene->makeContext();
    std::vector<double> q(scene->dimension());
    int colliding = 0;
    for (int i = 0; i < 3000; ++i) {
      uniformState(*scene, rng, q);
      scene->computePoses(q.data(), placed);
      const LinkPair* a = checker.firstCollision(placed.poses().data(), kept, placed.jointValues().data());
      const LinkPair* b = checker.firstCollision(placed.poses().data(), plain, placed.jointValues().data());
      ASSERT_EQ(a != nullptr, b != nullptr) << file << ", state " << i;
      colliding += a != nullptr;
    }
    EXPECT_GT(colliding, 100) << file;
    EXPECT_LT(colliding, 2900) << file;
  };
  check(std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/dual_arm_shelf.yaml");
  CLEARWAY_SHARED_OR_SKIP(root, "scenes");
  check(root + "/box_ur5/box_ur5_0001.yaml");
}

// tabledCollision (the tables alone, before any pose) and then firstCollision at the same configuration
// answer as firstCollision alone, state by state; and a firstCollision at a configuration none of the tables'
// kept look-ups was made at looks them up again rather than use those (here: the previous states').
// The shared UR5, whose tables prove over half its self-colliding random states colliding.
TEST(SelfCollision, TablesFirstAnswerAsTheWholeCheck) {
  CLEARWAY_SHARED_OR_SKIP(root, "scenes");
  const auto scene = test::loadScene(root + "/box_ur5/box_ur5_0001.yaml");
  const SelfCollision& checker = scene->selfCollision();
  ASSERT_TRUE(checker.hasTables());
  SelfCollisionContext split = checker.makeContext(), whole = checker.makeContext(), stale = checker.makeContext();
  SceneContext placed = scene->makeContext();
  std::mt19937 rng(43);
  std::vector<double> q(scene->dimension());
  std::vector<double> previous;
  int tabled = 0, colliding = 0;
  for (int i = 0; i < 3000; ++i) {
    uniformState(*scene, rng, q);
    scene->computePoses(q.data(), placed);
    const double* full = placed.jointValues().data();
    const bool expected = checker.firstCollision(placed.poses().data(), whole, full) != nullptr;
    const LinkPair* first = checker.tabledCollision(full, split);
    tabled += first != nullptr;
    if (!first) first = checker.firstCollision(placed.poses().data(), split, full);
    ASSERT_EQ(first != nullptr, expected) << "state " << i;
    if (!previous.empty()) {  // the tables asked at the previous state, the pairs at this one
      checker.tabledCollision(previous.data(), stale);
      ASSERT_EQ(checker.firstCollision(placed.poses().data(), stale, full) != nullptr, expected) << "state " << i;
    }
    previous = placed.jointValues();
    colliding += expected;
  }
  std::printf("  %d of %d colliding states proved so by the tables alone\n", tabled, colliding);
  EXPECT_GT(tabled, colliding / 4);
  EXPECT_LT(colliding, 2900);
}

// A state check that a pair table settles (before any pose) leaves the context's placed state as it was:
// poses() and jointValues() still describe one state, the last one placed.
TEST(SelfCollision, AStateTheTablesSettleLeavesThePlacedState) {
  CLEARWAY_SHARED_OR_SKIP(root, "scenes");
  const auto scene = test::loadScene(root + "/box_ur5/box_ur5_0001.yaml");
  const SelfCollision& checker = scene->selfCollision();
  SceneContext ctx = scene->makeContext(), scratch = scene->makeContext();
  SelfCollisionContext tables = checker.makeContext();
  std::mt19937 rng(47);
  std::vector<double> q(scene->dimension());
  int settled = 0;
  for (int i = 0; i < 2000 && settled < 50; ++i) {
    uniformState(*scene, rng, q);
    scene->computePoses(q.data(), scratch);
    const bool by_table = checker.tabledCollision(scratch.jointValues().data(), tables) != nullptr;
    const std::vector<double> joints = ctx.jointValues();
    const std::vector<Pose> poses = ctx.poses();
    CollisionReport report;
    const bool free = scene->isFree(q.data(), ctx, &report);
    if (!by_table) continue;
    ++settled;
    ASSERT_FALSE(free) << "state " << i;
    EXPECT_EQ(report.kind, CollisionReport::Kind::Self) << "state " << i;
    ASSERT_EQ(ctx.jointValues(), joints) << "state " << i;
    for (std::size_t l = 0; l < poses.size(); ++l)
      ASSERT_TRUE(ctx.poses()[l].t == poses[l].t && ctx.poses()[l].R == poses[l].R) << "state " << i << " link " << l;
  }
  EXPECT_EQ(settled, 50);
}

TEST(SelfCollision, PaddingWidensTheContact) {
  const auto model = test::scissors();
  auto geometry = std::make_shared<const RobotGeometry>(model);
  // At θ = π/2 the arm points along y: its near corner (x = −0.05 … 0.05, y = 0.2) is 0.15 from the base
  // bar's top face (y = 0.05) along y, but the bar starts at x = 0.5: the gap is the corner distance
  // from (0.05, 0.2) to (0.5, 0.05) = √(0.45² + 0.15²).
  const double gap = std::hypot(0.45, 0.15);
  const double theta = M_PI / 2;
  std::vector<Pose> poses(3);
  computeLinkPoses(*model, &theta, poses.data());
  for (const double pad : {gap * 0.49, gap * 0.51}) {
    SelfCollisionOptions o;
    o.link_padding = {pad, 0.0, pad};
    const SelfCollision checker(geometry, CollisionFilter(*model), o);
    SelfCollisionContext ctx = checker.makeContext();
    EXPECT_EQ(checker.firstCollision(poses.data(), ctx) != nullptr, 2 * pad > gap) << pad;
    LinkPair pair;
    const DistanceResult d = checker.minimumDistance(poses.data(), &pair);
    EXPECT_NEAR(d.distance, std::max(0.0, gap - 2 * pad), 1e-9);
    EXPECT_EQ(pair, (LinkPair{0, 2}));
  }
  SelfCollisionOptions bad;
  bad.link_padding = {0.0, -1.0, 0.0};
  EXPECT_THROW(SelfCollision(geometry, CollisionFilter(*model), bad), std::invalid_argument);
  bad.link_padding = {0.0};
  EXPECT_THROW(SelfCollision(geometry, CollisionFilter(*model), bad), std::invalid_argument);
}

TEST(SelfCollision, NonFinitePoseCollides) {
  const auto model = test::scissors();
  const SelfCollision checker(std::make_shared<const RobotGeometry>(model), CollisionFilter(*model));
  SelfCollisionContext ctx = checker.makeContext();
  const double theta = std::nan("");
  std::vector<Pose> poses(3);
  computeLinkPoses(*model, &theta, poses.data());
  EXPECT_NE(checker.firstCollision(poses.data(), ctx), nullptr);
}

// The brute-force mesh of one link (its mesh elements in the link frame).
TriangleMesh linkMesh(const RobotModel& m, int link) {
  TriangleMesh out;
  for (const CollisionElement& e : m.link(link).collisions) {
    if (e.mesh < 0) continue;
    const TriangleMesh& src = m.meshes()[e.mesh];
    const auto base = static_cast<std::int32_t>(out.vertices.size());
    for (const Vec3& v : src.vertices) out.vertices.push_back(e.origin * v);
    for (auto t : src.triangles) out.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  }
  return out;
}

std::vector<double> randomState(const RobotModel& m, std::mt19937_64& rng) {
  std::vector<double> q(m.variableCount());
  for (int v = 0; v < m.variableCount(); ++v) {
    const JointVariable& var = m.variables()[v];
    const double lo = std::isfinite(var.lower) ? var.lower : -M_PI, hi = std::isfinite(var.upper) ? var.upper : M_PI;
    q[v] = std::uniform_real_distribution<double>(lo, hi)(rng);
  }
  return q;
}

// Mesh mode against brute force over every triangle pair (only where the hulls overlap: elsewhere the
// hull containment, tested in tests/tree, already proves "free"); hull mode never free where mesh collides;
// each pair's verdict the same with and without the enclosing layer.
void differential(const std::string& urdf, const std::string& srdf, int states, std::uint64_t seed) {
  auto model = std::make_shared<const RobotModel>(loadRobot(urdf, srdf));
  // The triangle brute force knows meshes only: pairs with a primitive link are compared with hull mode
  // alone here (primitives against triangles are tested in tests/tree).
  std::vector<char> mesh_only(model->linkCount(), 1);
  for (int i = 0; i < model->linkCount(); ++i)
    for (const CollisionElement& e : model->link(i).collisions) mesh_only[i] &= e.mesh >= 0;
  auto geometry = std::make_shared<const RobotGeometry>(model);
  const CollisionFilter filter(*model);
  SelfCollisionOptions hull_options;
  hull_options.mode = GeometryMode::Hull;
  const SelfCollision mesh(geometry, filter), hull(geometry, filter, hull_options);
  SelfCollisionContext mctx = mesh.makeContext(), hctx = hull.makeContext();
  std::vector<TriangleMesh> meshes(model->linkCount());
  std::vector<char> closed(model->linkCount(), 0);
  for (int i : geometry->geometricLinks()) {
    meshes[i] = linkMesh(*model, i);
    closed[i] = tree_ref::closedMesh(meshes[i]);
  }
  int contained = 0;
  std::mt19937_64 rng(seed);
  std::vector<Pose> poses(model->linkCount());
  int colliding = 0, free = 0, band = 0, disagreements = 0;
  for (int s = 0; s < states; ++s) {
    const std::vector<double> q = randomState(*model, rng);
    computeLinkPoses(*model, q.data(), poses.data());
    std::vector<LinkPair> mesh_hits, hull_hits;
    mesh.allCollisions(poses.data(), mctx, mesh_hits);
    hull.allCollisions(poses.data(), hctx, hull_hits);
    // The first collision (cheap rungs of every pair, then the triangles) is one of the colliding pairs.
    const LinkPair* first = mesh.firstCollision(poses.data(), mctx);
    EXPECT_EQ(first != nullptr, !mesh_hits.empty());
    if (first) EXPECT_NE(std::find(mesh_hits.begin(), mesh_hits.end(), *first), mesh_hits.end()) << "state " << s;
    // pairCollides skips the enclosing balls (body/enclosing.h): every verdict the same without them.
    for (int k = 0; k < static_cast<int>(mesh.pairs().size()); ++k) {
      const bool listed = std::find(mesh_hits.begin(), mesh_hits.end(), mesh.pairs()[k]) != mesh_hits.end();
      EXPECT_EQ(mesh.pairCollides(k, poses.data(), mctx), listed) << "state " << s << ": the enclosing balls changed pair " << k;
    }
    for (const LinkPair& p : mesh_hits)
      EXPECT_NE(std::find(hull_hits.begin(), hull_hits.end(), p), hull_hits.end()) << "hull free, mesh collides";
    bool any_collide = false, any_band = false;
    for (const LinkPair& p : hull_hits) {
      if (!mesh_only[p.a] || !mesh_only[p.b]) continue;
      const double band_width = 1e-9;
      const tree_ref::WorldMesh wa = tree_ref::place(meshes[p.a], poses[p.a]), wb = tree_ref::place(meshes[p.b], poses[p.b]);
      tree_ref::Verdict v = tree_ref::classify(wa, wb, 0.0, band_width);
      // Closed meshes are solids: surfaces apart, a piece of one may still lie inside the other.
      if (v == tree_ref::Verdict::Free && closed[p.b]) v = tree_ref::containment(wa, wb);
      if (v == tree_ref::Verdict::Free && closed[p.a]) v = tree_ref::containment(wb, wa);
      if (v == tree_ref::Verdict::Collide && tree_ref::classify(wa, wb, 0.0, band_width) != tree_ref::Verdict::Collide)
        ++contained;
      const bool said = std::find(mesh_hits.begin(), mesh_hits.end(), p) != mesh_hits.end();
      if (v == tree_ref::Verdict::Band) { any_band = true; continue; }
      if (said != (v == tree_ref::Verdict::Collide)) {
        ++disagreements;
        ADD_FAILURE() << "state " << s << " pair " << model->link(p.a).name << "/" << model->link(p.b).name
                      << ": mesh mode says " << said;
      }
      any_collide |= v == tree_ref::Verdict::Collide;
    }
    (any_collide ? colliding : any_band ? band : free)++;
  }
  EXPECT_EQ(disagreements, 0);
  std::printf("%d states: %d colliding, %d free, %d in the band; %d pairs collide only as solids (one inside the other)\n",
              states, colliding, free, band, contained);
  EXPECT_GT(colliding, states / 50) << "too few colliding states to test anything";
  EXPECT_GT(free, states / 5);
  EXPECT_LE(band, states / 20);
}

TEST(SelfCollision, PandaMeshModeMatchesBruteForce) {
  CLEARWAY_SHARED_ROBOT_OR_SKIP(urdf, "panda/panda.urdf");
  // Without the SRDF: more pairs checked, more contacts to get right.
  differential(urdf, "", 2000, 7);
}

TEST(SelfCollision, Arm6MeshModeMatchesBruteForce) {
  differential(test::sourceRobot("arm6/arm6.urdf"), "", 2000, 8);
}

// The convex parts' rung (links past 512 triangles: the UR5's arm and gripper) keeps every pair's verdict:
// on random states, with and without padding, each pair's answer (cheap rungs, parts, triangles) is the
// triangle search's alone, and the first collision is found exactly when some pair collides. The parts
// must settle pairs the cheaper rungs left, else this would test nothing.
TEST(SelfCollision, UR5PartsRungKeepsEveryVerdict) {
  CLEARWAY_SHARED_ROBOT_OR_SKIP(urdf, "ur5/ur5.urdf");
  auto model = std::make_shared<const RobotModel>(loadRobot(urdf, test::sharedRobot("ur5/ur5.srdf")));
  auto geometry = std::make_shared<const RobotGeometry>(model);
  const CollisionFilter filter(*model);
  SelfCollisionOptions padded;
  padded.link_padding.assign(model->linkCount(), 0.005);
  const Tolerances tol;
  std::mt19937_64 rng(41);
  std::vector<Pose> poses(model->linkCount());
  int by_parts = 0, colliding = 0, pairs_hit = 0;
  for (const SelfCollisionOptions& options : {SelfCollisionOptions{}, padded}) {
    const SelfCollision checker(geometry, filter, options);
    SelfCollisionContext ctx = checker.makeContext();
    for (int s = 0; s < 600; ++s) {
      computeLinkPoses(*model, randomState(*model, rng).data(), poses.data());
      bool any = false;
      for (int k = 0; k < static_cast<int>(checker.pairs().size()); ++k) {
        const LinkPair& p = checker.pairs()[k];
        const LinkGeometry &a = *geometry->link(p.a), &b = *geometry->link(p.b);
        const double padding = checker.pairPadding(k);
        const bool truth = meshesIntersectExactly(a, poses[p.a], b, poses[p.b], tol, padding);
        any |= truth;
        pairs_hit += truth;
        EXPECT_EQ(checker.pairCollides(k, poses.data(), ctx), truth)
            << "state " << s << " pair " << model->link(p.a).name << "/" << model->link(p.b).name;
        const IntersectQuery q{padding, GeometryMode::Mesh};
        BodyPair cold(a, b);
        if (cold.screen(poses[p.a], poses[p.b], tol, q) != Screen::Unsure) continue;
        if (screenMeshes(a, poses[p.a], b, poses[p.b], tol, GeometryMode::Mesh, padding) != Screen::Apart) continue;
        ++by_parts;  // the cheap rungs left it; the parts proved it apart
        EXPECT_FALSE(truth) << "state " << s << ": the parts cleared a colliding pair";
      }
      colliding += any;
      EXPECT_EQ(checker.firstCollision(poses.data(), ctx) != nullptr, any) << "state " << s;
    }
  }
  std::printf("  1200 states: %d colliding (%d colliding pairs), %d pairs cleared by the parts\n", colliding, pairs_hit,
              by_parts);
  EXPECT_GT(by_parts, 50);
  EXPECT_GT(colliding, 100);
}

TEST(SelfCollision, ContextsMakeThreadsIndependent) {
  CLEARWAY_SHARED_ROBOT_OR_SKIP(urdf, "panda/panda.urdf");
  auto model = std::make_shared<const RobotModel>(loadRobot(urdf, test::sharedRobot("panda/panda.srdf")));
  const SelfCollision checker(std::make_shared<const RobotGeometry>(model), CollisionFilter(*model));
  std::mt19937_64 rng(3);
  std::vector<std::vector<Pose>> states(400, std::vector<Pose>(model->linkCount()));
  for (auto& poses : states) computeLinkPoses(*model, randomState(*model, rng).data(), poses.data());
  std::vector<char> serial(states.size()), parallel(states.size());
  SelfCollisionContext ctx = checker.makeContext();
  for (std::size_t i = 0; i < states.size(); ++i) serial[i] = checker.firstCollision(states[i].data(), ctx) != nullptr;
  auto run = [&](std::size_t begin) {
    SelfCollisionContext c = checker.makeContext();
    for (std::size_t i = begin; i < states.size(); i += 2) parallel[i] = checker.firstCollision(states[i].data(), c) != nullptr;
  };
  std::thread a(run, 0), b(run, 1);
  a.join();
  b.join();
  EXPECT_EQ(serial, parallel);
  EXPECT_GT(std::count(serial.begin(), serial.end(), 1), 0);
}

}  // namespace
}  // namespace clearway
