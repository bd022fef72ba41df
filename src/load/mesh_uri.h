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
/// (<prefix>/share/NAME). Other URI schemes than file:// and package:// are an error.
ResolvedUri resolveMeshUri(const std::string& uri, const std::string& urdf_dir,
                           const std::vector<std::string>& package_paths);

}  // namespace clearway::detail
