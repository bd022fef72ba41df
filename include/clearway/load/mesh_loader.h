#pragma once
// Triangle meshes as the rest of Clearway sees them: one indexed triangle list per file, in metres,
// in the frame the URDF expects (z up), whatever format, unit and node hierarchy the file used.
#include <clearway/shape/triangle_mesh.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace clearway {

/// How mesh files are read.
struct MeshOptions {
  /// COLLADA: rotate the mesh so that the file's `<up_axis>` becomes z. Off by default, to load meshes as
  /// ROS does (RViz, MoveIt): the coordinates as written, in the file's `<unit>`.
  bool honour_up_axis = false;
  /// COLLADA: the most triangles a node's instances may expand to (each geometry counted once per path to
  /// it), unless the file's geometries themselves hold more: a file past it is refused (LoadError).
  std::uint64_t max_expanded_triangles = std::uint64_t{1} << 20;
};

/// Loads every mesh of a file (STL binary and ASCII, COLLADA and OBJ through assimp; PLY, ASCII or binary,
/// through Clearway's own reader, which refuses counts beyond the file's data) into one TriangleMesh:
///  - node transforms are applied and all meshes of the scene are merged; vertices at identical
///    positions are joined (within and across meshes), so shared edges are shared in the index list;
///  - COLLADA (.dae, .zae): the `<unit>` is honoured; the `<up_axis>` is ignored as ROS, RViz and MoveIt
///    ignore it (the coordinates are the link's), unless options.honour_up_axis (then a Y_UP file is
///    rotated so that its y becomes z); a file that is not Z_UP gets a warning saying which was done;
///  - then each vertex is multiplied componentwise by scale (the URDF `<mesh scale>`);
///  - zero-area triangles (two equal corners, or a height below 1e-12 of the longest edge) are dropped
///    with a warning; points and lines in the file are ignored with a warning;
///  - warnings, each "PATH: REASON", also for a mesh that is not closed (an edge not shared by exactly
///    two triangles) and for a mesh whose largest extent exceeds 10 m (probably millimetres).
/// Throws LoadError for a missing file, a format assimp cannot read, a mesh without triangles, a
/// non-finite scale or a non-finite coordinate.
TriangleMesh loadMesh(const std::string& path, const Vec3& scale, std::vector<std::string>* warnings = nullptr,
                      const MeshOptions& options = {});

/// True when every edge of the mesh is shared by exactly two triangles (a closed surface).
bool isClosed(const TriangleMesh& mesh);

}  // namespace clearway
