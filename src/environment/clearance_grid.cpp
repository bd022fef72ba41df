#include <clearway/environment/clearance_grid.h>

#include <clearway/detail/margins.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

namespace clearway {
namespace {

constexpr int kPad = 2;  // cells beyond the boxes on each side: room for the marks' extra cell
constexpr std::int32_t kCap = (ClearanceGrid::kWindow + 1) * (ClearanceGrid::kWindow + 1);

// One pass along y or z over whole rows of x: out = min(kCap, min over |d| ≤ kWindow of d² + in[+d rows]),
// for the n rows `stride` apart from `in`, each `width` long. Exact in integers; the inner loop runs
// along x, where the compiler's vectors take several cells at once.
void pass(const std::int32_t* in, std::int32_t* out, int n, std::ptrdiff_t stride, int width) noexcept {
  for (int q = 0; q < n; ++q) {
    std::int32_t* o = out + q * stride;
    std::fill(o, o + width, kCap);
    const int lo = std::max(0, q - ClearanceGrid::kWindow), hi = std::min(n - 1, q + ClearanceGrid::kWindow);
    for (int r = lo; r <= hi; ++r) {
      const std::int32_t d2 = (q - r) * (q - r);
      const std::int32_t* row = in + r * stride;
      for (int x = 0; x < width; ++x) o[x] = std::min(o[x], d2 + row[x]);
    }
  }
}

}  // namespace

ClearanceGrid::ClearanceGrid(const std::vector<Aabb>& boxes, int max_cells) {
  for (const Aabb& b : boxes) {
    if (b.isEmpty() || !b.min.allFinite() || !b.max.allFinite())
      throw std::invalid_argument("clearance grid: a box is empty or not finite");
    bounds_.merge(b);
  }
  if (boxes.empty()) return;
  max_cells = std::max(max_cells, 1000);
  const Vec3 e = bounds_.extents();
  const double e_max = e.maxCoeff();
  const double scale = std::max(bounds_.min.cwiseAbs().maxCoeff(), bounds_.max.cwiseAbs().maxCoeff());
  // Boxes near the doubles' end (extents that overflow): no cells, every point reads the boxes' box.
  slack_ = margins::kSlack * (1.0 + scale);
  if (!(scale < 1e300) || !std::isfinite(e_max)) return;
  // The finest cells within the budget. Exits: h starts at no less than e_max / 1024 and grows by a
  // quarter per step, so within 32 steps h ≥ e_max, where at most 6³ cells remain (≤ 1000 ≤ max_cells).
  double h = std::max(e_max / 1024.0, 1e-6 * (1.0 + scale));
  const auto count = [&](double edge, int* n) {
    std::int64_t total = 1;
    for (int a = 0; a < 3; ++a) {
      n[a] = static_cast<int>(std::floor(e[a] / edge)) + 1 + 2 * kPad;
      total *= n[a];
    }
    return total;
  };
  while (count(h, n_) > max_cells) h *= 1.25;
  h_ = h;
  inv_h_ = 1.0 / h;
  origin_ = bounds_.min - Vec3::Constant(kPad * h);
  slack_ = margins::kSlack * (1.0 + scale + kPad * h);

  const std::size_t total = static_cast<std::size_t>(n_[0]) * n_[1] * n_[2];
  std::vector<std::int32_t> a(total, kCap), b(total);
  const std::ptrdiff_t sy = n_[0], sz = static_cast<std::ptrdiff_t>(n_[0]) * n_[1];
  const auto cell = [&](double x, int axis) {  // a coordinate's cell, clamped to the grid
    const double f = std::floor((x - origin_[axis]) * inv_h_);
    return static_cast<int>(std::clamp(f, 0.0, static_cast<double>(n_[axis] - 1)));
  };
  for (const Aabb& box : boxes) {
    int lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::max(cell(box.min[k], k) - 1, 0);
      hi[k] = std::min(cell(box.max[k], k) + 1, n_[k] - 1);
    }
    for (int z = lo[2]; z <= hi[2]; ++z)
      for (int y = lo[1]; y <= hi[1]; ++y)
        std::fill(a.begin() + (z * sz + y * sy + lo[0]), a.begin() + (z * sz + y * sy + hi[0] + 1), 0);
  }
  // Along x, from the marks alone: the squared distance to the nearest mark in the row (two sweeps).
  for (std::ptrdiff_t row = 0; row < static_cast<std::ptrdiff_t>(total); row += n_[0]) {
    std::int32_t* r = &a[row];
    constexpr int kFar = ClearanceGrid::kWindow + 1;
    int gap = kFar;
    for (int x = 0; x < n_[0]; ++x) {
      gap = r[x] == 0 ? 0 : std::min(gap + 1, kFar);
      r[x] = gap;
    }
    gap = kFar;
    for (int x = n_[0] - 1; x >= 0; --x) {
      gap = r[x] == 0 ? 0 : std::min(gap + 1, kFar);
      r[x] = std::min(r[x], gap);
    }
    for (int x = 0; x < n_[0]; ++x) r[x] = std::min(r[x] * r[x], kCap);
  }
  for (int z = 0; z < n_[2]; ++z) pass(&a[z * sz], &b[z * sz], n_[1], sy, n_[0]);
  for (int y = 0; y < n_[1]; ++y) pass(&b[y * sy], &a[y * sy], n_[2], sz, n_[0]);

  // h·√D less the half diagonal, each widened by margins::kRounding (far beyond the few roundings here),
  // then rounded down to a float.
  const double half_diagonal = h * (std::sqrt(3.0) / 2.0) * (1.0 + margins::kRounding);
  float of[kCap + 1];  // the stored bound for each D
  constexpr double kFloatMax = std::numeric_limits<float>::max();
  for (int d = 0; d <= kCap; ++d) {
    const double v = h * std::sqrt(static_cast<double>(d)) * (1.0 - margins::kRounding) - half_diagonal;
    // (Beyond the floats' range, the nearest float below: the largest one, or −∞.)
    float f = v >= kFloatMax ? std::numeric_limits<float>::max()
              : v <= -kFloatMax ? -std::numeric_limits<float>::infinity()
                                : static_cast<float>(v);
    if (static_cast<double>(f) > v) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
    of[d] = f;
  }
  bound_.resize(total);
  for (std::size_t i = 0; i < total; ++i) bound_[i] = of[a[i]];
}

double ClearanceGrid::outside(const Vec3& p, double slack) const noexcept {
  if (bounds_.isEmpty()) return std::numeric_limits<double>::infinity();
  if (p.hasNaN()) return 0.0;  // (max() below would pass over a NaN)
  const Vec3 gap = (bounds_.min - p).cwiseMax(p - bounds_.max).cwiseMax(0.0);
  // (The largest gap where the squares could overflow: no more than the distance either.)
  const double largest = gap.maxCoeff();
  const double d = (largest < 1e150 ? gap.norm() : largest) - slack;
  return d > 0.0 ? std::min(d, std::numeric_limits<double>::max()) : 0.0;
}

}  // namespace clearway
