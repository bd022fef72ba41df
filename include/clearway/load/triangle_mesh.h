#pragma once
// Triangle meshes as the rest of Clearway sees them: one indexed triangle list per file, in metres,
// in the frame the URDF expects (z up), whatever format, unit and node hierarchy the file used.
#include <clearway/math.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace clearway {

/// An indexed triangle mesh: vertices (no duplicates) and triangles indexing them.
struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::int32_t, 3>> triangles;
};

/// Loads every mesh of a file through assimp (STL binary and ASCII, COLLADA, OBJ and any other format
/// assimp reads) into one TriangleMesh:
///  - node transforms are applied and all meshes of the scene are merged; vertices at identical
///    positions are joined (within and across meshes), so shared edges are shared in the index list;
///  - COLLADA (.dae, .zae): the <unit> is honoured, and the <up_axis> too: the result is z-up whatever
///    the file declares (a Y_UP file is rotated so that its y becomes z). RViz and MoveIt ignore
///    <up_axis>; a file that is not Z_UP gets a warning saying so;
///  - then each vertex is multiplied componentwise by scale (the URDF <mesh scale>);
///  - zero-area triangles (two equal corners, or a height below 1e-12 of the longest edge) are dropped
///    with a warning; points and lines in the file are ignored with a warning;
///  - warnings, each "PATH: REASON", also for a mesh that is not closed (an edge not shared by exactly
///    two triangles) and for a mesh whose largest extent exceeds 10 m (probably millimetres).
/// Throws LoadError for a missing file, a format assimp cannot read, a mesh without triangles, a
/// non-finite scale or a non-finite coordinate.
TriangleMesh loadMesh(const std::string& path, const Vec3& scale, std::vector<std::string>* warnings = nullptr);

/// True when every edge of the mesh is shared by exactly two triangles (a closed surface).
bool isClosed(const TriangleMesh& mesh);

}  // namespace clearway
