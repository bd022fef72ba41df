// `clearway motion SCENE [--motions FILE] [--mode certified|cast|sampled:RES]`: checks joint-space segments.
#include "scene_commands.h"

#include <clearway/motion/motion.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>

namespace clearway::cli {

namespace {

constexpr int kExitOk = 0, kExitBadLine = 1, kExitUsage = 2;

const char* const kMotionUsage =
    "usage: clearway motion SCENE [--motions FILE] [--mode certified|cast|sampled:RES] [--geometry mesh|hull]\n"
    "                        [--package-path DIR]... [--honour-up-axis]\n"
    "\n"
    "Checks straight joint-space segments. Each line holds two joint vectors (the group's joints in order,\n"
    "2n numbers separated by spaces or commas; '#' starts a comment); each output line is 'free',\n"
    "'collision F WHAT' (F: the last valid fraction of the segment; WHAT: the links, obstacle or\n"
    "'invalid state', or 'capped: ...' when the check would take more work than its cap), or\n"
    "'error REASON'. Without --motions it checks the scene's start -> goal.\n"
    "In a scene with moving obstacles (checks: moving) a line may also hold each state's time, 2n + 2\n"
    "numbers 't0 q0... t1 q1...' (seconds): the obstacles are where they are at each moment of the segment.\n"
    "Modes: certified (default: conservative advancement, never steps over an obstacle, contact within\n"
    "1 mm), cast (certified, with one GJK shape cast for what only translates: prismatic joints),\n"
    "sampled:RES (states every RES in the Euclidean joint norm, as OMPL's DiscreteMotionValidator;\n"
    "may tunnel). FILE may be - for stdin.\n"
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

}  // namespace

int motionCommand(const std::vector<std::string>& args) {
  std::string scene_path, motions_path;
  SceneOptions options;
  MotionOptions motion;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-h" || a == "--help") {
      std::cout << kMotionUsage << kLoadOptionsUsage;
      return kExitOk;
    }
    std::string error;
    if (parseLoadOption(args, i, options.load, error)) {
      if (error.empty()) continue;
      std::cerr << "clearway motion: " << error << "\n" << kMotionUsage << kLoadOptionsUsage;
      return kExitUsage;
    }
    if ((a == "--motions" || a == "--mode" || a == "--geometry") && i + 1 >= args.size()) {
      std::cerr << "clearway motion: " << a << " needs a value\n" << kMotionUsage;
      return kExitUsage;
    }
    if (a == "--motions") {
      motions_path = args[++i];
    } else if (a == "--mode") {
      const std::string m = args[++i];
      if (m == "certified") {
        motion.mode = MotionMode::Certified;
      } else if (m.rfind("sampled:", 0) == 0) {
        char* end = nullptr;
        const std::string res = m.substr(8);
        motion.mode = MotionMode::Sampled;
        motion.resolution = std::strtod(res.c_str(), &end);
        if (res.empty() || *end != '\0' || !(motion.resolution > 0.0) || !std::isfinite(motion.resolution)) {
          std::cerr << "clearway motion: sampled:RES needs a resolution > 0, got '" << res << "'\n";
          return kExitUsage;
        }
      } else if (m == "cast") {
        motion.mode = MotionMode::Cast;
      } else {
        std::cerr << "clearway motion: unknown mode '" << m << "' (certified, cast or sampled:RES)\n";
        return kExitUsage;
      }
    } else if (a == "--geometry") {
      const std::string g = args[++i];
      if (g == "mesh") options.mode = GeometryMode::Mesh;
      else if (g == "hull") options.mode = GeometryMode::Hull;
      else {
        std::cerr << "clearway motion: unknown geometry '" << g << "' (mesh or hull)\n";
        return kExitUsage;
      }
    } else if (scene_path.empty() && (a.empty() || a[0] != '-')) {
      scene_path = a;
    } else {
      std::cerr << "clearway motion: unexpected argument '" << a << "'\n" << kMotionUsage;
      return kExitUsage;
    }
  }
  if (scene_path.empty()) {
    std::cerr << "clearway motion: expected a SCENE file\n" << kMotionUsage;
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
    std::cout << "start -> goal: " << verdict(*checker, d.start.data(), d.goal.data(), ctx) << "\n";
    return std::cout.flush() ? kExitOk : kExitUsage;
  }
  std::ifstream file;
  std::istream* input = openInput("motion", motions_path, file);
  if (!input) return kExitUsage;
  int status = kExitOk;
  std::string line, why;
  std::vector<double> q;
  for (int line_no = 1; std::getline(*input, line); ++line_no) {
    if (!parseNumbers(line, q, why)) {
      std::cout << "error line " << line_no << ": " << why << "\n";
      status = kExitBadLine;
      continue;
    }
    if (q.empty()) continue;
    const bool timed = static_cast<int>(q.size()) == 2 * n + 2;
    if (static_cast<int>(q.size()) != 2 * n && !timed) {
      std::cout << "error line " << line_no << ": " << q.size() << " values for two states of " << n
                << " group joints (2n, or 2n + 2 with their times)\n";
      status = kExitBadLine;
      continue;
    }
    const double* q0 = q.data() + (timed ? 1 : 0);
    const double* q1 = q.data() + (timed ? n + 2 : n);
    const double t0 = timed ? q[0] : 0.0, t1 = timed ? q[n + 1] : 0.0;
    std::string bad;
    if (!scene->validState(q0, &bad) || !scene->validState(q1, &bad)) {
      std::cout << "error line " << line_no << ": " << bad << "\n";
      status = kExitBadLine;
      continue;
    }
    if (!std::isfinite(t0) || !std::isfinite(t1)) {
      std::cout << "error line " << line_no << ": a time is not finite\n";
      status = kExitBadLine;
      continue;
    }
    std::cout << verdict(*checker, q0, q1, ctx, t0, t1) << "\n";
  }
  std::cout.flush();
  return std::cout ? status : kExitUsage;
}

}  // namespace clearway::cli
