#pragma once
// A world's static obstacles as oriented boxes in SIMD lanes: a ball farther than its slack from every box
// is that far from every obstacle, whatever their shapes, in a few multiply-adds per obstacle (the ball
// moved into the box's frame, its distance to the box). Each box holds its obstacle: a primitive's tight
// box in its own frame, a mesh's box of its hull, a voxel's cell. Where a tree walk compares the axis-
// aligned box of a link's ball with the axis-aligned boxes of turned obstacles, this compares the ball
// itself with the turned boxes: cheaper for a few obstacles, and far tighter beside a turned wall.
//
// Why it never clears by accident. An obstacle point is p = R·(l + y) + t for its pose (R, t), its box's
// centre l and some |y_k| ≤ h_k. With o = R·l + t and RᵀR = I + Δ, Rᵀ(c − p) = Rᵀ(c − o) − y − Δ·y, so the
// distance of Rᵀ(c − o) to the box [−h, h] is at most |Rᵀ(c − p)| + |Δ|·|h| ≤ (1 + |Δ|)·|c − p| + |Δ|·|h|.
// Boxes are kept only for |Δ| ≤ kMaxSkew (every entry; a rotation from a unit quaternion errs by a few ε),
// and the computed distance errs from its exact value by a few ε of |c| + |o| + |h| + |l| + |t| (o placed,
// the dot products, the squares). Both are far below margins::kRounding of those sizes, which the limit
// adds: a box the test calls clear is more than `slack` from the ball.
#include <clearway/math.h>
#include <clearway/tree/aabb.h>

#include <memory>
#include <vector>

namespace clearway {

/// The oriented boxes of a few obstacles, tested against balls in SIMD lanes. Immutable once built.
class ObstacleBoxes {
 public:
  /// More obstacles than this are left to the trees and the clearance grid (a map's voxels, a cloud).
  static constexpr int kMaxBoxes = 64;
  /// How far from a rotation (any entry of RᵀR − I) a pose may be for its box to be kept.
  static constexpr double kMaxSkew = 1e-13;

  /// A box in the frame `pose` places in the world.
  struct Placed {
    Pose pose;  ///< the obstacle's pose (a voxel's: the identity)
    Aabb box;   ///< its box in its own frame (finite, not empty)
  };
  /// The boxes, or null when there are none, more than kMaxBoxes, or one that is not finite or whose pose
  /// is not a rotation within kMaxSkew (the caller then keeps to its trees).
  static std::shared_ptr<const ObstacleBoxes> build(const std::vector<Placed>& boxes);

  /// How many boxes there are.
  int size() const noexcept { return count_; }
  /// True when the ball (world frame) is more than `slack` metres from every box, beyond rounding, and so
  /// from every obstacle they hold. False proves nothing; a NaN or infinite input is never clear.
  bool ballClear(const Vec3& center, double radius, double slack) const noexcept;

 private:
  ObstacleBoxes() = default;
  // One array per field, each `padded_` long (a multiple of the widest lanes; the last box repeated):
  // the world centre, R's nine entries column by column, the half extents, and the size sizing the band.
  enum Field { kOx, kOy, kOz, kR00, kR10, kR20, kR01, kR11, kR21, kR02, kR12, kR22, kHx, kHy, kHz, kSize, kFields };
  int count_ = 0, padded_ = 0;
  std::vector<double> soa_;  // kFields arrays of padded_ entries
};

}  // namespace clearway
