#pragma once
// Numbers in the scene's messages as they read back: a joint value 1e-10 past a limit must not print as
// the limit.
#include <charconv>
#include <string>

namespace clearway::scene_detail {

inline std::string exactText(double x) {
  char buffer[32];
  return std::string(buffer, std::to_chars(buffer, buffer + sizeof buffer, x).ptr);
}

}  // namespace clearway::scene_detail
