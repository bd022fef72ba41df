// Where a state check's and a certified motion's time goes, per shared problem (issue 41: a sphere stage
// must beat every part at once, so each part's share is the first thing to know). For random states in the
// bounds: free states' kinematics alone, kinematics and the self pairs (their tables' look-ups among them), and
// the whole check (the rest: the environment and the check's own steps); colliding states; the same states
// eight to a call (Scene::areFree). For segments as RRTConnect draws them (a fifth of the bounds' extent at
// most): free and colliding certified motions (verdict only, 1 mm contact), their distance queries, and how
// many colliding ones no query settled.
// Times are the best of five rounds of this thread's CPU time (bench_clock.h); compare shares and ratios, not
// nanoseconds across machines.
// Instructions, which do not depend on the machine's load: one round (--once) under callgrind, then each
// phase function's inclusive count over the items it printed, e.g.
//   valgrind --tool=callgrind bench_breakdown --once --states 3000 SCENE.yaml
//   callgrind_annotate --inclusive=yes callgrind.out.* | grep phase
//
// Usage: bench_breakdown [--states N] [--once] [SCENE.yaml ...]   (default: problem 0001 of box_panda, box_ur5)
#include <clearway/motion/motion.h>
#include <clearway/scene/scene.h>
#include <clearway/scene/scene_file.h>
#include <clearway/scene/self_collision.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "bench_clock.h"

#ifndef CLEARWAY_SHARED_DIR
#define CLEARWAY_SHARED_DIR "../shared"
#endif

namespace cw = clearway;

namespace {

int g_rounds = 5;

// The best of g_rounds rounds of `body`, in nanoseconds per item.
template <class Body>
double bestNs(std::size_t items, Body&& body) {
  double best = INFINITY;
  for (int round = 0; round < g_rounds; ++round) {
    const double t0 = cw::bench::threadSeconds();
    body();
    best = std::min(best, cw::bench::threadSeconds() - t0);
  }
  return items ? 1e9 * best / static_cast<double>(items) : 0.0;
}

// The phases, each a function of its own so that callgrind counts it (inclusive): states flat, n values each.
// Each first stores its number, so that no two have the same code (identical functions may be folded into
// one, and callgrind would count them together).
volatile int g_phase = 0;
[[gnu::noinline]] void phasePoses(const cw::Scene& scene, const std::vector<double>& states, cw::SceneContext& ctx) {
  g_phase = 1;
  const std::size_t n = static_cast<std::size_t>(scene.dimension());
  for (std::size_t i = 0; i < states.size() / n; ++i) scene.computePoses(&states[i * n], ctx);
}
[[gnu::noinline]] void phasePosesAndSelf(const cw::Scene& scene, const std::vector<double>& states,
                                         cw::SceneContext& ctx, cw::SelfCollisionContext& self_ctx) {
  g_phase = 2;
  const std::size_t n = static_cast<std::size_t>(scene.dimension());
  for (std::size_t i = 0; i < states.size() / n; ++i) {
    scene.computePoses(&states[i * n], ctx);
    scene.selfCollision().firstCollision(ctx.poses().data(), self_ctx, ctx.jointValues().data());
  }
}
[[gnu::noinline]] void phaseFreeStates(const cw::Scene& scene, const std::vector<double>& states,
                                       cw::SceneContext& ctx) {
  g_phase = 3;
  const std::size_t n = static_cast<std::size_t>(scene.dimension());
  for (std::size_t i = 0; i < states.size() / n; ++i) scene.isFree(&states[i * n], ctx);
}
[[gnu::noinline]] void phaseCollidingStates(const cw::Scene& scene, const std::vector<double>& states,
                                            cw::SceneContext& ctx) {
  g_phase = 4;
  const std::size_t n = static_cast<std::size_t>(scene.dimension());
  for (std::size_t i = 0; i < states.size() / n; ++i) scene.isFree(&states[i * n], ctx);
}
[[gnu::noinline]] void phaseFreeMotions(const cw::MotionChecker& checker, const std::vector<std::vector<double>>& from,
                                        const std::vector<std::vector<double>>& to,
                                        const std::vector<std::size_t>& which, cw::MotionContext& ctx) {
  g_phase = 5;
  for (const std::size_t k : which) checker.check(from[k].data(), to[k].data(), ctx, false);
}
[[gnu::noinline]] void phaseCollidingMotions(const cw::MotionChecker& checker,
                                             const std::vector<std::vector<double>>& from,
                                             const std::vector<std::vector<double>>& to,
                                             const std::vector<std::size_t>& which, cw::MotionContext& ctx) {
  g_phase = 6;
  for (const std::size_t k : which) checker.check(from[k].data(), to[k].data(), ctx, false);
}

void breakdown(const std::string& file, int count) {
  const auto scene = std::make_shared<const cw::Scene>(cw::parseSceneFile(file));
  const int n = scene->dimension();
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto draw = [&] {
    std::vector<double> q(n);
    for (int i = 0; i < n; ++i) q[i] = scene->lower(i) + u(rng) * (scene->upper(i) - scene->lower(i));
    return q;
  };
  std::vector<double> free_flat, colliding_flat, all_flat;
  cw::SceneContext ctx = scene->makeContext();
  for (int k = 0; k < count; ++k) {
    const std::vector<double> q = draw();
    all_flat.insert(all_flat.end(), q.begin(), q.end());
    std::vector<double>& to = scene->isFree(q.data(), ctx) ? free_flat : colliding_flat;
    to.insert(to.end(), q.begin(), q.end());
  }
  const std::size_t nf = free_flat.size() / n, nc = colliding_flat.size() / n, na = all_flat.size() / n;
  const cw::SelfCollision& self = scene->selfCollision();
  cw::SelfCollisionContext self_ctx = self.makeContext();
  const double poses = bestNs(nf, [&] { phasePoses(*scene, free_flat, ctx); });
  const double with_self = bestNs(nf, [&] { phasePosesAndSelf(*scene, free_flat, ctx, self_ctx); });
  const double free_state = bestNs(nf, [&] { phaseFreeStates(*scene, free_flat, ctx); });
  const double colliding_state = bestNs(nc, [&] { phaseCollidingStates(*scene, colliding_flat, ctx); });
  const double one = bestNs(na, [&] {
    for (std::size_t i = 0; i < na; ++i) scene->isFree(&all_flat[i * n], ctx);
  });
  bool verdicts[8];
  const double eight = bestNs(na / 8 * 8, [&] {
    for (std::size_t i = 0; i + 8 <= na; i += 8) scene->areFree(&all_flat[i * n], 8, ctx, verdicts);
  });
  std::printf("%s: %d joints, %zu checked self pairs\n", file.substr(file.find_last_of('/') + 1).c_str(), n,
              self.pairs().size());
  if (nf == 0 || nc == 0) {
    std::printf("  %zu free and %zu colliding states of %d: nothing to split\n", nf, nc, count);
    return;
  }
  const double self_ns = with_self - poses, rest = free_state - with_self;
  std::printf("  free state (%zu): %.0f ns = kinematics %.0f (%.0f%%) + self pairs %.0f (%.0f%%) + environment and "
              "the rest %.0f (%.0f%%)\n",
              nf, free_state, poses, 100 * poses / free_state, self_ns, 100 * self_ns / free_state, rest,
              100 * rest / free_state);
  std::printf("  colliding state (%zu): %.0f ns; all states one per call %.0f ns, eight per call %.0f ns per state\n",
              nc, colliding_state, one, eight);

  // Segments: from a random state towards another, at most a fifth of the bounds' extent long.
  double extent = 0.0;
  for (int i = 0; i < n; ++i) extent += (scene->upper(i) - scene->lower(i)) * (scene->upper(i) - scene->lower(i));
  const double range = 0.2 * std::sqrt(extent);
  std::vector<std::vector<double>> from, to;
  for (int k = 0; k < count / 5; ++k) {
    std::vector<double> a = draw(), b = draw();
    double length = 0.0;
    for (int i = 0; i < n; ++i) length += (b[i] - a[i]) * (b[i] - a[i]);
    length = std::sqrt(length);
    if (length > range)
      for (int i = 0; i < n; ++i) b[i] = a[i] + (b[i] - a[i]) * (range / length);
    if (!scene->isFree(a.data(), ctx)) continue;  // (a planner's segments start at a valid state)
    from.push_back(a), to.push_back(b);
  }
  const cw::MotionChecker checker(scene);
  cw::MotionContext mctx = checker.makeContext();
  std::vector<std::size_t> free_motions, colliding_motions;
  long free_queries = 0, colliding_queries = 0, colliding_without = 0;
  for (std::size_t k = 0; k < from.size(); ++k) {
    const cw::MotionResult r = checker.check(from[k].data(), to[k].data(), mctx, false);
    (r.free ? free_motions : colliding_motions).push_back(k);
    (r.free ? free_queries : colliding_queries) += r.distance_queries;
    colliding_without += !r.free && r.distance_queries == 0;
  }
  // Mixed, as a planner asks them (the probe adapts to the share that collides), and each kind alone.
  const double mixed = bestNs(from.size(), [&] {
    for (std::size_t k = 0; k < from.size(); ++k) checker.check(from[k].data(), to[k].data(), mctx, false);
  });

  const double nfm = std::max<double>(1.0, static_cast<double>(free_motions.size()));
  const double ncm = std::max<double>(1.0, static_cast<double>(colliding_motions.size()));
  std::printf(
      "  motions (%zu, mixed): %.0f ns; free (%zu) %.0f ns alone, %.2f distance queries each; colliding (%zu) "
      "%.0f ns alone, %.2f queries each, %ld settled with none\n",
      from.size(), mixed, free_motions.size(),
      bestNs(free_motions.size(), [&] { phaseFreeMotions(checker, from, to, free_motions, mctx); }), free_queries / nfm,
      colliding_motions.size(),
      bestNs(colliding_motions.size(), [&] { phaseCollidingMotions(checker, from, to, colliding_motions, mctx); }),
      colliding_queries / ncm, colliding_without);
}

}  // namespace

int main(int argc, char** argv) {
  int count = 10000;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--states") && i + 1 < argc) {
      count = std::max(8, std::atoi(argv[++i]));
    } else if (!std::strcmp(argv[i], "--once")) {
      g_rounds = 1;
    } else if (argv[i][0] == '-') {
      std::fprintf(stderr, "usage: bench_breakdown [--states N] [--once] [SCENE.yaml ...]\n");
      return 2;
    } else {
      files.push_back(argv[i]);
    }
  }
  if (files.empty())
    for (const char* f : {"box_panda/box_panda_0001.yaml", "box_ur5/box_ur5_0001.yaml"})
      files.push_back(std::string(CLEARWAY_SHARED_DIR) + "/scenes/" + f);
  try {
    for (const std::string& f : files) breakdown(f, count);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_breakdown: %s\n", e.what());
    return 1;
  }
  return 0;
}
