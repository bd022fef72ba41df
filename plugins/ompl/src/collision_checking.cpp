#include <clearway/ompl/collision_checking.h>

#include <clearway/per_thread.h>

#include "segment_memo.h"

#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/base/spaces/SE2StateSpace.h>
#include <ompl/base/spaces/SE3StateSpace.h>
#include <ompl/base/spaces/SO2StateSpace.h>

#include <chrono>
#include <cmath>
#include <stdexcept>

namespace clearway {

namespace ob = ompl::base;

namespace ompl_detail {

// A thread's scratch, made again when the world's snapshot changes (an attached body changes the links).
struct ValidityScratch {
  std::uint64_t version = 0;
  SceneContext ctx;
  std::vector<double> q;
  std::vector<double> batch;  // areValid's states, one after another (grows to the largest batch)
};

struct MotionScratch {
  std::uint64_t version = 0;
  MotionContext ctx;
  std::vector<double> q0, q1;
  SegmentMemo memo;  // this snapshot's last answers
};

}  // namespace ompl_detail

namespace {

using ompl_detail::MotionScratch;
using ompl_detail::SegmentMemo;
using ompl_detail::ValidityScratch;

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

JointType typeOf(const Scene& scene, int i) {
  const RobotModel& model = scene.robot();
  return model.joint(model.variables()[scene.groupVariables()[i]].joint).type;
}

// The subspaces of a scene's group in state order: each entry one, a planar joint's three one SE(2),
// a floating joint's seven one SE(3).
std::vector<StateMap::Part> partsOf(const Scene& scene) {
  std::vector<StateMap::Part> parts;
  for (int i = 0; i < scene.dimension();) {
    const JointType type = typeOf(scene, i);
    const StateMap::Kind kind = type == JointType::Planar     ? StateMap::Kind::SE2
                                : type == JointType::Floating ? StateMap::Kind::SE3
                                : isContinuous(scene, i)      ? StateMap::Kind::SO2
                                                              : StateMap::Kind::Real;
    parts.push_back({kind, i});
    i += kind == StateMap::Kind::SE2 ? 3 : kind == StateMap::Kind::SE3 ? 7 : 1;
  }
  return parts;
}

}  // namespace

ob::StateSpacePtr makeStateSpace(const Scene& scene) {
  const int n = scene.dimension();
  const std::vector<StateMap::Part> parts = partsOf(scene);
  bool all_real = true;
  for (const StateMap::Part& p : parts) all_real &= p.kind == StateMap::Kind::Real;
  if (all_real) {
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
  // A planar or floating joint's position needs bounds to be sampled: the scene's robot.bounds.
  const auto positionBounds = [&](int first, int count) {
    ob::RealVectorBounds bounds(count);
    for (int k = 0; k < count; ++k) {
      if (isContinuous(scene, first + k))
        throw std::invalid_argument(
            "makeStateSpace: scene '" + scene.name() + "': " + scene.robot().variables()[scene.groupVariables()[first + k]].name +
            " is unbounded; give it robot.bounds in the scene file (a planner samples positions within them)");
      bounds.setLow(k, scene.lower(first + k));
      bounds.setHigh(k, scene.upper(first + k));
    }
    return bounds;
  };
  auto compound = std::make_shared<ob::CompoundStateSpace>();
  for (const StateMap::Part& p : parts) {
    switch (p.kind) {
      case StateMap::Kind::SO2: compound->addSubspace(std::make_shared<ob::SO2StateSpace>(), 1.0); break;
      case StateMap::Kind::Real: {
        auto r = std::make_shared<ob::RealVectorStateSpace>(1);
        r->setBounds(scene.lower(p.first), scene.upper(p.first));
        compound->addSubspace(r, 1.0);
        break;
      }
      case StateMap::Kind::SE2: {
        auto se2 = std::make_shared<ob::SE2StateSpace>();
        se2->setBounds(positionBounds(p.first, 2));
        compound->addSubspace(se2, 1.0);
        break;
      }
      case StateMap::Kind::SE3: {
        auto se3 = std::make_shared<ob::SE3StateSpace>();
        se3->setBounds(positionBounds(p.first, 3));
        compound->addSubspace(se3, 1.0);
        break;
      }
    }
  }
  compound->lock();
  return compound;
}

StateMap::StateMap(const Scene& scene) : parts_(partsOf(scene)), dimension_(scene.dimension()) {
  compound_ = false;
  for (const Part& p : parts_) compound_ = compound_ || p.kind != Kind::Real;
}

void StateMap::toVector(const ob::State* state, double* out) const noexcept {
  if (!compound_) {
    const double* v = state->as<ob::RealVectorStateSpace::StateType>()->values;
    for (int i = 0; i < dimension_; ++i) out[i] = v[i];
    return;
  }
  const auto* c = state->as<ob::CompoundState>();
  for (std::size_t k = 0; k < parts_.size(); ++k) {
    double* o = out + parts_[k].first;
    switch (parts_[k].kind) {
      case Kind::Real: o[0] = c->as<ob::RealVectorStateSpace::StateType>(k)->values[0]; break;
      case Kind::SO2: o[0] = c->as<ob::SO2StateSpace::StateType>(k)->value; break;
      case Kind::SE2: {
        const auto* se2 = c->as<ob::SE2StateSpace::StateType>(k);
        o[0] = se2->getX(), o[1] = se2->getY(), o[2] = se2->getYaw();
        break;
      }
      case Kind::SE3: {
        const auto* se3 = c->as<ob::SE3StateSpace::StateType>(k);
        const auto& r = se3->rotation();
        o[0] = se3->getX(), o[1] = se3->getY(), o[2] = se3->getZ();
        o[3] = r.x, o[4] = r.y, o[5] = r.z, o[6] = r.w;
        break;
      }
    }
  }
}

void StateMap::fromVector(const double* values, ob::State* state) const noexcept {
  if (!compound_) {
    double* v = state->as<ob::RealVectorStateSpace::StateType>()->values;
    for (int i = 0; i < dimension_; ++i) v[i] = values[i];
    return;
  }
  auto* c = state->as<ob::CompoundState>();
  for (std::size_t k = 0; k < parts_.size(); ++k) {
    const double* v = values + parts_[k].first;
    switch (parts_[k].kind) {
      case Kind::Real: c->as<ob::RealVectorStateSpace::StateType>(k)->values[0] = v[0]; break;
      case Kind::SO2: c->as<ob::SO2StateSpace::StateType>(k)->value = std::remainder(v[0], 2.0 * M_PI); break;  // [−π, π)
      case Kind::SE2: {
        auto* se2 = c->as<ob::SE2StateSpace::StateType>(k);
        se2->setXY(v[0], v[1]);
        se2->setYaw(std::remainder(v[2], 2.0 * M_PI));
        break;
      }
      case Kind::SE3: {
        auto* se3 = c->as<ob::SE3StateSpace::StateType>(k);
        se3->setXYZ(v[0], v[1], v[2]);
        // OMPL keeps unit quaternions; a zero one stays zero (and invalid) rather than becoming a rotation.
        const double norm = std::sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6]);
        const double scale = norm > 0.0 ? 1.0 / norm : 1.0;
        auto& r = se3->rotation();
        r.x = v[3] * scale, r.y = v[4] * scale, r.z = v[5] * scale, r.w = v[6] * scale;
        break;
      }
    }
  }
}

void StateMap::unwrap(const double* from, double* to) const noexcept {
  for (const Part& p : parts_) {
    if (p.kind == Kind::SO2 || p.kind == Kind::SE2) {
      const int i = p.kind == Kind::SO2 ? p.first : p.first + 2;
      to[i] = from[i] + std::remainder(to[i] - from[i], 2.0 * M_PI);
    }
  }
}

// ---- ValidityChecker ----------------------------------------------------------------------------------

namespace {

std::shared_ptr<World> worldOf(std::shared_ptr<const Scene> scene, MotionOptions options = {}) {
  return std::make_shared<World>(std::move(scene), options);
}

ValidityScratch& validityScratch(const PerThread<ValidityScratch>& scratch, const WorldSnapshot& w) {
  ValidityScratch& s = scratch.get([] { return ValidityScratch{}; });
  if (s.version != w.version) s = ValidityScratch{w.version, w.scene->makeContext(), std::vector<double>(w.scene->dimension()), {}};
  return s;
}

}  // namespace

ValidityChecker::ValidityChecker(const ob::SpaceInformationPtr& si, std::shared_ptr<const Scene> scene)
    : ValidityChecker(si, worldOf(std::move(scene))) {}

ValidityChecker::ValidityChecker(const ob::SpaceInformationPtr& si, std::shared_ptr<World> world)
    : ob::StateValidityChecker(si), world_(std::move(world)), map_(*world_->current().scene) {
  // Honest specs: clearance is an exact distance only when the scene computes it.
  specs_.clearanceComputationType = world_->current().scene->effects().clearance ? ob::StateValidityCheckerSpecs::EXACT
                                                                                 : ob::StateValidityCheckerSpecs::NONE;
  specs_.hasValidDirectionComputation = false;
}

bool ValidityChecker::isValid(const ob::State* state) const {
  const Timer timer(counters_.nanoseconds);
  ++counters_.states;
  const WorldSnapshot& w = world_->current();
  ValidityScratch& s = validityScratch(scratch_, w);
  map_.toVector(state, s.q.data());
  return w.scene->isFree(s.q.data(), s.ctx);
}

void ValidityChecker::areValid(const ob::State* const* states, std::size_t n, bool* valid) const {
  const Timer timer(counters_.nanoseconds);
  counters_.states += n;
  const WorldSnapshot& w = world_->current();
  ValidityScratch& s = validityScratch(scratch_, w);
  const std::size_t dim = static_cast<std::size_t>(w.scene->dimension());
  // In slices, so that a batch's count fits areFree's int however many states come.
  constexpr std::size_t kSlice = 1024;
  if (s.batch.size() < std::min(n, kSlice) * dim) s.batch.resize(std::min(n, kSlice) * dim);
  for (std::size_t first = 0; first < n; first += kSlice) {
    const std::size_t count = std::min(kSlice, n - first);
    for (std::size_t k = 0; k < count; ++k) map_.toVector(states[first + k], s.batch.data() + k * dim);
    w.scene->areFree(s.batch.data(), static_cast<int>(count), s.ctx, valid + first);
  }
}

double ValidityChecker::clearance(const ob::State* state) const {
  const WorldSnapshot& w = world_->current();
  if (!w.scene->effects().clearance) return ob::StateValidityChecker::clearance(state);
  ValidityScratch& s = validityScratch(scratch_, w);
  map_.toVector(state, s.q.data());
  const double c = w.scene->clearance(s.q.data(), s.ctx);
  return std::isnan(c) ? 0.0 : c;
}

// ---- ContinuousMotionValidator ------------------------------------------------------------------------

namespace {

// OMPL's states carry no time, and against moving obstacles a segment's verdict depends on when it is
// travelled: refused rather than checked with the obstacles held where they are at t = 0.
bool timeless(const Scene& scene) { return !(scene.effects().moving && scene.environment().hasMovingObstacles()); }

std::shared_ptr<World> timelessWorld(std::shared_ptr<World> world) {
  const Scene& scene = *world->current().scene;
  if (!timeless(scene))
    throw std::invalid_argument("ContinuousMotionValidator: scene '" + scene.name() +
                                "' has moving obstacles, and OMPL states carry no time (use MotionChecker::check with times)");
  return world;
}

}  // namespace

ContinuousMotionValidator::ContinuousMotionValidator(const ob::SpaceInformationPtr& si,
                                                     std::shared_ptr<const Scene> scene, MotionOptions options)
    : ContinuousMotionValidator(si, worldOf(std::move(scene), options)) {}

ContinuousMotionValidator::ContinuousMotionValidator(const ob::SpaceInformationPtr& si, std::shared_ptr<World> world)
    : ob::MotionValidator(si), world_(timelessWorld(std::move(world))), map_(*world_->current().scene) {}

MotionResult ContinuousMotionValidator::check(const ob::State* s1, const ob::State* s2, bool locate_contact) const {
  const Timer timer(counters_.nanoseconds);
  ++counters_.motions;
  const WorldSnapshot& w = world_->current();
  if (!timeless(*w.scene)) {  // moving obstacles added after construction: never free by accident
    MotionResult r;
    r.free = false;
    return r;
  }
  MotionScratch& s = scratch_.get([] { return MotionScratch{}; });
  if (s.version != w.version) {
    const int n = w.scene->dimension();
    s = MotionScratch{w.version, w.motion->makeContext(), std::vector<double>(n), std::vector<double>(n),
                      SegmentMemo(n)};
  }
  map_.toVector(s1, s.q0.data());
  map_.toVector(s2, s.q1.data());
  map_.unwrap(s.q0.data(), s.q1.data());
  const bool remembering = remembering_.load(std::memory_order_relaxed);
  if (const MotionResult* kept = remembering ? s.memo.find(s.q0.data(), s.q1.data(), locate_contact) : nullptr) {
    ++counters_.remembered;
    MotionResult r = *kept;
    r.steps = r.distance_queries = 0;  // (no work was done for this answer)
    return r;
  }
  if (remembering && s.memo.inFree(s.q0.data(), s.q1.data(), [&](const double* p0, const double* p1, double margin) {
        return w.motion->within(s.q0.data(), s.q1.data(), p0, p1, margin, s.ctx);
      })) {
    ++counters_.within;
    MotionResult r;
    r.free = true;  // (its own margin unknown: 0, and so it is not kept as a segment others lie in)
    return r;
  }
  const MotionResult r = w.motion->check(s.q0.data(), s.q1.data(), s.ctx, locate_contact);
  if (remembering && !r.capped) s.memo.keep(s.q0.data(), s.q1.data(), locate_contact, r);  // (a cap: no verdict)
  return r;
}

void ContinuousMotionValidator::count(bool free) const {
  const std::lock_guard<std::mutex> lock(ompl_counters_);
  ++(free ? valid_ : invalid_);
}

bool ContinuousMotionValidator::checkMotion(const ob::State* s1, const ob::State* s2) const {
  const bool free = check(s1, s2, /*locate_contact=*/false).free;
  count(free);
  return free;
}

bool ContinuousMotionValidator::checkMotion(const ob::State* s1, const ob::State* s2,
                                            std::pair<ob::State*, double>& lastValid) const {
  const MotionResult r = check(s1, s2);
  count(r.free);
  if (r.free) return true;
  lastValid.second = r.last_valid;
  // The state space interpolates exactly as the checker did (linear; SO(2) the short way), so the
  // state at last_valid is the one the checker certified.
  if (lastValid.first) si_->getStateSpace()->interpolate(s1, s2, r.last_valid, lastValid.first);
  return false;
}

CollisionChecking setupCollisionChecking(const ob::SpaceInformationPtr& si, std::shared_ptr<const Scene> scene,
                                         MotionOptions options) {
  return setupCollisionChecking(si, std::make_shared<World>(std::move(scene), options));
}

CollisionChecking setupCollisionChecking(const ob::SpaceInformationPtr& si, std::shared_ptr<World> world) {
  CollisionChecking c;
  c.validity = std::make_shared<ValidityChecker>(si, world);
  c.motion = std::make_shared<ContinuousMotionValidator>(si, world);
  si->setStateValidityChecker(c.validity);
  si->setMotionValidator(c.motion);
  si->setup();
  return c;
}

}  // namespace clearway
