#pragma once
// Small wrappers that change how a support mapping is seen, never what it is: a shape through a
// pose, a shape with extra skin, and the Minkowski difference A − B that GJK, the ray cast and EPA
// run on. Each is a template over the concrete shapes, so a query pays no virtual call or variant
// dispatch per iteration.
#include <clearway/math.h>

#include <cstdint>
#include <type_traits>
#include <utility>

namespace clearway {

namespace detail {
// Shapes that can resume a support search from a previous answer (ConvexHull) expose
// support(d, hint); for the others the hint is ignored.
template <class S, class = void>
struct HasHintedSupport : std::false_type {};
template <class S>
struct HasHintedSupport<S, std::void_t<decltype(std::declval<const S&>().support(
                               std::declval<const Vec3&>(), std::declval<std::int32_t&>()))>> : std::true_type {};

template <class S>
Vec3 supportWithHint(const S& s, const Vec3& d, std::int32_t& hint) noexcept {
  if constexpr (HasHintedSupport<S>::value) return s.support(d, hint);
  else return s.support(d);
}
}  // namespace detail

/// A shape seen through a pose: support and center in the pose's parent frame.
template <class S>
struct Posed {
  const S& shape;  ///< borrowed: must outlive this wrapper
  Pose pose;       ///< the shape's local frame in the parent frame
  /// The shape's support point along d (both in the parent frame).
  Vec3 support(const Vec3& d) const noexcept { return pose * shape.support(pose.R.transpose() * d); }
  /// The shape's sweep radius (a pose does not change it).
  double radius() const noexcept { return shape.radius(); }
  /// The shape's center, in the parent frame.
  Vec3 center() const noexcept { return pose * shape.center(); }
};

/// A shape with a sphere-swept skin of `margin` metres added (padding): same core, larger radius. A hull
/// keeps its warm-started support search.
template <class S>
struct Margin {
  const S& shape;  ///< borrowed: must outlive this wrapper
  double margin;   ///< the skin's thickness (metres, ≥ 0)
  /// The shape's core support point along d (the skin is in radius()).
  Vec3 support(const Vec3& d) const noexcept { return shape.support(d); }
  /// The same, warm-started from `hint` when the shape can be (ConvexHull), which updates it.
  Vec3 support(const Vec3& d, std::int32_t& hint) const noexcept { return detail::supportWithHint(shape, d, hint); }
  /// The shape's sweep radius plus margin.
  double radius() const noexcept { return shape.radius() + margin; }
  /// The shape's center.
  Vec3 center() const noexcept { return shape.center(); }
};


/// A support point of A − B with its witnesses on A's and B's cores (all in A's frame).
struct SupportPoint {
  ///@{
  Vec3 w, a, b;  ///< w = a − b; a on core(A), b on core(B)
  ///@}
};

/// The Minkowski difference of the cores of A and B, in A's frame; B is placed by b_in_a.
/// radius() is the sum of both sweep radii: A − B's skin.
template <class A, class B>
struct MinkowskiDifference {
  const A& a;    ///< borrowed: must outlive the difference
  const B& b;    ///< borrowed: must outlive the difference
  Pose b_in_a;   ///< B's local frame in A's frame
  ///@{
  /// Where the last support searches of A and B ended (warm starts, -1 for none; a query owns its
  /// difference, so support() is not safe to call from two threads on one object).
  mutable std::int32_t hint_a = -1, hint_b = -1;
  ///@}

  /// The support point of core(A) − core(B) farthest along d (A's frame).
  SupportPoint support(const Vec3& d) const noexcept {
    const Vec3 pa = detail::supportWithHint(a, d, hint_a);
    const Vec3 pb = b_in_a * detail::supportWithHint(b, -(b_in_a.R.transpose() * d), hint_b);
    return {pa - pb, pa, pb};
  }
  /// The sum of A's and B's sweep radii: A − B's skin.
  double radius() const noexcept { return a.radius() + b.radius(); }
  /// A point inside core(A) − core(B).
  Vec3 center() const noexcept { return a.center() - b_in_a * b.center(); }
};

}  // namespace clearway
