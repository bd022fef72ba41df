// What outer balls (body/outer_balls.h) would settle, before any query asks them: for each robot and grid
// step, their count, build time, and, on random free states, how many of the self pairs that today's
// cheap rungs leave to the hulls (pair table not Free, bounding balls and boxes not apart) every pair of
// their balls proves apart, and how many of those the hulls would have left to the triangle search.
// Every pair the balls call apart is asked of the exact triangles too: a touching one counts as wrong
// (the run must print 0).
//
// Usage: bench_outer_balls [--states N] [SCENE.yaml ...]   (default: box_panda_0001, box_ur5_0001 and our
// dual arm's shelf)
#include <clearway/body/enclosing.h>
#include <clearway/body/outer_balls.h>
#include <clearway/body/proximity.h>
#include <clearway/scene/scene.h>
#include <clearway/scene/scene_file.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <vector>

#ifndef CLEARWAY_SHARED_DIR
#define CLEARWAY_SHARED_DIR "../shared"
#endif
#ifndef CLEARWAY_SOURCE_DIR
#define CLEARWAY_SOURCE_DIR "."
#endif

namespace cw = clearway;

namespace {

// True when every ball of a is more than `padding` from every ball of b (groups first), at these poses.
// Counts the ball pairs compared.
bool ballsApart(const cw::OuterBalls& a, const cw::Pose& pa, const cw::OuterBalls& b, const cw::Pose& pb,
                double padding, long& tests) {
  for (const cw::OuterBalls::Group& ga : a.groups) {
    const cw::Vec3 ca = pa * ga.center;
    for (const cw::OuterBalls::Group& gb : b.groups) {
      ++tests;
      if ((ca - pb * gb.center).norm() > ga.radius + gb.radius + padding) continue;
      for (int i = ga.first; i < ga.first + ga.count; ++i) {
        const cw::Vec3 c = pa * a.balls[i].center;
        for (int j = gb.first; j < gb.first + gb.count; ++j) {
          ++tests;
          if ((c - pb * b.balls[j].center).norm() <= a.balls[i].radius + b.balls[j].radius + padding) return false;
        }
      }
    }
  }
  return true;
}

void run(const std::string& path, int count) {
  const auto scene = std::make_shared<const cw::Scene>(cw::parseSceneFile(path));
  cw::SceneContext ctx = scene->makeContext();
  const cw::RobotGeometry& g = scene->geometry();
  const cw::RobotModel& m = g.model();
  const cw::SelfCollision& self = scene->selfCollision();
  // Random states in the scene's bounds (fixed seed); the free ones, whose pairs all go through every rung.
  std::mt19937_64 rng(1);
  std::vector<std::vector<double>> free;
  for (int s = 0; s < count; ++s) {
    std::vector<double> q(scene->dimension());
    for (int v = 0; v < scene->dimension(); ++v)
      q[v] = std::uniform_real_distribution<double>(scene->lower(v), scene->upper(v))(rng);
    if (scene->isFree(q.data(), ctx)) free.push_back(q);
  }
  std::printf("%s: %s, %zu of %d random states free, %zu checked pairs\n",
              std::filesystem::path(path).filename().c_str(), m.name().c_str(), free.size(), count,
              self.pairs().size());
  for (double step : {0.004, 0.006, 0.008}) {
    cw::OuterBallOptions options;
    options.step = step;
    std::vector<cw::OuterBalls> outer(m.linkCount());
    std::size_t balls = 0, groups = 0;
    int links = 0, proven = 0;
    const auto t0 = std::chrono::steady_clock::now();
    for (int i : g.geometricLinks()) {
      outer[i] = cw::buildOuterBalls(*g.link(i), options);
      ++links;
      proven += outer[i].proven();
      balls += outer[i].balls.size();
      groups += outer[i].groups.size();
    }
    const double build = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    cw::EnclosingBalls bounding(g);
    const cw::Tolerances tol;
    long reach = 0, settled = 0, exact = 0, exact_settled = 0, wrong = 0, tests = 0;
    for (const std::vector<double>& q : free) {
      scene->computePoses(q.data(), ctx);
      const std::vector<cw::Pose>& poses = ctx.poses();
      const double* joints = ctx.jointValues().data();
      bounding.place(poses.data());
      for (std::size_t k = 0; k < self.pairs().size(); ++k) {
        const cw::LinkPair p = self.pairs()[k];
        const double pad = self.pairPadding(static_cast<int>(k));
        const cw::PairTable* table = self.pairTable(static_cast<int>(k));
        if (table && table->lookup(joints) == cw::PairTable::Verdict::Free) continue;
        if (bounding.apart(p.a, p.b, pad, tol)) continue;
        ++reach;
        const bool apart = outer[p.a].proven() && outer[p.b].proven() &&
                           ballsApart(outer[p.a], poses[p.a], outer[p.b], poses[p.b], pad, tests);
        settled += apart;
        const cw::LinkGeometry &a = *g.link(p.a), &b = *g.link(p.b);
        if (cw::screenMeshes(a, poses[p.a], b, poses[p.b], tol, cw::GeometryMode::Mesh, pad) == cw::Screen::Unsure) {
          ++exact;
          exact_settled += apart;
        }
        if (apart && cw::meshesIntersectExactly(a, poses[p.a], b, poses[p.b], tol, pad)) ++wrong;
      }
    }
    std::printf(
        "  step %.0f mm: %d of %d links served, %zu balls in %zu groups, built in %.2f s; pairs past the bounding "
        "rung %.3f per state, balls settle %.1f%% (%.1f ball tests each); of those the hulls leave to the "
        "triangles (%.3f per state) balls settle %.1f%%; wrong %ld\n",
        step * 1e3, proven, links, balls, groups, build, double(reach) / free.size(),
        100.0 * settled / std::max(1L, reach), double(tests) / std::max(1L, reach), double(exact) / free.size(),
        100.0 * exact_settled / std::max(1L, exact), wrong);
    std::fflush(stdout);
  }
}

}  // namespace

int main(int argc, char** argv) {
  int count = 5000;
  std::vector<std::string> scenes;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--states") && i + 1 < argc)
      count = std::atoi(argv[++i]);
    else
      scenes.push_back(argv[i]);
  }
  if (scenes.empty()) {
    const std::string shared = CLEARWAY_SHARED_DIR;
    scenes = {shared + "/scenes/box_panda/box_panda_0001.yaml", shared + "/scenes/box_ur5/box_ur5_0001.yaml",
              std::string(CLEARWAY_SOURCE_DIR) + "/robots/scenes/dual_arm_shelf.yaml"};
  }
  for (const std::string& s : scenes) {
    if (!std::filesystem::exists(s)) {
      std::printf("%s: not found, skipped\n", s.c_str());
      continue;
    }
    run(s, count);
  }
}
