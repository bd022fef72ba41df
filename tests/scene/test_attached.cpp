// Attached bodies (robot.attached): a stick held by our arm collides with a wall the bare arm clears;
// it may touch its touch links and its link, nothing else; the certified motion check catches it
// sweeping through a post thinner than a 1% sampling step, which the sampling misses; bad
// declarations name the file and key.
#include <clearway/motion/motion.h>
#include <clearway/scene/scene.h>

#include "load/robot_files.h"
#include "scene/arm_scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace clearway {
namespace {

using test::armScene;
using test::TempDir;

const char* const kStick =
    "    - {name: stick, link: tool0, box: {size: [0.6, 0.02, 0.02]}, pose: {position: [0.3, 0, 0]},"
    " touch_links: [wrist_3_link]}\n";
const char* const kWall = "    - {name: wall, box: {size: [0.004, 1.0, 3.0]}, pose: {position: [0.3, 0, 1.5]}}\n";

TEST(Attached, CollidesWhereTheBareArmDoesNot) {
  TempDir dir;
  const auto held = Scene::load(dir.write("held.yaml", armScene(kStick, kWall)));
  const auto bare = Scene::load(dir.write("bare.yaml", armScene("", kWall)));
  const std::vector<double> upright(6, 0.0), turned{1.57, 0, 0, 0, 0, 0};
  EXPECT_TRUE(bare->isFree(upright));
  CollisionReport report;
  ASSERT_FALSE(held->isFree(upright, &report));
  ASSERT_EQ(report.kind, CollisionReport::Kind::Environment);
  EXPECT_EQ(held->robot().link(report.link).name, "stick");
  ASSERT_NE(report.hit.obstacle, nullptr);
  EXPECT_EQ(report.hit.obstacle->name, "wall");
  EXPECT_TRUE(held->isFree(turned));  // pointing along y, away from the wall
  EXPECT_EQ(held->dimension(), bare->dimension());  // the state is the arm's alone
}

TEST(Attached, TouchesOnlyItsTouchLinksAndItsLink) {
  TempDir dir;
  // A ball fixed to the base where the upright stick passes: a self collision between two held bodies.
  const std::string ball = "    - {name: ball, link: base_link, sphere: {radius: 0.05}, pose: {position: [0.3, 0, 0]}}\n";
  const auto plain = Scene::load(dir.write("plain.yaml", armScene(kStick, "")));
  const RobotModel& m = plain->robot();
  const int stick = m.linkIndex("stick");
  ASSERT_GE(stick, 0);
  EXPECT_FALSE(plain->filter().enabled(stick, m.linkIndex("wrist_3_link")));  // a touch link
  EXPECT_FALSE(plain->filter().enabled(stick, m.linkIndex("tool0")));         // its link (no geometry here)
  EXPECT_TRUE(plain->filter().enabled(stick, m.linkIndex("forearm_link")));
  EXPECT_TRUE(plain->filter().enabled(stick, m.linkIndex("base_link")));
  // Where the ball sits at the stick's height, the two held bodies meet.
  SceneContext ctx = plain->makeContext();
  plain->computePoses(std::vector<double>(6, 0.0).data(), ctx);
  const double height = ctx.poses()[stick].t.z();
  std::string at_height = ball;
  at_height.replace(at_height.find("[0.3, 0, 0]"), 11, "[0.3, 0, " + std::to_string(height) + "]");
  const auto both = Scene::load(dir.write("both.yaml", armScene(std::string(kStick) + at_height, "")));
  CollisionReport report;
  ASSERT_FALSE(both->isFree(std::vector<double>(6, 0.0), &report));
  ASSERT_EQ(report.kind, CollisionReport::Kind::Self);
  EXPECT_EQ(both->robot().link(report.link).name == "stick" ? both->robot().link(report.other_link).name
                                                               : both->robot().link(report.link).name,
            "ball");
}

TEST(Attached, CertifiedCatchesASweepThroughAPostThatSamplingMisses) {
  TempDir dir;
  // A 2 mm stick, and a 2 mm post half a metre from the pan axis, midway between two states of the 1%
  // sampling of the pan sweep −0.5 → 0.5: every sampled state clears it by 0.5 mm.
  const std::string thin = "    - {name: stick, link: tool0, box: {size: [0.6, 0.002, 0.002]}, pose: {position: [0.3, 0, 0]}}\n";
  const auto probe = Scene::load(dir.write("probe.yaml", armScene(thin, "")));
  const double a = -0.5, b = 0.5, resolution = 0.01;
  const double n = std::ceil((b - a) / resolution);  // as the sampled check counts its steps
  const double mid = a + (b - a) * (std::floor(n / 2) + 0.5) / n;
  SceneContext ctx = probe->makeContext();
  probe->computePoses(std::vector<double>{mid, 0, 0, 0, 0, 0}.data(), ctx);
  const Vec3 post = ctx.poses()[probe->robot().linkIndex("stick")] * Vec3(0.2, 0, 0);  // 0.5 m out along the stick
  const std::string obstacles = "    - {name: post, cylinder: {radius: 0.001, length: 0.1}, pose: {position: [" +
                                std::to_string(post.x()) + ", " + std::to_string(post.y()) + ", " +
                                std::to_string(post.z()) + "]}}\n";
  const auto scene = Scene::load(dir.write("post.yaml", armScene(thin, obstacles)));
  const std::vector<double> q0{a, 0, 0, 0, 0, 0}, q1{b, 0, 0, 0, 0, 0};
  ASSERT_TRUE(scene->isFree(q0));
  ASSERT_TRUE(scene->isFree(q1));
  ASSERT_FALSE(scene->isFree(std::vector<double>{mid, 0, 0, 0, 0, 0}));  // the post is on the stick's path
  MotionChecker certified(scene);
  MotionContext cctx = certified.makeContext();
  const MotionResult c = certified.check(q0.data(), q1.data(), cctx, true);
  EXPECT_FALSE(c.free);
  EXPECT_EQ(scene->robot().link(c.report.link).name, "stick");
  MotionOptions sampled;
  sampled.mode = MotionMode::Sampled;
  sampled.resolution = resolution;
  MotionChecker one_percent(scene, sampled);
  MotionContext sctx = one_percent.makeContext();
  EXPECT_TRUE(one_percent.check(q0.data(), q1.data(), sctx).free) << "the 1% sampling was to step over the post";
}

// Found by fuzz_scene_attached: a body the scene file allows a pair with (robot.allow) could not be taken
// off (Scene::withoutAttached, World::detach, Python's without_attached): the scene built without it still
// allowed the pair, and its check of the file's keys threw LoadError (key 'robot.allow[0]': link 'stick'
// is not in robot 'arm6'). The pairs naming the body now go with it; the others stay.
TEST(Attached, TakingABodyOffTakesItsAllowedPairsOff) {
  TempDir dir;
  std::string text = armScene(kStick, kWall);
  text.insert(text.find("environment:\n"), "  allow: [[stick, forearm_link], [base_link, forearm_link]]\n");
  const auto held = Scene::load(dir.write("held.yaml", text));
  const RobotModel& m = held->robot();
  EXPECT_FALSE(held->filter().enabled(m.linkIndex("stick"), m.linkIndex("forearm_link")));
  std::shared_ptr<const Scene> bare;
  ASSERT_NO_THROW(bare = held->withoutAttached("stick"));
  EXPECT_LT(bare->robot().linkIndex("stick"), 0);
  ASSERT_EQ(bare->description().allow.size(), 1u);
  EXPECT_EQ(bare->description().allow[0], std::make_pair(std::string("base_link"), std::string("forearm_link")));
  const RobotModel& b = bare->robot();
  EXPECT_FALSE(bare->filter().enabled(b.linkIndex("base_link"), b.linkIndex("forearm_link")));
  const std::vector<double> upright(6, 0.0);
  EXPECT_FALSE(held->isFree(upright));  // the stick in the wall
  EXPECT_TRUE(bare->isFree(upright));
  // Held again, as the file holds it.
  SceneDescription::AttachedSpec stick = held->description().attached[0];
  const auto again = bare->withAttached(stick);
  EXPECT_FALSE(again->isFree(upright));
}

// Found by fuzz_scene_edits: an edit (Python's with_attached) placed a point 8.5e307 m from its link. The
// link's pose overflowed: isFree called the state colliding, a cast motion of length zero from it free.
// Bodies reaching beyond kMaxInputLength are refused, as a scene file's lengths are; one within it holds.
TEST(Attached, EditedBodiesBeyondTheLargestLengthAreRefused) {
  TempDir dir;
  const auto bare = Scene::load(dir.write("bare.yaml", armScene("", kWall)));
  const auto spec = [](Shape shape, const Vec3& at) {
    SceneDescription::AttachedSpec a;
    a.body.name = "far";
    a.link = "forearm_link";
    a.body.shape = std::move(shape);
    a.body.pose = Pose::fromQuaternion(0, 0, 0, 1, at);
    return a;
  };
  const std::pair<SceneDescription::AttachedSpec, const char*> refused[] = {
      {spec(Point(Vec3(0.1, 0.2, 0.3)), Vec3(8.4716234799357126e307, -2.0596186621375958e307, 1.6)), "point near 1e308"},
      {spec(Sphere(0.1), Vec3(0, 2e6, 0)), "sphere 2e6 m away"},
      {spec(Box(Vec3(3e6, 0.1, 0.1)), Vec3::Zero()), "box 3e6 m long"},
      {spec(Point(Vec3(0, 0, -1.5e6)), Vec3::Zero()), "point 1.5e6 m below its frame"},
  };
  for (const auto& [a, what] : refused) {
    SCOPED_TRACE(what);
    try {
      bare->withAttached(a);
      ADD_FAILURE() << "attached";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("attach 'far': the body reaches beyond 1000000 m"), std::string::npos) << e.what();
    }
  }
  // Within the limit: a ball 900 km away touches nothing; a ball of radius 900 km holds the wall.
  const auto far = bare->withAttached(spec(Sphere(0.05), Vec3(9e5, 0, 0)));
  EXPECT_TRUE(far->isFree(std::vector<double>(6, 0.0)));
  const auto huge = bare->withAttached(spec(Sphere(9e5), Vec3::Zero()));
  EXPECT_FALSE(huge->isFree(std::vector<double>(6, 0.0)));
}

TEST(Attached, BadDeclarationsNameTheKey) {
  TempDir dir;
  struct Case {
    std::string attached, key, reason;
  };
  const Case cases[] = {
      {"    - {name: stick, link: hand, sphere: {radius: 0.1}}\n", "key 'robot.attached[0].link'", "link 'hand' is not in robot"},
      {"    - {name: stick, link: tool0, sphere: {radius: 0.1}, touch_links: [claw]}\n",
       "key 'robot.attached[0].touch_links[0]'", "link 'claw' is not in robot"},
      {"    - {name: forearm_link, link: tool0, sphere: {radius: 0.1}}\n", "key 'robot.attached'", "already a link"},
      {"    - {link: tool0, sphere: {radius: 0.1}}\n", "key 'robot.attached[0].name'", "missing"},
      {"    - {name: stick, sphere: {radius: 0.1}}\n", "key 'robot.attached[0].link'", "missing"},
      {"    - {name: stick, link: tool0, sphere: {radius: 0.1}, box: {size: [1, 1, 1]}}\n", "key 'robot.attached[0]'",
       "exactly one of box, sphere"},
      {"    - {name: stick, link: tool0, sphere: {radius: 0.1}, velocity: [1, 0, 0]}\n", "key 'robot.attached[0].velocity'", "unknown key"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.attached);
    const std::string path = dir.write("bad.yaml", armScene(c.attached, kWall));
    EXPECT_LOAD_ERROR(Scene::load(path), path, c.key, c.reason);
  }
}

}  // namespace
}  // namespace clearway
