// `clearway check SCENE [--states FILE|-] [--geometry mesh|hull]`: classifies joint vectors of a scene.
#include "commands.h"
#include "exit_codes.h"
#include "scene_commands.h"

#include <iostream>
#include <memory>
#include <string>
#include <utility>

namespace clearway::cli {

namespace {

const char* const kCheckHelp =
    "Classifies joint vectors (group order, numbers separated by spaces or commas, one per line; '#'\n"
    "starts a comment) and prints one line per state: 'free', 'collision LINK OTHER' (OTHER is a link,\n"
    "an obstacle or 'octomap'), or 'error REASON' for a bad line. Without --states it checks the\n"
    "scene's start and goal, printing 'start: ...' and 'goal: ...'.\n"
    "Exit status: 0 when every line was a state (colliding or not), 1 when some line was an error,\n"
    "2 on a usage error or a scene that does not load.\n";

struct CheckSettings {
  std::string scene, states;
  SceneOptions options;
};

std::string verdict(const Scene& scene, const std::vector<double>& q, SceneContext& ctx) {
  std::string why;
  if (!scene.validState(q.data(), &why)) return "error " + why;
  CollisionReport r;
  if (scene.isFree(q.data(), ctx, &r)) return "free";
  return "collision " + scene.describe(r);
}

int runCheck(const CheckSettings& s) {
  if (s.scene == "-" && s.states == "-") {
    std::cerr << "clearway check: SCENE and --states cannot both be - (one stdin)\n";
    return kExitUsage;
  }
  const std::shared_ptr<const Scene> scene = loadScene("check", s.scene, s.options);
  if (!scene) return kExitUsage;
  SceneContext ctx = scene->makeContext();
  if (s.states.empty()) {
    const SceneDescription& d = scene->description();
    if (d.start.empty() && d.goal.empty()) {
      std::cerr << "clearway check: " << s.scene << " has no start or goal; give --states FILE\n";
      return kExitUsage;
    }
    int status = kExitOk;  // (as for --states: a state that is an error makes the exit status 1)
    for (const auto& [name, q] : {std::pair{"start", &d.start}, std::pair{"goal", &d.goal}}) {
      if (q->empty()) continue;
      const std::string v = verdict(*scene, *q, ctx);
      if (v.compare(0, 5, "error") == 0) status = kExitNo;
      std::cout << name << ": " << v << "\n";
    }
    std::cout.flush();
    return std::cout ? status : kExitUsage;
  }
  std::ifstream file;
  std::istream* input = openInput("check", s.states, file);
  if (!input) return kExitUsage;
  int status = kExitOk;
  std::string line, why;
  std::vector<double> q;
  std::string read_error;
  for (int line_no = 1; readInputLine(*input, line, read_error); ++line_no) {
    if (!parseNumbers(line, q, why)) {
      std::cout << "error line " << line_no << ": " << why << "\n";
      status = kExitNo;
      continue;
    }
    if (q.empty()) continue;  // blank or comment
    if (static_cast<int>(q.size()) != scene->dimension()) {
      std::cout << "error line " << line_no << ": " << q.size() << " values for " << scene->dimension()
                << " group joints\n";
      status = kExitNo;
      continue;
    }
    const std::string v = verdict(*scene, q, ctx);
    if (v.compare(0, 5, "error") == 0) status = kExitNo;
    std::cout << v << "\n";
  }
  if (!read_error.empty()) {
    std::cout.flush();
    std::cerr << "clearway check: " << (s.states == "-" ? "<stdin>" : s.states) << ": " << read_error << "\n";
    return kExitUsage;
  }
  std::cout.flush();
  return std::cout ? status : kExitUsage;
}

}  // namespace

Subcommand addCheckCommand(CLI::App& root) {
  auto s = std::make_shared<CheckSettings>();
  CLI::App* app = root.add_subcommand("check", "classify joint vectors of a scene: free or which links collide");
  app->add_option("SCENE", s->scene, "the scene file (YAML; - for stdin, its paths then from the working directory)")
      ->required();
  app->add_option("--states", s->states, "joint vectors, one per line (- for stdin)")->type_name("FILE|-");
  addGeometryOption(*app, s->options.mode, /*mode_alias=*/true);
  addLoadOptions(*app, s->options.load);
  app->footer(std::string(kCheckHelp) + kFormatsHelp);
  return {app, [s] { return runCheck(*s); }};
}

}  // namespace clearway::cli
