// A mesh file → TriangleMesh → LinkGeometry (trees, hull, convex parts), as a link's mesh is loaded.
// Built once per format (CLEARWAY_FUZZ_MESH_EXT: stl, obj, dae, ply), because the loader picks the
// reader by the extension. Documented: loadMesh throws LoadError; LinkGeometry ShapeError.
#include "fuzz_support.h"

#include <clearway/body/link_geometry.h>
#include <clearway/load/load_error.h>
#include <clearway/load/mesh_loader.h>

#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace clearway;
  const std::string path = fuzz::writeFile("mesh." CLEARWAY_FUZZ_MESH_EXT, data, size);
  TriangleMesh mesh;
  std::vector<std::string> warnings;
  if (!fuzz::expectOnly<LoadError>("loadMesh", [&] { mesh = loadMesh(path, Vec3::Ones(), &warnings); })) return 0;
  // What the loader returns must be usable: every index in range, every vertex finite.
  for (const auto& t : mesh.triangles)
    for (const std::int32_t i : t)
      if (i < 0 || i >= static_cast<std::int32_t>(mesh.vertices.size())) fuzz::finding("loadMesh: index out of range");
  for (const Vec3& v : mesh.vertices)
    if (!v.allFinite()) fuzz::finding("loadMesh: a vertex is not finite");
  fuzz::expectOnly<ShapeError>("LinkGeometry", [&] { const LinkGeometry link(mesh); });
  return 0;
}
