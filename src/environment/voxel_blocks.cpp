// VoxelBlocks: the finest lattice's occupied cells merged greedily into boxes (voxel_blocks.h says why the
// union is exact).
#include <clearway/environment/voxel_blocks.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace clearway {
namespace {

// Lattice coordinates are packed 21 bits per axis, z most significant, so that sorting the keys orders the
// cells z, then y, then x: the order the greedy growth below starts its blocks in.
constexpr std::int64_t kHalfRange = std::int64_t{1} << 20;
constexpr int kBits = 21;

std::uint64_t keyOf(std::int64_t x, std::int64_t y, std::int64_t z) noexcept {
  const auto u = [](std::int64_t v) { return static_cast<std::uint64_t>(v + kHalfRange); };
  return (u(z) << (2 * kBits)) | (u(y) << kBits) | u(x);
}
bool inRange(std::int64_t v) noexcept { return v >= -kHalfRange && v < kHalfRange; }

// True when `box` is, bit for bit, the loader's cube of corner k and span n (n ≤ kMaxSpan) on the lattice of
// edge `res`: k·res and (k + n)·res on every axis, as octomap_loader.cpp computes them.
bool onLattice(const Aabb& box, double res, std::int64_t k[3], int& n) noexcept {
  const double span = std::nearbyint((box.max.x() - box.min.x()) / res);
  if (!(span >= 1.0 && span <= VoxelBlocks::kMaxSpan)) return false;  // (NaN too)
  n = static_cast<int>(span);
  for (int a = 0; a < 3; ++a) {
    const double q = std::nearbyint(box.min[a] / res);
    if (!(std::abs(q) < static_cast<double>(kHalfRange - VoxelBlocks::kMaxSpan))) return false;
    k[a] = static_cast<std::int64_t>(q);
    if (static_cast<double>(k[a]) * res != box.min[a] || static_cast<double>(k[a] + n) * res != box.max[a])
      return false;
  }
  return true;
}

struct Cell {
  std::uint64_t key;
  int voxel;  // the map's voxel holding it
};

}  // namespace

VoxelBlocks::VoxelBlocks(const OccupancyMap& map, bool merge) {
  const std::vector<Aabb>& voxels = map.occupied;
  const double res = map.resolution;
  const int count = static_cast<int>(voxels.size());
  // Which voxels lie on the lattice, and whether their cells fit the budget.
  std::vector<std::int64_t> corner(3 * voxels.size());
  std::vector<int> span(voxels.size(), 0);  // 0: a block of its own
  std::int64_t cells_total = 0;
  if (merge && res > 0.0 && std::isfinite(res))
    for (int v = 0; v < count; ++v) {
      int n = 0;
      if (!onLattice(voxels[v], res, &corner[3 * v], n)) continue;
      span[v] = n;
      cells_total += std::int64_t{n} * n * n;
    }
  if (cells_total > kMaxCells) {
    std::fill(span.begin(), span.end(), 0);
    cells_total = 0;
  }

  std::vector<Cell> cells;
  cells.reserve(static_cast<std::size_t>(cells_total));
  for (int v = 0; v < count; ++v) {
    const int n = span[v];
    if (n == 0) {
      boxes_.push_back(voxels[v]);
      voxel_.push_back(v);
      continue;
    }
    const std::int64_t* k = &corner[3 * v];
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) cells.push_back({keyOf(k[0] + x, k[1] + y, k[2] + z), v});
  }
  std::sort(cells.begin(), cells.end(), [](const Cell& a, const Cell& b) { return a.key < b.key; });
  // (Overlapping voxels, possible in a map built in code, share cells: each cell once.)
  cells.erase(std::unique(cells.begin(), cells.end(), [](const Cell& a, const Cell& b) { return a.key == b.key; }),
              cells.end());

  // Each unclaimed cell, in key order, starts a block: grown along x while the next cell is free (occupied,
  // unclaimed), then along y while the whole next row is, then along z while the whole next layer is. Every
  // cell is claimed once; a failed row or layer costs at most the block's own row or face, so the work is
  // a few look-ups per cell.
  std::vector<char> claimed(cells.size(), 0);
  const auto freeAt = [&](std::int64_t x, std::int64_t y, std::int64_t z) -> std::ptrdiff_t {
    if (!inRange(x) || !inRange(y) || !inRange(z)) return -1;
    const std::uint64_t key = keyOf(x, y, z);
    const auto it =
        std::lower_bound(cells.begin(), cells.end(), key, [](const Cell& c, std::uint64_t k) { return c.key < k; });
    if (it == cells.end() || it->key != key) return -1;
    const std::ptrdiff_t i = it - cells.begin();
    return claimed[static_cast<std::size_t>(i)] ? -1 : i;
  };
  const std::uint64_t mask = (std::uint64_t{1} << kBits) - 1;
  const auto coord = [&](std::uint64_t key, int axis) {
    return static_cast<std::int64_t>((key >> (axis * kBits)) & mask) - kHalfRange;
  };
  for (std::size_t c = 0; c < cells.size(); ++c) {
    if (claimed[c]) continue;
    const std::int64_t x0 = coord(cells[c].key, 0), y0 = coord(cells[c].key, 1), z0 = coord(cells[c].key, 2);
    std::int64_t x1 = x0, y1 = y0, z1 = z0;  // (inclusive)
    while (freeAt(x1 + 1, y0, z0) >= 0) ++x1;
    const auto rowFree = [&](std::int64_t y, std::int64_t z) {
      for (std::int64_t x = x0; x <= x1; ++x)
        if (freeAt(x, y, z) < 0) return false;
      return true;
    };
    while (rowFree(y1 + 1, z0)) ++y1;
    const auto layerFree = [&](std::int64_t z) {
      for (std::int64_t y = y0; y <= y1; ++y)
        if (!rowFree(y, z)) return false;
      return true;
    };
    while (layerFree(z1 + 1)) ++z1;
    for (std::int64_t z = z0; z <= z1; ++z)
      for (std::int64_t y = y0; y <= y1; ++y)
        for (std::int64_t x = x0; x <= x1; ++x) claimed[static_cast<std::size_t>(freeAt(x, y, z))] = 1;
    const auto at = [res](std::int64_t x, std::int64_t y, std::int64_t z) {
      return Vec3(static_cast<double>(x) * res, static_cast<double>(y) * res, static_cast<double>(z) * res);
    };
    boxes_.push_back(Aabb::fromMinMax(at(x0, y0, z0), at(x1 + 1, y1 + 1, z1 + 1)));
    voxel_.push_back(cells[c].voxel);
  }
  if (!boxes_.empty()) tree_ = AabbTree(boxes_, TreeBuildOptions{TreeSplit::Sah, 2});
}

}  // namespace clearway
