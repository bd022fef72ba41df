#pragma once
// The shared Panda's collision meshes that body tests add to their generated ones (from ../shared).
#include <clearway/load/mesh_loader.h>

#include <string>
#include <vector>

#include "shared_data.h"

namespace clearway::test {

/// Appends the shared Panda's link5, link7 and hand collision meshes; without the shared data, appends
/// nothing and returns why when the data is required (the caller fails), else "".
inline std::string addSharedPandaMeshes(std::vector<TriangleMesh>& meshes) {
  const std::string rel = "robots/panda/meshes/collision";
  if (sharedPath(rel).empty()) return sharedDataRequired() ? sharedMissing(rel) : std::string();
  for (const char* name : {"link5", "link7", "hand"})
    meshes.push_back(loadMesh(sharedDir() + "/" + rel + "/" + name + ".stl", Vec3::Ones()));
  return {};
}

}  // namespace clearway::test
