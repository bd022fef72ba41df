#include <clearway/ompl/collision_checking.h>

#include <clearway/detail/per_thread.h>

#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/base/spaces/SO2StateSpace.h>

#include <chrono>
#include <cmath>

namespace clearway {

namespace ob = ompl::base;

namespace {

std::atomic<std::uint64_t> g_next_serial{1};

using detail::perThread;

struct ValidityScratch {
  SceneContext ctx;
  std::vector<double> q;
};

struct MotionScratch {
  MotionContext ctx;
  std::vector<double> q0, q1;
};

class Timer {
 public:
  explicit Timer(std::atomic<std::uint64_t>& sink) : sink_(sink), t0_(std::chrono::steady_clock::now()) {}
  ~Timer() {
    sink_ += static_cast<std::uint64_t>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - t0_).count());
  }

 private:
  std::atomic<std::uint64_t>& sink_;
  std::chrono::steady_clock::time_point t0_;
};

bool isContinuous(const Scene& scene, int i) {
  return !std::isfinite(scene.lower(i)) || !std::isfinite(scene.upper(i));
}

}  // namespace

ob::StateSpacePtr makeStateSpace(const Scene& scene) {
  const int n = scene.dimension();
  bool all_bounded = true;
  for (int i = 0; i < n; ++i) all_bounded &= !isContinuous(scene, i);
  if (all_bounded) {
    auto space = std::make_shared<ob::RealVectorStateSpace>(n);
    ob::RealVectorBounds bounds(n);
    for (int i = 0; i < n; ++i) {
      bounds.setLow(i, scene.lower(i));
      bounds.setHigh(i, scene.upper(i));
      space->setDimensionName(i, scene.robot().variables()[scene.groupVariables()[i]].name);
    }
    space->setBounds(bounds);
    return space;
  }
  auto compound = std::make_shared<ob::CompoundStateSpace>();
  for (int i = 0; i < n; ++i) {
    if (isContinuous(scene, i)) {
      compound->addSubspace(std::make_shared<ob::SO2StateSpace>(), 1.0);
    } else {
      auto r = std::make_shared<ob::RealVectorStateSpace>(1);
      r->setBounds(scene.lower(i), scene.upper(i));
      compound->addSubspace(r, 1.0);
    }
  }
  compound->lock();
  return compound;
}

StateMap::StateMap(const Scene& scene) : continuous_(scene.dimension()) {
  for (int i = 0; i < scene.dimension(); ++i) {
    continuous_[i] = isContinuous(scene, i);
    compound_ = compound_ || continuous_[i];
  }
}

void StateMap::toVector(const ob::State* state, double* out) const noexcept {
  const int n = dimension();
  if (!compound_) {
    const double* v = state->as<ob::RealVectorStateSpace::StateType>()->values;
    for (int i = 0; i < n; ++i) out[i] = v[i];
    return;
  }
  const auto* c = state->as<ob::CompoundState>();
  for (int i = 0; i < n; ++i)
    out[i] = continuous_[i] ? c->as<ob::SO2StateSpace::StateType>(i)->value
                            : c->as<ob::RealVectorStateSpace::StateType>(i)->values[0];
}

void StateMap::fromVector(const double* values, ob::State* state) const noexcept {
  const int n = dimension();
  if (!compound_) {
    double* v = state->as<ob::RealVectorStateSpace::StateType>()->values;
    for (int i = 0; i < n; ++i) v[i] = values[i];
    return;
  }
  auto* c = state->as<ob::CompoundState>();
  for (int i = 0; i < n; ++i) {
    if (continuous_[i]) {
      // Into SO(2)'s [−π, π).
      c->as<ob::SO2StateSpace::StateType>(i)->value = std::remainder(values[i], 2.0 * M_PI);
    } else {
      c->as<ob::RealVectorStateSpace::StateType>(i)->values[0] = values[i];
    }
  }
}

void StateMap::unwrap(const double* from, double* to) const noexcept {
  for (int i = 0; i < dimension(); ++i)
    if (continuous_[i]) to[i] = from[i] + std::remainder(to[i] - from[i], 2.0 * M_PI);
}

// ---- ValidityChecker ----------------------------------------------------------------------------------

ValidityChecker::ValidityChecker(const ob::SpaceInformationPtr& si, std::shared_ptr<const Scene> scene)
    : ob::StateValidityChecker(si), scene_(std::move(scene)), map_(*scene_), serial_(g_next_serial++) {
  // Honest specs: clearance is an exact distance only when the scene computes it.
  specs_.clearanceComputationType = scene_->effects().clearance ? ob::StateValidityCheckerSpecs::EXACT
                                                                : ob::StateValidityCheckerSpecs::NONE;
  specs_.hasValidDirectionComputation = false;
}

bool ValidityChecker::isValid(const ob::State* state) const {
  const Timer timer(counters_.nanoseconds);
  ++counters_.states;
  ValidityScratch& s = perThread<ValidityScratch>(serial_, [&] {
    return ValidityScratch{scene_->makeContext(), std::vector<double>(scene_->dimension())};
  });
  map_.toVector(state, s.q.data());
  return scene_->isFree(s.q.data(), s.ctx);
}

double ValidityChecker::clearance(const ob::State* state) const {
  if (!scene_->effects().clearance) return ob::StateValidityChecker::clearance(state);
  ValidityScratch& s = perThread<ValidityScratch>(serial_, [&] {
    return ValidityScratch{scene_->makeContext(), std::vector<double>(scene_->dimension())};
  });
  map_.toVector(state, s.q.data());
  const double c = scene_->clearance(s.q.data(), s.ctx);
  return std::isnan(c) ? 0.0 : c;
}

// ---- ContinuousMotionValidator ------------------------------------------------------------------------

ContinuousMotionValidator::ContinuousMotionValidator(const ob::SpaceInformationPtr& si,
                                                     std::shared_ptr<const Scene> scene, MotionOptions options)
    : ob::MotionValidator(si), checker_(scene, options), map_(*scene), serial_(g_next_serial++) {}

MotionResult ContinuousMotionValidator::check(const ob::State* s1, const ob::State* s2) const {
  const Timer timer(counters_.nanoseconds);
  ++counters_.motions;
  MotionScratch& s = perThread<MotionScratch>(serial_, [&] {
    const int n = checker_.scene().dimension();
    return MotionScratch{checker_.makeContext(), std::vector<double>(n), std::vector<double>(n)};
  });
  map_.toVector(s1, s.q0.data());
  map_.toVector(s2, s.q1.data());
  map_.unwrap(s.q0.data(), s.q1.data());
  return checker_.check(s.q0.data(), s.q1.data(), s.ctx);
}

bool ContinuousMotionValidator::checkMotion(const ob::State* s1, const ob::State* s2) const {
  const bool free = check(s1, s2).free;
  // OMPL's own counters are plain integers; they are kept for its tools, but ours are the reliable ones.
  return free;
}

bool ContinuousMotionValidator::checkMotion(const ob::State* s1, const ob::State* s2,
                                            std::pair<ob::State*, double>& lastValid) const {
  const MotionResult r = check(s1, s2);
  if (r.free) return true;
  lastValid.second = r.last_valid;
  // The state space interpolates exactly as the checker did (linear; SO(2) the short way), so the
  // state at last_valid is the one the checker certified.
  if (lastValid.first) si_->getStateSpace()->interpolate(s1, s2, r.last_valid, lastValid.first);
  return false;
}

CollisionChecking setupCollisionChecking(const ob::SpaceInformationPtr& si, std::shared_ptr<const Scene> scene,
                                         MotionOptions options) {
  CollisionChecking c;
  c.validity = std::make_shared<ValidityChecker>(si, scene);
  c.motion = std::make_shared<ContinuousMotionValidator>(si, scene, options);
  si->setStateValidityChecker(c.validity);
  si->setMotionValidator(c.motion);
  si->setup();
  return c;
}

}  // namespace clearway
