// The obstacles' oriented boxes (environment/obstacle_boxes.h): a ball they call clear is farther than its
// slack from every obstacle, of every shape, at any pose, near the origin and 10⁵ m from it, on every SIMD
// target; a ball that reaches an obstacle is never clear; and the boxes clear balls just beyond a box
// obstacle (they are as tight as its box). Then which worlds have them.
#include <clearway/environment/environment.h>
#include <clearway/environment/obstacle_boxes.h>
#include <clearway/kinematics/kinematic_lanes.h>
#include <clearway/narrowphase/gjk.h>

#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "box_surface.h"
#include "forced_target.h"

namespace clearway {
namespace {

Mat3 randomRotation(std::mt19937& rng) {
  std::normal_distribution<double> n;
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
}

// 1–12 obstacles of every kind (each primitive, and a closed box mesh) turned at random around `centre`.
std::vector<Obstacle> randomObstacles(std::mt19937& rng, const Vec3& centre) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), size(0.01, 0.3);
  const int n = std::uniform_int_distribution<int>(1, 12)(rng);
  std::vector<Obstacle> out;
  for (int i = 0; i < n; ++i) {
    Obstacle o;
    o.name = "o" + std::to_string(i);
    o.pose.R = randomRotation(rng);
    o.pose.t = centre + Vec3(u(rng), u(rng), u(rng));
    switch (i % 8) {
      case 0:
        o.shape = Box(Vec3(size(rng), size(rng), size(rng)));
        break;
      case 1:
        o.shape = Sphere(size(rng));
        break;
      case 2:
        o.shape = Cylinder(size(rng), size(rng));
        break;
      case 3:
        o.shape = Capsule(size(rng), size(rng));
        break;
      case 4:
        o.shape = Cone(size(rng), size(rng));
        break;
      case 5:
        o.shape = Segment(Vec3(u(rng), u(rng), u(rng)) * 0.2, Vec3(u(rng), u(rng), u(rng)) * 0.2);
        break;
      case 6:
        o.shape = Box(Vec3(size(rng), size(rng), 0.0));
        break;  // a flat box
      default:
        o.mesh = std::make_shared<const LinkGeometry>(test::boxSurface(Vec3(size(rng), size(rng), size(rng))));
    }
    out.push_back(std::move(o));
  }
  return out;
}

// The exact distance from a point to an obstacle (GJK, to its tolerance).
double distanceTo(const Obstacle& o, const Vec3& p) {
  const Pose at = Pose::translation(p);
  return o.mesh ? shapeLinkDistance(Point(), at, *o.mesh, o.pose).distance
                : gjkDistance(Shape(Point()), at, o.shape, o.pose).distance;
}

TEST(ObstacleBoxes, AClearBallIsThatFarFromEveryObstacleAndANearOneIsNever) {
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> u(-1.5, 1.5), unit(0.0, 1.0);
  long clear = 0, tight = 0, tight_asked = 0;
  for (const std::int64_t target : KinematicLanes::targets()) {  // the lanes' targets (simd_targets.h)
    const test::ForcedTarget forced(target);
    for (int world = 0; world < 60; ++world) {
      const Vec3 centre = world % 2 ? Vec3(1e5, -1e5, 3e4) : Vec3::Zero();
      const std::vector<Obstacle> obstacles = randomObstacles(rng, centre);
      const Environment env(obstacles);
      const ObstacleBoxes* boxes = env.obstacleBoxes();
      ASSERT_NE(boxes, nullptr);
      ASSERT_EQ(boxes->size(), static_cast<int>(obstacles.size()));
      for (int k = 0; k < 200; ++k) {
        const Vec3 c = centre + Vec3(u(rng), u(rng), u(rng));
        double nearest = std::numeric_limits<double>::infinity();
        int closest = 0;
        for (std::size_t i = 0; i < obstacles.size(); ++i) {
          const double d = distanceTo(obstacles[i], c);
          if (d < nearest) nearest = d, closest = static_cast<int>(i);
        }
        const double slack = k % 3 == 0 ? 0.0 : 0.05 * unit(rng);
        // GJK's own error, and then some: a ball this much past the nearest obstacle's slack reaches it.
        const double eta = 1e-8 * (1.0 + c.norm());
        if (nearest <= slack + eta) continue;
        const double radius = (nearest - slack) * unit(rng);
        if (boxes->ballClear(c, radius, slack)) {
          ++clear;
          for (const Obstacle& o : obstacles)
            ASSERT_GT(distanceTo(o, c) + eta, radius + slack)
                << hwy::TargetName(target) << ": a ball " << radius << " m about " << c.transpose() << " within slack "
                << slack << " of obstacle " << o.name << " called clear";
        }
        EXPECT_FALSE(boxes->ballClear(c, nearest - slack + eta, slack))
            << hwy::TargetName(target) << ": a ball reaching obstacle " << obstacles[closest].name << " called clear";
        // Beside a box obstacle, whose box is itself, a ball just short of it is clear (unless another is near).
        if (std::holds_alternative<Box>(obstacles[closest].shape) && !obstacles[closest].mesh &&
            nearest > slack + 1e-3) {
          double second = std::numeric_limits<double>::infinity();
          for (std::size_t i = 0; i < obstacles.size(); ++i)
            if (static_cast<int>(i) != closest) second = std::min(second, distanceTo(obstacles[i], c));
          if (second > nearest + 0.8) {  // (no other box reaches 0.8 m beyond its obstacle)
            ++tight_asked;
            tight += boxes->ballClear(c, nearest - slack - 1e-9 * (1.0 + c.norm()), slack);
          }
        }
      }
    }
  }
  EXPECT_GT(clear, 1000) << "the boxes cleared too few balls to have been tested";
  EXPECT_GT(tight_asked, 20);
  EXPECT_EQ(tight, tight_asked) << "a ball just short of a box obstacle was not cleared: the boxes are loose";
}

TEST(ObstacleBoxes, NonFiniteBallsAreNeverClear) {
  const ObstacleBoxes::Placed box{Pose::translation(Vec3(10.0, 0.0, 0.0)),
                                  Aabb::fromCenterHalf(Vec3::Zero(), Vec3::Ones())};
  const auto boxes = ObstacleBoxes::build({box});
  ASSERT_NE(boxes, nullptr);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(boxes->ballClear(Vec3::Zero(), 1.0, 0.0));
  EXPECT_FALSE(boxes->ballClear(Vec3(nan, 0.0, 0.0), 1.0, 0.0));
  EXPECT_FALSE(boxes->ballClear(Vec3(-inf, 0.0, 0.0), 1.0, 0.0));
  EXPECT_FALSE(boxes->ballClear(Vec3::Zero(), nan, 0.0));
  EXPECT_FALSE(boxes->ballClear(Vec3::Zero(), inf, 0.0));
  EXPECT_FALSE(boxes->ballClear(Vec3::Zero(), 1.0, nan));
  EXPECT_FALSE(boxes->ballClear(Vec3::Zero(), 9.0, 0.0));  // touching the box's face
}

TEST(ObstacleBoxes, NoneForNoBoxesTooManyOrAPoseThatIsNoRotation) {
  const ObstacleBoxes::Placed box{Pose::identity(), Aabb::fromCenterHalf(Vec3::Zero(), Vec3::Ones())};
  EXPECT_EQ(ObstacleBoxes::build({}), nullptr);
  EXPECT_NE(ObstacleBoxes::build(std::vector<ObstacleBoxes::Placed>(ObstacleBoxes::kMaxBoxes, box)), nullptr);
  EXPECT_EQ(ObstacleBoxes::build(std::vector<ObstacleBoxes::Placed>(ObstacleBoxes::kMaxBoxes + 1, box)), nullptr);
  ObstacleBoxes::Placed stretched = box;
  stretched.pose.R(0, 0) = 1.0 + 1e-9;  // a scale, not a rotation: distances in its frame are not the world's
  EXPECT_EQ(ObstacleBoxes::build({box, stretched}), nullptr);
  ObstacleBoxes::Placed empty = box;
  empty.box = Aabb();
  EXPECT_EQ(ObstacleBoxes::build({empty}), nullptr);
}

TEST(ObstacleBoxes, AWorldHasThemOnlyWhileTheyAreAllThereIsToHit) {
  Obstacle wall;
  wall.name = "wall";
  wall.shape = Box(Vec3(0.1, 1.0, 1.0));
  wall.pose = Pose::translation(Vec3(1.0, 0.0, 0.0));
  const Environment env({wall});
  ASSERT_NE(env.obstacleBoxes(), nullptr);
  // An edit builds its own; a moving obstacle or the map's voxels are not among them, so there are none.
  Obstacle post = wall;
  post.name = "post";
  post.pose.t.x() = -1.0;
  EXPECT_EQ(env.withObstacle(post).obstacleBoxes()->size(), 2);
  EXPECT_EQ(env.withObstacle(post).withoutObstacle("wall").obstacleBoxes()->size(), 1);
  Obstacle moving = post;
  moving.velocity = Vec3(0.1, 0.0, 0.0);
  EXPECT_EQ(env.withObstacle(moving).obstacleBoxes(), nullptr);
  auto map = std::make_shared<OccupancyMap>();
  map->resolution = 0.1;
  map->occupied.push_back(Aabb::fromCenterHalf(Vec3(0.0, 2.0, 0.0), Vec3::Constant(0.05)));
  EXPECT_EQ(env.withMap(map).obstacleBoxes(), nullptr);
  // Points' voxels are static items: boxes of their own.
  EXPECT_EQ(env.withPoints({Vec3(0.0, -2.0, 0.0)}, 0.1).obstacleBoxes()->size(), 2);
  // Past kMaxBoxes the trees and the grid take them all.
  std::vector<Obstacle> many;
  for (int i = 0; i <= ObstacleBoxes::kMaxBoxes; ++i) {
    Obstacle o = wall;
    o.name = "w" + std::to_string(i);
    o.pose.t.y() = 3.0 * i;
    many.push_back(o);
  }
  EXPECT_EQ(Environment(many).obstacleBoxes(), nullptr);
  many.pop_back();
  EXPECT_NE(Environment(many).obstacleBoxes(), nullptr);
  // Without them stays without, through edits.
  EXPECT_EQ(env.withoutObstacleBoxes().obstacleBoxes(), nullptr);
  EXPECT_EQ(env.withoutObstacleBoxes().withObstacle(post).obstacleBoxes(), nullptr);
}

}  // namespace
}  // namespace clearway
