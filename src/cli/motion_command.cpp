// `clearway motion SCENE [--motions FILE|-] [--motion certified|cast|sampled:RES]`: checks joint-space segments.
#include "commands.h"
#include "exit_codes.h"
#include "scene_commands.h"

#include <clearway/motion/motion.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>

namespace clearway::cli {

namespace {

const char* const kMotionHelp =
    "Checks straight joint-space segments. Each line holds two joint vectors (the group's joints in order,\n"
    "2n numbers separated by spaces or commas; '#' starts a comment); each output line is 'free',\n"
    "'collision F WHAT' (F: the last valid fraction of the segment; WHAT: the links, obstacle or\n"
    "'invalid state', or 'capped: ...' when the check would take more work than its cap), or\n"
    "'error REASON'. Without --motions it checks the scene's start -> goal.\n"
    "In a scene with moving obstacles (checks: moving) a line may also hold each state's time, 2n + 2\n"
    "numbers 't0 q0... t1 q1...' (seconds): the obstacles are where they are at each moment of the segment.\n"
    "--mode is the old spelling of --motion (deprecated).\n"
    "Exit status: 0 when every line was a segment, 1 when some line was an error, 2 on a usage error or\n"
    "a scene that does not load.\n";

std::string verdict(const MotionChecker& checker, const double* q0, const double* q1, MotionContext& ctx,
                    double t0 = 0.0, double t1 = 0.0) {
  const MotionResult r = checker.check(q0, t0, q1, t1, ctx);
  if (r.free) return "free";
  if (r.capped)
    return checker.options().mode == MotionMode::Sampled
               ? "collision 0 capped: more than " + std::to_string(checker.options().max_samples) +
                     " states at this resolution (never called free)"
               : "collision 0 capped: more than " + std::to_string(checker.options().max_queries) +
                     " distance queries (never called free)";
  char fraction[32];
  std::snprintf(fraction, sizeof fraction, "%.9g", r.last_valid);
  return std::string("collision ") + fraction + " " + checker.scene().describe(r.report);
}

struct MotionSettings {
  std::string scene, motions;
  SceneOptions options;
  MotionOptions motion;
};

int runMotion(const MotionSettings& s) {
  const std::string& scene_path = s.scene;
  const std::string& motions_path = s.motions;
  const SceneOptions& options = s.options;
  const MotionOptions& motion = s.motion;
  if (scene_path == "-" && motions_path == "-") {
    std::cerr << "clearway motion: SCENE and --motions cannot both be - (one stdin)\n";
    return kExitUsage;
  }
  const std::shared_ptr<const Scene> scene = loadScene("motion", scene_path, options);
  if (!scene) return kExitUsage;
  std::unique_ptr<MotionChecker> checker;
  try {
    checker = std::make_unique<MotionChecker>(scene, motion);
  } catch (const std::exception& e) {
    std::cerr << "clearway motion: " << scene_path << ": " << e.what() << "\n";
    return kExitUsage;
  }
  MotionContext ctx = checker->makeContext();
  const int n = scene->dimension();
  if (motions_path.empty()) {
    const SceneDescription& d = scene->description();
    if (d.start.empty() || d.goal.empty()) {
      std::cerr << "clearway motion: " << scene_path << " needs a start and a goal; give --motions FILE\n";
      return kExitUsage;
    }
    // (As a line of --motions: an end that is no valid state is an error, exit status 1.)
    std::string bad;
    if (!scene->validState(d.start.data(), &bad) || !scene->validState(d.goal.data(), &bad)) {
      std::cout << "start -> goal: error " << bad << "\n";
      return std::cout.flush() ? kExitNo : kExitUsage;
    }
    std::cout << "start -> goal: " << verdict(*checker, d.start.data(), d.goal.data(), ctx) << "\n";
    return std::cout.flush() ? kExitOk : kExitUsage;
  }
  std::ifstream file;
  std::istream* input = openInput("motion", motions_path, file);
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
    if (q.empty()) continue;
    const bool timed = static_cast<int>(q.size()) == 2 * n + 2;
    if (static_cast<int>(q.size()) != 2 * n && !timed) {
      std::cout << "error line " << line_no << ": " << q.size() << " values for two states of " << n
                << " group joints (2n, or 2n + 2 with their times)\n";
      status = kExitNo;
      continue;
    }
    const double* q0 = q.data() + (timed ? 1 : 0);
    const double* q1 = q.data() + (timed ? n + 2 : n);
    const double t0 = timed ? q[0] : 0.0, t1 = timed ? q[n + 1] : 0.0;
    std::string bad;
    if (!scene->validState(q0, &bad) || !scene->validState(q1, &bad)) {
      std::cout << "error line " << line_no << ": " << bad << "\n";
      status = kExitNo;
      continue;
    }
    if (!(std::abs(t0) <= kMaxTime && std::abs(t1) <= kMaxTime)) {
      std::cout << "error line " << line_no << ": a time is not finite or beyond ±1e6 s, the largest a query may give\n";
      status = kExitNo;
      continue;
    }
    std::cout << verdict(*checker, q0, q1, ctx, t0, t1) << "\n";
  }
  if (!read_error.empty()) {
    std::cout.flush();
    std::cerr << "clearway motion: " << (motions_path == "-" ? "<stdin>" : motions_path) << ": " << read_error << "\n";
    return kExitUsage;
  }
  std::cout.flush();
  return std::cout ? status : kExitUsage;
}

}  // namespace

Subcommand addMotionCommand(CLI::App& root) {
  auto s = std::make_shared<MotionSettings>();
  CLI::App* app = root.add_subcommand("motion", "check joint-space segments of a scene: free, or the last valid fraction");
  app->add_option("SCENE", s->scene, "the scene file (YAML; - for stdin, its paths then from the working directory)")
      ->required();
  app->add_option("--motions", s->motions, "segments, two joint vectors per line (- for stdin)")->type_name("FILE|-");
  addMotionOption(*app, s->motion, /*mode_alias=*/true);
  addGeometryOption(*app, s->options.mode, /*mode_alias=*/false);
  addLoadOptions(*app, s->options.load);
  app->footer(std::string(kMotionHelp) + kFormatsHelp);
  return {app, [s] { return runMotion(*s); }};
}

}  // namespace clearway::cli
