#pragma once
// Where a URDF <mesh filename="..."> points: a path relative to the URDF, an absolute path, a file://
// URI, or package://NAME/PATH found through explicit search paths, ROS_PACKAGE_PATH and AMENT_PREFIX_PATH;
// and opening what a mesh path names, only when it is a regular file.
#include <cstdio>
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

/// Opens path for reading, without blocking, when it is a regular file (after symbolic links); else
/// returns null and says why in *reason. A FIFO would block its reader until a writer comes, and a
/// device (/dev/zero) may never end.
std::FILE* openRegularFile(const std::string& path, std::string* reason);

/// The bytes of path; throws LoadError(path, "", reason) when it is not a regular file or cannot be read.
std::string readRegularFile(const std::string& path);

}  // namespace clearway::detail
