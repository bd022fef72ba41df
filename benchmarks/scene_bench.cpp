// Per-state checks on the shared problems, both forms (primitives and OctoMap), Clearway against FCL 0.7
// in one run on the same geometry, pairs and states:
//   env        the robot's moving links against the environment (FCL: DynamicAABBTree manager holding the
//              primitives, or the map as an fcl::OcTree)
//   scene      self pairs and environment (what a validity checker does)
//   clearance  the distance from the robot to the environment (Clearway: Scene::clearance with only the
//              environment declared; FCL: fcl::distance of every link through the manager)
// and the cost of each effect: Clearway's isFree with `checks` reduced to each subset.
// States: uniform within the joint limits (fixed seed). Reported: ns per state (thread CPU time, best of
// 2 passes), colliding fraction, verdicts that differ from FCL's, the ratio FCL / Clearway. Clearway and
// FCL may differ where a link lies within a voxel of the map (FCL tests occupied cells at the finest
// resolution, as Clearway does; both treat unknown space as free) or within GJK's tolerance.
//
// With --start-goal it instead classifies the start and goal of every shared problem in both forms with
// Clearway and with FCL and prints the verdicts side by side (the check `clearway check SCENE` performs).
//
// With --scene FILE (repeatable) it measures those scene files instead of the shared problems (our robots'
// scenes, such as robots/scenes/dual_arm_shelf.yaml: 528 checked pairs of URDF primitives).
//
// Usage: bench_scene [--states N] [--problems K] [--shared DIR] [--scene FILE]... [--csv FILE] [--start-goal]
#include "bench_clock.h"
#include "fcl_robot.h"
#include "shared_problems.h"

#include <clearway/scene/scene.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <vector>

#ifndef CLEARWAY_SHARED_DIR
#define CLEARWAY_SHARED_DIR "../shared"
#endif

namespace cw = clearway;

namespace {

using clearway::bench::threadSeconds;

struct Sum {
  double seconds = 0;
  long long states = 0, colliding = 0, disagree = 0;
  double worst_gap = 0;  // clearance: largest |Clearway − FCL|
};

// Times f over all states (best of 2 passes), recording verdicts.
template <class F>
double timed(int n, std::vector<char>& verdict, F&& f) {
  verdict.assign(n, 0);
  double best = 1e30;
  for (int pass = 0; pass < 2; ++pass) {
    const double t0 = threadSeconds();
    for (int s = 0; s < n; ++s) verdict[s] = f(s);
    best = std::min(best, threadSeconds() - t0);
  }
  return best;
}

// Start and goal of every problem, both forms: Clearway's and FCL's verdicts.
int startGoal(const std::string& scenes) {
  std::vector<std::string> files;
  for (const auto& f : std::filesystem::recursive_directory_iterator(scenes))
    if (f.path().extension() == ".yaml") files.push_back(f.path().string());
  std::sort(files.begin(), files.end());
  cw::bench::RobotCache robots;
  int states = 0, agree = 0, free_states = 0;
  for (const std::string& file : files) {
    const cw::SceneDescription d = cw::parseSceneFile(file);
    const cw::Scene scene(d, robots.robot(d), cw::loadEnvironment(d));
    cw::bench::FclScene fcl(scene);
    cw::SceneContext ctx = scene.makeContext();
    for (const auto* q : {&d.start, &d.goal}) {
      cw::CollisionReport r;
      const bool ours = scene.isFree(q->data(), ctx, &r);
      const bool theirs = fcl.isFree(q->data());
      ++states;
      agree += ours == theirs;
      free_states += ours;
      std::printf("%-60s %-5s clearway %-28s fcl %s\n", std::filesystem::path(file).filename().c_str(),
                  q == &d.start ? "start" : "goal", ours ? "free" : ("collision " + scene.describe(r)).c_str(),
                  theirs ? "free" : "collision");
    }
  }
  std::printf("%zu scene files: %d states, %d free (Clearway), Clearway and FCL agree on %d\n", files.size(), states,
              free_states, agree);
  return agree == states ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  int n = 2000, problems = 2;
  bool start_goal = false;
  std::string shared = CLEARWAY_SHARED_DIR, csv;
  std::vector<std::string> own;  // --scene files
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--states") && i + 1 < argc) n = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--problems") && i + 1 < argc) problems = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--shared") && i + 1 < argc) shared = argv[++i];
    else if (!std::strcmp(argv[i], "--csv") && i + 1 < argc) csv = argv[++i];
    else if (!std::strcmp(argv[i], "--start-goal")) start_goal = true;
    else if (!std::strcmp(argv[i], "--scene") && i + 1 < argc) own.push_back(argv[++i]);
    else {
      std::fprintf(stderr,
                   "usage: bench_scene [--states N] [--problems K] [--shared DIR] [--scene FILE]... [--csv FILE] [--start-goal]\n");
      return 2;
    }
  }
  if (n < 1 || problems < 1) {
    std::fprintf(stderr, "bench_scene: --states and --problems must be > 0\n");
    return 2;
  }
  if (start_goal && !own.empty()) {
    std::fprintf(stderr, "bench_scene: --start-goal classifies the shared problems, not --scene files\n");
    return 2;
  }
  // (family, form, file, k) of each problem measured
  struct Problem {
    std::string family, form, file;
    int k;
  };
  std::vector<Problem> list;
  for (const std::string& file : own) {
    if (!std::filesystem::is_regular_file(file)) {
      std::fprintf(stderr, "bench_scene: no scene file %s\n", file.c_str());
      return 2;
    }
    list.push_back({std::filesystem::path(file).stem().string(), "scene", file, 1});
  }
  if (own.empty()) {
    const std::string scenes = shared + "/scenes";
    if (!std::filesystem::is_directory(scenes)) {
      std::fprintf(stderr, "bench_scene: no shared scenes at %s\n", scenes.c_str());
      return 2;
    }
    if (start_goal) return startGoal(scenes);
    for (const std::string& family : cw::bench::sceneFamilies(scenes))
      for (int k = 1; k <= problems; ++k)
        for (const char* form : {"primitive", "octomap"}) {
          const std::string file = cw::bench::problemFile(scenes, family, k, !std::strcmp(form, "octomap"));
          if (!file.empty()) list.push_back({family, form, file, k});
        }
  }

  // family/form → method → sums
  std::map<std::string, std::map<std::string, Sum>> sums;
  cw::bench::RobotCache robots;
  for (const Problem& problem : list) {
    const std::string &family = problem.family, &form = problem.form, &file = problem.file;
    const int k = problem.k;
    const cw::SceneDescription d = cw::parseSceneFile(file);
    const auto g = robots.robot(d);
    const auto env = cw::loadEnvironment(d);
    auto with = [&](bool self, bool environment, bool clearance) {
      cw::SceneDescription e = d;
      e.effects = cw::Effects{};
      e.effects.self = self;
      e.effects.environment = environment;
      e.effects.clearance = clearance;
      return std::make_shared<const cw::Scene>(e, g, env);
    };
    const auto full = with(true, true, false), env_only = with(false, true, false), self_only = with(true, false, false);
    const auto clear = with(false, true, true);
    cw::bench::FclScene fcl(*full);

    const int dim = full->dimension();
    std::mt19937_64 rng(20261123 + k);
    std::vector<std::vector<double>> states(n, std::vector<double>(dim));
    for (auto& q : states)
      for (int i = 0; i < dim; ++i)
        q[i] = std::uniform_real_distribution<double>(std::max(-M_PI, full->lower(i)), std::min(M_PI, full->upper(i)))(rng);

    const std::string key = family + " " + form;
    auto& row = sums[key];
    cw::SceneContext c_full = full->makeContext(), c_env = env_only->makeContext(),
                     c_self = self_only->makeContext(), c_clear = clear->makeContext();
    std::vector<char> v_env, v_fenv, v_full, v_ffull, v_self, dummy;
    auto record = [&](const char* name, double t, const std::vector<char>& v, const std::vector<char>* ref) {
      Sum& s = row[name];
      s.seconds += t;
      s.states += n;
      for (int i = 0; i < n; ++i) {
        s.colliding += v[i];
        if (ref) s.disagree += v[i] != (*ref)[i];
      }
    };
    const double t_fenv = timed(n, v_fenv, [&](int s) { return !fcl.isFree(states[s].data(), false, true); });
    const double t_env = timed(n, v_env, [&](int s) { return !env_only->isFree(states[s].data(), c_env); });
    const double t_ffull = timed(n, v_ffull, [&](int s) { return !fcl.isFree(states[s].data(), true, true); });
    const double t_full = timed(n, v_full, [&](int s) { return !full->isFree(states[s].data(), c_full); });
    const double t_self = timed(n, v_self, [&](int s) { return !self_only->isFree(states[s].data(), c_self); });
    record("clearway-env", t_env, v_env, &v_fenv);
    record("fcl-env", t_fenv, v_fenv, nullptr);
    record("clearway-scene", t_full, v_full, &v_ffull);
    record("fcl-scene", t_ffull, v_ffull, nullptr);
    record("clearway-self-only", t_self, v_self, nullptr);
    // Clearance on the first 50 states: FCL's distance through the manager takes up to a second per state.
    const int m = std::min(n, 50);
    std::vector<double> cw_d(m), fcl_d(m);
    double t0 = threadSeconds();
    for (int s = 0; s < m; ++s) cw_d[s] = std::max(0.0, clear->clearance(states[s].data(), c_clear));
    const double t_cd = threadSeconds() - t0;
    t0 = threadSeconds();
    for (int s = 0; s < m; ++s) fcl_d[s] = fcl.environmentDistance(states[s].data());
    const double t_fd = threadSeconds() - t0;
    Sum& cd = row["clearway-clearance"];
    Sum& fd = row["fcl-distance"];
    cd.seconds += t_cd;
    fd.seconds += t_fd;
    cd.states += m;
    fd.states += m;
    for (int s = 0; s < m; ++s) {
      cd.colliding += cw_d[s] == 0.0;
      fd.colliding += fcl_d[s] == 0.0;
      const double gap = std::abs(cw_d[s] - fcl_d[s]);
      cd.worst_gap = std::max(cd.worst_gap, gap);
      cd.disagree += gap > 1e-3;
    }
    std::fprintf(stderr, "%s: %d states\n", file.c_str(), n);
  }

  std::FILE* out = csv.empty() ? nullptr : std::fopen(csv.c_str(), "w");
  if (!csv.empty() && !out) {
    std::fprintf(stderr, "bench_scene: cannot write %s\n", csv.c_str());
    return 2;
  }
  if (out) std::fprintf(out, "family,form,method,states,ns_per_state,colliding,disagree,fcl_ratio\n");
  std::printf("%-32s %-20s %8s %11s %9s %8s %9s\n", "family form", "method", "states", "ns/state", "colliding", "differ",
              "fcl/x");
  for (const auto& [key, row] : sums) {
    auto ns = [&](const Sum& s) { return 1e9 * s.seconds / std::max<long long>(1, s.states); };
    for (const auto& [method, s] : row) {
      double ratio = 0;
      if (method == "clearway-env") ratio = ns(row.at("fcl-env")) / ns(s);
      if (method == "clearway-scene") ratio = ns(row.at("fcl-scene")) / ns(s);
      if (method == "clearway-clearance") ratio = ns(row.at("fcl-distance")) / ns(s);
      std::printf("%-32s %-20s %8lld %11.0f %9.4f %8lld %9.2f", key.c_str(), method.c_str(), s.states, ns(s),
                  double(s.colliding) / std::max<long long>(1, s.states), s.disagree, ratio);
      if (method == "clearway-clearance") std::printf("   (largest |clearway - fcl| %.2e m)", s.worst_gap);
      std::printf("\n");
      if (out) {
        const std::string family = key.substr(0, key.find(' ')), form = key.substr(key.find(' ') + 1);
        std::fprintf(out, "%s,%s,%s,%lld,%.1f,%.5f,%lld,%.4f\n", family.c_str(), form.c_str(), method.c_str(), s.states,
                     ns(s), double(s.colliding) / std::max<long long>(1, s.states), s.disagree, ratio);
      }
    }
  }
  if (out) std::fclose(out);
  return 0;
}
