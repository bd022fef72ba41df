#pragma once
// PLY files read by Clearway itself rather than assimp. Assimp's PLY reader allocates every list by the
// count the file claims, and where its view of the header differs from the file's (an unknown type, a
// `comment` line it takes for an element) it reads counts out of unrelated bytes: gigabytes for a file
// of a few hundred. Here each value is read where the header says it lies, and storage grows only with
// the data actually read.
#include <clearway/math.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace clearway::detail {

/// A PLY file's surface as written: no scale, no welding, no dropped triangles.
struct PlyMesh {
  std::vector<Vec3> vertices;                           ///< the vertex element's x, y, z
  std::vector<std::array<std::uint32_t, 3>> triangles;  ///< faces triangulated, strips unrolled
  std::size_t points_and_lines = 0;                     ///< faces of one or two corners (not triangles)
};

/// Reads a PLY file (ASCII, binary little- or big-endian; `face` or `tristrips` lists named
/// vertex_indices or vertex_index; any other element skipped). Faces of more than three corners are
/// triangulated in their plane (a fan when convex, ear clipping otherwise) without the corners that repeat
/// the one before them (or, last, the first): as the same polygon written without the repeats. Throws
/// LoadError naming the header line, data line or byte and the reason for anything it cannot read as the
/// header declares: an unknown type, a count beyond the data, a value that is not a number of its type, a
/// corner index outside the vertices, a face of no corners, a face whose clipping takes more work than
/// the file's size allows. Unknown header lines are skipped with a warning, as assimp (and so MoveIt)
/// skips them.
PlyMesh readPly(const std::string& path, std::vector<std::string>* warnings);

/// How ear clipping ended: every ear clipped, no ear left (the polygon crosses itself: the rest is
/// fanned), or stopped when its work passed the budget.
enum class EarClip { Done, Crossed, OverBudget };

/// Ear clipping of the polygon whose corners, in order, are `points` (2-D, counter-clockwise): appends to
/// `out` triangles of corner numbers, counter-clockwise (n − 2 for a simple polygon). A corner in a
/// candidate ear (in its closed triangle, not at one of its corners) refuses it. In a simple polygon an
/// ear holding a corner holds one that is not convex: those are looked up in a k-d tree, or, `exact`,
/// every corner is tested (the reference). `work` grows by one for each candidate, corner tested and tree
/// node visited; once it passes `budget` clipping stops.
EarClip clipEars(const std::vector<std::array<double, 2>>& points, bool exact, double budget, double& work,
                 std::vector<std::array<std::uint32_t, 3>>& out);

}  // namespace clearway::detail
