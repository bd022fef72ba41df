// Pair tables (scene/pair_table.h): every cell they call Free or Colliding is so at every configuration
// of it, borders included, on our robots and the shared ones; a witness that touches means a collision;
// scenes answer state by state as they do without tables; and only pairs moved by one or two joints get one.
#include <clearway/body/proximity.h>
#include <clearway/kinematics/forward_kinematics.h>
#include <clearway/load/robot_loader.h>
#include <clearway/scene/pair_table.h>
#include <clearway/scene/scene.h>
#include <clearway/scene/self_collision.h>

#include "load/robot_files.h"
#include "scene/arm_scene.h"
#include "scene/scissors.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>

namespace clearway {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Tally {
  long free = 0, colliding = 0, unsure = 0, witnessed = 0;
};

// Random configurations within the limits (±π for unbounded joints), with some values of the tables'
// variables put on a cell border, or a hair either side of one (the coarsest cells' borders are those
// of every finer cell too).
std::vector<double> randomConfiguration(const RobotModel& m, std::mt19937_64& rng) {
  std::vector<double> q(m.variableCount());
  for (int v = 0; v < m.variableCount(); ++v) {
    const JointVariable& var = m.variables()[v];
    const double lo = std::isfinite(var.lower) ? var.lower : -M_PI, hi = std::isfinite(var.upper) ? var.upper : M_PI;
    q[v] = std::uniform_real_distribution<double>(lo, hi)(rng);
    if (rng() % 4 == 0) {  // onto a border of a 256-cell grid, which holds every grid of the tables
      const double w = (hi - lo) / 256;
      const double k = std::floor((q[v] - lo) / w);
      const double nudge[3] = {0.0, 1e-12, -1e-12};
      q[v] = std::clamp(lo + k * w + nudge[rng() % 3], lo, hi);
    }
  }
  return q;
}

// Every table of `checker` against meshesIntersect (the exact verdict) at `states` configurations.
Tally checkTables(const RobotModel& model, const SelfCollision& checker, int states, std::uint64_t seed,
                  const std::vector<double>& held = {}) {
  Tally t;
  std::mt19937_64 rng(seed);
  std::vector<Pose> poses(model.linkCount());
  const RobotGeometry& g = checker.geometry();
  for (int s = 0; s < states; ++s) {
    std::vector<double> q = randomConfiguration(model, rng);
    for (std::size_t v = 0; v < held.size(); ++v)
      if (std::isfinite(held[v])) q[v] = held[v];
    computeLinkPoses(model, q.data(), poses.data());
    for (int k = 0; k < static_cast<int>(checker.pairs().size()); ++k) {
      const PairTable* table = checker.pairTable(k);
      if (!table) continue;
      const LinkPair& p = checker.pairs()[k];
      TrianglePair w;
      const PairTable::Verdict v = table->lookup(q.data(), &w);
      const bool exact = meshesIntersect(*g.link(p.a), poses[p.a], *g.link(p.b), poses[p.b],
                                         checker.options().tolerances, checker.options().mode, checker.pairPadding(k));
      const std::string where = "state " + std::to_string(s) + " pair " + model.link(p.a).name + "/" + model.link(p.b).name;
      if (v == PairTable::Verdict::Free) {
        ++t.free;
        EXPECT_FALSE(exact) << where << ": the table says free";
      } else if (v == PairTable::Verdict::Colliding) {
        ++t.colliding;
        EXPECT_TRUE(exact) << where << ": the table says colliding";
      } else {
        ++t.unsure;
        if (w.valid() && trianglesTouch(*g.link(p.a), poses[p.a], *g.link(p.b), poses[p.b], w,
                                        checker.options().tolerances, checker.pairPadding(k))) {
          ++t.witnessed;
          EXPECT_TRUE(exact) << where << ": the witness touches";
        }
      }
    }
  }
  std::printf("%ld free, %ld colliding, %ld unsure (%ld proved colliding by their witness)\n", t.free, t.colliding,
              t.unsure, t.witnessed);
  return t;
}

// The table of two named links of `model`, with the default options (null when a name is unknown or the
// pair gets none).
std::unique_ptr<const PairTable> tableOf(const std::shared_ptr<const RobotModel>& model, const char* a_name,
                                         const char* b_name, GeometryMode mode) {
  const RobotGeometry geometry(model);
  const int a = model->linkIndex(a_name), b = model->linkIndex(b_name);
  if (a < 0 || b < 0) return nullptr;
  return PairTable::build(*model, a, *geometry.link(a), b, *geometry.link(b), 0.0, mode, Tolerances{});
}

TEST(PairTable, PandaCellsHoldWhatTheyCertify) {
  CLEARWAY_SHARED_ROBOT_OR_SKIP(urdf, "panda/panda.urdf");
  auto model = std::make_shared<const RobotModel>(loadRobot(urdf, ""));
  auto geometry = std::make_shared<const RobotGeometry>(model);
  // The fingers held (as the shared scenes hold them): the pairs with the fingers are moved by two joints.
  SelfCollisionOptions options;
  options.table_seconds = 1e3;  // whole tables even under sanitizers: the test asks how much they settle
  options.held.assign(model->variableCount(), NAN);
  for (int v = 0; v < model->variableCount(); ++v)
    if (model->variables()[v].name.find("finger") != std::string::npos) options.held[v] = 0.02;
  const SelfCollision checker(geometry, CollisionFilter(*model), options);
  int tables = 0;
  for (int k = 0; k < static_cast<int>(checker.pairs().size()); ++k) tables += checker.pairTable(k) != nullptr;
  EXPECT_GE(tables, 4);
  const Tally t = checkTables(*model, checker, 3000, 11, options.held);
  EXPECT_GT(t.free, 10 * t.unsure) << "the tables should settle most lookups";
  EXPECT_GT(t.witnessed, 0);
}

TEST(PairTable, PaddedAndHullModeCellsHold) {
  CLEARWAY_SHARED_ROBOT_OR_SKIP(urdf, "panda/panda.urdf");
  auto model = std::make_shared<const RobotModel>(loadRobot(urdf, ""));
  auto geometry = std::make_shared<const RobotGeometry>(model);
  SelfCollisionOptions padded;
  padded.link_padding.assign(model->linkCount(), 0.01);
  const Tally p = checkTables(*model, SelfCollision(geometry, CollisionFilter(*model), padded), 1500, 12);
  EXPECT_GT(p.free, 0);
  SelfCollisionOptions hull;
  hull.mode = GeometryMode::Hull;
  const Tally h = checkTables(*model, SelfCollision(geometry, CollisionFilter(*model), hull), 1500, 13);
  EXPECT_GT(h.free, 0);
  EXPECT_EQ(h.witnessed, 0) << "hull mode has no triangles to witness";
}

TEST(PairTable, OurRobotsCellsHold) {
  for (const char* rel : {"arm6/arm6.urdf", "twin_arm/twin_arm.urdf"}) {
    SCOPED_TRACE(rel);
    auto model = std::make_shared<const RobotModel>(loadRobot(test::sourceRobot(rel), ""));
    SelfCollisionOptions options;
    options.table_seconds = 1e3;
    const SelfCollision checker(std::make_shared<const RobotGeometry>(model), CollisionFilter(*model), options);
    const Tally t = checkTables(*model, checker, 2000, 14);
    EXPECT_GT(t.free + t.colliding, 0);
  }
}

TEST(PairTable, Ur5CellsHold) {
  CLEARWAY_SHARED_ROBOT_OR_SKIP(urdf, "ur5/ur5.urdf");
  auto model = std::make_shared<const RobotModel>(loadRobot(urdf, ""));
  const SelfCollision checker(std::make_shared<const RobotGeometry>(model), CollisionFilter(*model));
  const Tally t = checkTables(*model, checker, 500, 15);
  EXPECT_GT(t.free, 0);
}

// The tables a load builds on several threads at once (sharedMany) are the tables built one at a time:
// two loads of the UR5 (so that neither finds the other's tables in the cache), one on the calling thread
// and one on four threads, give every pair the same variables, cells checked and certified share, and the
// same verdict and witness at random configurations, and both equal build()'s own.
TEST(PairTable, TablesBuiltAtOnceAreTheTablesBuiltOneAtATime) {
  CLEARWAY_SHARED_ROBOT_OR_SKIP(urdf, "ur5/ur5.urdf");
  const auto load = [&] {
    auto model = std::make_shared<const RobotModel>(loadRobot(urdf, ""));
    return std::make_shared<const RobotGeometry>(model);
  };
  const auto g1 = load(), g4 = load();
  const RobotModel& model = g1->model();
  const CollisionFilter filter(model);
  std::vector<PairTable::Request> requests;
  for (const auto& [a, b] : filter.enabledPairs()) requests.push_back({a, b, 0.002});
  PairTableOptions one, four;
  one.threads = 1;
  four.threads = 4;
  const Tolerances tol;
  const auto t1 = PairTable::sharedMany(g1, requests, GeometryMode::Mesh, tol, {}, one);
  const auto t4 = PairTable::sharedMany(g4, requests, GeometryMode::Mesh, tol, {}, four);
  ASSERT_EQ(t1.size(), requests.size());
  ASSERT_EQ(t4.size(), requests.size());
  std::mt19937_64 rng(29);
  int tabled = 0;
  for (std::size_t k = 0; k < requests.size(); ++k) {
    const std::string where = model.link(requests[k].a).name + "/" + model.link(requests[k].b).name;
    ASSERT_EQ(t1[k] == nullptr, t4[k] == nullptr) << where;
    if (!t1[k]) continue;
    ++tabled;
    EXPECT_NE(t1[k], t4[k]) << where << ": shared from the cache, not built";
    const auto alone = PairTable::build(model, requests[k].a, *g1->link(requests[k].a), requests[k].b,
                                        *g1->link(requests[k].b), requests[k].padding, GeometryMode::Mesh, tol);
    ASSERT_TRUE(alone) << where;
    for (const PairTable* t : {t4[k].get(), alone.get()}) {
      EXPECT_EQ(t->variables(), t1[k]->variables()) << where;
      EXPECT_EQ(t->freeOnly(), t1[k]->freeOnly()) << where;
      EXPECT_EQ(t->cellsChecked(), t1[k]->cellsChecked()) << where;
      EXPECT_EQ(t->certifiedShare(), t1[k]->certifiedShare()) << where;
    }
    for (int s = 0; s < 300; ++s) {
      const std::vector<double> q = randomConfiguration(model, rng);
      TrianglePair w1, w4;
      const PairTable::Verdict v1 = t1[k]->lookup(q.data(), &w1), v4 = t4[k]->lookup(q.data(), &w4);
      ASSERT_EQ(v4, v1) << where << " at state " << s;
      ASSERT_EQ(alone->lookup(q.data()), v1) << where << " at state " << s;
      EXPECT_TRUE(w4.a == w1.a && w4.b == w1.b) << where << " at state " << s;
    }
  }
  EXPECT_GT(tabled, 10) << "too few tabled pairs to say anything";
}

// A cell whose bodies a rung proves at least the needed margin apart is Free: the rungs answer exactly
// `enough` once they prove it (the parts do when every part is that far), and a table that asked for more
// than that left such cells Unsure. On the UR5's forearm and wrist_2 (a table of two joints, its links
// concave where they meet) that was 41% of random lookups Unsure instead of 28%, each costing a screen and
// often a triangle search per state. Each part of the lower link moved by its own δ (parts near the axes
// move less than the link's farthest point) took that to 12%.
TEST(PairTable, CellsTheRungsProveFarEnoughAreFree) {
  CLEARWAY_SHARED_ROBOT_OR_SKIP(urdf, "ur5/ur5.urdf");
  auto model = std::make_shared<const RobotModel>(loadRobot(urdf, ""));
  const auto table = tableOf(model, "forearm_link", "wrist_2_link", GeometryMode::Mesh);
  ASSERT_TRUE(table);
  std::mt19937_64 rng(16);
  long unsure = 0;
  const int states = 3000;
  for (int s = 0; s < states; ++s)
    unsure += table->lookup(randomConfiguration(*model, rng).data()) == PairTable::Verdict::Unsure;
  std::printf("  forearm_link/wrist_2_link: %ld of %d lookups unsure\n", unsure, states);
  EXPECT_LT(unsure, states * 3 / 20);
}

// The UR5 stands on a box (a primitive, without triangles). Its upper arm dips into it at over half of the
// random states that collide with themselves: a cell whose upper-arm cores reach into the box by more than
// the cell's δ is Colliding everywhere in it. Cores against cores alone left half those lookups Unsure.
TEST(PairTable, ACoreDeepInAPrimitiveCollidesThroughItsCell) {
  CLEARWAY_SHARED_ROBOT_OR_SKIP(urdf, "ur5/ur5.urdf");
  auto model = std::make_shared<const RobotModel>(loadRobot(urdf, ""));
  const RobotGeometry geometry(model);
  const int a = model->linkIndex("box_link"), b = model->linkIndex("upper_arm_link");
  ASSERT_GE(a, 0);
  ASSERT_GE(b, 0);
  const auto table = PairTable::build(*model, a, *geometry.link(a), b, *geometry.link(b), 0.0, GeometryMode::Mesh, {});
  ASSERT_TRUE(table);
  std::mt19937_64 rng(17);
  std::vector<Pose> poses(model->linkCount());
  long colliding = 0, said_colliding = 0;
  for (int s = 0; s < 20000; ++s) {
    const std::vector<double> q = randomConfiguration(*model, rng);
    computeLinkPoses(*model, q.data(), poses.data());
    const bool exact = meshesIntersect(*geometry.link(a), poses[a], *geometry.link(b), poses[b], Tolerances{},
                                       GeometryMode::Mesh, 0.0);
    const PairTable::Verdict v = table->lookup(q.data());
    colliding += exact;
    if (v == PairTable::Verdict::Colliding) {
      ++said_colliding;
      ASSERT_TRUE(exact) << "state " << s << ": the table says colliding";
    }
  }
  std::printf("  box_link/upper_arm_link: %ld of %ld colliding lookups Colliding\n", said_colliding, colliding);
  EXPECT_GT(colliding, 1000);
  EXPECT_GT(said_colliding, colliding * 4 / 5);
}

// The UR5's base and upper arm are 16 mm apart at every free state, near the shoulder, where the upper arm
// lies close to the lift axis; its far end swings 0.45 m about it. With the whole link's motion bound a cell
// had to be a few hundredths of a radian wide, and the pair got no table (every state screened it). Each
// part moved by its own bound, in cells half as wide as before, settles most of the range.
TEST(PairTable, APairNearAtEveryStateIsTabulatedPartByPart) {
  CLEARWAY_SHARED_ROBOT_OR_SKIP(urdf, "ur5/ur5.urdf");
  auto model = std::make_shared<const RobotModel>(loadRobot(urdf, ""));
  const auto table = tableOf(model, "base_link", "upper_arm_link", GeometryMode::Mesh);
  ASSERT_TRUE(table) << "no table for base_link/upper_arm_link";
  std::printf("  base_link/upper_arm_link: %.1f%% of the range certified, %d cells checked\n",
              100.0 * table->certifiedShare(), table->cellsChecked());
  EXPECT_GT(table->certifiedShare(), 0.75);
  // Hull mode cannot split the link: its parts do not hold the hull.
  const auto hull = tableOf(model, "base_link", "upper_arm_link", GeometryMode::Hull);
  EXPECT_TRUE(!hull || hull->certifiedShare() < table->certifiedShare());
}

// freeAlong walks every cell a segment crosses: where it says free, every one of 4,000 points along the
// segment looks up Free and the exact pair is apart there; and it says free for most segments whose points
// all look up Free (the rest touch a cell not Free between two points).
TEST(PairTable, SegmentsAreWalkedThroughEveryCellTheyCross) {
  struct Case {
    std::string urdf;
    std::uint64_t seed;
  };
  std::vector<Case> cases = {{test::sourceRobot("arm6/arm6.urdf"), 31}};
  const std::string panda = test::sharedRobot("panda/panda.urdf");
  if (!panda.empty() && std::filesystem::exists(panda)) cases.push_back({panda, 32});
  for (const Case& c : cases) {
    SCOPED_TRACE(c.urdf);
    auto model = std::make_shared<const RobotModel>(loadRobot(c.urdf, ""));
    auto geometry = std::make_shared<const RobotGeometry>(model);
    SelfCollisionOptions options;
    options.table_seconds = 1e3;
    const SelfCollision checker(geometry, CollisionFilter(*model), options);
    std::mt19937_64 rng(c.seed);
    std::vector<Pose> poses(model->linkCount());
    int said_free = 0, all_points_free = 0, walked = 0;
    for (int k = 0; k < static_cast<int>(checker.pairs().size()); ++k) {
      const PairTable* table = checker.pairTable(k);
      if (!table) continue;
      const LinkPair& p = checker.pairs()[k];
      for (int s = 0; s < 150; ++s) {
        const std::vector<double> q0 = randomConfiguration(*model, rng);
        std::vector<double> q1 = randomConfiguration(*model, rng), q(q0.size());
        for (std::size_t v = 0; v < q0.size(); ++v) q1[v] = q0[v] + (q1[v] - q0[v]) * (s % 3 == 0 ? 1.0 : 0.1);
        const bool free = table->freeAlong(q0.data(), q1.data());
        bool points = true;
        for (int i = 0; i <= 4000; ++i) {
          for (std::size_t v = 0; v < q.size(); ++v) q[v] = q0[v] + (q1[v] - q0[v]) * (i / 4000.0);
          const bool cell_free = table->lookup(q.data()) == PairTable::Verdict::Free;
          points = points && cell_free;
          if (free) {
            ASSERT_TRUE(cell_free) << "segment " << s << " point " << i << ": walked free through a cell that is not";
            if (i % 200 == 0) {
              computeLinkPoses(*model, q.data(), poses.data());
              EXPECT_FALSE(meshesIntersect(*geometry->link(p.a), poses[p.a], *geometry->link(p.b), poses[p.b],
                                           Tolerances{}, GeometryMode::Mesh, checker.pairPadding(k)));
            }
          }
        }
        ++walked;
        said_free += free;
        all_points_free += points;
      }
    }
    std::printf("%d segments: %d walked free, %d free at every point\n", walked, said_free, all_points_free);
    EXPECT_GT(said_free, walked / 4);
    EXPECT_GE(said_free, all_points_free * 9 / 10);
  }
}

// Scenes with and without tables: the same verdict at every state, self and environment together.
void sameVerdicts(const SceneDescription& d, int states, std::uint64_t seed) {
  SceneOptions without;
  without.pair_tables = false;
  const Scene fast(d), plain(d, fast.geometryPtr(), fast.environmentPtr(), without);  // (one robot: one load)
  SceneContext a = fast.makeContext(), b = plain.makeContext();
  std::mt19937_64 rng(seed);
  std::vector<double> x(fast.dimension());
  int colliding = 0;
  for (int s = 0; s < states; ++s) {
    for (int i = 0; i < fast.dimension(); ++i) x[i] = std::uniform_real_distribution<double>(fast.lower(i), fast.upper(i))(rng);
    const bool f = fast.isFree(x.data(), a);
    ASSERT_EQ(f, plain.isFree(x.data(), b)) << "state " << s;
    colliding += !f;
  }
  std::printf("%d of %d states collide\n", colliding, states);
  EXPECT_GT(colliding, states / 20);
  EXPECT_GT(states - colliding, states / 20);
}

TEST(PairTable, SharedScenesAnswerAsWithoutTables) {
  CLEARWAY_SHARED_OR_SKIP(scenes, "scenes");
  for (const char* rel : {"box_panda/box_panda_0001.yaml", "bookshelf_small_panda/bookshelf_small_panda_0002.octomap.yaml",
                          "cage_ur5/cage_ur5_0001.yaml"}) {
    SCOPED_TRACE(rel);
    const SceneDescription d = parseSceneFile(scenes + "/" + rel);
    sameVerdicts(d, std::string(rel).find("ur5") != std::string::npos ? 800 : 3000, 21);
  }
}

TEST(PairTable, ArmSceneAnswersAsWithoutTablesPaddedOrNot) {
  SceneDescription d = parseSceneText(test::armScene("", ""), "<arm>", "");
  sameVerdicts(d, 4000, 22);
  d.padding = 0.01;
  sameVerdicts(d, 4000, 23);
}

TEST(PairTable, OneJointPairAgreesWithGeometryOverTheTurnAndBeyond) {
  for (const auto& [type, lo, hi] : {std::tuple{JointType::Revolute, -2.0, 2.5}, std::tuple{JointType::Continuous, -kInf, kInf},
                                     std::tuple{JointType::Revolute, -7.0, 7.0}}) {
    auto model = test::scissors({0.1, type, lo, hi});
    auto geometry = std::make_shared<const RobotGeometry>(model);
    SelfCollisionOptions options;
    options.table_seconds = 1e3;
    const SelfCollision checker(geometry, CollisionFilter(*model), options);
    ASSERT_EQ(checker.pairs().size(), 1u);
    const PairTable* table = checker.pairTable(0);
    ASSERT_NE(table, nullptr);
    EXPECT_EQ(table->variables(), std::vector<int>{0});
    EXPECT_GT(table->certifiedShare(), 0.8);
    std::vector<Pose> poses(3);
    const double from = std::isfinite(lo) ? lo : -20.0, to = std::isfinite(hi) ? hi : 20.0;
    int settled = 0;
    for (int i = 0; i <= 20000; ++i) {
      const double q = from + (to - from) * i / 20000;
      computeLinkPoses(*model, &q, poses.data());
      const bool exact = meshesIntersect(*geometry->link(0), poses[0], *geometry->link(2), poses[2], Tolerances{}, GeometryMode::Mesh);
      const PairTable::Verdict v = table->lookup(&q);
      if (v == PairTable::Verdict::Unsure) continue;
      ++settled;
      EXPECT_EQ(v == PairTable::Verdict::Colliding, exact) << "q = " << q;
    }
    EXPECT_GT(settled, 16000);
    // Beyond the limits, not finite, or a turn too large to reduce safely: Unsure.
    for (double q : {std::nan(""), kInf, -kInf, 1e6})
      EXPECT_EQ(table->lookup(&q), PairTable::Verdict::Unsure) << q;
    if (type == JointType::Revolute && hi < 3.0) {
      const double beyond = hi + 0.1;
      EXPECT_EQ(table->lookup(&beyond), PairTable::Verdict::Unsure);
    }
  }
}

TEST(PairTable, OnlyPairsMovedByFewPlainJoints) {
  // The scissors' finger follows the swing through a mimic joint: no table for the pair it moves.
  {
    auto model = test::scissors({0.1, JointType::Revolute, -2.0, 2.0, true});
    auto g = std::make_shared<const RobotGeometry>(model);
    EXPECT_EQ(PairTable::build(*model, 0, *g->link(0), 3, *g->link(3), 0.0, GeometryMode::Mesh, Tolerances{}), nullptr);
    EXPECT_NE(PairTable::build(*model, 0, *g->link(0), 2, *g->link(2), 0.0, GeometryMode::Mesh, Tolerances{}), nullptr);
    // Held, the swing is fixed: the pair is rigid, decided once by the scene, and has no table either.
    EXPECT_EQ(PairTable::build(*model, 0, *g->link(0), 3, *g->link(3), 0.0, GeometryMode::Mesh, Tolerances{}, {0.5}), nullptr);
  }
  // arm6: tables only for pairs with one or two joints between them on one branch, or three of which the
  // lowest turns the lower link (its solid of revolution: a free-only table over the other two).
  auto model = std::make_shared<const RobotModel>(loadRobot(test::sourceRobot("arm6/arm6.urdf"), ""));
  const SelfCollision checker(std::make_shared<const RobotGeometry>(model), CollisionFilter(*model));
  int with = 0, with_three = 0;
  for (int k = 0; k < static_cast<int>(checker.pairs().size()); ++k) {
    const LinkPair& p = checker.pairs()[k];
    int moving = -1;
    for (int up : {p.a, p.b}) {
      const int down = up == p.a ? p.b : p.a;
      int n = 0;
      int l = down;
      for (; l >= 0 && l != up; l = model->parentLink(l))
        if (model->link(l).parent_joint >= 0) n += model->joint(model->link(l).parent_joint).type != JointType::Fixed;
      if (l == up) moving = n;
    }
    // (A pair may lack a table it could have: one whose probe settled too little.)
    if (const PairTable* t = checker.pairTable(k)) {
      EXPECT_TRUE(moving == 1 || moving == 2 || (moving == 3 && t->freeOnly()))
          << model->link(p.a).name << "/" << model->link(p.b).name;
      EXPECT_EQ(t->freeOnly(), moving == 3) << model->link(p.a).name << "/" << model->link(p.b).name;
      EXPECT_EQ(static_cast<int>(t->variables().size()), std::min(moving, 2));
      with_three += moving == 3;
    }
    with += checker.pairTable(k) != nullptr;
  }
  EXPECT_GT(with, 0);
  EXPECT_GT(with_three, 0);
}

// A wrist's last link turns about its own axis: the pair of it and the forearm (three joints between them)
// is tabulated over the other two, against the solid the link sweeps over the whole turn. It never says
// Colliding; where it says Free the exact pair is apart at every angle of that turn, checked at the states
// that matter, those with the links within 2 cm of each other; and it settles most of those.
TEST(PairTable, AWristsTurningLinkIsTabulatedAsTheSolidItSweeps) {
  CLEARWAY_SHARED_ROBOT_OR_SKIP(urdf, "ur5/ur5.urdf");
  auto model = std::make_shared<const RobotModel>(loadRobot(urdf, ""));
  const RobotGeometry geometry(model);
  const int turn = model->joint(model->link(model->linkIndex("wrist_3_link")).parent_joint).first_variable;
  for (const char* lower : {"wrist_3_link", "robotiq_85_base_link", "fts_robotside"}) {
    SCOPED_TRACE(lower);
    const auto table = tableOf(model, "forearm_link", lower, GeometryMode::Mesh);
    ASSERT_TRUE(table);
    EXPECT_TRUE(table->freeOnly());
    ASSERT_EQ(table->variables().size(), 2u);
    const int a = model->linkIndex("forearm_link"), b = model->linkIndex(lower);
    const LinkGeometry &ga = *geometry.link(a), &gb = *geometry.link(b);
    std::mt19937_64 rng(23);
    std::vector<Pose> poses(model->linkCount());
    long near = 0, near_free = 0;
    for (int s = 0; s < 6000; ++s) {
      std::vector<double> q = randomConfiguration(*model, rng);
      const PairTable::Verdict v = table->lookup(q.data());
      EXPECT_NE(v, PairTable::Verdict::Colliding);
      computeLinkPoses(*model, q.data(), poses.data());
      if (!meshesIntersect(ga, poses[a], gb, poses[b], Tolerances{}, GeometryMode::Mesh, 0.02)) continue;
      ++near;
      if (v != PairTable::Verdict::Free) continue;
      ++near_free;
      for (int k = 0; k < 16; ++k) {  // the whole turn: the table does not look at it
        q[turn] = -M_PI + (2.0 * M_PI) * (k + 0.5 * (s % 2)) / 16.0;
        computeLinkPoses(*model, q.data(), poses.data());
        EXPECT_FALSE(meshesIntersect(ga, poses[a], gb, poses[b], Tolerances{}, GeometryMode::Mesh, 0.0))
            << "state " << s << " turn " << q[turn] << ": the table says free";
      }
    }
    std::printf("  forearm_link/%s: %.1f%% certified; of 6000 states %ld within 2 cm, %ld of them free\n", lower,
                100.0 * table->certifiedShare(), near, near_free);
    EXPECT_GT(table->certifiedShare(), 0.8);
    EXPECT_GT(near, 200);
    EXPECT_GT(near_free, near / 4);
  }
}

}  // namespace
}  // namespace clearway

TEST(PairTable, BudgetBringsTheDeadlineForward) {
  using Clock = std::chrono::steady_clock;
  const clearway::PairTableOptions none;
  const Clock::time_point before = Clock::now();
  for (const double budget : {0.0, -1.0, std::nan("")}) {
    const Clock::time_point deadline = none.within(budget).deadline;  // (before the now() it is compared with)
    EXPECT_LE(deadline, Clock::now()) << budget;
  }
  EXPECT_GE(none.within(60.0).deadline, before + std::chrono::seconds(60));
  EXPECT_GE(none.within(std::numeric_limits<double>::infinity()).deadline, before + std::chrono::hours(24));
  clearway::PairTableOptions soon;
  soon.deadline = before;
  EXPECT_EQ(soon.within(60.0).deadline, before);  // never later than it was
}

namespace clearway {
namespace {

using test::armScene;
using test::TempDir;

// A body attached to one link changes only the pairs it is in: every other pair's table is shared with the
// robot it was attached to (the tables' cache is keyed by the two link geometries and the joints between
// them), so that an edit costs its own pairs' tables only.
TEST(PairTable, AttachingABodySharesEveryOtherPairsTable) {
  TempDir dir;
  const auto bare = Scene::load(dir.write("bare.yaml", armScene("", "")));
  SceneDescription::AttachedSpec spec;
  spec.link = "wrist_3_link";
  spec.body.name = "tool";
  spec.body.shape = Box(Vec3(0.02, 0.02, 0.05));
  spec.body.pose = Pose::translation(Vec3(0, 0, 0.06));
  const long long built_before = PairTable::cacheStats().built;
  const auto held = bare->withAttached(spec);
  const long long built = PairTable::cacheStats().built - built_before;
  const RobotModel& m0 = bare->robot();
  const RobotModel& m1 = held->robot();
  const SelfCollision& s0 = bare->selfCollision();
  const SelfCollision& s1 = held->selfCollision();
  int shared = 0, with_tool = 0;
  for (int k = 0; k < static_cast<int>(s1.pairs().size()); ++k) {
    const LinkPair& p = s1.pairs()[k];
    const std::string a = m1.link(p.a).name, b = m1.link(p.b).name;
    if (a == "tool" || b == "tool") {
      ++with_tool;
      continue;
    }
    const auto it = std::find_if(s0.pairs().begin(), s0.pairs().end(),
                                 [&](const LinkPair& q) { return m0.link(q.a).name == a && m0.link(q.b).name == b; });
    ASSERT_NE(it, s0.pairs().end()) << a << " " << b;
    const PairTable* before = s0.pairTable(static_cast<int>(it - s0.pairs().begin()));
    EXPECT_EQ(s1.pairTable(k), before) << a << " " << b << ": built again";
    shared += before != nullptr;
  }
  EXPECT_GT(shared, 3) << "too few tabled pairs to say anything";
  EXPECT_GT(with_tool, 0);
  EXPECT_LE(built, with_tool) << "only the new body's pairs are built";
}

// Loading sweeps the tables' cache (to drop those of robots gone) a few times per table, not once per table:
// a sweep after every table made loading quartic in the links. A hub turning on a base, 48 blades turning
// on the hub: each blade against the base is moved by two joints and gets a table. Counted, not timed.
TEST(PairTable, LoadingSweepsTheCacheAFewTimesPerTable) {
  TempDir dir;
  const std::string limit = "<limit lower=\"-0.3\" upper=\"0.3\" effort=\"1\" velocity=\"1\"/>";
  std::string urdf =
      "<robot name=\"fan\"><link name=\"base\"><collision><geometry><box size=\"0.1 0.1 0.1\"/></geometry></collision>"
      "</link><link name=\"hub\"><collision><origin xyz=\"0 0 0.2\"/><geometry><cylinder radius=\"0.05\" "
      "length=\"0.1\"/>"
      "</geometry></collision></link><joint name=\"spin\" type=\"revolute\"><parent link=\"base\"/><child "
      "link=\"hub\"/>"
      "<axis xyz=\"0 0 1\"/>" +
      limit + "</joint>\n";
  std::string group = "spin";
  constexpr int kBlades = 48;
  for (int i = 0; i < kBlades; ++i) {
    const std::string n = std::to_string(i);
    urdf += "<link name=\"blade" + n +
            "\"><collision><origin xyz=\"0.3 0 0\"/><geometry><box size=\"0.2 0.01 0.01\"/>"
            "</geometry></collision></link><joint name=\"j" +
            n +
            "\" type=\"revolute\"><parent link=\"hub\"/>"
            "<child link=\"blade" +
            n + "\"/><origin xyz=\"0 0 0.2\" rpy=\"0 0 " + std::to_string(2.0 * M_PI * i / kBlades) +
            "\"/><axis xyz=\"1 0 0\"/>" + limit + "</joint>\n";
    group += ", j" + n;
  }
  urdf += "</robot>\n";
  const std::string path = dir.write("fan.urdf", urdf);
  const PairTable::CacheStats before = PairTable::cacheStats();
  const auto scene = Scene::load(dir.write(
      "fan.yaml", "format: 1\nname: fan\nrobot:\n  urdf: " + path + "\n  group: [" + group + "]\nchecks: [self]\n"));
  const PairTable::CacheStats after = PairTable::cacheStats();
  const long long built = after.built - before.built;
  int tabled = 0;
  for (int k = 0; k < static_cast<int>(scene->selfCollision().pairs().size()); ++k)
    tabled += scene->selfCollision().pairTable(k) != nullptr;
  EXPECT_GE(tabled, kBlades / 2) << "the blades against the base should have tables";
  // Each sweep visits the cache once it has doubled since the last: at most about twice every entry there
  // was or came (a sweep per table visited about built · entries / 2).
  EXPECT_LE(after.swept - before.swept, 2 * (static_cast<long long>(before.entries) + built) + 64)
      << built << " tables built, " << tabled << " kept";
}

}  // namespace
}  // namespace clearway
