#pragma once
// FCL inside OMPL: a StateValidityChecker over bench::FclScene (self pairs and environment, as MoveIt's
// FCL plugin checks them), for benchmarks that put it beside Clearway's checkers.
#include "fcl_robot.h"

#include <clearway/ompl/collision_checking.h>

#include <ompl/base/StateValidityChecker.h>

#include <vector>

namespace clearway::bench {

/// Not thread-safe (one FclScene): for single-threaded planners. Clearance, which a benchmark reads
/// once a path is found, is Clearway's (where the scene declares it), so that every checker's paths are
/// measured alike.
class FclValidity : public ompl::base::StateValidityChecker {
 public:
  FclValidity(const ompl::base::SpaceInformationPtr& si, const std::shared_ptr<const clearway::Scene>& scene)
      : ompl::base::StateValidityChecker(si), fcl_(*scene), measure_(si, scene), map_(*scene), q_(scene->dimension()) {}
  bool isValid(const ompl::base::State* s) const override {
    map_.toVector(s, q_.data());
    return fcl_.isFree(q_.data());
  }
  double clearance(const ompl::base::State* s) const override { return measure_.clearance(s); }

 private:
  mutable FclScene fcl_;
  clearway::ValidityChecker measure_;
  clearway::StateMap map_;
  mutable std::vector<double> q_;
};

}  // namespace clearway::bench
