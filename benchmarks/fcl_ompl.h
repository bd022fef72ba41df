#pragma once
// FCL inside OMPL: a StateValidityChecker over bench::FclScene (self pairs and environment, as MoveIt's
// FCL plugin checks them), for benchmarks that put it beside Clearway's checkers.
#include "fcl_robot.h"

#include <clearway/ompl/collision_checking.h>

#include <ompl/base/StateValidityChecker.h>

#include <vector>

namespace clearway::bench {

/// Not thread-safe (one FclScene): for single-threaded planners.
class FclValidity : public ompl::base::StateValidityChecker {
 public:
  FclValidity(const ompl::base::SpaceInformationPtr& si, const clearway::Scene& scene)
      : ompl::base::StateValidityChecker(si), fcl_(scene), map_(scene), q_(scene.dimension()) {}
  bool isValid(const ompl::base::State* s) const override {
    map_.toVector(s, q_.data());
    return fcl_.isFree(q_.data());
  }

 private:
  mutable FclScene fcl_;
  clearway::StateMap map_;
  mutable std::vector<double> q_;
};

}  // namespace clearway::bench
