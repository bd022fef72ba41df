// The enclosing layer: at random configurations of our arms and the shared robots, a pair it calls apart
// is farther apart than the padding by the exact meshes, and it clears pairs the bounding balls alone do
// not (a layer that never fires would pass the first check).
#include <clearway/body/enclosing.h>
#include <clearway/kinematics/forward_kinematics.h>
#include <clearway/load/robot_loader.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "shared_data.h"

namespace clearway {
namespace {

std::vector<double> randomState(const RobotModel& m, std::mt19937_64& rng) {
  std::vector<double> q(m.variableCount());
  for (int i = 0; i < m.variableCount(); ++i) {
    const JointVariable& v = m.variables()[i];
    const double lo = std::isfinite(v.lower) ? v.lower : -3.0, hi = std::isfinite(v.upper) ? v.upper : 3.0;
    q[i] = std::uniform_real_distribution<double>(lo, hi)(rng);
  }
  return q;
}

TEST(EnclosingBalls, ApartOnlyWhereTheMeshesAreApart) {
  std::vector<std::string> urdfs{std::string(CLEARWAY_SOURCE_DIR) + "/robots/arm6/arm6.urdf",
                                 std::string(CLEARWAY_SOURCE_DIR) + "/robots/twin_arm/twin_arm.urdf"};
  for (const char* rel : {"robots/panda/panda.urdf", "robots/ur5/ur5.urdf"}) {
    CLEARWAY_REQUIRE_SHARED(rel);
    urdfs.push_back(test::sharedPath(rel));
  }
  const Tolerances tol;
  for (const std::string& urdf : urdfs) {
    auto model = std::make_shared<const RobotModel>(loadRobot(urdf));
    const RobotGeometry geometry(model);
    EnclosingBalls balls(geometry);
    ASSERT_TRUE(balls.madeFor(geometry));
    std::vector<Pose> poses(model->linkCount());
    std::mt19937_64 rng(7);
    const std::vector<int>& links = geometry.geometricLinks();
    int apart = 0, by_parts = 0, pairs = 0;
    for (int s = 0; s < 150; ++s) {
      const std::vector<double> q = randomState(*model, rng);
      computeLinkPoses(*model, q.data(), poses.data());
      balls.place(poses.data());
      for (std::size_t i = 0; i < links.size(); ++i)
        for (std::size_t j = i + 1; j < links.size(); ++j) {
          const int a = links[i], b = links[j];
          const LinkGeometry &ga = *geometry.link(a), &gb = *geometry.link(b);
          for (double padding : {0.0, 0.02}) {
            ++pairs;
            if (!balls.apart(a, b, padding, tol)) continue;
            ++apart;
            const double centres = (poses[a] * ga.sphereCenter() - poses[b] * gb.sphereCenter()).norm();
            by_parts += centres <= ga.sphereRadius() + gb.sphereRadius() + padding;
            EXPECT_FALSE(meshesIntersect(ga, poses[a], gb, poses[b], tol, GeometryMode::Mesh, padding))
                << urdf << ": links " << model->link(a).name << " and " << model->link(b).name << " called apart";
          }
        }
    }
    std::printf("  %s: %d of %d pairs apart, %d of them by the parts' balls\n", urdf.c_str(), apart, pairs, by_parts);
    EXPECT_GT(apart, 0);
    bool several = false;  // (a link of one primitive has one part: only its bounding ball)
    for (int a : links) several |= geometry.link(a)->parts().size() > 1;
    if (several) EXPECT_GT(by_parts, 0) << urdf << ": the parts' balls never clear a pair the bounding balls keep";
    // A non-finite pose is never apart.
    poses[links.back()].t.x() = std::numeric_limits<double>::quiet_NaN();
    balls.place(poses.data());
    for (int a : links)
      if (a != links.back()) EXPECT_FALSE(balls.apart(a, links.back(), 0.0, tol));
  }
}

TEST(EnclosingBalls, MadeOnlyForItsRobot) {
  auto model = std::make_shared<const RobotModel>(loadRobot(std::string(CLEARWAY_SOURCE_DIR) + "/robots/arm6/arm6.urdf"));
  const RobotGeometry a(model), b(model);
  EXPECT_TRUE(EnclosingBalls(a).madeFor(a));
  EXPECT_FALSE(EnclosingBalls(a).madeFor(b));
  EXPECT_FALSE(EnclosingBalls().madeFor(a));
}

}  // namespace
}  // namespace clearway
