#include "scene_commands.h"

#include <clearway/scene/scene.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>

namespace clearway::cli {

namespace {

constexpr int kExitOk = 0, kExitBadLine = 1, kExitUsage = 2;

const char* const kCheckUsage =
    "usage: clearway check SCENE [--states FILE] [--mode mesh|hull] [--package-path DIR]... [--honour-up-axis]\n"
    "\n"
    "Classifies joint vectors (group order, numbers separated by spaces or commas, one per line; '#'\n"
    "starts a comment) and prints one line per state: 'free', 'collision LINK OTHER' (OTHER is a link,\n"
    "an obstacle or 'octomap'), or 'error REASON' for a bad line. Without --states it checks the\n"
    "scene's start and goal, printing 'start: ...' and 'goal: ...'. FILE may be - for stdin.\n"
    "Exit status: 0 when every line was a state, 1 when some line was an error, 2 on a usage error or\n"
    "a scene that does not load.\n";

std::string verdict(const Scene& scene, const std::vector<double>& q, SceneContext& ctx) {
  std::string why;
  if (!scene.validState(q.data(), &why)) return "error " + why;
  CollisionReport r;
  if (scene.isFree(q.data(), ctx, &r)) return "free";
  return "collision " + scene.describe(r);
}

}  // namespace

const char* const kLoadOptionsUsage =
    "Robot loading: --package-path DIR (repeatable) is searched for package://NAME/... meshes before the\n"
    "scene file's package_paths, ROS_PACKAGE_PATH and AMENT_PREFIX_PATH. COLLADA meshes are read as ROS\n"
    "reads them, ignoring <up_axis> (their <unit> applies); --honour-up-axis rotates each so that its up\n"
    "axis is z.\n";

bool parseLoadOption(const std::vector<std::string>& args, std::size_t& i, LoadOptions& options, std::string& error) {
  const std::string& a = args[i];
  if (a == "--honour-up-axis") {
    options.mesh.honour_up_axis = true;
    return true;
  }
  if (a != "--package-path") return false;
  if (i + 1 >= args.size() || args[i + 1].empty()) {
    error = a + " needs a folder";
    return true;
  }
  const std::string& dir = args[++i];
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) {
    error = a + " " + dir + ": folder not found";
    return true;
  }
  options.package_paths.push_back(dir);
  return true;
}

namespace {
bool quiet_mode = false;
}  // namespace

bool quiet() { return quiet_mode; }
void setQuiet(bool on) { quiet_mode = on; }

void printWarning(const std::string& text) {
  static std::set<std::string> printed;  // the tool is one thread while it loads
  if (!quiet_mode && printed.insert(text).second) std::cerr << "warning: " << text << "\n";
}

std::shared_ptr<const Scene> loadScene(const char* command, const std::string& path, const SceneOptions& options) {
  try {
    auto scene = Scene::load(path, options);
    for (const std::string& w : scene->robot().loadWarnings()) printWarning(w);
    return scene;
  } catch (const std::exception& e) {
    std::cerr << "clearway " << command << ": " << e.what() << "\n";
    return nullptr;
  }
}

std::istream* openInput(const char* command, const std::string& path, std::ifstream& file) {
  if (path == "-") return &std::cin;
  file.open(path);
  if (!file) {
    std::cerr << "clearway " << command << ": cannot open " << path << ": " << std::strerror(errno) << "\n";
    return nullptr;
  }
  return &file;
}

bool parseNumbers(const std::string& line, std::vector<double>& out, std::string& why) {
  out.clear();
  const char* p = line.c_str();
  while (true) {
    while (*p == ' ' || *p == '\t' || *p == ',' || *p == '\r') ++p;
    if (*p == '\0' || *p == '#') return true;
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(p, &end);
    if (end == p) {
      why = "not a number: '" + std::string(p, std::strcspn(p, " \t,")) + "'";
      return false;
    }
    if (*end != '\0' && *end != ' ' && *end != '\t' && *end != ',' && *end != '\r' && *end != '#') {
      why = "not a number: '" + std::string(p, std::strcspn(p, " \t,")) + "'";
      return false;
    }
    out.push_back(v);
    p = end;
  }
}

int checkCommand(const std::vector<std::string>& args) {
  std::string scene_path, states_path;
  SceneOptions options;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-h" || a == "--help") {
      std::cout << kCheckUsage << kLoadOptionsUsage;
      return kExitOk;
    }
    std::string error;
    if (parseLoadOption(args, i, options.load, error)) {
      if (error.empty()) continue;
      std::cerr << "clearway check: " << error << "\n" << kCheckUsage << kLoadOptionsUsage;
      return kExitUsage;
    }
    if ((a == "--states" || a == "--mode") && i + 1 >= args.size()) {
      std::cerr << "clearway check: " << a << " needs a value\n" << kCheckUsage;
      return kExitUsage;
    }
    if (a == "--states") {
      states_path = args[++i];
    } else if (a == "--mode") {
      const std::string m = args[++i];
      if (m == "mesh") options.mode = GeometryMode::Mesh;
      else if (m == "hull") options.mode = GeometryMode::Hull;
      else {
        std::cerr << "clearway check: unknown mode '" << m << "' (mesh or hull)\n";
        return kExitUsage;
      }
    } else if (scene_path.empty() && (a.empty() || a[0] != '-')) {
      scene_path = a;
    } else {
      std::cerr << "clearway check: unexpected argument '" << a << "'\n" << kCheckUsage;
      return kExitUsage;
    }
  }
  if (scene_path.empty()) {
    std::cerr << "clearway check: expected a SCENE file\n" << kCheckUsage;
    return kExitUsage;
  }
  const std::shared_ptr<const Scene> scene = loadScene("check", scene_path, options);
  if (!scene) return kExitUsage;
  SceneContext ctx = scene->makeContext();
  int status = kExitOk;
  if (states_path.empty()) {
    const SceneDescription& d = scene->description();
    if (d.start.empty() && d.goal.empty()) {
      std::cerr << "clearway check: " << scene_path << " has no start or goal; give --states FILE\n";
      return kExitUsage;
    }
    if (!d.start.empty()) std::cout << "start: " << verdict(*scene, d.start, ctx) << "\n";
    if (!d.goal.empty()) std::cout << "goal: " << verdict(*scene, d.goal, ctx) << "\n";
    std::cout.flush();
    return std::cout ? kExitOk : kExitUsage;
  }
  std::ifstream file;
  std::istream* input = openInput("check", states_path, file);
  if (!input) return kExitUsage;
  std::istream& in = *input;
  std::string line, why;
  std::vector<double> q;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (!parseNumbers(line, q, why)) {
      std::cout << "error line " << line_no << ": " << why << "\n";
      status = kExitBadLine;
      continue;
    }
    if (q.empty()) continue;  // blank or comment
    if (static_cast<int>(q.size()) != scene->dimension()) {
      std::cout << "error line " << line_no << ": " << q.size() << " values for " << scene->dimension()
                << " group joints\n";
      status = kExitBadLine;
      continue;
    }
    const std::string v = verdict(*scene, q, ctx);
    if (v.compare(0, 5, "error") == 0) status = kExitBadLine;
    std::cout << v << "\n";
  }
  std::cout.flush();
  if (!std::cout) return kExitUsage;
  return status;
}

bool runGnuplot(const std::string& script, std::string& why) {
  if (std::system("command -v gnuplot >/dev/null 2>&1") != 0) {
    why = "gnuplot is not installed (" + script + " written)";
    return false;
  }
  // Single-quoted for the shell: a quote inside becomes '\''.
  auto shell = [](const std::string& s) {
    std::string out = "'";
    for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
  };
  const std::filesystem::path path(script);
  const std::string dir = path.has_parent_path() ? path.parent_path().string() : ".";
  if (std::system(("cd " + shell(dir) + " && gnuplot " + shell(path.filename().string()) + " 2>/dev/null").c_str()) != 0) {
    why = "gnuplot failed on " + script;
    return false;
  }
  return true;
}

}  // namespace clearway::cli
