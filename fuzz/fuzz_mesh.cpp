// A mesh file → TriangleMesh → LinkGeometry (trees, hull, convex parts), as a link's mesh is loaded.
// Built once per format (CLEARWAY_FUZZ_MESH_EXT: stl, obj, dae, ply), because the loader picks the
// reader by the extension. Documented: loadMesh throws LoadError; LinkGeometry ShapeError.
#include "fuzz_support.h"

#include <clearway/body/link_geometry.h>
#include <clearway/load/load_error.h>
#include <clearway/load/mesh_loader.h>

#include <string>
#include <vector>

// Loading and LinkGeometry are linear in the triangles, but this build (ASan, UBSan, coverage, -O1) runs
// them some 60 to 90 times slower than Release: the shared UR5's 43,473-triangle sensor takes 18 s here (0.2 s
// in Release), and a few kilobytes of COLLADA instancing a mesh reach the loader's default limit of 2^20
// triangles (600,000 took 12 s to load here). So the fuzzer asks for a lower limit (the check that refuses
// a file past it is fuzzed the same), and leaves the geometry of larger meshes to the tests with real ones:
// a timeout past these would be this build's speed, not a hang.
constexpr std::uint64_t kExpandedTriangles = 32768;
constexpr std::size_t kGeometryTriangles = 8192;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace clearway;
  const std::string path = fuzz::writeFile("mesh." CLEARWAY_FUZZ_MESH_EXT, data, size);
  TriangleMesh mesh;
  std::vector<std::string> warnings;
  MeshOptions options;
  options.max_expanded_triangles = kExpandedTriangles;
  if (!fuzz::expectOnly<LoadError>("loadMesh", [&] { mesh = loadMesh(path, Vec3::Ones(), &warnings, options); }))
    return 0;
  // What the loader returns must be usable: every index in range, every vertex finite.
  for (const auto& t : mesh.triangles)
    for (const std::int32_t i : t)
      if (i < 0 || i >= static_cast<std::int32_t>(mesh.vertices.size())) fuzz::finding("loadMesh: index out of range");
  for (const Vec3& v : mesh.vertices)
    if (!v.allFinite()) fuzz::finding("loadMesh: a vertex is not finite");
  if (mesh.triangles.size() > kGeometryTriangles) return 0;
  fuzz::expectOnly<ShapeError>("LinkGeometry", [&] { const LinkGeometry link(mesh); });
  return 0;
}
