#pragma once
// Small wrappers that change how a support mapping is seen, never what it is: a shape through a
// pose, a shape with extra skin, and the Minkowski difference A − B that GJK, the ray cast and EPA
// run on. Each is a template over the concrete shapes, so a query pays no virtual call or variant
// dispatch per iteration.
#include <clearway/math.h>

namespace clearway {

/// A shape seen through a pose: support and center in the pose's parent frame.
template <class S>
struct Posed {
  const S& shape;
  Pose pose;
  Vec3 support(const Vec3& d) const noexcept { return pose * shape.support(pose.R.transpose() * d); }
  double radius() const noexcept { return shape.radius(); }
  Vec3 center() const noexcept { return pose * shape.center(); }
};

/// A shape with a sphere-swept skin of `margin` metres added (padding): same core, larger radius.
template <class S>
struct Margin {
  const S& shape;
  double margin;
  Vec3 support(const Vec3& d) const noexcept { return shape.support(d); }
  double radius() const noexcept { return shape.radius() + margin; }
  Vec3 center() const noexcept { return shape.center(); }
};

/// A support point of A − B with its witnesses on A's and B's cores (all in A's frame).
struct SupportPoint {
  Vec3 w, a, b;
};

/// The Minkowski difference of the cores of A and B, in A's frame; B is placed by b_in_a.
/// radius() is the sum of both sweep radii: A − B's skin.
template <class A, class B>
struct MinkowskiDifference {
  const A& a;
  const B& b;
  Pose b_in_a;

  /// The support point of core(A) − core(B) farthest along d (A's frame).
  SupportPoint support(const Vec3& d) const noexcept {
    const Vec3 pa = a.support(d);
    const Vec3 pb = b_in_a * b.support(-(b_in_a.R.transpose() * d));
    return {pa - pb, pa, pb};
  }
  double radius() const noexcept { return a.radius() + b.radius(); }
  /// A point inside core(A) − core(B).
  Vec3 center() const noexcept { return a.center() - b_in_a * b.center(); }
};

}  // namespace clearway
