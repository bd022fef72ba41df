#include "data_paths.h"

#include <cstdlib>
#include <filesystem>
#include <system_error>

namespace clearway::cli {

namespace fs = std::filesystem;

namespace {

// The folder of this executable, through /proc/self/exe (so a symlink to it, or a moved prefix, still
// leads to the real file); empty when it cannot be read.
fs::path executableDir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : exe.parent_path();
}

// True for the binary the build wrote (CLEARWAY_BUILD_BIN_DIR), never for an installed copy.
bool inBuildTree() {
  std::error_code ec;
  const fs::path dir = executableDir();
  return !dir.empty() && fs::equivalent(dir, CLEARWAY_BUILD_BIN_DIR, ec) && !ec;
}

}  // namespace

std::string installedDataDir() {
  const fs::path dir = executableDir();
  return dir.empty() ? std::string() : (dir / CLEARWAY_BIN_TO_DATA_DIR).lexically_normal().string();
}

std::string bundledDataDir() {
  std::error_code ec;
  const std::string installed = installedDataDir();
  if (!installed.empty() && fs::is_directory(installed + "/robots", ec)) return installed;
  if (inBuildTree() && fs::is_directory(CLEARWAY_SOURCE_DIR "/robots", ec)) return CLEARWAY_SOURCE_DIR;
  return "";
}

std::string sharedDataDir() {
  if (const char* env = std::getenv("CLEARWAY_SHARED"); env && *env) return env;
  return inBuildTree() ? CLEARWAY_SOURCE_DIR "/../shared" : "";
}

}  // namespace clearway::cli
