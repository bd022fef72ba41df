#pragma once
// The convex hull of a point set as a support mapping. Construction runs quickhull once; queries
// then hill-climb over the hull's vertex adjacency (a linear function on a convex polytope has no
// local maximum on its edge graph other than the global one), so a support query on a hull of
// n vertices costs about O(√n) dot products instead of O(n).
#include <clearway/shape/primitives.h>

#include <array>
#include <cstdint>
#include <vector>

namespace clearway {

/// The convex hull of a finite point set (duplicates, coplanar and interior points allowed).
class ConvexHull {
 public:
  /// Builds the hull; throws ShapeError on an empty set or a non-finite coordinate.
  explicit ConvexHull(const std::vector<Vec3>& points);

  /// A hull vertex farthest along d (local frame); exact (a brute-force scan would return the same value).
  Vec3 support(const Vec3& d) const noexcept;
  /// The same, hill-climbing from vertex `hint` (if valid) and leaving the answer's index in it.
  Vec3 support(const Vec3& d, std::int32_t& hint) const noexcept;
  /// 0: the hull is its own core.
  double radius() const noexcept { return 0.0; }
  /// An interior point of the hull (the mean of its vertices).
  Vec3 center() const noexcept { return center_; }

  /// The hull's vertices (a subset of the input points, each extreme).
  const std::vector<Vec3>& vertices() const noexcept { return vertices_; }
  /// Outward-facing triangles (counter-clockwise seen from outside) indexing vertices(); empty when
  /// the points are coplanar, collinear or coincident (a flat hull has no volume).
  const std::vector<std::array<int, 3>>& triangles() const noexcept { return triangles_; }

 private:
  std::vector<Vec3> vertices_;
  std::vector<std::array<int, 3>> triangles_;
  // Vertex adjacency in compressed rows: neighbours of i are adjacency_[offsets_[i] .. offsets_[i+1]).
  std::vector<std::int32_t> offsets_, adjacency_;
  // Start vertices for hill climbing: the extreme vertex along ±x, ±y, ±z.
  std::array<std::int32_t, 6> starts_{};
  // A cube map of start vertices (hulls that hill-climb): per face of the cube (±x, ±y, ±z) a kCube × kCube
  // grid, each cell's extreme vertex along the direction through its centre (climbed to).
  static constexpr int kCube = 8;
  std::vector<std::int32_t> cube_;
  Vec3 center_ = Vec3::Zero();
  // The vertex where steepest ascent of d·v over the edge graph stops, from vertex `from` (d·v = from_dot).
  std::int32_t climb(const Vec3& d, std::int32_t from, double from_dot) const noexcept;
};

}  // namespace clearway
