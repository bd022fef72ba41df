#pragma once
#include <cstdint>

namespace clearway {

/// Why a narrow-phase query stopped. Every status except NotConverged and InvalidInput is an answer
/// within the query's tolerance; those two must be treated as a collision by every caller.
enum class Status : std::uint8_t {
  Converged,        ///< upper and lower bound agree within the relative tolerance
  RepeatedSupport,  ///< the support point was already in the simplex: no closer point exists
  NoProgress,       ///< the bound stopped improving: rounding floor reached; the result is the best bound
  Touching,         ///< ‖v‖ fell under the absolute tolerance: the cores touch within rounding
  Overlapping,      ///< the cores overlap (the simplex encloses the origin)
  Separated,        ///< intersect/cast: a separating axis (or a miss) was proven
  NotConverged,     ///< iteration cap or a NaN: no certificate; callers must assume a collision
  InvalidInput,     ///< a non-finite pose, direction or parameter was passed in
};

/// A short lowercase name, as written in query results ("converged", "not_converged", ...).
const char* statusName(Status s) noexcept;

/// True when the status carries no certificate and the pair must be treated as colliding.
constexpr bool isFailure(Status s) noexcept { return s == Status::NotConverged || s == Status::InvalidInput; }

}  // namespace clearway
