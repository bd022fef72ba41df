#pragma once
// A link's outer balls: a few dozen balls, each hugging the link from inside out to a few millimetres
// past its surface, whose union provably holds every triangle and the inside of every closed mesh. Two
// links whose outer balls are all apart are apart, a test of multiply-adds where the hulls (GJK) and the
// triangles cost thousands of operations: the first piece of a sphere stage (issue 41), not yet asked by
// any query.
#include <clearway/body/link_geometry.h>

#include <vector>

namespace clearway {

/// Outer balls of one link, link frame, in groups of at most kGroupSize neighbours.
struct OuterBalls {
  /// At most this many balls in a group: a pair compares two groups' balls only when the groups' own
  /// balls are not apart.
  static constexpr int kGroupSize = 8;
  /// A group: balls [first, first + count), and a ball that holds them all.
  struct Group {
    Vec3 center;  ///< link frame
    double radius;  ///< every ball of the group lies within it (metres)
    int first;      ///< the group's first ball in balls
    int count;      ///< how many balls it has, from first on
  };
  std::vector<LinkGeometry::Ball> balls;  ///< link frame; their union holds the link (empty: none proven)
  std::vector<Group> groups;              ///< covering balls in order
  double cell = 0.0;  ///< the grid step they were built on (metres): their looseness is about one step

  /// True when the balls were proven to hold the link; false for a link they do not serve (primitives,
  /// a proof that gave up): such a link is compared by its other rungs alone.
  bool proven() const noexcept { return !balls.empty(); }
};

/// How outer balls are built.
struct OuterBallOptions {
  /// The grid step (metres): the balls reach about this far past the surface. Finer is tighter, with
  /// more balls, and slower to build.
  double step = 0.004;
  /// Most grid cells: a large link gets a coarser step rather than more cells.
  long max_cells = 60000;
};

/// The outer balls of a link's triangles (and the inside of its closed meshes), proven at build time:
/// every triangle is cut into pieces no longer than a grid step, each of which lies in one ball by
/// its corners (a ball is convex), with room for the rounding of the cut; the inside of the closed meshes
/// is proven held by LinkGeometry::ballsHoldSolids. Not proven (empty) for a link with primitives or
/// without triangles, one too large for the grid's bounds, or when the proof gives up. Pure and
/// deterministic; up to 0.8 s a link on the shared UR5 (1.6 s for all its links, 1.5 s for the Panda's
/// at 4 mm steps; 0.3 s each at 8 mm), too slow yet to build at load.
OuterBalls buildOuterBalls(const LinkGeometry& link, const OuterBallOptions& options = {});

}  // namespace clearway
