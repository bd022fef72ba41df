#pragma once
// A distance field over boxes: per cell of a regular grid, a lower bound on the distance from the cell's
// centre to every box, so that one look-up and one square root clear a ball from all of them at once,
// where a tree walks its nodes. The environment keeps one over its static obstacles' and voxels' boxes
// (environment.h): a link's bounding ball it clears needs no tree walk and no narrow phase.
//
// Why it is a lower bound. Every cell a box touches is marked (one cell more on each side, so that no
// rounding of the cell index can leave a touched cell unmarked). A point x of a box then lies in a marked
// cell m, whose centre is within h√3/2 of x (h: the cell edge). For any cell centre c, the least |c − c_m|
// over marked cells is h·√D, D the least squared distance in whole cells, computed exactly in integers by
// one pass per axis (the squared distance to the nearest mark along x; then, along y and z, the least
// d² + the last pass's value over a window of kWindow cells), each pass capped at (kWindow + 1)²: no more
// than its exact value, so neither is D. Then |c − x| ≥ h·√D − h√3/2, stored rounded down; and for a
// query point p, |p − x| ≥ stored(c) − |p − c| for whichever cell c it reads.
#include <clearway/detail/margins.h>
#include <clearway/math.h>
#include <clearway/tree/aabb.h>

#include <array>
#include <vector>

namespace clearway {

/// Certified lower bounds on the distance from a point to a fixed set of boxes. Immutable once built.
class ClearanceGrid {
 public:
  /// Cells per axis of a pass's window: distances beyond it (in cells) are read as just beyond it.
  static constexpr int kWindow = 16;
  /// The default budget of cells (a quarter million floats: 1 MiB).
  static constexpr int kDefaultCells = 1 << 18;

  /// The grid over `boxes` (each finite and non-empty; any number), with the finest cells that keep it to
  /// at most `max_cells` (at least 1000). Throws std::invalid_argument for a non-finite or empty box.
  explicit ClearanceGrid(const std::vector<Aabb>& boxes, int max_cells = kDefaultCells);

  /// A lower bound on the distance from p to every box given: +∞ when there are none; 0 or less proves
  /// nothing (and a p with a NaN or an infinity gives 0).
  /// (Inlined into the per-link loops that call it: a call costs as much as the look-up.)
  [[gnu::always_inline]] double lowerBound(const Vec3& p) const noexcept {
    const double slack = slack_ + margins::kSlack * p.cwiseAbs().maxCoeff();
    int i[3];
    for (int k = 0; k < 3; ++k) {
      const double f = (p[k] - origin_[k]) * inv_h_;
      if (!(f >= 0.0 && f < n_[k])) return outside(p, slack);  // (also a NaN)
      i[k] = static_cast<int>(f);
    }
    const Vec3 c = origin_ + h_ * Vec3(i[0] + 0.5, i[1] + 0.5, i[2] + 0.5);
    const std::size_t at = (static_cast<std::size_t>(i[2]) * n_[1] + i[1]) * n_[0] + i[0];
    return static_cast<double>(bound_[at]) - (p - c).norm() - slack;
  }

  /// The cells' edge, metres.
  double cellSize() const noexcept { return h_; }
  /// Cells along x, y and z.
  std::array<int, 3> cells() const noexcept { return {n_[0], n_[1], n_[2]}; }

 private:
  Aabb bounds_;  // of the boxes (empty: none)
  Vec3 origin_ = Vec3::Zero();  // the low corner of cell (0, 0, 0)
  double h_ = 0.0, inv_h_ = 0.0;
  int n_[3] = {0, 0, 0};
  double slack_ = 0.0;  // what a query subtracts for its own rounding (scaled by the point's size)
  std::vector<float> bound_;  // per cell (x fastest), the lower bound at its centre, rounded down
  // A point outside the grid (or not finite): its distance to the boxes' box (0 for a NaN).
  double outside(const Vec3& p, double slack) const noexcept;
};

}  // namespace clearway
