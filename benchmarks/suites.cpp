// The suites of `clearway bench` (see suites.h). Times are this thread's CPU time, the faster of two
// passes; FCL runs in the same process on the same shapes, states and segments.
#include "suites.h"

#include "bench_clock.h"
#include "bench_rng.h"
#include "shared_problems.h"
#ifdef CLEARWAY_HAVE_FCL
#include "fcl_ompl.h"
#include "narrowphase_shapes.h"
#endif

#include <clearway/kinematics/kinematic_lanes.h>
#include <clearway/ompl/collision_checking.h>
#include <hwy/targets.h>

#ifdef CLEARWAY_HAVE_FCL
#include <fcl/narrowphase/detail/gjk_solver_indep.h>
#include <fcl/narrowphase/detail/gjk_solver_libccd.h>
#endif
#include <ompl/base/DiscreteMotionValidator.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/tools/benchmark/Benchmark.h>
#include <ompl/util/Console.h>

#include <algorithm>
#include <memory>
#include <cstring>
#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace clearway::bench {
namespace {

namespace ob = ompl::base;
namespace og = ompl::geometric;

// A case's own seed: the run's seed and the case's name, never its position, so shards agree.
std::uint64_t caseSeed(const SuiteConfig& config, const SuiteCase& c) {
  std::uint64_t h = 1469598103934665603ULL;  // FNV-1a
  for (char ch : c.suite + "/" + c.subject) h = (h ^ static_cast<unsigned char>(ch)) * 1099511628211ULL;
  return h ^ config.seed;
}

template <class T>
inline void doNotOptimize(const T& value) {
  asm volatile("" : : "r,m"(value) : "memory");
}

// ns per item of body(0 … n−1), one pass.
template <class Body>
double timedNs(std::size_t n, Body&& body) {
  const double t0 = threadSeconds();
  for (std::size_t i = 0; i < n; ++i) body(i);
  return 1e9 * (threadSeconds() - t0) / static_cast<double>(std::max<std::size_t>(n, 1));
}

// The faster of two passes.
template <class Body>
double bestNs(std::size_t n, Body&& body) {
  return std::min(timedNs(n, body), timedNs(n, body));
}

// Verdict counts against a reference (true = colliding).
void judge(SuiteRow& row, const std::vector<char>& verdict, const std::vector<char>& truth) {
  row.items = static_cast<long>(truth.size());
  for (std::size_t i = 0; i < truth.size(); ++i) {
    row.positives += truth[i];
    row.misses += truth[i] && !verdict[i];
    row.false_alarms += !truth[i] && verdict[i];
  }
  row.error = row.items ? double(row.misses + row.false_alarms) / double(row.items) : 0.0;
  row.max_error = row.misses + row.false_alarms > 0 ? 1.0 : 0.0;
}

// Built without FCL, the suites measure Clearway alone: these are the comparisons they cannot make.
#ifdef CLEARWAY_HAVE_FCL
constexpr bool kFcl = true;
#else
constexpr bool kFcl = false;
#endif

// ---- narrowphase: GJK distance on separated convex pairs, by tolerance --------------------------------
#ifdef CLEARWAY_HAVE_FCL

const double kGjkTolerances[] = {1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-9};

template <class FA, class FB>
void distanceRows(const Family<FA, FB>& f, std::vector<SuiteRow>& rows) {
  const std::size_t n = f.cases.size();
  std::vector<double> value(n);
  std::vector<char> failed(n);
  std::vector<int> iterations(n);
  auto finish = [&](const char* engine, double tol, double ns) {
    SuiteRow r;
    r.suite = "narrowphase", r.subject = f.name, r.engine = engine, r.mode = "distance", r.tolerance = tol;
    r.items = static_cast<long>(n), r.ns_per_item = ns;
    double sum = 0;
    long iters = 0;
    for (std::size_t i = 0; i < n; ++i) {
      iters += iterations[i];
      if (failed[i]) {
        ++r.misses;
        continue;
      }
      const double e = std::abs(value[i] - f.cases[i].ref);
      sum += e;
      r.max_error = std::max(r.max_error, e);
    }
    r.error = n > static_cast<std::size_t>(r.misses) ? sum / double(n - r.misses) : 0.0;
    r.work_per_item = double(iters) / double(std::max<std::size_t>(n, 1));
    rows.push_back(r);
    std::fill(iterations.begin(), iterations.end(), 0);
  };
  for (double tol : kGjkTolerances) {
    Tolerances t;
    t.gjk_relative = tol;
    const double ns = bestNs(n, [&](std::size_t i) {
      const PairCase& c = f.cases[i];
      const DistanceResult r = gjkDistance(f.ca[c.ia], c.pa, f.cb[c.ib], c.pb, t);
      doNotOptimize(r.point_a);
      value[i] = r.distance, failed[i] = isFailure(r.status), iterations[i] = r.iterations;
    });
    finish("clearway", tol, ns);
    // FCL's two GJK solvers at the same nominal tolerance (indep: relative; libccd: absolute, metres).
    auto fcl = [&](auto solver, const char* engine) {
      const double fns = bestNs(n, [&](std::size_t i) {
        const PairCase& c = f.cases[i];
        double d = -1;
        Vec3 p1, p2;
        failed[i] = !solver.shapeDistance(f.fa[c.ia], c.ta, f.fb[c.ib], c.tb, &d, &p1, &p2);
        doNotOptimize(p1);
        value[i] = d;
      });
      finish(engine, tol, fns);
    };
    fcl::detail::GJKSolver_indep<double> indep;
    indep.gjk_tolerance = tol;
    fcl(indep, "fcl-indep");
    fcl::detail::GJKSolver_libccd<double> libccd;
    libccd.distance_tolerance = tol;
    fcl(libccd, "fcl-libccd");
  }
}

void narrowphaseCase(const SuiteCase& c, const SuiteConfig& config, std::vector<SuiteRow>& rows) {
  const std::uint64_t seed = caseSeed(config, c);
  constexpr int kPool = 32;
  if (c.subject == "hull16") {
    auto hull = [](Rng& rng) { return makeHull(rng, 16); };
    auto f = makePools<fcl::Convexd, fcl::Convexd>(c.subject, kPool, seed, hull, hull);
    addSeparatedPairs(f, config.count, seed + 1);
    distanceRows(f, rows);
  } else if (c.subject == "box-capsule") {
    auto f = makePools<fcl::Boxd, fcl::Capsuled>(c.subject, kPool, seed, makeBox, makeCapsule);
    addSeparatedPairs(f, config.count, seed + 1);
    distanceRows(f, rows);
  } else if (c.subject == "cylinder-cone") {
    auto f = makePools<fcl::Cylinderd, fcl::Coned>(c.subject, kPool, seed, makeCylinder, makeCone);
    addSeparatedPairs(f, config.count, seed + 1);
    distanceRows(f, rows);
  } else {
    throw std::runtime_error("unknown shape family '" + c.subject + "'");
  }
}
#endif  // CLEARWAY_HAVE_FCL

// ---- shared problems ------------------------------------------------------------------------------------

// Every case of a process shares the robots it has loaded.
RobotCache& robots() {
  static RobotCache cache;
  return cache;
}

// Uniform in the group's bounds (continuous joints: [−π, π)).
void randomState(const Scene& scene, Rng& rng, double* q) {
  for (int i = 0; i < scene.dimension(); ++i) {
    const double lo = std::isfinite(scene.lower(i)) ? scene.lower(i) : -M_PI;
    const double hi = std::isfinite(scene.upper(i)) ? scene.upper(i) : M_PI;
    q[i] = rng.uniform(lo, hi);
  }
}

// ---- states: one joint vector at a time (and 64 to a call), exact meshes, convex hulls and FCL -------------

void statesCase(const SuiteCase& c, const SuiteConfig& config, std::vector<SuiteRow>& rows) {
  const SceneDescription d = parseSceneFile(c.file);
  const auto mesh = robots().scene(d);
  SceneOptions hull_options;
  hull_options.mode = GeometryMode::Hull;
  const Scene hull(d, mesh->geometryPtr(), mesh->environmentPtr(), hull_options);

  Rng rng(caseSeed(config, c));
  const int n = mesh->dimension();
  std::vector<double> states(static_cast<std::size_t>(config.count) * n);
  for (int i = 0; i < config.count; ++i) randomState(*mesh, rng, &states[i * n]);
  const std::size_t count = config.count;
  std::vector<char> truth(count), verdict(count);
  SceneContext ctx = mesh->makeContext();
  for (std::size_t i = 0; i < count; ++i) truth[i] = !mesh->isFree(&states[i * n], ctx);

  auto row = [&](const char* engine, const char* mode, double ns) {
    SuiteRow r;
    r.suite = "states", r.subject = c.subject, r.engine = engine, r.mode = mode, r.ns_per_item = ns;
    r.work_per_item = 1;
    judge(r, verdict, truth);
    rows.push_back(r);
  };
  row("clearway", "mesh", bestNs(count, [&](std::size_t i) { verdict[i] = !mesh->isFree(&states[i * n], ctx); }));
  // The same states 64 to a call (Scene::areFree: kinematics in SIMD lanes), as a roadmap planner would.
  constexpr std::size_t kBatch = 64;
  std::unique_ptr<bool[]> batch_free(new bool[kBatch]);
  row("clearway", "mesh-batch", bestNs(count, [&](std::size_t i) {
        if (i % kBatch != 0) return;
        const std::size_t k = std::min(kBatch, count - i);
        mesh->areFree(&states[i * n], static_cast<int>(k), ctx, batch_free.get());
        for (std::size_t j = 0; j < k; ++j) verdict[i + j] = !batch_free[j];
      }));
  SceneContext hull_ctx = hull.makeContext();
  row("clearway", "hull", bestNs(count, [&](std::size_t i) { verdict[i] = !hull.isFree(&states[i * n], hull_ctx); }));
#ifdef CLEARWAY_HAVE_FCL
  FclScene fcl(*mesh);
  row("fcl", "obbrss", bestNs(count, [&](std::size_t i) { verdict[i] = !fcl.isFree(&states[i * n]); }));
#endif
}

// ---- verdicts: every path to a state's verdict, state by state, against FCL -------------------------------

// The same states through each way Clearway decides one: one per call with the obstacles' boxes and the
// clearance grid (built first), one per call with the grid alone (no boxes), one per call through the trees
// alone (an environment that never has either), and 64 to a call
// (Scene::areFree) with the lanes forced to every SIMD target this CPU runs. Each row is judged against
// FCL's verdicts (without FCL: the trees'); and since a faster path may never change a verdict, a state
// where any row differs from the first fails the case, naming it.
void verdictsCase(const SuiteCase& c, const SuiteConfig& config, std::vector<SuiteRow>& rows) {
  const SceneDescription d = parseSceneFile(c.file);
  const auto scene = robots().scene(d);
  scene->environment().prepareClearanceGrid();
  const Environment& env = scene->environment();
  const Scene grid(d, scene->geometryPtr(), std::make_shared<const Environment>(env.withoutObstacleBoxes()),
                   scene->options());
  grid.environment().prepareClearanceGrid();
  const Scene trees(d, scene->geometryPtr(),
                    std::make_shared<const Environment>(env.withoutClearanceGrid().withoutObstacleBoxes()),
                    scene->options());
  Rng rng(caseSeed(config, c));
  const int n = scene->dimension();
  const std::size_t count = config.count;
  std::vector<double> states(count * n);
  for (std::size_t i = 0; i < count; ++i) randomState(*scene, rng, &states[i * n]);

  std::vector<std::pair<std::string, std::vector<char>>> found;  // (mode, colliding per state)
  std::vector<double> ns;
  const auto measure = [&](std::string mode, auto&& verdict_of) {
    std::vector<char> colliding(count);
    ns.push_back(timedNs(count, [&](std::size_t i) { verdict_of(i, colliding); }));
    found.emplace_back(std::move(mode), std::move(colliding));
  };
  SceneContext ctx = scene->makeContext(), grid_ctx = grid.makeContext(), trees_ctx = trees.makeContext();
  measure("one-by-one", [&](std::size_t i, std::vector<char>& v) { v[i] = !scene->isFree(&states[i * n], ctx); });
  measure("grid", [&](std::size_t i, std::vector<char>& v) { v[i] = !grid.isFree(&states[i * n], grid_ctx); });
  measure("trees", [&](std::size_t i, std::vector<char>& v) { v[i] = !trees.isFree(&states[i * n], trees_ctx); });
  constexpr std::size_t kBatch = 64;
  std::unique_ptr<bool[]> batch_free(new bool[kBatch]);
  for (const std::int64_t target : KinematicLanes::targets()) {
    // Highway's dispatch forced to one target for the scope, however it ends (the CPU's own targets after).
    struct Forced {
      explicit Forced(std::int64_t t) { hwy::SetSupportedTargetsForTest(t); }
      ~Forced() { hwy::SetSupportedTargetsForTest(0); }
    } forced(target);
    measure(std::string("batch-") + hwy::TargetName(target), [&](std::size_t i, std::vector<char>& v) {
      if (i % kBatch != 0) return;
      const std::size_t k = std::min(kBatch, count - i);
      scene->areFree(&states[i * n], static_cast<int>(k), ctx, batch_free.get());
      for (std::size_t j = 0; j < k; ++j) v[i + j] = !batch_free[j];
    });
  }
  std::vector<char> truth = found[2].second;  // (the trees')
#ifdef CLEARWAY_HAVE_FCL
  FclScene fcl(*scene);
  for (std::size_t i = 0; i < count; ++i) truth[i] = !fcl.isFree(&states[i * n]);
#endif
  for (std::size_t r = 0; r < found.size(); ++r) {
    for (std::size_t i = 0; i < count; ++i)
      if (found[r].second[i] != found[0].second[i])
        throw std::runtime_error(c.subject + ": state " + std::to_string(i) + " is " +
                                 (found[r].second[i] ? "colliding" : "free") + " by " + found[r].first + " but " +
                                 (found[0].second[i] ? "colliding" : "free") + " one by one");
    SuiteRow row;
    row.suite = "verdicts", row.subject = c.subject, row.engine = "clearway", row.mode = found[r].first;
    row.ns_per_item = ns[r];
    row.work_per_item = 1;
    judge(row, found[r].second, truth);
    rows.push_back(row);
  }
}

// OMPL's validity checker over Clearway ("clearway") or over FCL ("fcl", only when built with it).
ob::StateValidityCheckerPtr validity(const char* engine, const ob::SpaceInformationPtr& si,
                                     const std::shared_ptr<const Scene>& scene) {
#ifdef CLEARWAY_HAVE_FCL
  if (!std::strcmp(engine, "fcl")) return std::make_shared<FclValidity>(si, scene);
#endif
  (void)engine;
  return std::make_shared<ValidityChecker>(si, scene);
}

// ---- motions: certified, and OMPL's sampling over Clearway and over FCL, by tolerance -------------------

struct MotionMode {
  const char* engine;
  const char* mode;
  double tolerance;  // certified: contact distance (m); sampled: resolution (fraction of the extent)
};
const MotionMode kMotionModes[] = {
    {"clearway", "certified", 1e-2}, {"clearway", "certified", 1e-3}, {"clearway", "certified", 1e-4},
    {"clearway", "sampled", 0.05},   {"clearway", "sampled", 0.01},   {"clearway", "sampled", 0.001},
    {"fcl", "sampled", 0.05},        {"fcl", "sampled", 0.01},        {"fcl", "sampled", 0.001},
};

void motionsCase(const SuiteCase& c, const SuiteConfig& config, std::vector<SuiteRow>& rows) {
  const SceneDescription d = parseSceneFile(c.file);
  const auto scene = robots().scene(d);
  const StateMap map(*scene);
  const int n = scene->dimension();
  const double extent = makeStateSpace(*scene)->getMaximumExtent();

  // Segments: a valid state, and a valid one up to 0.2·extent away (RRTConnect's default range).
  Rng rng(caseSeed(config, c));
  SceneContext ctx = scene->makeContext();
  std::vector<std::vector<double>> q0s, q1s;
  std::vector<double> a(n), b(n), dir(n);
  for (long attempts = 0; static_cast<int>(q0s.size()) < config.count && attempts < 1000L * config.count; ++attempts) {
    randomState(*scene, rng, a.data());
    if (!scene->isFree(a.data(), ctx)) continue;
    double norm = 0;
    for (double& x : dir) {
      x = rng.normal();
      norm += x * x;
    }
    const double length = 0.2 * extent * rng.uniform(0.05, 1.0) / std::sqrt(norm);
    for (int i = 0; i < n; ++i) {
      b[i] = a[i] + length * dir[i];
      if (std::isfinite(scene->lower(i))) b[i] = std::clamp(b[i], scene->lower(i), scene->upper(i));
      else b[i] = std::remainder(b[i], 2 * M_PI);
    }
    if (!scene->isFree(b.data(), ctx)) continue;
    q0s.push_back(a);
    q1s.push_back(b);
  }
  const std::size_t count = q0s.size();
  // The reference: Clearway's states every 1e-3 rad along the segment.
  MotionOptions dense;
  dense.mode = clearway::MotionMode::Sampled;
  dense.resolution = 1e-3;
  const MotionChecker reference(scene, dense);
  MotionContext ref_ctx = reference.makeContext();
  std::vector<char> truth(count), verdict(count);
  for (std::size_t s = 0; s < count; ++s) {
    std::vector<double> u = q1s[s];
    map.unwrap(q0s[s].data(), u.data());
    truth[s] = !reference.check(q0s[s].data(), u.data(), ref_ctx).free;
  }

  // Every mode's checker first; then the timing passes go round the modes, so that Clearway's and FCL's
  // best passes come from the same stretch of this (shared, noisy) machine's time, not minutes apart.
  struct Run {
    const MotionMode* mode;
    std::shared_ptr<ob::SpaceInformation> si;
    ob::State* sa;
    ob::State* sb;
    double best_ns = INFINITY;
  };
  std::vector<Run> runs;
  for (const MotionMode& m : kMotionModes) {
    if (!kFcl && !std::strcmp(m.engine, "fcl")) continue;
    auto si = std::make_shared<ob::SpaceInformation>(makeStateSpace(*scene));
    if (!std::strcmp(m.mode, "certified")) {
      MotionOptions options;
      options.contact_distance = m.tolerance;
      // (The passes below ask each segment three times, and the work is counted by asking again: the
      // validator computes every answer, as for a planner's distinct segments.)
      setupCollisionChecking(si, scene, options).motion->setRemembering(false);
    } else {
      si->setStateValidityChecker(validity(m.engine, si, scene));
      si->setMotionValidator(std::make_shared<ob::DiscreteMotionValidator>(si));
      si->setStateValidityCheckingResolution(m.tolerance);
      si->setup();
    }
    runs.push_back({&m, si, si->allocState(), si->allocState()});
  }
  constexpr int kPasses = 3;
  for (int pass = 0; pass < kPasses; ++pass)
    for (Run& run : runs)
      run.best_ns = std::min(run.best_ns, timedNs(count, [&](std::size_t s) {
                               map.fromVector(q0s[s].data(), run.sa);
                               map.fromVector(q1s[s].data(), run.sb);
                               verdict[s] = !run.si->checkMotion(run.sa, run.sb);
                             }));
  for (Run& run : runs) {
    const MotionMode& m = *run.mode;
    const bool certified = !std::strcmp(m.mode, "certified");
    // Verdicts and work, counted outside the timing: advancement steps, or the states OMPL checks.
    long work = 0;
    for (std::size_t s = 0; s < count; ++s) {
      map.fromVector(q0s[s].data(), run.sa);
      map.fromVector(q1s[s].data(), run.sb);
      verdict[s] = !run.si->checkMotion(run.sa, run.sb);
      if (certified)  // (as timed: checkMotion(s1, s2) asks for the verdict alone)
        work += static_cast<const ContinuousMotionValidator&>(*run.si->getMotionValidator()).check(run.sa, run.sb, false).steps;
      else work += run.si->getStateSpace()->validSegmentCount(run.sa, run.sb);
    }
    run.si->freeState(run.sa);
    run.si->freeState(run.sb);
    SuiteRow r;
    r.suite = "motions", r.subject = c.subject, r.engine = m.engine, r.mode = m.mode, r.tolerance = m.tolerance;
    r.ns_per_item = run.best_ns;
    r.work_per_item = double(work) / double(std::max<std::size_t>(count, 1));
    judge(r, verdict, truth);
    r.error = r.items ? double(r.misses) / double(r.items) : 0.0;  // the missed-collision rate
    rows.push_back(r);
  }
}

// ---- plan: RRTConnect with each checker, through ompl::tools::Benchmark (Planner Arena logs) ------------

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// The checkers a planning problem is run with, each a "planner" of the problem's one OMPL experiment
// (RRTConnect[certified], ...), so that Planner Arena plots them side by side.
struct PlanChecker {
  const char* engine;
  const char* mode;
  std::string planner;  // the name in the log
  ob::StateValidityCheckerPtr validity;
  ob::MotionValidatorPtr motion;
};

void planCase(const SuiteCase& c, const SuiteConfig& config, std::vector<SuiteRow>& rows) {
  const SceneDescription d = parseSceneFile(c.file);
  const auto scene = robots().scene(d);
  if (!scene->isFree(d.start) || !scene->isFree(d.goal)) {
    std::fprintf(stderr, "%s: start or goal in collision: no planning\n", c.file.c_str());
    return;
  }
  const MotionChecker certify(scene);
  MotionContext certify_ctx = certify.makeContext();
  MotionOptions dense_options;
  dense_options.mode = clearway::MotionMode::Sampled;
  dense_options.resolution = 1e-3;
  const MotionChecker dense(scene, dense_options);
  MotionContext dense_ctx = dense.makeContext();
  const StateMap map(*scene);
  const std::string logs = config.out + "/plan";
  std::filesystem::create_directories(logs);

  og::SimpleSetup setup(makeStateSpace(*scene));
  const ob::SpaceInformationPtr si = setup.getSpaceInformation();
  std::vector<PlanChecker> checkers;
  for (const auto& [engine, mode] : {std::pair{"clearway", "certified"}, {"clearway", "sampled"}, {"fcl", "sampled"}}) {
    if (!kFcl && !std::strcmp(engine, "fcl")) continue;
    PlanChecker k{engine, mode, "", nullptr, nullptr};
    if (!std::strcmp(mode, "certified")) {
      const CollisionChecking cc = setupCollisionChecking(si, scene);
      k.planner = "RRTConnect[certified]";
      k.validity = cc.validity, k.motion = cc.motion;
    } else {
      k.planner = std::string("RRTConnect[") + engine + "-sampled]";
      k.validity = validity(engine, si, scene);
      k.motion = std::make_shared<ob::DiscreteMotionValidator>(si);
    }
    checkers.push_back(k);
  }
  ob::ScopedState<> start(setup.getStateSpace()), goal(setup.getStateSpace());
  map.fromVector(d.start.data(), start.get());
  map.fromVector(d.goal.data(), goal.get());
  setup.setStartAndGoalStates(start, goal);
  setup.setStateValidityChecker(checkers.front().validity);  // (replaced before every run)
  setup.setup();

  ompl::tools::Benchmark bench(setup, c.subject);
  bench.addExperimentParameter("problem", "STRING", c.subject);
  bench.addExperimentParameter("sampled resolution", "REAL", "0.01");  // OMPL's default, of the extent
  bench.addExperimentParameter("certified contact distance", "REAL", std::to_string(MotionOptions{}.contact_distance));
  auto checkerOf = [&](const ob::PlannerPtr& planner) -> const PlanChecker& {
    for (const PlanChecker& k : checkers)
      if (k.planner == planner->getName()) return k;
    throw std::logic_error("no checker for planner " + planner->getName());
  };
  for (const PlanChecker& k : checkers) {
    auto planner = std::make_shared<og::RRTConnect>(si);
    planner->setName(k.planner);
    bench.addPlanner(planner);
  }
  // Each run plans with its planner's checker on the one SpaceInformation the benchmark reads its
  // counters from (valid segment fraction, clearance), the counters zeroed.
  bench.setPreRunEvent([&](const ob::PlannerPtr& planner) {
    const PlanChecker& k = checkerOf(planner);
    si->setStateValidityChecker(k.validity);
    si->setMotionValidator(k.motion);
    si->setStateValidityCheckingResolution(0.01);
    si->setup();
    k.motion->resetMotionCounter();
  });
  std::vector<double> q0(scene->dimension()), q1(scene->dimension());
  // Every solution is re-checked: certified ("certified": each segment's own check calls it free; one the
  // validator answered as lying within a longer free segment may stop within 1 mm here, never at a
  // collision) and densely sampled at 1e-3 rad ("collides_dense": a collision the sampling sees). Clearance
  // is logged only where the scene declares it: elsewhere OMPL's 0 would read as a measurement.
  bench.setPostRunEvent([&](const ob::PlannerPtr& planner, ompl::tools::Benchmark::RunProperties& run) {
    bool certified_path = false, collides = false;
    const ob::ProblemDefinitionPtr& pdef = planner->getProblemDefinition();
    if (pdef->hasExactSolution()) {
      certified_path = true;
      const auto* path = pdef->getSolutionPath()->as<og::PathGeometric>();
      for (std::size_t i = 0; i + 1 < path->getStateCount(); ++i) {
        map.toVector(path->getState(i), q0.data());
        map.toVector(path->getState(i + 1), q1.data());
        map.unwrap(q0.data(), q1.data());
        certified_path = certified_path && certify.check(q0.data(), q1.data(), certify_ctx).free;
        collides = collides || !dense.check(q0.data(), q1.data(), dense_ctx).free;
      }
    }
    run["certified BOOLEAN"] = certified_path ? "1" : "0";
    run["collides_dense BOOLEAN"] = collides ? "1" : "0";
    if (!scene->effects().clearance) {
      run.erase("solution clearance REAL");
      run.erase("simplified solution clearance REAL");
    }
  });
  // (Each solution simplified as SimpleSetup::simplifySolution does: the planning a user gets, end to end.)
  const ompl::tools::Benchmark::Request request(config.plan_time, 4096.0, config.plan_runs, 0.05, false, false,
                                               /*simplify=*/true);
  bench.benchmark(request);
  bench.saveResultsToFile((logs + "/" + c.subject + ".log").c_str());

  const auto& planners = bench.getRecordedExperimentData().planners;
  for (std::size_t p = 0; p < checkers.size(); ++p) {
    const PlanChecker& k = checkers[p];
    SuiteRow r;
    r.suite = "plan", r.subject = c.subject, r.engine = k.engine, r.mode = k.mode;
    r.tolerance = !std::strcmp(k.mode, "certified") ? MotionOptions{}.contact_distance : 0.01;
    std::vector<double> times, end_to_end;
    for (const auto& run : planners.at(p).runs) {
      ++r.items;
      const bool solved = run.count("solved BOOLEAN") && run.at("solved BOOLEAN") == "1";
      const bool exact = !run.count("approximate solution BOOLEAN") || run.at("approximate solution BOOLEAN") == "0";
      if (!solved || !exact) continue;
      ++r.positives;
      times.push_back(std::stod(run.at("time REAL")));
      const auto simplified = run.find("simplification time REAL");
      end_to_end.push_back(times.back() + (simplified != run.end() ? std::stod(simplified->second) : 0.0));
      r.false_alarms += run.at("certified BOOLEAN") != "1";
      r.misses += run.at("collides_dense BOOLEAN") == "1";
    }
    r.ns_per_item = 1e9 * median(times);
    r.work_per_item = r.items ? double(r.positives) / double(r.items) : 0.0;
    r.error = r.positives ? double(r.misses) / double(r.positives) : 0.0;
    r.max_error = r.misses ? 1.0 : 0.0;
    rows.push_back(r);
    // End to end: the solve and the simplification of each solved run (the same runs and paths).
    r.mode = std::string(k.mode) + "+simplify";
    r.ns_per_item = 1e9 * median(end_to_end);
    rows.push_back(r);
  }
}

const char* const kShapeFamilies[] = {"hull16", "box-capsule", "cylinder-cone"};

}  // namespace

const std::vector<std::string>& suiteNames() {
  static const std::vector<std::string> names = {"narrowphase", "states", "verdicts", "motions", "plan"};
  return names;
}

std::vector<SuiteCase> enumerateCases(const SuiteConfig& config) {
  std::vector<SuiteCase> cases;
  for (const std::string& suite : suiteNames()) {
    if (std::find(config.suites.begin(), config.suites.end(), suite) == config.suites.end()) continue;
    if (suite == "narrowphase") {
      if (kFcl)  // (its shape pools are built for both libraries)
        for (const char* family : kShapeFamilies) cases.push_back({suite, family, ""});
      continue;
    }
    // The tool's --shared DIR and $CLEARWAY_SHARED set config.shared: say so, a user has no other way to learn it.
    const std::string need = "suite '" + suite + "' needs the shared scenes (clearway bench --shared DIR or $CLEARWAY_SHARED)";
    if (config.shared.empty()) throw std::runtime_error(need + ", and no shared data folder was given");
    const std::string scenes = config.shared + "/scenes";
    if (!std::filesystem::is_directory(scenes)) throw std::runtime_error(need + ", and " + scenes + " is not a folder");
    for (const std::string& family : sceneFamilies(scenes))
      for (int k = 1; k <= config.problems; ++k)
        for (const bool octomap : {false, true}) {  // (both forms of a problem: primitives, and the map)
          const std::string file = problemFile(scenes, family, k, octomap);
          if (!file.empty()) cases.push_back({suite, std::filesystem::path(file).stem().string(), file});
        }
  }
  if (!config.subjects.empty())
    cases.erase(std::remove_if(cases.begin(), cases.end(),
                               [&](const SuiteCase& c) {
                                 return std::none_of(config.subjects.begin(), config.subjects.end(), [&](const std::string& s) {
                                   return c.subject.find(s) != std::string::npos;
                                 });
                               }),
                cases.end());
  for (const std::string& suite : config.suites)
    if (std::find(suiteNames().begin(), suiteNames().end(), suite) == suiteNames().end())
      throw std::runtime_error("unknown suite '" + suite + "' (known: narrowphase, states, verdicts, motions, plan)");
  return cases;
}

const std::vector<std::string>& missingComparisons() {
  static const std::vector<std::string> missing =
      kFcl ? std::vector<std::string>{}
           : std::vector<std::string>{"narrowphase: the whole suite (Clearway's GJK against FCL's two solvers)",
                                      "states: fcl obbrss",
                                      "verdicts: FCL as the reference (the trees' verdicts stand in)",
                                      "motions: fcl sampled (OMPL's sampling over FCL)",
                                      "plan: fcl sampled (RRTConnect over FCL)"};
  return missing;
}

void runCase(const SuiteCase& c, const SuiteConfig& config, std::vector<SuiteRow>& rows) {
  ompl::msg::setLogLevel(ompl::msg::LOG_ERROR);
  if (c.suite == "narrowphase") {
#ifdef CLEARWAY_HAVE_FCL
    narrowphaseCase(c, config, rows);
#else
    throw std::runtime_error("the narrowphase suite needs FCL (libfcl-dev) at build time");
#endif
  } else if (c.suite == "states") statesCase(c, config, rows);
  else if (c.suite == "verdicts") verdictsCase(c, config, rows);
  else if (c.suite == "motions") motionsCase(c, config, rows);
  else if (c.suite == "plan") planCase(c, config, rows);
  else throw std::runtime_error("unknown suite '" + c.suite + "'");
}

}  // namespace clearway::bench
