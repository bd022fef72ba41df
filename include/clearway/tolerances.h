#pragma once
// Every tolerance and iteration cap of the narrow phase, with its unit and meaning, in one place.
// Queries take a Tolerances by const reference; nothing here is global or mutable.

#include <vector>

namespace clearway {

/// Tolerances and caps for GJK, the GJK ray cast and EPA. Defaults suit robot-sized geometry (metres).
struct Tolerances {
  /// GJK distance: stop when upper − lower bound ≤ gjk_relative · upper bound (relative error of the distance).
  double gjk_relative = 1e-6;
  /// GJK: the cores touch when ‖v‖ ≤ gjk_absolute · max‖yᵢ‖ (yᵢ the simplex vertices): below rounding, distance is 0.
  double gjk_absolute = 1e-10;
  /// GJK: iteration cap; reaching it yields Status::NotConverged (treated as a collision).
  int gjk_max_iterations = 128;

  /// Ray / shape cast: the GJK cast hands over to conservative advancement once the ray point is within
  /// cast_relative · max‖yᵢ‖ of the shape; the answer is then exact to the band of gjk_absolute (hits and t).
  double cast_relative = 1e-6;
  /// Ray / shape cast: iteration cap (GJK cast steps, at most half of it when above 8, plus advancement
  /// steps); reaching it reports a hit at the certified lower bound of the time of impact.
  int cast_max_iterations = 128;

  /// EPA: stop when upper − lower bound of the depth ≤ epa_relative · depth.
  double epa_relative = 1e-6;
  /// EPA: iteration cap (also bounded by the fixed polytope capacity).
  int epa_max_iterations = 96;
};

/// Appends every field of t to `out`, in a fixed order: the part of a key that results computed with these
/// tolerances are remembered by (one list, so that a field added here reaches every such key).
inline void appendTolerances(const Tolerances& t, std::vector<double>& out) {
  out.insert(out.end(),
             {t.gjk_relative, t.gjk_absolute, static_cast<double>(t.gjk_max_iterations), t.cast_relative,
              static_cast<double>(t.cast_max_iterations), t.epa_relative, static_cast<double>(t.epa_max_iterations)});
}

}  // namespace clearway
