// Whether balls hold the inside of a link's closed meshes. The parts' balls hold the surfaces (each part's
// hull holds its triangles), but a closed mesh is a solid, and a body wholly inside it touches no surface:
// the enclosing layer may clear a pair by parts' balls only where their union holds the solids too.
//
// The proof splits each closed piece's box into cells (an octree, depth first). A cell is settled when
//  (1) it lies in one ball grown by the margin δ: |c − c_k| + h ≤ r_k + δ, h its half diagonal; or
//  (2) no triangle comes within h of its centre, so no surface crosses it: being connected, the cell lies
//      wholly inside or wholly outside each closed piece, and its centre, outside all of them
//      (containsPoint, never "outside" by accident), puts it outside.
// Otherwise it is split, down to cells with h ≤ δ/4. Such a cell meeting a triangle of part k is within
// r_k + 2h ≤ r_k + δ/2 of c_k, so (1) settles it with δ/2 to spare for rounding: a cell that (1) leaves
// unsettled at the bottom is decided by (2) alone, and one that (2) calls inside fails the proof. Why δ at
// all: a part's farthest vertex lies on its ball, and the cells around it straddle that ball's boundary at
// every size, so without growth the split would never end there.
#include <clearway/body/link_geometry.h>
#include <clearway/detail/margins.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace clearway {
namespace {

// The parts' balls grow by this fraction of the link's bounding ball (0.03 to 0.17 mm on the Panda's links):
// the octree reaches about log₂(4·1024·√3) ≈ 13 levels below a piece's box, but only where a ball's boundary
// meets the surface; a proof visits 160 to 17,000 cells on the shared robots' links.
constexpr double kMarginFraction = 1.0 / 1024.0;
// The proof gives up (the link keeps its bounding ball only) after this many cells.
constexpr long kMaxCells = 1L << 18;

}  // namespace

bool LinkGeometry::ballsHoldSolids(const std::vector<Ball>& balls, double margin) const {
  if (solid_boxes_.empty()) return true;
  if (!(margin > 0.0) || !std::isfinite(margin)) return false;
  const double rounding = margins::kSlack * (1.0 + bounding_radius_);  // far above the few ulps of each distance
  const double smallest = 0.25 * margin;                     // the bottom cells' half diagonal
  long cells = 0;
  std::vector<Aabb> stack;
  for (const Aabb& piece : solid_boxes_) {
    stack.push_back(piece);
    while (!stack.empty()) {
      const Aabb cell = stack.back();
      stack.pop_back();
      if (++cells > kMaxCells) return false;
      const Vec3 c = cell.center();
      const double h = 0.5 * (cell.max - cell.min).norm();
      const bool held = std::any_of(balls.begin(), balls.end(), [&](const Ball& b) {
        // (A ball's own size adds to the rounding: balls given far from the link.)
        const double own = 1e-15 * (b.center.norm() + b.radius);
        return (c - b.center).norm() + h + rounding + own <= b.radius + margin;
      });
      if (held) continue;
      if (!(surfaceDistance(c, 2.0 * (h + rounding)) > h + rounding)) {  // a surface may cross it
        if (h <= smallest) return false;  // (never at the bottom, but for rounding)
      } else if (!containsPoint(c)) {
        continue;  // wholly outside
      } else if (h <= smallest) {
        return false;  // inside, and held by no ball
      }
      // Split at the centre on each axis: the children share the parent's faces exactly.
      for (int k = 0; k < 8; ++k) {
        Aabb child;
        for (int a = 0; a < 3; ++a) {
          const bool upper = (k >> a) & 1;
          child.min[a] = upper ? c[a] : cell.min[a];
          child.max[a] = upper ? cell.max[a] : c[a];
        }
        stack.push_back(child);
      }
    }
  }
  return true;
}

double LinkGeometry::partBallMargin() const {
  double margin = part_ball_margin_.value.load(std::memory_order_relaxed);
  if (std::isnan(margin)) {
    margin = coverSolids();
    part_ball_margin_.value.store(margin, std::memory_order_relaxed);
  }
  return margin;
}

double LinkGeometry::coverSolids() const {
  // Without closed meshes the parts hold every surface and primitive; one part's hull holds all triangles,
  // so the inside of the closed meshes they bound too.
  if (solid_boxes_.empty() || parts_.size() <= 1) return 0.0;
  std::vector<Ball> balls;
  for (const Part& p : parts_) balls.push_back({p.center, p.radius});
  const double margin = kMarginFraction * sphere_radius_;
  return ballsHoldSolids(balls, margin) ? margin : std::numeric_limits<double>::infinity();
}

}  // namespace clearway
