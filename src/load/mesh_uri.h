#pragma once
// Where a URDF <mesh filename="..."> points: a path relative to the URDF, an absolute path, a file://
// URI, or package://NAME/PATH found through explicit search paths, ROS_PACKAGE_PATH and AMENT_PREFIX_PATH.
#include <string>
#include <vector>

namespace clearway::detail {

struct ResolvedUri {
  std::string path;   // the file the URI names (it may not exist); empty when unresolved
  std::string error;  // why it could not be resolved; empty on success
};

/// Resolves uri. package://NAME is looked up, in this order, in each explicit search path P, then each
/// ROS_PACKAGE_PATH entry P (P itself when its last component is NAME, P/NAME, P/share/NAME, or a folder
/// NAME holding a package.xml at most three levels below P), then each AMENT_PREFIX_PATH entry
/// (<prefix>/share/NAME). Other URI schemes than file:// and package:// are an error, and so is a NUL or
/// other control character in the URI or in the path it names (%XX escapes decoded).
ResolvedUri resolveMeshUri(const std::string& uri, const std::string& urdf_dir,
                           const std::vector<std::string>& package_paths);

/// Why path names no file, "" when it does: a NUL or other control character in it (the system reads a
/// path up to its first NUL, so "x.dae\0.stl" would open x.dae). note follows "the path" in the reason.
std::string controlCharacterReason(const std::string& path, const std::string& note = "");

}  // namespace clearway::detail
