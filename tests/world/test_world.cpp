// Changing worlds (world/world.h, Environment's edits): random obstacle edits answer as a scene built
// from scratch after each edit, states and certified motions alike; attached bodies collide, move with
// their link, are certified through thin walls and detach cleanly; inserted points become voxels that
// states touching them collide with; edits during queries on other threads give every query the verdict
// of one whole version; bad edits are refused with their reason.
#include <clearway/kinematics/attached_body.h>
#include <clearway/motion/motion.h>
#include <clearway/scene/scene.h>
#include <clearway/world/world.h>

#include "box_surface.h"
#include "load/robot_files.h"
#include "scene/arm_scene.h"
#include "shared_data.h"

#include <gtest/gtest.h>

#include <atomic>
#include <functional>
#include <cmath>
#include <mutex>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace clearway {
namespace {

using test::armScene;
using test::boxSurface;
using test::TempDir;

const char* const kWall = "    - {name: wall, box: {size: [0.004, 1.0, 3.0]}, pose: {position: [0.3, 0, 1.5]}}\n";

SceneDescription::AttachedSpec stick(double thickness = 0.02) {
  SceneDescription::AttachedSpec a;
  a.link = "tool0";
  a.body.name = "stick";
  a.body.shape = Box(Vec3(0.3, 0.5 * thickness, 0.5 * thickness));
  a.body.pose = Pose::translation(Vec3(0.3, 0, 0));
  a.touch_links = {"wrist_3_link"};
  return a;
}

std::vector<double> randomState(const Scene& scene, std::mt19937& rng) {
  std::vector<double> q(scene.dimension());
  for (int i = 0; i < scene.dimension(); ++i)
    q[i] = std::uniform_real_distribution<double>(std::max(scene.lower(i), -3.2), std::min(scene.upper(i), 3.2))(rng);
  return q;
}

Pose randomPose(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Vec3 t(u(rng), u(rng), 0.6 + 0.6 * u(rng));
  Eigen::Quaterniond q(u(rng), u(rng), u(rng), u(rng));
  if (q.norm() < 1e-3) q = Eigen::Quaterniond::Identity();
  q.normalize();
  return Pose::fromQuaternion(q.x(), q.y(), q.z(), q.w(), t);
}

Obstacle randomObstacle(const std::string& name, std::mt19937& rng) {
  std::uniform_real_distribution<double> size(0.02, 0.12);
  Obstacle o;
  o.name = name;
  switch (rng() % 4) {
    case 0: o.shape = Box(Vec3(size(rng), size(rng), size(rng))); break;
    case 1: o.shape = Sphere(size(rng)); break;
    case 2: o.shape = Cylinder(size(rng), size(rng)); break;
    default: o.mesh = std::make_shared<const LinkGeometry>(boxSurface(Vec3(size(rng), size(rng), size(rng))));
  }
  o.pose = randomPose(rng);
  return o;
}

// After every edit, the world answers as a scene built from scratch on the obstacles it should now hold:
// `states` states after each edit (`last_states` after the last), and 20 certified motions every 50 edits.
void expectEditsMatchFreshScenes(World& world, std::vector<Obstacle> live, int n_edits, int states, int last_states,
                                 const std::function<Obstacle(int, std::mt19937&)>& make,
                                 const std::function<Pose(const Obstacle&, std::mt19937&)>& move, std::mt19937& rng) {
  const std::shared_ptr<const Scene> base = world.current().scene;
  const std::shared_ptr<const OccupancyMap> map =
      base->environment().map() ? std::make_shared<const OccupancyMap>(*base->environment().map()) : nullptr;
  const std::size_t floor = live.size() / 2 + 5, ceiling = live.size() + 30;
  int next_name = 0;
  long checked_states = 0, colliding = 0, checked_motions = 0;
  for (int edit = 1; edit <= n_edits; ++edit) {
    // Between `floor` and `ceiling` obstacles: add, move or remove alike.
    const unsigned kind = live.size() < floor ? 0 : live.size() > ceiling ? 2 : rng() % 3;
    if (kind == 0) {
      live.push_back(make(next_name++, rng));
      world.addObstacle(live.back());
    } else if (kind == 1) {
      Obstacle& o = live[rng() % live.size()];
      o.pose = move(o, rng);
      world.moveObstacle(o.name, o.pose);
    } else {
      const std::size_t k = rng() % live.size();
      world.removeObstacle(live[k].name);
      live.erase(live.begin() + static_cast<std::ptrdiff_t>(k));
    }
    const WorldSnapshot& w = world.current();
    ASSERT_EQ(w.version, static_cast<std::uint64_t>(edit + 1));
    ASSERT_EQ(w.scene->environment().obstacleCount(), live.size());
    const auto fresh = std::make_shared<const Scene>(base->description(), base->geometryPtr(),
                                                     std::make_shared<const Environment>(live, map), base->options());
    const int n_states = edit == n_edits ? last_states : states;
    SceneContext a = w.scene->makeContext(), b = fresh->makeContext();
    for (int i = 0; i < n_states; ++i) {
      const std::vector<double> q = randomState(*fresh, rng);
      const bool free = fresh->isFree(q.data(), b);
      ASSERT_EQ(w.scene->isFree(q.data(), a), free) << "edit " << edit << ", state " << i;
      colliding += !free;
      ++checked_states;
    }
    if (edit % 50 != 0) continue;
    const MotionChecker fresh_motion(fresh);
    MotionContext ma = w.motion->makeContext(), mb = fresh_motion.makeContext();
    for (int i = 0; i < 20; ++i) {
      const std::vector<double> q0 = randomState(*fresh, rng), q1 = randomState(*fresh, rng);
      ASSERT_EQ(w.motion->check(q0.data(), q1.data(), ma, false).free, fresh_motion.check(q0.data(), q1.data(), mb, false).free)
          << "edit " << edit << ", motion " << i;
      ++checked_motions;
    }
  }
  // The sample means something: many states collide, many do not.
  EXPECT_GT(colliding, checked_states / 20);
  EXPECT_LT(colliding, checked_states * 19 / 20);
  EXPECT_EQ(checked_motions, 20 * (n_edits / 50));
}

TEST(WorldEdits, RandomEditsAnswerAsAFreshSceneStatesAndMotions) {
  TempDir dir;
  auto world = World::load(dir.write("w.yaml", armScene("", "")));
  std::mt19937 rng(7);
  expectEditsMatchFreshScenes(
      *world, {}, 1000, 60, 10000, [](int id, std::mt19937& r) { return randomObstacle("o" + std::to_string(id), r); },
      [](const Obstacle&, std::mt19937& r) { return randomPose(r); }, rng);
}

// The Panda among a shared problem's shelves (primitive form, then OctoMap form): its own obstacles
// moved a few centimetres, removed, and new ones added among them.
TEST(WorldEdits, SharedPandaShelvesEditedAnswerAsAFreshScene) {
  for (const char* form : {"bookshelf_small_panda_0001.yaml", "bookshelf_small_panda_0001.octomap.yaml"}) {
    SCOPED_TRACE(form);
    CLEARWAY_SHARED_OR_SKIP(file, std::string("scenes/bookshelf_small_panda/") + form);
    auto world = World::load(file);
    const auto own = world->current().scene->environment().obstacles();
    std::vector<Obstacle> live;
    for (const auto& o : own) live.push_back(*o);
    std::mt19937 rng(11);
    const auto nudge = [](const Obstacle& o, std::mt19937& r) {
      std::uniform_real_distribution<double> u(-0.05, 0.05);
      Pose p = o.pose;
      p.t += Vec3(u(r), u(r), u(r));
      return p;
    };
    const auto make = [&](int id, std::mt19937& r) {
      Obstacle o = randomObstacle("new" + std::to_string(id), r);
      o.pose.t = Vec3(std::uniform_real_distribution<double>(0.2, 0.9)(r), std::uniform_real_distribution<double>(-0.6, 0.6)(r),
                      std::uniform_real_distribution<double>(0.0, 1.0)(r));
      return o;
    };
    expectEditsMatchFreshScenes(*world, live, 150, 20, 2000, make, nudge, rng);
  }
}

// A world made from a built checker publishes that checker, and its edits keep the checker's options.
TEST(WorldEdits, AWorldOfABuiltCheckerKeepsItsOptions) {
  TempDir dir;
  const std::shared_ptr<const Scene> scene = Scene::load(dir.write("w.yaml", armScene("", kWall)));
  MotionOptions wide;
  wide.contact_distance = 0.05;
  const auto checker = std::make_shared<const MotionChecker>(scene, wide);
  World world(checker);
  EXPECT_EQ(world.current().motion, checker);
  EXPECT_EQ(world.current().scene, scene);
  EXPECT_EQ(world.version(), 1u);
  Obstacle post;
  post.name = "post";
  post.shape = Cylinder(0.02, 1.0);
  post.pose = Pose::translation(Vec3(-0.4, 0.0, 0.5));
  world.addObstacle(post);
  EXPECT_EQ(world.version(), 2u);
  EXPECT_EQ(world.current().motion->options().contact_distance, 0.05);
  EXPECT_EQ(world.current().scene->environment().obstacleCount(), scene->environment().obstacleCount() + 1);
  EXPECT_THROW(World(std::shared_ptr<const MotionChecker>()), std::invalid_argument);
}

TEST(WorldEdits, OldSnapshotsStayWhole) {
  TempDir dir;
  auto world = World::load(dir.write("w.yaml", armScene("", kWall)));
  const std::vector<double> upright(6, 0.0);
  const std::shared_ptr<const WorldSnapshot> before = world->snapshot();
  Obstacle block;
  block.name = "block";
  block.shape = Box(Vec3(0.2, 0.2, 0.2));
  block.pose = Pose::translation(Vec3(0, 0, 0.8));  // around the upright arm
  world->addObstacle(block);
  EXPECT_FALSE(world->current().scene->isFree(upright));
  EXPECT_TRUE(before->scene->isFree(upright));
  world->moveObstacle("block", Pose::translation(Vec3(0, -3, 0.8)));
  EXPECT_TRUE(world->current().scene->isFree(upright));
  world->removeObstacle("block");
  EXPECT_EQ(world->current().scene->environment().obstacleCount(), 1u);
  EXPECT_EQ(world->version(), 4u);
  EXPECT_EQ(before->version, 1u);
}

TEST(WorldEdits, BadEditsAreRefusedWithTheirReason) {
  TempDir dir;
  auto world = World::load(dir.write("w.yaml", armScene("", kWall)));
  const auto fails = [](auto&& edit, const std::string& reason) {
    try {
      edit();
      ADD_FAILURE() << "no error; expected: " << reason;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
    }
  };
  Obstacle wall;
  wall.name = "wall";
  fails([&] { world->addObstacle(wall); }, "'wall' already exists");
  wall.name = "";
  fails([&] { world->addObstacle(wall); }, "needs a name");
  wall.name = "nan";
  wall.pose.t.x() = std::nan("");
  fails([&] { world->addObstacle(wall); }, "non-finite pose");
  fails([&] { world->removeObstacle("door"); }, "no obstacle is named 'door'");
  fails([&] { world->moveObstacle("wall", Pose::translation(Vec3(INFINITY, 0, 0))); }, "non-finite pose");
  fails([&] { world->insertPoints({Vec3(0, 0, 0)}); }, "voxel size");
  fails([&] { world->insertPoints({Vec3(0, std::nan(""), 0)}, 0.05); }, "point 0 is not finite");
  fails([&] { world->detach("forearm_link"); }, "no attached body");
  SceneDescription::AttachedSpec bad = stick();
  bad.link = "claw";
  fails([&] { world->attach(bad); }, "no link 'claw'");
  bad = stick();
  bad.body.name = "forearm_link";
  fails([&] { world->attach(bad); }, "already a link");
  EXPECT_EQ(world->version(), 1u);  // nothing was published
  // Two obstacles of one name: loaded, but not edited by that name.
  auto twins = World::load(dir.write("t.yaml", armScene("", std::string(kWall) + kWall)));
  EXPECT_EQ(twins->current().scene->environment().obstacleCount(), 2u);
  fails([&] { twins->removeObstacle("wall"); }, "2 obstacles are named 'wall'");
}

TEST(WorldAttach, AttachedBoxCollidesAndDetachRestoresTheRobot) {
  TempDir dir;
  auto world = World::load(dir.write("w.yaml", armScene("", kWall)));
  const std::vector<double> upright(6, 0.0), turned{1.57, 0, 0, 0, 0, 0};
  const int links = world->current().scene->robot().linkCount();
  ASSERT_TRUE(world->current().scene->isFree(upright));
  world->attach(stick());
  const Scene& held = *world->current().scene;
  EXPECT_EQ(held.robot().linkCount(), links + 1);
  CollisionReport report;
  ASSERT_FALSE(held.isFree(upright, &report));
  EXPECT_EQ(held.describe(report), "stick wall");
  EXPECT_TRUE(held.isFree(turned));  // it moves with its link
  // The stick and its touch link overlap where it is fixed: allowed, as declared.
  EXPECT_FALSE(held.filter().enabled(held.robot().linkIndex("stick"), held.robot().linkIndex("wrist_3_link")));
  EXPECT_TRUE(held.filter().enabled(held.robot().linkIndex("stick"), held.robot().linkIndex("forearm_link")));
  world->detach("stick");
  const Scene& bare = *world->current().scene;
  EXPECT_EQ(bare.robot().linkCount(), links);
  EXPECT_EQ(bare.robot().linkIndex("stick"), -1);
  EXPECT_TRUE(bare.isFree(upright));
  world->attach(stick());  // the name is free again
  EXPECT_FALSE(world->current().scene->isFree(upright));
}

TEST(WorldAttach, DetachesABodyTheSceneFileAttached) {
  TempDir dir;
  const std::string held =
      "    - {name: stick, link: tool0, box: {size: [0.6, 0.02, 0.02]}, pose: {position: [0.3, 0, 0]}, touch_links: [wrist_3_link]}\n";
  auto world = World::load(dir.write("w.yaml", armScene(held, kWall)));
  EXPECT_FALSE(world->current().scene->isFree(std::vector<double>(6, 0.0)));
  world->detach("stick");
  EXPECT_TRUE(world->current().scene->isFree(std::vector<double>(6, 0.0)));
}

TEST(WorldAttach, CertifiedCatchesAnAttachedStickSweepingThroughAPostThatSamplingMisses) {
  TempDir dir;
  // A 2 mm stick, and a 1 mm post half a metre out, midway between two states of the 1% sampling of the
  // pan sweep −0.5 → 0.5 (as test_attached's scene-file case, here attached through the World).
  auto world = World::load(dir.write("w.yaml", armScene("", "")));
  world->attach(stick(0.002));
  const double a = -0.5, b = 0.5, resolution = 0.01;
  const double n = std::ceil((b - a) / resolution);
  const double mid = a + (b - a) * (std::floor(n / 2) + 0.5) / n;
  SceneContext ctx = world->current().scene->makeContext();
  world->current().scene->computePoses(std::vector<double>{mid, 0, 0, 0, 0, 0}.data(), ctx);
  const Vec3 post_at = ctx.poses()[world->current().scene->robot().linkIndex("stick")] * Vec3(0.2, 0, 0);
  Obstacle post;
  post.name = "post";
  post.shape = Cylinder(0.001, 0.05);
  post.pose = Pose::translation(post_at);
  world->addObstacle(post);
  const WorldSnapshot& w = world->current();
  const std::vector<double> q0{a, 0, 0, 0, 0, 0}, q1{b, 0, 0, 0, 0, 0};
  ASSERT_TRUE(w.scene->isFree(q0));
  ASSERT_TRUE(w.scene->isFree(q1));
  ASSERT_FALSE(w.scene->isFree(std::vector<double>{mid, 0, 0, 0, 0, 0}));
  MotionContext cctx = w.motion->makeContext();
  const MotionResult c = w.motion->check(q0.data(), q1.data(), cctx, true);
  EXPECT_FALSE(c.free);
  EXPECT_EQ(w.scene->robot().link(c.report.link).name, "stick");
  MotionOptions sampled;
  sampled.mode = MotionMode::Sampled;
  sampled.resolution = resolution;
  MotionChecker one_percent(w.scene, sampled);
  MotionContext sctx = one_percent.makeContext();
  EXPECT_TRUE(one_percent.check(q0.data(), q1.data(), sctx).free) << "the 1% sampling was to step over the post";
}

TEST(WorldPoints, VoxelsAppearWherePointsFell) {
  TempDir dir;
  auto world = World::load(dir.write("w.yaml", armScene("", "")));
  const std::vector<double> q{0.3, -1.0, 1.2, 0, 0.4, 0};
  ASSERT_TRUE(world->current().scene->isFree(q));
  // A vertex of the forearm, where the state puts it: its voxel must make the state collide.
  const Scene& scene = *world->current().scene;
  SceneContext ctx = scene.makeContext();
  scene.computePoses(q.data(), ctx);
  const int forearm = scene.robot().linkIndex("forearm_link");
  const LinkGeometry& g = *scene.geometry().link(forearm);
  ASSERT_FALSE(g.hull().vertices().empty());
  const Vec3 on_link = ctx.poses()[forearm] * g.hull().vertices()[0];
  const double res = 0.02;
  world->insertPoints({Vec3(2.0, 2.0, 2.0), Vec3(2.001, 2.001, 2.001), Vec3(-2.0, 0.0, 0.5)}, res);
  EXPECT_EQ(world->current().scene->environment().pointVoxelCount(), 2);  // two points share a voxel
  EXPECT_TRUE(world->current().scene->isFree(q));
  world->insertPoints({on_link}, res);
  EXPECT_EQ(world->current().scene->environment().pointVoxelCount(), 3);
  CollisionReport report;
  ASSERT_FALSE(world->current().scene->isFree(q, &report));
  EXPECT_EQ(report.kind, CollisionReport::Kind::Environment);
  EXPECT_EQ(report.hit.kind, EnvironmentHit::Kind::Voxel);
  EXPECT_TRUE(report.hit.voxel.contains(on_link));
  EXPECT_NEAR(report.hit.voxel.extents().maxCoeff(), res, 1e-12);
  // On OctoMap's grid: the cell's corner is a multiple of the resolution.
  const Vec3 corner = report.hit.voxel.min / res;
  EXPECT_NEAR((corner - corner.array().round().matrix()).norm(), 0.0, 1e-9);
  world->insertPoints({on_link}, res);  // the same voxel again: nothing new
  EXPECT_EQ(world->current().scene->environment().pointVoxelCount(), 3);
}

TEST(WorldPoints, PointsInsideTheMapsVoxelsAddNothing) {
  auto map = std::make_shared<OccupancyMap>();
  map->resolution = 0.1;
  map->occupied.push_back(Aabb::fromMinMax(Vec3(0, 0, 0), Vec3(0.4, 0.4, 0.4)));  // a coarse leaf
  map->known_bounds = map->occupied.back();
  map->occupied_leaves = 1;
  const Environment env({}, map);
  const Environment more = env.withPoints({Vec3(0.05, 0.05, 0.05), Vec3(0.35, 0.15, 0.25), Vec3(0.45, 0.05, 0.05)});
  EXPECT_EQ(more.pointVoxelCount(), 1);  // only the point outside the leaf
  EXPECT_EQ(env.pointVoxelCount(), 0);   // the old environment is unchanged
}

// A box's surface scanned into the shared OctoMap problem: the world with the points inserted answers as
// a map holding the same voxels among its own (the points' voxels checked as obstacles, the map's as
// voxels: two paths, one verdict).
TEST(WorldPoints, ScannedBoxAnswersAsTheSameVoxelsInTheMap) {
  CLEARWAY_SHARED_OR_SKIP(file, "scenes/bookshelf_small_panda/bookshelf_small_panda_0001.octomap.yaml");
  auto world = World::load(file);
  const std::shared_ptr<const Scene> base = world->current().scene;
  ASSERT_NE(base->environment().map(), nullptr);
  const double res = base->environment().map()->resolution;
  // The surface of a 30 cm box in front of the shelf, sampled every 7 mm.
  std::vector<Vec3> points;
  const Vec3 lo(0.35, -0.15, 0.35), hi(0.65, 0.15, 0.65);
  for (double u = 0.0; u <= 1.0; u += 0.007 / 0.3)
    for (double v = 0.0; v <= 1.0; v += 0.007 / 0.3)
      for (int axis = 0; axis < 3; ++axis)
        for (const double side : {0.0, 1.0}) {
          Vec3 t;
          t[axis] = side;
          t[(axis + 1) % 3] = u;
          t[(axis + 2) % 3] = v;
          points.push_back(lo + t.cwiseProduct(hi - lo));
        }
  world->insertPoints(points);
  EXPECT_GT(world->current().scene->environment().pointVoxelCount(), 100);
  auto map = std::make_shared<OccupancyMap>(*base->environment().map());
  for (const Vec3& p : points) {
    const Vec3 corner = (p / res).array().floor() * res;
    map->occupied.push_back(Aabb::fromMinMax(corner, corner + Vec3::Constant(res)));
  }
  const Scene same(base->description(), base->geometryPtr(), std::make_shared<const Environment>(std::vector<Obstacle>{}, map),
                   base->options());
  const Scene& edited = *world->current().scene;
  std::mt19937 rng(5);
  SceneContext a = edited.makeContext(), b = same.makeContext();
  int colliding = 0, changed = 0;
  SceneContext c = base->makeContext();
  for (int i = 0; i < 3000; ++i) {
    const std::vector<double> q = randomState(same, rng);
    const bool free = same.isFree(q.data(), b);
    ASSERT_EQ(edited.isFree(q.data(), a), free) << "state " << i;
    colliding += !free;
    changed += base->isFree(q.data(), c) != free;
  }
  EXPECT_GT(changed, 30) << "the scanned box was to stand where the arm reaches";
  EXPECT_LT(colliding, 3000);
}

// Readers check states on whatever snapshot is current while a writer edits; every verdict is then
// compared with the verdict of the very snapshot it was taken on, kept by the writer.
TEST(WorldThreads, EditsWhileOtherThreadsQuery) {
  TempDir dir;
  auto world = World::load(dir.write("w.yaml", armScene("", kWall)));
  std::mt19937 rng(3);
  std::vector<std::vector<double>> states;
  for (int i = 0; i < 64; ++i) states.push_back(randomState(*world->current().scene, rng));
  std::vector<std::shared_ptr<const WorldSnapshot>> versions{world->snapshot()};
  std::atomic<bool> done{false};
  struct Seen {
    std::uint64_t version;
    int state;
    bool free;
  };
  std::vector<std::vector<Seen>> seen(3);
  std::vector<std::thread> readers;
  for (int r = 0; r < 3; ++r)
    readers.emplace_back([&, r] {
      for (int i = 0; !done.load() || i < 200; ++i) {
        const WorldSnapshot& w = world->current();
        const int k = i % static_cast<int>(states.size());
        seen[r].push_back({w.version, k, w.scene->isFree(states[k])});
      }
    });
  std::vector<std::string> names;
  for (int edit = 0; edit < 150; ++edit) {
    if (names.size() > 10 && rng() % 3 == 0) {
      world->removeObstacle(names.front());
      names.erase(names.begin());
    } else if (!names.empty() && rng() % 3 == 0) {
      world->moveObstacle(names[rng() % names.size()], randomPose(rng));
    } else {
      names.push_back("o" + std::to_string(edit));
      world->addObstacle(randomObstacle(names.back(), rng));
    }
    versions.push_back(world->snapshot());
    if (edit % 50 == 25) {
      world->attach(stick());
      versions.push_back(world->snapshot());
    }
    if (edit % 50 == 40) {
      world->detach("stick");
      versions.push_back(world->snapshot());
    }
  }
  done = true;
  for (std::thread& t : readers) t.join();
  std::size_t total = 0;
  std::vector<char> met(versions.size(), 0);
  for (const std::vector<Seen>& list : seen)
    for (const Seen& s : list) {
      ASSERT_GE(s.version, 1u);
      ASSERT_LE(s.version, versions.size());
      const WorldSnapshot& v = *versions[s.version - 1];
      ASSERT_EQ(v.version, s.version);
      ASSERT_EQ(v.scene->isFree(states[s.state]), s.free) << "version " << s.version << ", state " << s.state;
      met[s.version - 1] = 1;
      ++total;
    }
  EXPECT_GE(total, 600u);
  EXPECT_GT(std::count(met.begin(), met.end(), 1), 1) << "the readers saw only one version";
}

TEST(DetachBodies, UndoesAttachBodies) {
  const RobotModel arm = [] {
    TempDir dir;
    return Scene::load(dir.write("w.yaml", armScene("", "")))->robot();
  }();
  AttachedBody box;
  box.name = "box";
  box.link = arm.linkIndex("tool0");
  box.element.primitive = Box(Vec3(0.1, 0.1, 0.1));
  box.touch_links = {arm.linkIndex("wrist_3_link")};
  AttachedBody mesh = box;
  mesh.name = "mesh";
  mesh.element.primitive.reset();
  mesh.element.mesh = 0;
  const RobotModel held = attachBodies(arm, {box, mesh}, {boxSurface(Vec3(0.1, 0.2, 0.3))});
  ASSERT_EQ(held.linkCount(), arm.linkCount() + 2);
  // Detaching the first leaves the second, its mesh renumbered, its touch pair kept.
  const RobotModel one = detachBodies(held, {"box"});
  EXPECT_EQ(one.linkCount(), arm.linkCount() + 1);
  const int m = one.linkIndex("mesh");
  ASSERT_GE(m, 0);
  EXPECT_EQ(one.meshes().size(), arm.meshes().size() + 1);
  EXPECT_EQ(one.meshes()[one.link(m).collisions[0].mesh].vertices.size(), 8u);
  EXPECT_EQ(one.disabledCollisions().size(), arm.disabledCollisions().size() + 1);
  const RobotModel none = detachBodies(one, {"mesh"});
  EXPECT_EQ(none.linkCount(), arm.linkCount());
  EXPECT_EQ(none.jointCount(), arm.jointCount());
  EXPECT_EQ(none.meshes().size(), arm.meshes().size());
  EXPECT_EQ(none.disabledCollisions().size(), arm.disabledCollisions().size());
  for (int l = 0; l < arm.linkCount(); ++l) EXPECT_EQ(none.link(l).name, arm.link(l).name);
  EXPECT_THROW(detachBodies(arm, {"forearm_link"}), std::invalid_argument);  // not a leaf
  EXPECT_THROW(detachBodies(arm, {"claw"}), std::invalid_argument);
}

}  // namespace
}  // namespace clearway
