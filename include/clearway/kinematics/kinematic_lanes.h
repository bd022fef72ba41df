#pragma once
// Forward kinematics for several joint vectors at once: each double of a link's pose is one SIMD vector
// whose lanes are the states. The widest vectors the CPU offers, up to AVX2 (SSE4: 2 lanes, AVX2: 4), are
// chosen at run time, so one binary serves every x86-64 machine (src/detail/simd_targets.h says why not
// AVX-512).
//
// The lanes repeat computeLinkPose's operations in its order, with no fused multiply-add (the library is
// built with -ffp-contract=off), so every pose equals the scalar one bit for bit, on every target: a batch
// of states gets the verdicts the states get one at a time.
#include <clearway/kinematics/robot_model.h>

#include <cstdint>
#include <vector>

namespace clearway {

/// Forward kinematics of one robot over lanes of states. Made per thread; compute() allocates nothing.
class KinematicLanes {
 public:
  /// At least the most lanes any target has, which sizes the scratch (8: room for 512-bit vectors).
  static constexpr int kMaxLanes = 8;

  /// For `model`, which must outlive this.
  explicit KinematicLanes(const RobotModel& model);

  /// True when made for this model (the very object).
  bool madeFor(const RobotModel& model) const noexcept { return model_ == &model; }
  /// The states the chosen target computes together (1 without SIMD, 2 or 4).
  static int width() noexcept;
  /// The name of the target chosen at run time ("AVX2", "SSE4", ...).
  static const char* targetName() noexcept;
  /// The Highway targets compiled for the lanes that this CPU runs, best first (the first is chosen).
  static std::vector<std::int64_t> targets();

  /// For s < n: writes joint vector q[s]'s link poses to poses[s][0 .. linkCount), equal bit for bit to
  /// computeLinkPoses(model, q[s], poses[s]). Any n ≥ 0; takes width() states per pass.
  void compute(const double* const* q, int n, Pose* const* poses) noexcept;

 private:
  const RobotModel* model_;
  std::vector<double> lanes_;  // per link, R (column-major) then t: 12 rows of kMaxLanes doubles
};

}  // namespace clearway
