#pragma once
// The margins "never free by accident" rests on. A computed bound is widened by more than the rounding it
// can carry before it may call two bodies apart, and every such widening reads its amount here, with the
// reason it suffices. tests/detail/test_margins.cpp pins each value: a change is deliberate.
//
// Notation: ε = 2⁻⁵² (std::numeric_limits<double>::epsilon()); one rounding of a sum, product or square
// root errs by at most ε/2 of its result.
#include <algorithm>
#include <limits>

namespace clearway::margins {

/// ε: the gap between 1 and the next double.
constexpr double kUlp = std::numeric_limits<double>::epsilon();

/// A relative widening for a value computed in a handful of roundings (a norm, a placed point, a box
/// corner): each errs by ≤ ε/2 ≈ 1.1e-16 of the magnitudes involved, and 1e-12 ≈ 4,500 ε covers any chain
/// of fewer than a thousand. Times a length, the absolute widening for the same.
constexpr double kRounding = 1e-12;

/// A relative widening for a value built through cancelling steps or iterative results (hull planes, a
/// circumscribed polytope, cores, GJK's answers at its tolerances, 1e-10 relative at most): 1e-9 is far
/// above their error and, at a metre, one nanometre, far below any clearance that matters.
constexpr double kSlack = 1e-9;

/// A factor just above 1: a radius or distance multiplied by it lies strictly beyond what it bounds, with
/// room for the rounding of the product (kSlack).
constexpr double kBeyond = 1.0 + kSlack;

/// r rounded up for its computation: r·(1 + kRounding) + kRounding·size, where size bounds the
/// magnitudes r was computed from (coordinates, offsets).
constexpr double roundedUp(double r, double size) noexcept { return r * (1.0 + kRounding) + kRounding * size; }

/// The narrow phase's band per unit of size: pairs closer than band · size count as touching. It is
/// gjk_absolute (Tolerances), never below 64 ε: below that, a distance is the rounding of its own points.
constexpr double narrowBand(double gjk_absolute) noexcept { return std::max(gjk_absolute, 64.0 * kUlp); }

/// The rounding of a point placed by a pose, R·c + t, as a length: a coordinate is three products and
/// three sums, erring by < 2ε(|c|₁ + |tᵢ|) ≤ 3.5ε(|c| + |t|) (with R's own rounding), so the point by
/// < 6.1ε(|c| + |t|); 16 ε(|c| + |t|) is more than twice that. `c` the local point's norm, `t` the
/// translation's (or any bound on it, such as |R·c + t| + |c|).
constexpr double placedRounding(double c, double t) noexcept { return 16.0 * kUlp * (c + t); }

/// The rounding of a box's corners computed from coordinates of magnitude ≤ scale (a placed shape's
/// box): 16 ε · scale, as placedRounding.
constexpr double boxRounding(double scale) noexcept { return 16.0 * kUlp * scale; }

}  // namespace clearway::margins
