#pragma once
// A sphere tree over one body's geometry (Hubbard's bounding-sphere hierarchy, built from the top levels of
// the body's triangle tree): every node is a ball holding everything below it, and the leaves' union holds
// every triangle and every primitive of the body. Two bodies whose leaf balls are pairwise apart have
// surfaces and primitives apart, decided by distance comparisons alone; this is the rung of the ladder
// between the bounding ball and the convex hulls, and it is where most near-but-free pairs end.
//
// The balls cover surfaces and primitives, not the inside of a closed mesh: a body wholly inside another's
// closed mesh touches no ball. Callers rule that out separately (LinkGeometry::mayHold).
#include <clearway/math.h>
#include <clearway/shape/primitives.h>
#include <clearway/shape/shape.h>
#include <clearway/tree/aabb_tree.h>

#include <cstdint>
#include <utility>
#include <vector>

namespace clearway {

/// A hierarchy of balls over a body (its frame). Immutable; queries are const and allocate nothing.
class SphereTree {
 public:
  /// A ball and its children: nodes [first, first + count) of nodes(); a leaf has count 0.
  struct Node {
    Vec3 center = Vec3::Zero();
    double radius = 0.0;
    std::int32_t first = 0;
    std::int32_t count = 0;
    bool isLeaf() const noexcept { return count == 0; }
  };
  /// A primitive of the body, placed in its frame.
  struct Placed {
    const Shape* shape;
    Pose pose;
  };
  /// How deep the triangle tree is followed: at most 2^kLevels leaf balls over the triangles. Five: on the
  /// Panda and UR5 links deeper trees cost more comparisons than the hull tests they saved.
  static constexpr int kLevels = 5;

  /// The empty tree (a body without geometry): never apart from anything.
  SphereTree() = default;
  /// The tree over `triangles` (indexed by `tree`, the body's triangle tree) and the primitives, each covered
  /// by a few balls (a sphere by itself, a capsule by balls along its axis, any other shape by the balls
  /// around cells of its box). Radii are rounded outward, so each ball holds what it claims in exact arithmetic.
  SphereTree(const std::vector<Triangle>& triangles, const AabbTree& tree, const std::vector<Placed>& primitives);

  bool empty() const noexcept { return nodes_.empty(); }
  /// Node 0 is the root; children follow their parent.
  const std::vector<Node>& nodes() const noexcept { return nodes_; }
  /// The number of leaf balls.
  int leafCount() const noexcept { return leaves_; }

 private:
  std::vector<Node> nodes_;
  int leaves_ = 0;
};

/// True when every leaf ball of `a` lies more than `gap` from every leaf ball of `b` (b placed in a's frame
/// by b_in_a): then no point of a's surfaces or primitives is within `gap` of b's. False proves nothing; an
/// empty tree, or a NaN, is never apart.
bool sphereTreesApart(const SphereTree& a, const SphereTree& b, const Pose& b_in_a, double gap) noexcept;

/// True when every leaf ball of the tree lies more than `gap` from the convex shape (placed in the tree's
/// frame by shape_in_tree). Exact point distances for points, segments, spheres, capsules, boxes and
/// cylinders; a cone is measured as its cylinder; triangles and hulls are never apart (the hull test decides).
bool sphereTreeApartFrom(const SphereTree& tree, const Shape& shape, const Pose& shape_in_tree, double gap) noexcept;

/// A lower bound on the distance between any point of a's leaf balls and any of b's (b placed in a's frame by
/// b_in_a), computed only as far as `enough`: at least `enough` when every pair of leaves is that far apart.
/// Bounds the distance between the bodies' surfaces and primitives (not a closed mesh's inside: see
/// sphereTreesApart). 0 for an empty tree, overlapping leaves, or a NaN.
double sphereTreesLowerBound(const SphereTree& a, const SphereTree& b, const Pose& b_in_a, double enough) noexcept;
/// The same between the tree's leaf balls and a convex shape (placed in the tree's frame), as sphereTreeApartFrom
/// measures it (0 for triangles and hulls).
double sphereTreeLowerBoundTo(const SphereTree& tree, const Shape& shape, const Pose& shape_in_tree,
                              double enough) noexcept;

/// A lower bound on the distance from point p (the shape's frame) to the shape: exact for points, segments,
/// spheres, capsules, boxes and cylinders, the enclosing cylinder's for a cone, 0 for triangles and hulls.
/// 0 inside. NaN for a NaN point.
double pointShapeLowerBound(const Shape& shape, const Vec3& p) noexcept;

}  // namespace clearway
