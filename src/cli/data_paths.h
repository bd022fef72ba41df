#pragma once
// Where the tool finds its data: the bundled robots and scenes, and the shared development data that
// `clearway bench` measures on. An installed tool finds the bundled data beside itself
// (BIN/../share/clearway, whatever the prefix was moved to); only the binary still in its build tree
// falls back to the source tree it was built from, so an installed tool never depends on that tree.
#include <string>

namespace clearway::cli {

/// The folder holding robots/ (BIN/../share/clearway, or the source tree for the build-tree binary),
/// or "" when neither has it.
std::string bundledDataDir();

/// Where bundledDataDir() looks first: BIN/../share/clearway for this executable (for messages).
std::string installedDataDir();

/// The shared development data (the folder holding scenes/): $CLEARWAY_SHARED when set and not empty,
/// else ../shared beside the source tree for the build-tree binary, else "".
std::string sharedDataDir();

}  // namespace clearway::cli
