#pragma once
// What a SceneContext holds (scene_queries.cpp): one thread's scratch for a scene's queries.
#include <clearway/body/enclosing.h>
#include <clearway/kinematics/kinematic_lanes.h>
#include <clearway/scene/scene.h>
#include <clearway/scene/self_collision.h>

#include <cstdint>
#include <optional>
#include <vector>

namespace clearway::scene_detail {

struct SceneScratch {
  std::vector<double> q;      // the full joint vector (group values, held values, defaults)
  // The full joint vector of a state the pair tables are asked before it is placed (q and poses stay the
  // last placed state's until it is).
  std::vector<double> tabled_q;
  std::vector<Pose> poses;    // world pose of every link
  SelfCollisionContext self;  // the self-collision checker's scratch
  // The links' enclosing balls at the current query's poses: the clearance grid's look-ups, shared with
  // the self check of the same state.
  EnclosingBalls balls;
  int env_last_hit = -1;  // the environment link (index into Scene::environmentLinks()) that last met an obstacle
  SceneCounters counters;
  std::optional<KinematicLanes> lanes;  // Scene::areFree's kinematics over lanes of states
  std::vector<double> lane_q;           // KinematicLanes::kMaxLanes joint vectors
  std::vector<Pose> lane_poses;         // KinematicLanes::kMaxLanes sets of link poses
  std::uint64_t owner = 0;              // the serial of the scene whose held values q and lane_q hold
};

}  // namespace clearway::scene_detail
