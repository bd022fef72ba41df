// Self-collision per configuration on the shared Panda and UR5, Clearway against FCL 0.7 in the same
// run, on the same meshes and the same pair list (the SRDF's and the adjacency filter's).
//
// For each robot: N random joint vectors within the limits (fixed seed); every checked pair is tested
// until the first collision (what a validity checker does). Clearway runs in Mesh mode (exact) and Hull
// mode (conservative), with one context kept across states (as a planner's thread keeps it); FCL runs
// BVHModel<OBBRSS> and BVHModel<OBB> collision objects, one per link, fcl::collide with one contact.
// Reported: ns per state, the colliding fraction, verdict agreement with FCL OBBRSS (Mesh must agree on
// every state; Hull may only add collisions), and the ratio FCL / Clearway. Also the load time.
//
// Usage: bench_selfcollision [--states N] [--shared DIR] [--csv FILE]
#include <clearway/kinematics/forward_kinematics.h>
#include <clearway/load/robot_loader.h>
#include <clearway/scene/self_collision.h>

#include "bench_clock.h"
#include "fcl_robot.h"

#include <fcl/fcl.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <vector>

#ifndef CLEARWAY_SHARED_DIR
#define CLEARWAY_SHARED_DIR "../shared"
#endif

namespace cw = clearway;

namespace {

using clearway::bench::threadSeconds;

struct Row {
  std::string robot, method;
  double ns_per_state;
  double colliding_fraction;
  int disagreements;  // with FCL OBBRSS
  double ratio;       // FCL OBBRSS time / this method's time
};

std::vector<std::vector<double>> randomStates(const cw::RobotModel& m, int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<std::vector<double>> out(n, std::vector<double>(m.variableCount()));
  for (auto& q : out)
    for (int v = 0; v < m.variableCount(); ++v) {
      const cw::JointVariable& var = m.variables()[v];
      const double lo = std::isfinite(var.lower) ? var.lower : -M_PI, hi = std::isfinite(var.upper) ? var.upper : M_PI;
      q[v] = std::uniform_real_distribution<double>(lo, hi)(rng);
    }
  return out;
}

void benchRobot(const std::string& name, const std::string& urdf, const std::string& srdf, int n,
                std::vector<Row>& rows) {
  const auto t0 = std::chrono::steady_clock::now();
  auto model = std::make_shared<const cw::RobotModel>(cw::loadRobot(urdf, srdf));
  auto geometry = std::make_shared<const cw::RobotGeometry>(model);
  const double load_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  const cw::CollisionFilter filter(*model);
  cw::SelfCollisionOptions hull_options;
  hull_options.mode = cw::GeometryMode::Hull;
  const cw::SelfCollision mesh(geometry, filter), hull(geometry, filter, hull_options);
  const auto t1 = std::chrono::steady_clock::now();
  const cw::bench::FclRobot<fcl::OBBRSSd> obbrss(*model);
  const cw::bench::FclRobot<fcl::OBBd> obb(*model);
  const double fcl_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count();
  std::printf("%s: %d links, %zu checked pairs, %zu triangles; load (URDF + meshes + trees + hulls) %.1f ms, "
              "FCL BVH build (both) %.1f ms\n",
              name.c_str(), model->linkCount(), mesh.pairs().size(), [&] {
                std::size_t t = 0;
                for (int i : geometry->geometricLinks()) t += geometry->link(i)->triangles().size();
                return t;
              }(), load_ms, fcl_ms);

  const auto states = randomStates(*model, n, 20261123);
  std::vector<std::vector<cw::Pose>> poses(n, std::vector<cw::Pose>(model->linkCount()));
  for (int s = 0; s < n; ++s) cw::computeLinkPoses(*model, states[s].data(), poses[s].data());

  // Each method over all states, 3 interleaved passes, the fastest pass counted (thread CPU time).
  auto runClearway = [&](const cw::SelfCollision& c, std::vector<char>& verdict) {
    cw::SelfCollisionContext ctx = c.makeContext();
    verdict.assign(n, 0);
    const double t = threadSeconds();
    for (int s = 0; s < n; ++s) verdict[s] = c.firstCollision(poses[s].data(), ctx) != nullptr;
    return threadSeconds() - t;
  };
  auto runFcl = [&](const auto& robot, std::vector<char>& verdict) {
    verdict.assign(n, 0);
    const double t = threadSeconds();
    for (int s = 0; s < n; ++s)
      for (const cw::LinkPair& p : mesh.pairs())
        if (robot.pairCollides(p.a, p.b, poses[s].data())) {
          verdict[s] = 1;
          break;
        }
    return threadSeconds() - t;
  };
  std::vector<char> v_mesh, v_hull, v_obbrss, v_obb;
  double t_mesh = 1e30, t_hull = 1e30, t_obbrss = 1e30, t_obb = 1e30;
  for (int pass = 0; pass < 3; ++pass) {
    t_mesh = std::min(t_mesh, runClearway(mesh, v_mesh));
    t_hull = std::min(t_hull, runClearway(hull, v_hull));
    t_obbrss = std::min(t_obbrss, runFcl(obbrss, v_obbrss));
    t_obb = std::min(t_obb, runFcl(obb, v_obb));
  }
  auto add = [&](const char* method, double t, const std::vector<char>& v) {
    int dis = 0;
    for (int s = 0; s < n; ++s) dis += v[s] != v_obbrss[s];
    rows.push_back({name, method, 1e9 * t / n, std::count(v.begin(), v.end(), 1) / double(n), dis, t_obbrss / t});
  };
  add("clearway-mesh", t_mesh, v_mesh);
  add("clearway-hull", t_hull, v_hull);
  add("fcl-obbrss", t_obbrss, v_obbrss);
  add("fcl-obb", t_obb, v_obb);
  int hull_free_mesh_hit = 0;  // hull mode is conservative: it must never say free where mesh collides
  for (int s = 0; s < n; ++s) hull_free_mesh_hit += v_mesh[s] && !v_hull[s];
  std::printf("  %s: hull said free where mesh collides: %d states (must be 0)\n", name.c_str(), hull_free_mesh_hit);
  for (int s = 0; s < n; ++s)
    if (v_mesh[s] != v_obbrss[s]) {
      std::printf("  disagreement at state %d: clearway-mesh %d, fcl-obbrss %d\n", s, v_mesh[s], v_obbrss[s]);
      if (s > 20) break;
    }
}

}  // namespace

int main(int argc, char** argv) {
  int n = 10000;
  std::string shared = CLEARWAY_SHARED_DIR, csv;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--states") && i + 1 < argc) n = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--shared") && i + 1 < argc) shared = argv[++i];
    else if (!std::strcmp(argv[i], "--csv") && i + 1 < argc) csv = argv[++i];
    else {
      std::fprintf(stderr, "usage: bench_selfcollision [--states N] [--shared DIR] [--csv FILE]\n");
      return 2;
    }
  }
  if (n <= 0) {
    std::fprintf(stderr, "bench_selfcollision: --states must be > 0\n");
    return 2;
  }
  std::vector<Row> rows;
  for (const char* robot : {"panda", "ur5"}) {
    const std::string dir = shared + "/robots/" + robot + "/";
    if (!std::filesystem::exists(dir + robot + ".urdf")) {
      std::fprintf(stderr, "bench_selfcollision: no %s at %s: skipped\n", robot, dir.c_str());
      continue;
    }
    benchRobot(robot, dir + robot + ".urdf", dir + robot + ".srdf", n, rows);
  }
  std::printf("\n%-6s %-14s %12s %10s %14s %14s\n", "robot", "method", "ns/state", "colliding", "disagree(FCL)",
              "FCL-OBBRSS/x");
  for (const Row& r : rows)
    std::printf("%-6s %-14s %12.0f %10.4f %14d %14.2f\n", r.robot.c_str(), r.method.c_str(), r.ns_per_state,
                r.colliding_fraction, r.disagreements, r.ratio);
  if (!csv.empty()) {
    std::ofstream out(csv);
    out << "robot,method,ns_per_state,colliding_fraction,disagreements_vs_fcl_obbrss,speedup_vs_fcl_obbrss\n";
    for (const Row& r : rows)
      out << r.robot << "," << r.method << "," << r.ns_per_state << "," << r.colliding_fraction << ","
          << r.disagreements << "," << r.ratio << "\n";
  }
  return 0;
}
