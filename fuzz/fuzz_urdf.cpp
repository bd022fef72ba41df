// URDF + SRDF → RobotModel → RobotGeometry, as `clearway check` loads a robot. The input is a URDF,
// optionally followed by a line "@@SRDF@@" and an SRDF. The URDF lies in a folder whose meshes/ is our
// arm's (robots/arm6/meshes), so that relative mesh paths load real meshes of every format.
// Documented: loadRobot throws LoadError, RobotGeometry ShapeError.
#include "fuzz_support.h"

#include <clearway/body/robot_geometry.h>
#include <clearway/load/robot_loader.h>
#include <clearway/scene/collision_filter.h>

#include <memory>
#include <string>

namespace {

const char* const kSrdfSeparator = "\n@@SRDF@@\n";

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  std::error_code ec;
  std::filesystem::create_directory_symlink(CLEARWAY_SOURCE_DIR "/robots/arm6/meshes",
                                            clearway::fuzz::scratchDir() / "meshes", ec);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace clearway;
  const std::string input(reinterpret_cast<const char*>(data), size);
  const std::size_t split = input.find(kSrdfSeparator);
  const std::string urdf = fuzz::writeFile("robot.urdf", input.substr(0, split));
  std::string srdf;
  if (split != std::string::npos)
    srdf = fuzz::writeFile("robot.srdf", input.substr(split + std::char_traits<char>::length(kSrdfSeparator)));

  std::shared_ptr<const RobotModel> model;
  if (!fuzz::expectOnly<LoadError>("loadRobot", [&] { model = std::make_shared<const RobotModel>(loadRobot(urdf, srdf)); }))
    return 0;
  fuzz::expectOnly<ShapeError>("RobotGeometry", [&] {
    const RobotGeometry geometry(model);
    const CollisionFilter filter(*model);
  });
  return 0;
}
