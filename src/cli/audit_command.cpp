// `clearway audit URDF [--srdf S] [--samples N] [--seed N] [--srdf-out FILE] [--report FILE]`.
#include "scene_commands.h"

#include <clearway/load/robot_loader.h>
#include <clearway/scene/audit.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>

namespace clearway::cli {

namespace {

constexpr int kExitOk = 0, kExitUsage = 2;

const char* const kAuditUsage =
    "usage: clearway audit URDF [--srdf SRDF] [--samples N] [--seed N] [--srdf-out FILE] [--report FILE]\n"
    "\n"
    "Classifies every pair of links with collision geometry as MoveIt Setup Assistant does: Adjacent,\n"
    "Default (colliding at the default configuration), Always (colliding in >= 95% of N random\n"
    "configurations), Never (never seen colliding), or checked; with the evidence (samples, colliding count,\n"
    "95% Clopper-Pearson upper bound on the collision probability, smallest clearance seen; 'near' marks\n"
    "a Never pair that came within 1 mm). Prints a summary, and with --srdf the pairs where the given SRDF\n"
    "and the audit disagree. --srdf-out writes disable_collisions for every classified pair; --report a\n"
    "Markdown table of all pairs. Defaults: 10000 samples, seed 1; both cores are used.\n"
    "Exit status: 0 on success, 2 on a usage error or a robot that does not load.\n";

bool parseCount(const std::string& s, long long& out) {
  char* end = nullptr;
  out = std::strtoll(s.c_str(), &end, 10);
  return !s.empty() && *end == '\0';
}

std::string clearanceText(double c) {
  char buf[32];
  if (std::isnan(c)) return "-";
  if (std::isinf(c)) return "inf";
  std::snprintf(buf, sizeof buf, "%.4g", c);
  return buf;
}

}  // namespace

int auditCommand(const std::vector<std::string>& args) {
  std::string urdf, srdf, srdf_out, report;
  AuditOptions options;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-h" || a == "--help") {
      std::cout << kAuditUsage;
      return kExitOk;
    }
    const bool valued = a == "--srdf" || a == "--samples" || a == "--seed" || a == "--srdf-out" || a == "--report";
    if (valued && i + 1 >= args.size()) {
      std::cerr << "clearway audit: " << a << " needs a value\n" << kAuditUsage;
      return kExitUsage;
    }
    long long n = 0;
    if (a == "--srdf") {
      srdf = args[++i];
    } else if (a == "--srdf-out") {
      srdf_out = args[++i];
    } else if (a == "--report") {
      report = args[++i];
    } else if (a == "--samples") {
      if (!parseCount(args[++i], n) || n < 1 || n > 100000000) {
        std::cerr << "clearway audit: --samples needs a whole number from 1 to 1e8, got '" << args[i] << "'\n";
        return kExitUsage;
      }
      options.samples = static_cast<int>(n);
    } else if (a == "--seed") {
      if (!parseCount(args[++i], n) || n < 0) {
        std::cerr << "clearway audit: --seed needs a whole number >= 0, got '" << args[i] << "'\n";
        return kExitUsage;
      }
      options.seed = static_cast<std::uint64_t>(n);
    } else if (urdf.empty() && !a.empty() && a[0] != '-') {
      urdf = a;
    } else {
      std::cerr << "clearway audit: unexpected argument '" << a << "'\n" << kAuditUsage;
      return kExitUsage;
    }
  }
  if (urdf.empty()) {
    std::cerr << "clearway audit: expected a URDF file\n" << kAuditUsage;
    return kExitUsage;
  }
  std::shared_ptr<const RobotModel> model;
  std::map<std::pair<int, int>, std::string> shipped;  // the given SRDF's disabled pairs
  try {
    model = std::make_shared<const RobotModel>(loadRobot(urdf));
    if (!srdf.empty()) {
      const RobotModel with_srdf = loadRobot(urdf, srdf);
      for (const DisabledCollision& d : with_srdf.disabledCollisions())
        shipped[{std::min(d.link_a, d.link_b), std::max(d.link_a, d.link_b)}] = d.reason;
    }
  } catch (const std::exception& e) {
    std::cerr << "clearway audit: " << e.what() << "\n";
    return kExitUsage;
  }
  for (const std::string& w : model->loadWarnings()) std::cerr << "warning: " << w << "\n";
  const auto geometry = std::make_shared<const RobotGeometry>(model);
  std::cerr << "clearway audit: " << model->name() << ", " << geometry->geometricLinks().size()
            << " links with geometry, " << options.samples << " samples (seed " << options.seed << ")\n";
  const std::vector<PairAudit> audit = auditSelfCollision(geometry, options);

  std::map<std::string, int> counts;
  int near = 0;
  for (const PairAudit& p : audit) {
    ++counts[p.reason.empty() ? "checked" : p.reason];
    near += p.near_miss;
  }
  std::cout << model->name() << ": " << audit.size() << " pairs:";
  for (const char* r : {"Adjacent", "Default", "Always", "Never", "checked"}) std::cout << " " << counts[r] << " " << r;
  std::cout << " (" << near << " Never pairs came within 1 mm)\n";
  if (!srdf.empty()) {
    int differ = 0;
    for (const PairAudit& p : audit) {
      const auto it = shipped.find({p.a, p.b});
      const std::string theirs = it == shipped.end() ? "" : it->second;
      if (theirs == p.reason) continue;
      ++differ;
      std::cout << "differs: " << model->link(p.a).name << " " << model->link(p.b).name << ": SRDF "
                << (theirs.empty() ? "checked" : theirs) << ", audit " << (p.reason.empty() ? "checked" : p.reason)
                << " (" << p.colliding << "/" << p.samples << " colliding, p <= " << p.p_upper << ", min clearance "
                << clearanceText(p.min_clearance) << ")\n";
    }
    std::cout << differ << " pairs differ from " << srdf << "\n";
  }
  if (!srdf_out.empty()) {
    std::ofstream out(srdf_out);
    out << auditSrdf(*model, audit);
    if (!out) {
      std::cerr << "clearway audit: cannot write " << srdf_out << "\n";
      return kExitUsage;
    }
  }
  if (!report.empty()) {
    std::ofstream out(report);
    out << "# Self-collision audit of " << model->name() << "\n\n" << options.samples << " samples, seed "
        << options.seed << ".\n\n| link 1 | link 2 | verdict | colliding | samples | p (95% upper) | min clearance (m) |\n"
        << "|---|---|---|---|---|---|---|\n";
    for (const PairAudit& p : audit)
      out << "| " << model->link(p.a).name << " | " << model->link(p.b).name << " | "
          << (p.reason.empty() ? "checked" : p.reason) << (p.near_miss ? " (near)" : "") << " | " << p.colliding
          << " | " << p.samples << " | " << p.p_upper << " | " << clearanceText(p.min_clearance) << " |\n";
    if (!out) {
      std::cerr << "clearway audit: cannot write " << report << "\n";
      return kExitUsage;
    }
  }
  return kExitOk;
}

}  // namespace clearway::cli
