#pragma once
// The indexed triangle list every mesh becomes (load/mesh_loader.h reads files into it; bodies own it).
#include <clearway/math.h>

#include <array>
#include <cstdint>
#include <vector>

namespace clearway {

/// An indexed triangle mesh: vertices (no duplicates) and triangles indexing them.
struct TriangleMesh {
  std::vector<Vec3> vertices;                          ///< positions (metres, the mesh's frame)
  std::vector<std::array<std::int32_t, 3>> triangles;  ///< three indices into vertices each
};

}  // namespace clearway
