// Planning with RRTConnect on the shared problems (primitive form), three collision checkers in one run,
// through ompl::tools::Benchmark so that every experiment is written as an OMPL benchmark log (Planner
// Arena reads them; one log per problem and checker in --logs DIR):
//   clearway          Clearway's validity checker and certified ContinuousMotionValidator
//   clearway-sampled  Clearway's validity checker, OMPL's DiscreteMotionValidator at 1% (OMPL's default)
//   fcl-sampled       an FCL validity checker (OBBRSS, DynamicAABBTree), OMPL's DiscreteMotionValidator at 1%
// After each run the (unsimplified) solution path is re-checked segment by segment with Clearway's
// certified check ("uncertified": it passes within 1 mm of an obstacle or through one) and by dense
// sampling at 1e-3 rad ("colliding": a collision the sampling sees). Printed per family: runs, solved,
// median solve time, its ratio to fcl-sampled, uncertified and colliding paths.
//
// Usage: bench_plan [--problems K] [--runs R] [--time S] [--logs DIR] [--shared DIR] [--csv FILE]
#include "fcl_ompl.h"
#include "shared_problems.h"

#include <clearway/ompl/collision_checking.h>

#include <ompl/base/DiscreteMotionValidator.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/tools/benchmark/Benchmark.h>
#include <ompl/util/Console.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#ifndef CLEARWAY_SHARED_DIR
#define CLEARWAY_SHARED_DIR "../shared"
#endif

namespace cw = clearway;
namespace ob = ompl::base;
namespace og = ompl::geometric;

namespace {

struct Totals {
  int runs = 0, solved = 0, uncertified = 0, colliding = 0;
  std::vector<double> times;  // solved runs only
};

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

}  // namespace

int main(int argc, char** argv) {
  int problems = 2, runs = 5;
  double time_limit = 10.0;
  std::string shared = CLEARWAY_SHARED_DIR, logs, csv;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--problems") && i + 1 < argc) problems = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--runs") && i + 1 < argc) runs = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--time") && i + 1 < argc) time_limit = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--logs") && i + 1 < argc) logs = argv[++i];
    else if (!std::strcmp(argv[i], "--shared") && i + 1 < argc) shared = argv[++i];
    else if (!std::strcmp(argv[i], "--csv") && i + 1 < argc) csv = argv[++i];
    else {
      std::fprintf(stderr, "usage: bench_plan [--problems K] [--runs R] [--time S] [--logs DIR] [--shared DIR] [--csv FILE]\n");
      return 2;
    }
  }
  if (problems < 1 || runs < 1 || !(time_limit > 0)) {
    std::fprintf(stderr, "bench_plan: --problems, --runs and --time must be > 0\n");
    return 2;
  }
  const std::string scenes = shared + "/scenes";
  if (!std::filesystem::is_directory(scenes)) {
    std::fprintf(stderr, "bench_plan: no shared scenes at %s\n", scenes.c_str());
    return 2;
  }
  if (!logs.empty()) std::filesystem::create_directories(logs);
  ompl::msg::setLogLevel(ompl::msg::LOG_ERROR);
  const std::vector<std::string> families = cw::bench::sceneFamilies(scenes);

  const char* checkers[] = {"clearway", "clearway-sampled", "fcl-sampled"};
  std::map<std::string, std::map<std::string, Totals>> totals;
  cw::bench::RobotCache robots;
  for (const std::string& family : families)
    for (int k = 1; k <= problems; ++k) {
      const std::string file = cw::bench::problemFile(scenes, family, k);
      if (file.empty()) continue;
      const cw::SceneDescription d = cw::parseSceneFile(file);
      const auto scene = robots.scene(d);
      if (!scene->isFree(d.start) || !scene->isFree(d.goal)) {
        std::fprintf(stderr, "%s: start or goal in collision, skipped\n", file.c_str());
        continue;
      }
      const cw::MotionChecker certify(scene);
      cw::MotionContext certify_ctx = certify.makeContext();
      cw::MotionOptions dense_options;
      dense_options.mode = cw::MotionMode::Sampled;
      dense_options.resolution = 1e-3;
      const cw::MotionChecker dense(scene, dense_options);
      cw::MotionContext dense_ctx = dense.makeContext();
      const cw::StateMap map(*scene);
      for (const char* checker : checkers) {
        og::SimpleSetup setup(cw::makeStateSpace(*scene));
        const ob::SpaceInformationPtr si = setup.getSpaceInformation();
        if (!std::strcmp(checker, "clearway")) {
          cw::setupCollisionChecking(si, scene);
        } else {
          if (!std::strcmp(checker, "fcl-sampled")) si->setStateValidityChecker(std::make_shared<cw::bench::FclValidity>(si, *scene));
          else si->setStateValidityChecker(std::make_shared<cw::ValidityChecker>(si, scene));
          si->setMotionValidator(std::make_shared<ob::DiscreteMotionValidator>(si));
          si->setStateValidityCheckingResolution(0.01);
        }
        ob::ScopedState<> start(setup.getStateSpace()), goal(setup.getStateSpace());
        map.fromVector(d.start.data(), start.get());
        map.fromVector(d.goal.data(), goal.get());
        setup.setStartAndGoalStates(start, goal);
        setup.setup();
        ompl::tools::Benchmark bench(setup, d.name + " " + checker);
        bench.addPlanner(std::make_shared<og::RRTConnect>(si));
        std::vector<double> q0(scene->dimension()), q1(scene->dimension());
        bench.setPostRunEvent([&](const ob::PlannerPtr& planner, ompl::tools::Benchmark::RunProperties& run) {
          bool certified = false, collides = false;
          const ob::ProblemDefinitionPtr& pdef = planner->getProblemDefinition();
          if (pdef->hasExactSolution()) {
            certified = true;
            const auto* path = pdef->getSolutionPath()->as<og::PathGeometric>();
            for (std::size_t i = 0; i + 1 < path->getStateCount(); ++i) {
              map.toVector(path->getState(i), q0.data());
              map.toVector(path->getState(i + 1), q1.data());
              map.unwrap(q0.data(), q1.data());
              certified = certified && certify.check(q0.data(), q1.data(), certify_ctx).free;
              collides = collides || !dense.check(q0.data(), q1.data(), dense_ctx).free;
            }
          }
          run["certified BOOLEAN"] = certified ? "1" : "0";            // free, and never within 1 mm
          run["collides_dense BOOLEAN"] = collides ? "1" : "0";        // a collision at 1e-3 rad sampling
        });
        ompl::tools::Benchmark::Request request(time_limit, 4096.0, runs, 0.05, false, false, false);
        bench.benchmark(request);
        if (!logs.empty())
          bench.saveResultsToFile((logs + "/" + d.name + "_" + checker + ".log").c_str());
        Totals& t = totals[family][checker];
        for (const auto& run : bench.getRecordedExperimentData().planners.at(0).runs) {
          ++t.runs;
          const bool solved = run.count("solved BOOLEAN") && run.at("solved BOOLEAN") == "1";
          const bool exact = !run.count("approximate solution BOOLEAN") || run.at("approximate solution BOOLEAN") == "0";
          if (solved && exact) {
            ++t.solved;
            t.times.push_back(std::stod(run.at("time REAL")));
            t.uncertified += run.at("certified BOOLEAN") != "1";
            t.colliding += run.at("collides_dense BOOLEAN") == "1";
          }
        }
      }
      std::fprintf(stderr, "%s: done\n", file.c_str());
    }

  std::FILE* out = csv.empty() ? nullptr : std::fopen(csv.c_str(), "w");
  if (!csv.empty() && !out) {
    std::fprintf(stderr, "bench_plan: cannot write %s\n", csv.c_str());
    return 2;
  }
  if (out) std::fprintf(out, "family,checker,runs,solved,median_s,fcl_ratio,uncertified,colliding\n");
  std::printf("%-22s %-17s %5s %7s %10s %9s %12s %10s\n", "family", "checker", "runs", "solved", "median s", "fcl/x",
              "uncertified", "colliding");
  for (const auto& [family, by] : totals) {
    const double fcl = median(by.at("fcl-sampled").times);
    for (const char* checker : checkers) {
      const Totals& t = by.at(checker);
      const double m = median(t.times);
      const double ratio = m > 0 ? fcl / m : 0.0;
      std::printf("%-22s %-17s %5d %7d %10.4f %9.2f %12d %10d\n", family.c_str(), checker, t.runs, t.solved, m, ratio,
                  t.uncertified, t.colliding);
      if (out)
        std::fprintf(out, "%s,%s,%d,%d,%.6f,%.4f,%d,%d\n", family.c_str(), checker, t.runs, t.solved, m, ratio,
                     t.uncertified, t.colliding);
    }
  }
  if (out) std::fclose(out);
  return 0;
}
