// Editing a world between planning queries (issue: changing worlds), Clearway against a rebuild and
// against FCL 0.7's DynamicAABBTreeCollisionManager on the same edit sequence, in one run:
//   edits   n random static obstacles (boxes, spheres, cylinders in a 4 m cube), then 2,000 edits, a
//           third each of move, add and remove (an add then a remove keeps n steady). Clearway: the
//           Environment edit (a new version sharing the rest, O(log n)); the same plus the World's new
//           snapshot (Scene::withEnvironment and the motion checker, robots/arm6); a rebuild of the
//           environment from its obstacle list. FCL: setTransform + update(obj), registerObject,
//           unregisterObject on one manager (which FCL edits in place: no snapshot for other threads).
//   points  a 10,000-point cloud (a scanned table top and a box on it, 1 cm apart) into a world whose map
//           holds the floor: Clearway's withPoints (endpoints only), against OctoMap's updateNode per
//           point and insertPointCloud (with ray casting, which also clears free space), each followed by
//           what Clearway would then do without edits: write the map, read it (loadOctomap) and build the
//           environment.
// Reported: µs per edit (thread CPU time, mean over the sequence) and ratios. Absolute times on shared
// machines are noise; the ratios are the result.
//
// Usage: bench_edit [--obstacles N,N,...] [--edits E] [--seed S]
#include "bench_clock.h"
#include "fcl_robot.h"

#include <clearway/environment/environment.h>
#include <clearway/world/world.h>

#include <octomap/octomap.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#ifndef CLEARWAY_SOURCE_DIR
#define CLEARWAY_SOURCE_DIR "."
#endif

namespace cw = clearway;
using cw::bench::threadSeconds;
using cw::bench::toFcl;
using cw::bench::toFclShape;

namespace {

cw::Pose randomPose(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  Eigen::Quaterniond q(u(rng), u(rng), u(rng), u(rng));
  if (q.norm() < 1e-3) q = Eigen::Quaterniond::Identity();
  q.normalize();
  return cw::Pose::fromQuaternion(q.x(), q.y(), q.z(), q.w(), cw::Vec3(u(rng), u(rng), u(rng) + 2.0));
}

cw::Obstacle randomObstacle(int id, std::mt19937& rng) {
  std::uniform_real_distribution<double> size(0.02, 0.15);
  cw::Obstacle o;
  o.name = "o" + std::to_string(id);
  switch (rng() % 3) {
    case 0: o.shape = cw::Box(cw::Vec3(size(rng), size(rng), size(rng))); break;
    case 1: o.shape = cw::Sphere(size(rng)); break;
    default: o.shape = cw::Cylinder(size(rng), size(rng));
  }
  o.pose = randomPose(rng);
  return o;
}

struct Edit {
  enum Kind { Move, Add, Remove } kind;
  int slot;          // index into the live list at the time of the edit
  cw::Obstacle obstacle;  // Add: the new one; Move: the new pose in obstacle.pose
};

std::string armScene() {
  const std::string robots = std::string(CLEARWAY_SOURCE_DIR) + "/robots/arm6/";
  return "format: 1\nname: bench\nrobot:\n  urdf: " + robots + "arm6.urdf\n  srdf: " + robots +
         "arm6.srdf\n  group: [shoulder_pan_joint, shoulder_lift_joint, elbow_joint, wrist_1_joint, wrist_2_joint, "
         "wrist_3_joint]\nenvironment:\n  obstacles: []\nchecks: [self, environment, continuous]\n";
}

void benchEdits(int n, int n_edits, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<cw::Obstacle> live;
  int next_id = 0;
  for (int i = 0; i < n; ++i) live.push_back(randomObstacle(next_id++, rng));
  // The sequence, fixed before anything is timed.
  std::vector<Edit> edits;
  {
    int count = n;
    for (int e = 0; e < n_edits; ++e) {
      Edit ed{static_cast<Edit::Kind>(e % 3), 0, {}};
      if (ed.kind == Edit::Add) {
        ed.obstacle = randomObstacle(next_id++, rng);
        ++count;
      } else {
        ed.slot = static_cast<int>(rng() % count);
        if (ed.kind == Edit::Move) ed.obstacle.pose = randomPose(rng);
        else --count;
      }
      edits.push_back(ed);
    }
  }
  double t_env[3] = {0, 0, 0}, t_world[3] = {0, 0, 0}, t_fcl[3] = {0, 0, 0};
  int count[3] = {0, 0, 0};

  // Clearway Environment.
  {
    std::vector<std::string> names;
    for (const cw::Obstacle& o : live) names.push_back(o.name);
    cw::Environment env(live);
    for (const Edit& ed : edits) {
      const double t0 = threadSeconds();
      if (ed.kind == Edit::Move) env = env.withObstacleMoved(names[ed.slot], ed.obstacle.pose);
      else if (ed.kind == Edit::Add) env = env.withObstacle(ed.obstacle);
      else env = env.withoutObstacle(names[ed.slot]);
      t_env[ed.kind] += threadSeconds() - t0;
      ++count[ed.kind];
      if (ed.kind == Edit::Add) names.push_back(ed.obstacle.name);
      if (ed.kind == Edit::Remove) names.erase(names.begin() + ed.slot);
    }
  }
  // Clearway World (environment edit + new snapshot: scene and motion checker).
  {
    const std::string path = (std::filesystem::temp_directory_path() / "clearway_bench_edit.yaml").string();
    { std::FILE* f = std::fopen(path.c_str(), "w"); std::fputs(armScene().c_str(), f); std::fclose(f); }
    auto scene = cw::Scene::load(path);
    std::filesystem::remove(path);
    cw::World world(scene->withEnvironment(std::make_shared<const cw::Environment>(live)));
    std::vector<std::string> names;
    for (const cw::Obstacle& o : live) names.push_back(o.name);
    for (const Edit& ed : edits) {
      const double t0 = threadSeconds();
      if (ed.kind == Edit::Move) world.moveObstacle(names[ed.slot], ed.obstacle.pose);
      else if (ed.kind == Edit::Add) world.addObstacle(ed.obstacle);
      else world.removeObstacle(names[ed.slot]);
      t_world[ed.kind] += threadSeconds() - t0;
      if (ed.kind == Edit::Add) names.push_back(ed.obstacle.name);
      if (ed.kind == Edit::Remove) names.erase(names.begin() + ed.slot);
    }
  }
  // FCL's dynamic manager, edited in place.
  {
    fcl::DynamicAABBTreeCollisionManagerd manager;
    std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
    for (const cw::Obstacle& o : live) {
      objects.push_back(std::make_unique<fcl::CollisionObjectd>(toFclShape(o.shape), toFcl(o.pose)));
      objects.back()->computeAABB();
      manager.registerObject(objects.back().get());
    }
    manager.setup();
    for (const Edit& ed : edits) {
      const double t0 = threadSeconds();
      if (ed.kind == Edit::Move) {
        fcl::CollisionObjectd* obj = objects[ed.slot].get();
        obj->setTransform(toFcl(ed.obstacle.pose));
        obj->computeAABB();
        manager.update(obj);
      } else if (ed.kind == Edit::Add) {
        objects.push_back(std::make_unique<fcl::CollisionObjectd>(toFclShape(ed.obstacle.shape), toFcl(ed.obstacle.pose)));
        objects.back()->computeAABB();
        manager.registerObject(objects.back().get());
      } else {
        manager.unregisterObject(objects[ed.slot].get());
      }
      t_fcl[ed.kind] += threadSeconds() - t0;
      if (ed.kind == Edit::Remove) objects.erase(objects.begin() + ed.slot);
    }
  }
  // A rebuild from the obstacle list (the cost of an edit without edits), timed a few times.
  double t_rebuild = 0.0;
  const int rebuilds = 20;
  for (int r = 0; r < rebuilds; ++r) {
    const double t0 = threadSeconds();
    const cw::Environment env(live);
    t_rebuild += threadSeconds() - t0;
    if (env.obstacleCount() != live.size()) std::abort();
  }
  t_rebuild /= rebuilds;
  const char* kind[3] = {"move", "add", "remove"};
  for (int k = 0; k < 3; ++k) {
    const double env_us = 1e6 * t_env[k] / count[k], world_us = 1e6 * t_world[k] / count[k], fcl_us = 1e6 * t_fcl[k] / count[k];
    std::printf("%6d  %-6s  %10.2f  %10.2f  %10.2f  %10.2f  %9.1f  %9.2f\n", n, kind[k], env_us, world_us, fcl_us,
                1e6 * t_rebuild, 1e6 * t_rebuild / env_us, env_us / fcl_us);
  }
}

// The map's floor: a 2 m × 2 m slab of 2 cm voxels at z ∈ [0, 0.02).
octomap::OcTree floorMap(double res) {
  octomap::OcTree tree(res);
  for (double x = -1.0; x < 1.0; x += res)
    for (double y = -1.0; y < 1.0; y += res) tree.updateNode(octomap::point3d(x + res / 2, y + res / 2, res / 2), true);
  tree.updateInnerOccupancy();
  return tree;
}

// What Clearway does with a changed map without edits: write it, read it, build the environment.
double rebuildFrom(const octomap::OcTree& tree, const std::string& path) {
  const double t0 = threadSeconds();
  tree.writeBinaryConst(path);
  const cw::Environment env({}, std::make_shared<const cw::OccupancyMap>(cw::loadOctomap(path)));
  if (env.empty()) std::abort();
  return threadSeconds() - t0;
}

void benchPoints(unsigned seed) {
  const double res = 0.02;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.4, 0.4);
  // A table top at z = 0.75 and a box on it, as a depth camera at (0, -1.5, 1.5) sees them.
  std::vector<cw::Vec3> points;
  for (int i = 0; i < 10000; ++i) {
    if (i % 4 == 0) points.emplace_back(0.25 * u(rng), 0.25 * u(rng), 0.75 + 0.1 + 0.1 * u(rng));  // the box
    else points.emplace_back(u(rng) * 1.5, u(rng), 0.75);                                          // the table
  }
  const octomap::point3d sensor(0.0f, -1.5f, 1.5f);
  const std::string path = (std::filesystem::temp_directory_path() / "clearway_bench_points.bt").string();
  const octomap::OcTree floor = floorMap(res);
  floor.writeBinaryConst(path);
  const cw::Environment base({}, std::make_shared<const cw::OccupancyMap>(cw::loadOctomap(path)));

  double t0 = threadSeconds();
  const cw::Environment with = base.withPoints(points, res);
  const double t_clearway = threadSeconds() - t0;

  octomap::OcTree a(floor);
  t0 = threadSeconds();
  for (const cw::Vec3& p : points) a.updateNode(octomap::point3d(p.x(), p.y(), p.z()), true);
  const double t_update = threadSeconds() - t0;
  const double t_update_rebuild = rebuildFrom(a, path);

  octomap::OcTree b(floor);
  octomap::Pointcloud cloud;
  for (const cw::Vec3& p : points) cloud.push_back(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
  t0 = threadSeconds();
  b.insertPointCloud(cloud, sensor);
  const double t_rays = threadSeconds() - t0;
  const double t_rays_rebuild = rebuildFrom(b, path);
  std::filesystem::remove(path);

  std::printf("\npoints: 10,000 (%d new voxels of %.0f cm; the floor map holds %zu)\n", with.pointVoxelCount(), 100 * res,
              base.map()->occupied.size());
  std::printf("  %-44s %10.2f ms\n", "Clearway withPoints", 1e3 * t_clearway);
  std::printf("  %-44s %10.2f ms  (%.1fx Clearway)\n", "OctoMap updateNode per point + rebuild", 1e3 * (t_update + t_update_rebuild),
              (t_update + t_update_rebuild) / t_clearway);
  std::printf("  %-44s %10.2f ms  (of which rebuild %.2f ms)\n", "", 1e3 * (t_update + t_update_rebuild), 1e3 * t_update_rebuild);
  std::printf("  %-44s %10.2f ms  (%.1fx Clearway)\n", "OctoMap insertPointCloud (rays) + rebuild", 1e3 * (t_rays + t_rays_rebuild),
              (t_rays + t_rays_rebuild) / t_clearway);
  std::printf("  %-44s %10.2f ms  (of which rebuild %.2f ms)\n", "", 1e3 * (t_rays + t_rays_rebuild), 1e3 * t_rays_rebuild);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> sizes{100, 1000, 10000};
  int n_edits = 2000;
  unsigned seed = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has = i + 1 < argc;
    if (a == "--obstacles" && has) {
      sizes.clear();
      std::stringstream list(argv[++i]);
      for (std::string item; std::getline(list, item, ',');) sizes.push_back(std::atoi(item.c_str()));
    } else if (a == "--edits" && has) {
      n_edits = std::atoi(argv[++i]);
    } else if (a == "--seed" && has) {
      seed = static_cast<unsigned>(std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: bench_edit [--obstacles N,N,...] [--edits E] [--seed S]\n");
      return 2;
    }
  }
  std::printf("edits: %d per size, a third each of move / add / remove; µs per edit (thread CPU time)\n", n_edits);
  std::printf("%6s  %-6s  %10s  %10s  %10s  %10s  %9s  %9s\n", "n", "edit", "clearway", "world", "fcl", "rebuild",
              "rebuild/cw", "cw/fcl");
  for (const int n : sizes) benchEdits(n, n_edits, seed);
  benchPoints(seed);
  return 0;
}
