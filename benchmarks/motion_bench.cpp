// Motion checks per segment on the shared problems (primitive form), every mode in one run, through
// OMPL's own interfaces (SpaceInformation::checkMotion):
//   certified        Clearway's ContinuousMotionValidator (conservative advancement: never tunnels)
//   sampled-1%       OMPL's DiscreteMotionValidator over Clearway's validity checker, resolution 1% of
//                    the space's extent (OMPL's default)
//   sampled-0.1%     the same at 0.1%
//   fcl-sampled-1%   OMPL's DiscreteMotionValidator over an FCL validity checker (OBBRSS meshes, the same
//                    pair list, obstacles in FCL's DynamicAABBTree manager): what OMPL.app and MoveIt users run
// Segments: random valid states (fixed seed) and a second valid state up to 0.2·extent away (RRTConnect's
// default range), ends valid. The reference verdict is dense sampling with Clearway's checker at 1e-3 rad
// (Euclidean step). Reported per family: µs per motion (thread CPU time), checks per motion, motions the
// reference finds colliding, missed collisions (said free where the reference collides), and the ratio of
// fcl-sampled-1%'s time to each mode's.
//
// Usage: bench_motion [--motions N] [--problems K] [--shared DIR] [--csv FILE]
#include "bench_clock.h"
#include "fcl_ompl.h"
#include "shared_problems.h"

#include <clearway/ompl/collision_checking.h>

#include <fcl/fcl.h>
#include <ompl/base/DiscreteMotionValidator.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/util/Console.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <vector>

#ifndef CLEARWAY_SHARED_DIR
#define CLEARWAY_SHARED_DIR "../shared"
#endif

namespace cw = clearway;
namespace ob = ompl::base;

namespace {

using clearway::bench::threadSeconds;

struct Mode {
  std::string name;
  ob::SpaceInformationPtr si;
  double seconds = 0;
  long long checks = 0;  // states (sampled) or advancement steps (certified)
  int collide = 0, missed = 0, false_alarms = 0;
};

struct Totals {
  double seconds = 0;
  long long checks = 0;
  int motions = 0, collide = 0, missed = 0, false_alarms = 0;
};

}  // namespace

int main(int argc, char** argv) {
  int motions = 200, problems = 2;
  std::string shared = CLEARWAY_SHARED_DIR, csv;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--motions") && i + 1 < argc) motions = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--problems") && i + 1 < argc) problems = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--shared") && i + 1 < argc) shared = argv[++i];
    else if (!std::strcmp(argv[i], "--csv") && i + 1 < argc) csv = argv[++i];
    else {
      std::fprintf(stderr, "usage: bench_motion [--motions N] [--problems K] [--shared DIR] [--csv FILE]\n");
      return 2;
    }
  }
  if (motions < 1 || problems < 1) {
    std::fprintf(stderr, "bench_motion: --motions and --problems must be > 0\n");
    return 2;
  }
  const std::string scenes = shared + "/scenes";
  if (!std::filesystem::is_directory(scenes)) {
    std::fprintf(stderr, "bench_motion: no shared scenes at %s\n", scenes.c_str());
    return 2;
  }
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  const std::vector<std::string> families = cw::bench::sceneFamilies(scenes);

  const char* names[] = {"certified", "sampled-1%", "sampled-0.1%", "fcl-sampled-1%"};
  std::map<std::string, std::map<std::string, Totals>> totals;  // family → mode → totals
  cw::bench::RobotCache robots;
  std::mt19937_64 rng(20261123);
  for (const std::string& family : families) {
    for (int k = 1; k <= problems; ++k) {
      const std::string file = cw::bench::problemFile(scenes, family, k);
      if (file.empty()) continue;
      const cw::SceneDescription d = cw::parseSceneFile(file);
      const auto scene = robots.scene(d);
      const ob::StateSpacePtr space = cw::makeStateSpace(*scene);
      const double extent = space->getMaximumExtent();

      std::vector<Mode> modes(4);
      // A space per mode: the validity-checking resolution is a property of the state space.
      for (int m = 0; m < 4; ++m) {
        modes[m].name = names[m];
        modes[m].si = std::make_shared<ob::SpaceInformation>(m == 0 ? space : cw::makeStateSpace(*scene));
      }
      cw::setupCollisionChecking(modes[0].si, scene);
      for (int m = 1; m < 4; ++m) {
        ob::SpaceInformation& si = *modes[m].si;
        if (m == 3) si.setStateValidityChecker(std::make_shared<cw::bench::FclValidity>(modes[m].si, *scene));
        else si.setStateValidityChecker(std::make_shared<cw::ValidityChecker>(modes[m].si, scene));
        si.setMotionValidator(std::make_shared<ob::DiscreteMotionValidator>(modes[m].si));
        si.setStateValidityCheckingResolution(m == 2 ? 0.001 : 0.01);
        si.setup();
      }
      // The reference: Clearway's states, dense.
      cw::MotionOptions dense;
      dense.mode = cw::MotionMode::Sampled;
      dense.resolution = 1e-3;
      const cw::MotionChecker reference(scene, dense);
      cw::MotionContext ref_ctx = reference.makeContext();

      // Segments.
      const int n = scene->dimension();
      const cw::StateMap map(*scene);
      auto sampler = modes[0].si->allocStateSampler();
      ob::State* a = modes[0].si->allocState();
      ob::State* b = modes[0].si->allocState();
      std::vector<double> q0(n), q1(n);
      std::vector<std::pair<std::vector<double>, std::vector<double>>> segments;
      for (int attempts = 0; static_cast<int>(segments.size()) < motions && attempts < 100 * motions; ++attempts) {
        sampler->sampleUniform(a);
        if (!modes[1].si->isValid(a)) continue;
        sampler->sampleUniformNear(b, a, 0.2 * extent * std::uniform_real_distribution<double>(0.05, 1.0)(rng));
        if (!modes[1].si->isValid(b)) continue;
        map.toVector(a, q0.data());
        map.toVector(b, q1.data());
        segments.emplace_back(q0, q1);
      }
      std::vector<char> truth(segments.size());
      for (std::size_t s = 0; s < segments.size(); ++s) {
        std::vector<double> u = segments[s].second;
        map.unwrap(segments[s].first.data(), u.data());
        truth[s] = !reference.check(segments[s].first.data(), u.data(), ref_ctx).free;
      }
      // Each mode over all segments; 2 passes, the faster counted.
      for (Mode& m : modes) {
        double best = 1e30;
        std::vector<char> verdict(segments.size());
        for (int pass = 0; pass < 2; ++pass) {
          const double t0 = threadSeconds();
          for (std::size_t s = 0; s < segments.size(); ++s) {
            map.fromVector(segments[s].first.data(), a);
            map.fromVector(segments[s].second.data(), b);
            verdict[s] = !m.si->checkMotion(a, b);
          }
          best = std::min(best, threadSeconds() - t0);
        }
        Totals& t = totals[family][m.name];
        t.seconds += best;
        t.motions += static_cast<int>(segments.size());
        if (m.name == "certified") {
          // Steps, counted once more outside the timing.
          auto* v = dynamic_cast<cw::ContinuousMotionValidator*>(m.si->getMotionValidator().get());
          for (std::size_t s = 0; s < segments.size(); ++s) {
            map.fromVector(segments[s].first.data(), a);
            map.fromVector(segments[s].second.data(), b);
            t.checks += v->check(a, b).steps;
          }
        } else {
          // OMPL's DiscreteMotionValidator checks ceil(d / resolution) states (the ends counted once).
          for (const auto& seg : segments) {
            map.fromVector(seg.first.data(), a);
            map.fromVector(seg.second.data(), b);
            t.checks += m.si->getStateSpace()->validSegmentCount(a, b);
          }
        }
        for (std::size_t s = 0; s < segments.size(); ++s) {
          t.collide += truth[s];
          t.missed += truth[s] && !verdict[s];
          t.false_alarms += !truth[s] && verdict[s];
        }
      }
      modes[0].si->freeState(a);
      modes[0].si->freeState(b);
      std::fprintf(stderr, "%s: %zu segments\n", file.c_str(), segments.size());
    }
  }

  std::FILE* out = csv.empty() ? nullptr : std::fopen(csv.c_str(), "w");
  if (!csv.empty() && !out) {
    std::fprintf(stderr, "bench_motion: cannot write %s\n", csv.c_str());
    return 2;
  }
  if (out) std::fprintf(out, "family,mode,motions,us_per_motion,checks_per_motion,colliding,missed,false_alarms,fcl_ratio\n");
  std::printf("%-22s %-15s %7s %10s %9s %9s %7s %6s %9s\n", "family", "mode", "motions", "us/motion", "checks", "collide",
              "missed", "extra", "fcl-1%/x");
  for (const auto& [family, by_mode] : totals) {
    const Totals& fcl = by_mode.at("fcl-sampled-1%");
    for (const char* name : names) {
      const Totals& t = by_mode.at(name);
      const double us = 1e6 * t.seconds / std::max(1, t.motions);
      const double ratio = fcl.seconds / t.seconds;
      std::printf("%-22s %-15s %7d %10.1f %9.1f %9d %7d %6d %9.2f\n", family.c_str(), name, t.motions, us,
                  double(t.checks) / std::max(1, t.motions), t.collide, t.missed, t.false_alarms, ratio);
      if (out)
        std::fprintf(out, "%s,%s,%d,%.3f,%.3f,%d,%d,%d,%.4f\n", family.c_str(), name, t.motions, us,
                     double(t.checks) / std::max(1, t.motions), t.collide, t.missed, t.false_alarms, ratio);
    }
  }
  if (out) std::fclose(out);
  return 0;
}
