#pragma once
// Test support for the OMPL tests: an obstacle put where the robot is at a state, to block a path.
#include <clearway/scene/scene.h>

#include <string>
#include <vector>

namespace clearway::test {

/// A ball named "ball" of radius r, centred at `link`'s origin with the robot at state q: on the robot there.
inline Obstacle ballAtLink(const Scene& scene, const std::vector<double>& q, const std::string& link, double r) {
  SceneContext ctx = scene.makeContext();
  scene.computePoses(q.data(), ctx);
  Obstacle ball;
  ball.name = "ball";
  ball.shape = Sphere(r);
  ball.pose = Pose::translation(ctx.poses()[scene.robot().linkIndex(link)].t);
  return ball;
}

}  // namespace clearway::test
