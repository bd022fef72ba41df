#pragma once
// Clearway inside OMPL: a state space made from a scene's group, a StateValidityChecker and a
// continuous MotionValidator. Both are thread-safe (OMPL's parallel planners and PRM's second thread
// call them at once): every thread gets its own scratch, and the counters are atomic. Both check a
// World's current snapshot: edit the world (world/world.h) and plan again, with the same space
// information; a planner already running sees each query answered by one whole snapshot.
//
// The namespace is clearway, not clearway::ompl: inside a clearway::ompl, `ompl::base` would resolve
// to clearway::ompl::base.
#include <clearway/motion/motion.h>
#include <clearway/per_thread.h>
#include <clearway/scene/scene.h>
#include <clearway/world/world.h>

#include <ompl/base/MotionValidator.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/StateValidityChecker.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>

namespace clearway {

namespace ompl_detail {
struct ValidityScratch;  // collision_checking.cpp
struct MotionScratch;
}  // namespace ompl_detail

/// The OMPL state space of a scene's group: bounded joints are real-vector dimensions with the joint
/// limits; continuous joints are SO(2); a planar joint is SE(2) and a floating joint SE(3), their
/// positions bounded by the scene's robot.bounds (std::invalid_argument when it gives none). All
/// bounded one-variable joints: one RealVectorStateSpace; otherwise a compound space, in state order.
ompl::base::StateSpacePtr makeStateSpace(const Scene& scene);

/// Converts between OMPL states of makeStateSpace(scene) and Clearway state vectors, allocation-free.
class StateMap {
 public:
  /// What a run of state entries maps to: a real dimension, SO(2), SE(2) (3 entries) or SE(3) (7).
  enum class Kind { Real, SO2, SE2, SE3 };
  /// One subspace of the state, in state order.
  struct Part {
    Kind kind;  ///< its subspace
    int first;  ///< its first state entry
  };
  /// The map of makeStateSpace(scene)'s states (the scene's group); the scene need not outlive it.
  explicit StateMap(const Scene& scene);
  /// Writes the state's scene-dimension values to out (SE(3): x, y, z, qx, qy, qz, qw).
  void toVector(const ompl::base::State* state, double* out) const noexcept;
  /// Writes the values into an OMPL state (angles wrapped into [−π, π), quaternions normalized).
  void fromVector(const double* values, ompl::base::State* state) const noexcept;
  /// After toVector of the two ends: shifts the SO(2) and SE(2) angles of `to` so that the segment turns
  /// the short way, as OMPL's interpolation does (quaternions: MotionChecker takes the short arc itself).
  void unwrap(const double* from, double* to) const noexcept;
  /// The number of Clearway state entries (Scene::dimension()).
  int dimension() const noexcept { return dimension_; }

 private:
  std::vector<Part> parts_;
  int dimension_ = 0;
  bool compound_ = false;
};

/// Counters readable by benchmarks (all cumulative).
struct CheckerCounters {
  ///@{
  /// States checked (isValid, areValid), segments checked (checkMotion, check), and the wall time spent
  /// in those calls, summed over threads (ns).
  std::atomic<std::uint64_t> states{0}, motions{0}, nanoseconds{0};
  ///@}
  /// Segments of `motions` answered from the thread's memo of its last 64: the same ends (bit for bit) on
  /// the same snapshot of the world, as OMPL's path simplifier often asks again.
  std::atomic<std::uint64_t> remembered{0};
  /// Segments of `motions` answered free as lying within one of the segments certified free the thread keeps
  /// (up to 1,024; MotionChecker::within): OMPL's simplifier subdivides a path's segments and asks for segments
  /// between their points.
  std::atomic<std::uint64_t> within{0};
};

/// ompl::base::StateValidityChecker over a Scene: isValid is Scene::isFree; clearance is
/// Scene::clearance when the scene declares `clearance` (otherwise OMPL's default, 0).
class ValidityChecker : public ompl::base::StateValidityChecker {
 public:
  /// The checker of one scene (in a World of its own, never edited).
  ValidityChecker(const ompl::base::SpaceInformationPtr& si, std::shared_ptr<const Scene> scene);
  /// The checker of a world's current snapshot, whichever it is at each query.
  ValidityChecker(const ompl::base::SpaceInformationPtr& si, std::shared_ptr<World> world);
  /// Scene::isFree of the state on the current snapshot: false for a collision or an invalid state.
  bool isValid(const ompl::base::State* state) const override;
  /// valid[k] = isValid(states[k]) for k < n, the states' kinematics in SIMD lanes (Scene::areFree): for
  /// planners and tools that check many states at once, such as a roadmap's samples or a path's states.
  void areValid(const ompl::base::State* const* states, std::size_t n, bool* valid) const;
  /// Scene::clearance of the state (metres; 0 when it is NaN), or OMPL's default when the scene does not
  /// declare `clearance`. Not counted in counters().
  double clearance(const ompl::base::State* state) const override;
  /// The calls made so far, by all threads.
  const CheckerCounters& counters() const noexcept { return counters_; }
  /// The current snapshot's scene (World::current(): valid until this thread's next query).
  const Scene& scene() const { return *world_->current().scene; }
  /// The world checked (one of its own for the scene constructor); edits reach the next query.
  World& world() const noexcept { return *world_; }

 private:
  std::shared_ptr<World> world_;
  StateMap map_;
  PerThread<ompl_detail::ValidityScratch> scratch_;  // each thread's context and state buffers
  mutable CheckerCounters counters_;
};

/// ompl::base::MotionValidator that checks the whole segment (MotionMode::Certified: no tunnelling).
/// checkMotion(s1, s2) asks for the verdict alone (the first contact found ends it); checkMotion(s1, s2,
/// lastValid) locates the first contact, reports the fraction of the last valid state before it and
/// writes that state when lastValid.first is given. Where the first says free, so does the second. Each
/// thread remembers its last 64 answers: a segment asked again with the same ends on the same snapshot of
/// the world gets the answer computed the first time, at once (counters().remembered); and up to 1,024 of its
/// segments certified free: a segment that lies within one of them is free (counters().within), though its
/// own check could stop within the contact distance where the longer one's check measured no contact.
class ContinuousMotionValidator : public ompl::base::MotionValidator {
 public:
  /// The validator of one scene, checked with `options`. Throws std::invalid_argument when the scene has
  /// moving obstacles (OMPL states carry no time).
  ContinuousMotionValidator(const ompl::base::SpaceInformationPtr& si, std::shared_ptr<const Scene> scene,
                            MotionOptions options = {});
  /// The validator of a world's current snapshot (its motion checker; the world's MotionOptions). A segment
  /// checked after moving obstacles were added is not free: OMPL states carry no time.
  ContinuousMotionValidator(const ompl::base::SpaceInformationPtr& si, std::shared_ptr<World> world);
  /// True when the segment s1 → s2 is certified free (the verdict alone).
  bool checkMotion(const ompl::base::State* s1, const ompl::base::State* s2) const override;
  /// The same, locating the first contact when not free: lastValid.second is the fraction of the last
  /// valid state, written into lastValid.first when that is not null.
  bool checkMotion(const ompl::base::State* s1, const ompl::base::State* s2,
                   std::pair<ompl::base::State*, double>& lastValid) const override;
  /// The calls made so far, by all threads.
  const CheckerCounters& counters() const noexcept { return counters_; }
  /// The verdict on s1 → s2 with the contact (MotionChecker::check; locate_contact as there).
  MotionResult check(const ompl::base::State* s1, const ompl::base::State* s2, bool locate_contact = true) const;
  /// Whether answers are remembered (on by default). Off, every call computes its answer: for timing the
  /// check itself over segments asked more than once (a benchmark's passes), or counting its work.
  void setRemembering(bool on) noexcept { remembering_ = on; }

 private:
  std::shared_ptr<World> world_;
  StateMap map_;
  PerThread<ompl_detail::MotionScratch> scratch_;  // each thread's context and state buffers
  mutable CheckerCounters counters_;
  std::atomic<bool> remembering_{true};
  // OMPL's valid_ and invalid_ are plain integers that its benchmark tools read once planning is done;
  // parallel planners call checkMotion from several threads, so each update takes this lock.
  mutable std::mutex ompl_counters_;
  void count(bool free) const;
};

/// The checkers setupCollisionChecking installs, returned for their counters.
struct CollisionChecking {
  std::shared_ptr<ValidityChecker> validity;          ///< installed as si's state validity checker
  std::shared_ptr<ContinuousMotionValidator> motion;  ///< installed as si's motion validator
};
/// Installs a ValidityChecker and a ContinuousMotionValidator on si (whose space must be
/// makeStateSpace(*scene) or equal to it) and calls si->setup(). Returns them for their counters.
CollisionChecking setupCollisionChecking(const ompl::base::SpaceInformationPtr& si, std::shared_ptr<const Scene> scene,
                                         MotionOptions options = {});
/// The same over a world: planning again after an edit needs no new space information.
CollisionChecking setupCollisionChecking(const ompl::base::SpaceInformationPtr& si, std::shared_ptr<World> world);

}  // namespace clearway
