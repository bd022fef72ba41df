#pragma once
// Narrow-phase query files (JSON Lines, format in docs/query-format.md): one case
// per line in, one JSON result per line out. Parsing checks every key once, up front, and names the
// key in its error; running a parsed case cannot fail (the narrow phase reports through its status).
#include <clearway/math.h>
#include <clearway/narrowphase/ray_cast.h>
#include <clearway/shape/shape.h>
#include <clearway/tolerances.h>

#include <nlohmann/json.hpp>

#include <iosfwd>
#include <optional>
#include <stdexcept>
#include <string>

namespace clearway {

/// Thrown by parseQueryCase when a line is not a valid case; what() names the key and the reason.
class QueryError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// The five narrow-phase queries a case may ask for.
enum class QueryKind { Intersect, Distance, Penetration, Raycast, Shapecast };

/// A shape in its local frame and the pose that places it in the world.
struct PosedShape {
  Shape shape;
  Pose pose;
};

/// One parsed case, every number checked finite and every shape and pose valid.
struct QueryCase {
  nlohmann::json id;             ///< as written: a string or a number
  QueryKind kind = QueryKind::Distance;
  PosedShape a;
  std::optional<PosedShape> b;   ///< absent only for raycast
  Ray ray;                       ///< raycast only (world frame)
  Vec3 velocity_a = Vec3::Zero();  ///< shapecast only: A moves by t·velocity_a (world frame)
  double max_t = 0.0;            ///< shapecast only
  Tolerances tolerances;         ///< defaults, or the case's "tolerance" in every relative field
};

/// Builds a case from one parsed line; throws QueryError naming the offending key.
QueryCase parseQueryCase(const nlohmann::json& line);

/// Runs a case and returns its result object: id, status, iterations and the query's fields.
nlohmann::ordered_json runQueryCase(const QueryCase& query);

/// The result of one input line: the object to print, and whether the line was an error.
struct QueryLineResult {
  nlohmann::ordered_json json;
  bool error = false;
};

/// Parses and runs one line of a query file (line_number counts from 1, for error results).
QueryLineResult runQueryLine(const std::string& line, long line_number);

/// Runs every non-blank line of `in`, writing one compact JSON object per line to `out` in input
/// order; flushes after each line when `flush_each_line`. Returns kExitOk when every case ran, kExitNo
/// when any line was an error (exit_codes.h).
int runQueryStream(std::istream& in, std::ostream& out, bool flush_each_line = false);

}  // namespace clearway
