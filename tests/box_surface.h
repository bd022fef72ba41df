#pragma once
// Closed and open box surfaces: the smallest meshes that are a solid and a surface, for tests of mesh
// obstacles and links.
#include <clearway/shape/triangle_mesh.h>

namespace clearway::test {

/// The closed surface of a box centred at the origin: 8 vertices, 12 outward triangles.
inline TriangleMesh boxSurface(const Vec3& half) {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back((i & 1 ? 1 : -1) * half.x(), (i & 2 ? 1 : -1) * half.y(), (i & 4 ? 1 : -1) * half.z());
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

/// The same surface with its last triangle removed: open, so a surface and not a solid.
inline TriangleMesh openBoxSurface(const Vec3& half) {
  TriangleMesh m = boxSurface(half);
  m.triangles.pop_back();
  return m;
}

}  // namespace clearway::test
