// OctoMap bytes → OccupancyMap → Environment, as a scene's `environment.octomap` is loaded. The
// extension follows the magic line (.bt for a binary map, .ot otherwise), so each reader gets the
// inputs meant for it; unknown space counts as occupied, which walks the tree a second time.
// Documented: loadOctomap throws LoadError; the Environment over a loaded map throws nothing.
#include "fuzz_support.h"

#include <clearway/environment/environment.h>

#include <cstring>
#include <memory>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace clearway;
  static const char kBinaryMagic[] = "# Octomap OcTree binary file";
  const bool binary = size >= sizeof kBinaryMagic - 1 && std::memcmp(data, kBinaryMagic, sizeof kBinaryMagic - 1) == 0;
  const std::string path = fuzz::writeFile(binary ? "map.bt" : "map.ot", data, size);
  std::shared_ptr<const OccupancyMap> map;
  if (!fuzz::expectOnly<LoadError>("loadOctomap", [&] {
        map = std::make_shared<const OccupancyMap>(loadOctomap(path, UnknownSpace::Occupied));
      }))
    return 0;
  for (const Aabb& box : map->occupied)
    if (!box.min.allFinite() || !box.max.allFinite() || !(box.min.array() < box.max.array()).all())
      fuzz::finding("loadOctomap: an occupied box is empty or not finite");
  try {
    const Environment environment({}, map);
  } catch (const std::exception& e) {
    fuzz::finding(std::string("Environment over a loaded map threw: ") + e.what());
  }
  return 0;
}
