#pragma once
// Points fixed to links (a bounding ball's centre, say), placed for up to eight joint vectors at once in
// float lanes, each within a proven distance of where the double kinematics (computeLinkPoses) puts it:
// a sphere stage grows its balls by that distance and tests eight states' balls in the time one state's
// double poses take. Only the links that carry a point, and their ancestors, are computed.
//
// Why the bound holds (u = 2⁻²⁴, float's unit roundoff; γₙ = n·u / (1 − n·u); norms: Frobenius for
// matrices, Euclidean for vectors). Per link, e bounds |R̂ − R| and ε bounds |t̂ − t| against the exact
// poses of the same joint values, and T bounds |t|, over every joint vector within the given magnitudes:
// - the root is the identity, exactly: e = ε = T = 0;
// - M = P·O (O the joint's fixed turn, rounded to float within √3·u; skipped, exact, when O = I): an entry
//   is a 3-term dot product, rounded within γ₃ of the dot product of absolute values, so
//   m ≤ e_P·(1 + √3u) + √3u + γ₃·(√3 + e_P)·√3·(1 + u), R_P and O being rotations (|R_P·X| = |X|);
// - t = P·o + t_P, o the joint's offset (a slide's value along its axis added: |o| ≤ |origin| + V for values
//   |v| ≤ V), rounded to within 5u·|o|: a 4-term sum, so ε ≤ ε_P + e_P·|ô| + 5u·|o| + γ₄·((√3 + e_P)·|ô| +
//   T_P + ε_P), and T ≤ T_P + |o|;
// - a turn about z multiplies M's first two columns by the 2 × 2 turn of cos and sin (double sinCos, within
//   2⁻⁵² of exact, then rounded to float: within δ = 2u each), whose norm is within 2δ of 1 and whose error
//   is within 2δ: e ≤ m·(1 + 2δ) + 2δ + γ₂·√2·(√3 + m)·(1 + 2δ); a turn about any axis (Rodrigues' form,
//   each entry ten roundings at most of terms whose absolute values add up to at most 4.5·(1 + m)):
//   e ≤ m·(1 + 6δ + 6u) + 6δ + 6u + 18·γ₁₀·(1 + m); a fixed joint or a slide: e = m;
// - a point p: |ĉ − c| ≤ e·|p̂| + u·|p| + γ₄·((√3 + e)·|p̂| + T + ε) + ε.
// The double poses err from the exact ones by the same recursion at u = 2⁻⁵³ (their kernel does the same
// operations), which is added; the sum is doubled, since the constants above are not tight and the factor
// costs nothing at these sizes (micrometres on a metre-sized robot).
#include <clearway/kinematics/robot_model.h>

#include <cstddef>
#include <vector>

namespace clearway {

/// World positions of points fixed to links, for up to kLanes joint vectors at once, in float, each within
/// error(k) of its position under the double poses. Immutable once made; compute() writes only its outputs.
class PointLanes {
 public:
  /// The states one compute() places.
  static constexpr int kLanes = 8;
  /// A point in a link's frame.
  struct Point {
    int link;  ///< the link it is fixed to
    Vec3 p;    ///< where, in the link's frame
  };

  /// Empty: serves nothing.
  PointLanes() = default;
  /// For `model` (which must outlive this), the points given, and joint vectors whose entries v satisfy
  /// |v| ≤ most[v] (one per variable of the model; only slides' are read, ∞ allowed). Serves nothing when
  /// the robot has a planar or floating joint on a point's chain, when a slide's bound is not finite, or when
  /// the chains reach farther than kMaxReach (float then rounds coarsely), or a bound exceeds kMaxError.
  PointLanes(const RobotModel& model, std::vector<Point> points, const std::vector<double>& most);

  /// How far (metres) the chains may reach from the root for the lanes to serve.
  static constexpr double kMaxReach = 1000.0;
  /// The largest error bound (metres) the lanes serve with: a ball grown by more settles little.
  static constexpr double kMaxError = 1e-3;

  /// True when compute() may be called.
  bool serves() const noexcept { return serves_; }
  /// The number of points.
  int size() const noexcept { return static_cast<int>(points_.size()); }
  /// A bound (metres) on the distance of point k's computed position from its position under the double
  /// poses of the same joint vector, for every joint vector within the magnitudes given.
  double error(int k) const noexcept { return error_[static_cast<std::size_t>(k)]; }
  /// The floats compute() needs as scratch.
  std::size_t scratchSize() const noexcept { return static_cast<std::size_t>(steps_.size() + 1) * 12 * kLanes; }

  /// For lanes l < n (1 ≤ n ≤ kLanes): point k of joint vector q[l] (full, model.variableCount() entries) to
  /// xyz[(3k + c)·kLanes + l], c = 0, 1, 2 for x, y, z. Lanes at and beyond n repeat lane n − 1. `scratch`
  /// holds scratchSize() floats. Only when serves().
  void compute(const double* const* q, int n, float* xyz, float* scratch) const noexcept;

  /// One link's step, folded for the lanes (point_lanes.cpp reads it).
  struct Step {
    int parent_slot;                    ///< the parent's slot in the scratch (0: the root)
    int kind;                           ///< detail::KinematicStep::Kind
    bool turned;                        ///< O is not the identity
    float O[9];                         ///< the joint's fixed turn, column-major
    float origin[3];                    ///< its offset
    float axis[3];                      ///< Turn: the axis; Slide: the direction slid along
    float axis_sign;                    ///< TurnZ
    const detail::KinematicStep* step;  ///< the joint's value
  };

 private:
  bool serves_ = false;
  std::vector<Point> points_;
  std::vector<int> point_slot_;  // each point's link's slot
  std::vector<float> point_p_;   // each point, rounded to float (3 per point)
  std::vector<Step> steps_;      // in topological order: slot s + 1 is steps_[s]'s link
  std::vector<double> error_;
};

}  // namespace clearway
