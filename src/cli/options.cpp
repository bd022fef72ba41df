#include "options.h"

#include "scene_commands.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <utility>
#include <vector>

namespace clearway::cli {

const char* const kFormatsHelp =
    "File formats: docs/scene-format.md (scene YAML), docs/query-format.md (query JSON Lines), in the source\n"
    "tree and in share/doc/clearway/ of an installed package.\n";

namespace {

std::vector<std::pair<std::string, std::string>>& deprecations() {
  static std::vector<std::pair<std::string, std::string>> used;  // parsing is single-threaded
  return used;
}

bool parseGeometry(const std::string& v, GeometryMode& mode) {
  if (v == "mesh") mode = GeometryMode::Mesh;
  else if (v == "hull") mode = GeometryMode::Hull;
  else return false;
  return true;
}

const CLI::Validator kGeometry(
    [](std::string& v) {
      GeometryMode m;
      return parseGeometry(v, m) ? std::string() : "unknown geometry '" + v + "' (mesh or hull)";
    },
    "");  // (the option's type name says it)

// "certified", "cast" or "sampled:RES" with RES > 0; "" on success, else the reason.
std::string parseMotion(const std::string& v, MotionOptions& motion) {
  if (v == "certified") motion.mode = MotionMode::Certified;
  else if (v == "cast") motion.mode = MotionMode::Cast;
  else if (v.rfind("sampled:", 0) == 0) {
    const std::string res = v.substr(8);
    char* end = nullptr;
    const double r = std::strtod(res.c_str(), &end);
    if (res.empty() || *end != '\0' || !(r > 0.0) || !std::isfinite(r))
      return "sampled:RES needs a resolution > 0, got '" + res + "'";
    motion.mode = MotionMode::Sampled;
    motion.resolution = r;
  } else {
    return "unknown motion mode '" + v + "' (certified, cast or sampled:RES)";
  }
  return "";
}

const CLI::Validator kMotion(
    [](std::string& v) {
      MotionOptions m;
      return parseMotion(v, m);
    },
    "");

}  // namespace

void noteDeprecated(const std::string& old_spelling, const std::string& new_spelling) {
  deprecations().emplace_back(old_spelling, new_spelling);
}

void printDeprecations() {
  for (const auto& [old_spelling, new_spelling] : deprecations())
    printWarning(old_spelling + " is deprecated; use " + new_spelling);  // (printed once each)
}

void addGeometryOption(CLI::App& app, GeometryMode& mode, bool mode_alias) {
  auto set = [&mode](const std::string& v) { parseGeometry(v, mode); };
  app.add_option_function<std::string>("--geometry", set,
                                       "mesh (default: hulls, then exact triangles) or hull (convex hulls only: conservative)")
      ->check(kGeometry)
      ->type_name("mesh|hull");
  if (mode_alias)
    app.add_option_function<std::string>(
           "--mode",
           [set](const std::string& v) {
             noteDeprecated("--mode", "--geometry");
             set(v);
           },
           "the old spelling of --geometry")
        ->check(kGeometry)
        ->type_name("mesh|hull")
        ->group("Deprecated");  // (a hidden option loses its name in CLI11's error messages)
}

void addMotionOption(CLI::App& app, MotionOptions& motion, bool mode_alias) {
  auto set = [&motion](const std::string& v) { parseMotion(v, motion); };
  app.add_option_function<std::string>(
         "--motion", set,
         "certified (default: conservative advancement, never steps over an obstacle, contact within 1 mm), cast "
         "(certified, with one GJK shape cast for what only translates), sampled:RES (states every RES in the "
         "Euclidean joint norm, as OMPL's DiscreteMotionValidator; may tunnel)")
      ->check(kMotion)
      ->type_name("MODE");
  if (mode_alias)
    app.add_option_function<std::string>(
           "--mode",
           [set](const std::string& v) {
             noteDeprecated("--mode", "--motion");
             set(v);
           },
           "the old spelling of --motion")
        ->check(kMotion)
        ->type_name("MODE")
        ->group("Deprecated");
}

CLI::Option* addSeedOption(CLI::App& app, std::uint64_t& seed, const std::string& what) {
  const CLI::Validator whole(
      [](std::string& v) {
        char* end = nullptr;
        errno = 0;
        std::strtoull(v.c_str(), &end, 10);
        const bool digits = !v.empty() && v.find_first_not_of("0123456789") == std::string::npos;
        return digits && errno == 0 && *end == '\0' ? std::string()
                                                    : "needs a whole number from 0 to 2^64 - 1, got '" + v + "'";
      },
      "");
  return app.add_option("--seed", seed, what)->check(whole)->type_name("N");
}

void addLoadOptions(CLI::App& app, LoadOptions& load) {
  const CLI::Validator folder(
      [](std::string& v) {
        std::error_code ec;
        return std::filesystem::is_directory(v, ec) ? std::string() : v + ": folder not found";
      },
      "");
  app.add_option("--package-path", load.package_paths,
                 "a folder searched for package://NAME/... meshes before the scene file's package_paths, "
                 "ROS_PACKAGE_PATH and AMENT_PREFIX_PATH (repeatable)")
      ->check(folder)
      ->type_name("DIR")
      ->allow_extra_args(false)  // one folder per --package-path: a SCENE after it stays a SCENE
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  app.add_flag("--honour-up-axis", load.mesh.honour_up_axis,
               "rotate each COLLADA mesh so that its <up_axis> is z (ROS, and the default, ignore it; <unit> always applies)");
}

CLI::Validator wholeNumber(long long lo, long long hi) {
  return CLI::Validator(
      [lo, hi](std::string& v) {
        char* end = nullptr;
        errno = 0;
        const long long n = std::strtoll(v.c_str(), &end, 10);
        if (!v.empty() && *end == '\0' && errno == 0 && n >= lo && n <= hi) return std::string();
        return "needs a whole number from " + std::to_string(lo) + " to " + std::to_string(hi) + ", got '" + v + "'";
      },
      "in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

CLI::Validator fileName() {
  return CLI::Validator([](std::string& v) { return v.empty() ? std::string("needs a file name, got ''") : std::string(); },
                        "FILE");
}

CLI::Validator numberAbove(double above, double at_most) {
  std::ostringstream bound;
  bound << "> " << above;
  if (at_most < HUGE_VAL) bound << ", <= " << at_most;
  return CLI::Validator(
      [above, at_most](std::string& v) {
        char* end = nullptr;
        const double x = std::strtod(v.c_str(), &end);
        if (!v.empty() && *end == '\0' && std::isfinite(x) && x > above && x <= at_most) return std::string();
        std::ostringstream why;
        why << "needs a number > " << above;
        if (at_most < HUGE_VAL) why << " and <= " << at_most;
        why << ", got '" << v << "'";
        return why.str();
      },
      bound.str());
}

}  // namespace clearway::cli
