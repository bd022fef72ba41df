#pragma once
// A map's occupied voxels merged into few boxes that cover exactly the same space. A shelf scanned at 2 cm
// is ten thousand voxels but a few hundred boxes: a distance walk that met twenty voxels of one board meets
// one box, and the board's nearest point is the same (Environment::lowerBound walks these).
//
// Why the union is exact. The loader places a voxel of lattice corner k and span n cells at k·res and
// (k + n)·res, per axis (octomap_loader.cpp). A voxel is merged only when its box is, bit for bit, that
// product for whole numbers k and n (n ≤ kMaxSpan); its n³ cells of the finest lattice are then occupied.
// A block is a box of occupied cells [i0, i1) per axis, placed by the same products i0·res and i1·res: its
// faces are its voxels' faces, so the blocks' union is the merged voxels' union, not a rounding more or
// less. Any other voxel (a map built in code, unknown space clipped to the known bounds, a cube wider than
// kMaxSpan cells) is a block of its own.
#include <clearway/environment/environment.h>
#include <clearway/tree/aabb.h>
#include <clearway/tree/aabb_tree.h>

#include <cstdint>
#include <vector>

namespace clearway {

/// A map's occupied voxels as disjoint boxes of exactly their union, in a tree. Immutable once built.
class VoxelBlocks {
 public:
  /// Voxels spanning up to this many cells of the finest lattice per axis are merged (OctoMap prunes eight
  /// occupied children into their parent, so a solid region is cubes of 2, 4, 8 cells).
  static constexpr int kMaxSpan = 8;
  /// Beyond this many cells in all, nothing is merged (each voxel its own block): a bound on the build.
  static constexpr std::int64_t kMaxCells = std::int64_t{1} << 22;

  /// The blocks of map.occupied (none for an empty map); with `merge` false, one per voxel.
  explicit VoxelBlocks(const OccupancyMap& map, bool merge = true);

  /// The blocks' boxes, disjoint, together exactly the union of the map's occupied boxes.
  const std::vector<Aabb>& boxes() const noexcept { return boxes_; }
  /// The blocks' tree (item b: boxes()[b]); empty when there are no blocks.
  const AabbTree& tree() const noexcept { return tree_; }
  /// A voxel of the map (an index into map.occupied) that shares part of block b (a coarse voxel's cells
  /// may lie in several blocks).
  int voxelOf(int b) const noexcept { return voxel_[static_cast<std::size_t>(b)]; }

 private:
  std::vector<Aabb> boxes_;
  std::vector<int> voxel_;
  AabbTree tree_;
};

}  // namespace clearway
