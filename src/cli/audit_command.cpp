// `clearway audit URDF [--srdf S] [--check] [--samples N] [--seed N] [--threads N] [--srdf-out FILE|-]
// [--report FILE]`.
#include "commands.h"
#include "exit_codes.h"
#include "gnuplot_text.h"
#include "scene_commands.h"

#include <clearway/load/robot_loader.h>
#include <clearway/scene/audit.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace clearway::cli {

namespace {

const char* const kAuditHelp =
    "Classifies every pair of links with collision geometry as MoveIt Setup Assistant does: Adjacent,\n"
    "Default (colliding at the default configuration), Always (colliding in >= 95% of N random\n"
    "configurations), Never (never seen colliding), or checked; with the evidence (samples, colliding count,\n"
    "95% Clopper-Pearson upper bound on the collision probability, smallest clearance seen; 'near' marks\n"
    "a Never pair that came within 1 mm). Default pairs are sampled too. Prints first the pairs whose\n"
    "verdict may mislead: disabled (Default, or by the --srdf given) yet colliding in more than 1% of the\n"
    "samples, or checked yet colliding in most; then a summary, and with --srdf the pairs where the given SRDF\n"
    "and the audit disagree; with --check, a disagreement is exit status 1 (a CI guard for the SRDF).\n"
    "--srdf-out writes an SRDF (- for stdout, the report then going to stderr): the --srdf given, with the\n"
    "disable_collisions of every audited pair replaced by one per classified pair (link1 < link2, sorted)\n"
    "and all else kept (groups, group states, end effectors, virtual and passive joints, comments), or a new\n"
    "one without --srdf; it may be the --srdf file itself. --report writes a Markdown table of all pairs\n"
    "and, beside it (REPORT with .png), a heat map of the link-pair matrix (drawn by gnuplot when\n"
    "installed). A progress bar goes to stderr on a terminal.\n"
    "Defaults: 10000 samples, seed 1, one thread per hardware thread. The same seed and samples give the\n"
    "same audit whatever the thread count.\n"
    "Exit status: 0 on success (with --check: the SRDF agrees), 1 with --check when the SRDF disagrees,\n"
    "2 on a usage error, a robot that does not load or an output that cannot be written.\n";

std::string clearanceText(double c) {
  char buf[32];
  if (std::isnan(c)) return "-";
  if (std::isinf(c)) return "inf";
  std::snprintf(buf, sizeof buf, "%.4g", c);
  return buf;
}

// The measured evidence of a pair, or "" for a pair that was not sampled (Adjacent).
std::string evidenceText(const PairAudit& p) {
  if (p.samples == 0) return "";
  std::ostringstream out;
  out << " (" << p.colliding << "/" << p.samples << " colliding, p <= " << p.p_upper << ", min clearance "
      << clearanceText(p.min_clearance) << ")";
  return out.str();
}

double collidingFraction(const PairAudit& p) { return p.samples > 0 ? static_cast<double>(p.colliding) / p.samples : 0.0; }

// A bar on stderr, redrawn in place: only on a terminal (logs and pipes get the summary lines alone).
void progressBar(int done, int total) {
  constexpr int kWidth = 40;
  const int filled = static_cast<int>(static_cast<long long>(kWidth) * done / std::max(total, 1));
  std::fprintf(stderr, "\r  [%s%s] %3d%%  %d / %d samples", std::string(filled, '#').c_str(),
               std::string(kWidth - filled, ' ').c_str(), static_cast<int>(100LL * done / std::max(total, 1)), done, total);
  if (done >= total) std::fputc('\n', stderr);
  std::fflush(stderr);
}

// The link-pair matrix as a PNG (through gnuplot, when installed): one cell per pair, coloured by the
// colliding fraction on a log scale; Never pairs green (dark when they came within the near margin),
// Adjacent and Default grey; each cell lettered with its verdict. Returns false (with a reason) when
// no picture was drawn.
bool writeHeatmap(const RobotModel& model, const std::vector<PairAudit>& audit, const std::string& png,
                  std::string& why) {
  std::string output;
  if (!gnuplotFileName(std::filesystem::path(png).filename().string(), output)) {
    why = "its file name holds a control character";
    return false;
  }
  std::vector<int> links;
  for (const PairAudit& p : audit) links.push_back(p.a), links.push_back(p.b);
  std::sort(links.begin(), links.end());
  links.erase(std::unique(links.begin(), links.end()), links.end());
  auto at = [&](int link) { return std::lower_bound(links.begin(), links.end(), link) - links.begin(); };
  std::ostringstream sampled, never, fixed, labels, tics;
  for (const PairAudit& p : audit) {
    const long x = at(p.a), y = at(p.b);
    const std::string cell = std::to_string(x) + " " + std::to_string(y);
    const char* letter = p.reason == "Adjacent" ? "A" : p.reason == "Default" ? "D" : p.reason == "Always" ? "Al"
                         : p.reason == "Never" ? (p.near_miss ? "N*" : "N") : "";
    if (p.samples == 0) fixed << cell << "\n";
    else if (p.colliding == 0) never << cell << " " << (p.near_miss ? 1 : 0) << "\n";
    else sampled << cell << " " << static_cast<double>(p.colliding) / p.samples << "\n";
    if (*letter) labels << cell << " " << letter << "\n";
  }
  for (std::size_t i = 0; i < links.size(); ++i) tics << (i ? ", " : "") << "'" << gnuplotSafeText(model.link(links[i]).name) << "' " << i;
  const int n = static_cast<int>(links.size());
  const int size = std::max(700, 40 * n + 300);
  std::ostringstream gp;
  gp << "# Written by clearway audit: the link-pair matrix of " << gnuplotSafeText(model.name()) << "\n"
     << "set terminal pngcairo noenhanced size " << size << "," << size << " font ',9'\n"
     << "set output " << output << "\n"
     << "set title \"Self-collision audit of " << gnuplotSafeText(model.name())
     << ": fraction of samples colliding\\nA adjacent, D default, Al always, N never, N* never but within 1 mm\"\n"
     << "set size ratio -1\nset xrange [-0.5:" << n - 0.5 << "]\nset yrange [-0.5:" << n - 0.5 << "]\n"
     << "set xtics (" << tics.str() << ") rotate by 60 right\nset ytics (" << tics.str() << ")\n"
     << "set logscale cb\nset cbrange [1e-5:1]\nset cblabel 'colliding fraction'\n"
     << "set palette defined (0 '#fff7bc', 0.5 '#fe9929', 1 '#cc4c02')\nset key off\nset grid front\n"
     << "$sampled << EOD\n" << sampled.str() << "EOD\n$never << EOD\n" << never.str() << "EOD\n$fixed << EOD\n"
     << fixed.str() << "EOD\n$labels << EOD\n" << labels.str() << "EOD\n";
  // Empty datablocks make gnuplot stop with an error: plot only those with rows.
  std::vector<std::string> parts;
  if (!sampled.str().empty()) parts.push_back("$sampled using 1:2:(0.5):(0.5):3 with boxxyerror fs solid 1.0 noborder lc palette");
  if (!never.str().empty())
    parts.push_back("$never using 1:2:(0.5):(0.5):($3 > 0 ? 0x2e7d32 : 0xa5d6a7) with boxxyerror fs solid 1.0 noborder lc rgb variable");
  if (!fixed.str().empty()) parts.push_back("$fixed using 1:2:(0.5):(0.5) with boxxyerror fs solid 1.0 noborder lc rgb '#bdbdbd'");
  if (!labels.str().empty()) parts.push_back("$labels using 1:2:3 with labels font ',7'");
  if (parts.empty()) {
    why = "no pairs";
    return false;
  }
  gp << "plot ";
  for (std::size_t i = 0; i < parts.size(); ++i) gp << (i ? ", " : "") << parts[i];
  gp << "\n";
  const std::string script = png + ".gp";
  std::ofstream(script) << gp.str();
  return runGnuplot(script, why);
}

struct AuditSettings {
  std::string urdf, srdf, srdf_out, report;
  bool check = false;
  AuditOptions options;
  LoadOptions load;
};

int runAudit(AuditSettings& settings) {
  const std::string &urdf = settings.urdf, &srdf = settings.srdf, &srdf_out = settings.srdf_out,
                    &report = settings.report;
  const bool check = settings.check;
  AuditOptions& options = settings.options;
  const LoadOptions& load = settings.load;
  if (check && srdf.empty()) {
    std::cerr << "clearway audit: --check needs the --srdf to compare with\n";
    return kExitUsage;
  }
  if (report == "-") {
    std::cerr << "clearway audit: --report needs a file name (its heat map is written beside it), not -\n";
    return kExitUsage;
  }
  // The heat map beside the report (report.md → report.png) is named in its gnuplot script.
  const std::filesystem::path png = std::filesystem::path(report).replace_extension(".png");
  if (std::string literal; !report.empty() && !gnuplotFileName(png.filename().string(), literal)) {
    std::cerr << "clearway audit: --report: the file name holds a control character (a newline, a tab...), which "
                 "its heat map's gnuplot script cannot name\n";
    return kExitUsage;
  }
  // With the SRDF on stdout, the report lines go to stderr.
  std::ostream& text = srdf_out == "-" ? std::cerr : std::cout;
  std::shared_ptr<const RobotModel> model;
  std::map<std::pair<int, int>, std::string> shipped;  // the given SRDF's disabled pairs
  std::string srdf_text;                               // the given SRDF, which --srdf-out keeps
  try {
    model = std::make_shared<const RobotModel>(loadRobot(urdf, "", load));
    for (const std::string& w : model->loadWarnings()) printWarning(w);
    if (!srdf.empty()) {
      const RobotModel with_srdf = loadRobot(urdf, srdf, load);
      for (const DisabledCollision& d : with_srdf.disabledCollisions())
        shipped[{std::min(d.link_a, d.link_b), std::max(d.link_a, d.link_b)}] = d.reason;
      // The URDF's own warnings come again, and are printed once (printWarning).
      for (const std::string& w : with_srdf.loadWarnings()) printWarning(w);
      std::ifstream in(srdf);
      std::ostringstream content;
      content << in.rdbuf();
      if (!in) throw std::runtime_error(srdf + ": cannot read the file");
      srdf_text = content.str();
    }
  } catch (const std::exception& e) {
    std::cerr << "clearway audit: " << e.what() << "\n";
    return kExitUsage;
  }
  const auto geometry = std::make_shared<const RobotGeometry>(model);
  if (options.threads > maxAuditThreads()) {
    printWarning("--threads " + std::to_string(options.threads) + " is more than this machine runs at once: " +
                 std::to_string(maxAuditThreads()) + " threads used (4 per hardware thread, at most 256)");
    options.threads = maxAuditThreads();
  }
  if (!quiet())
    std::cerr << "clearway audit: " << model->name() << ", " << geometry->geometricLinks().size()
              << " links with geometry, " << options.samples << " samples (seed " << options.seed << "), "
              << options.threads << " threads\n";
  if (isatty(STDERR_FILENO) && !quiet()) options.progress = progressBar;
  const std::vector<PairAudit> audit = auditSelfCollision(geometry, options);

  // The pairs whose verdict may mislead come first, the most often colliding first: the audit's own
  // (Default pairs that collide elsewhere, checked pairs that collide in most samples), and pairs the
  // given SRDF disables that the samples show colliding.
  std::vector<std::pair<const PairAudit*, std::string>> warnings;
  for (const PairAudit& p : audit) {
    if (!p.warning.empty()) {
      warnings.emplace_back(&p, p.warning);
      continue;
    }
    const auto it = shipped.find({p.a, p.b});
    if (it == shipped.end() || p.samples == 0 || p.reason == "Always") continue;
    const double fraction = collidingFraction(p);
    if (fraction > options.warn_fraction) {
      std::ostringstream why;
      why << srdf << " disables it (" << it->second << ") but it collides in " << p.colliding << " of " << p.samples
          << " samples (" << 100.0 * fraction << "%)";
      warnings.emplace_back(&p, why.str());
    }
  }
  std::stable_sort(warnings.begin(), warnings.end(),
                   [](const auto& x, const auto& y) { return collidingFraction(*x.first) > collidingFraction(*y.first); });
  for (const auto& [p, why] : warnings)
    text << "warning: " << model->link(p->a).name << " " << model->link(p->b).name << ": " << why << "\n";

  std::map<std::string, int> counts;
  int near = 0;
  for (const PairAudit& p : audit) {
    ++counts[p.reason.empty() ? "checked" : p.reason];
    near += p.near_miss;
  }
  text << model->name() << ": " << audit.size() << " pairs:";
  for (const char* r : {"Adjacent", "Default", "Always", "Never", "checked"}) text << " " << counts[r] << " " << r;
  text << " (" << near << " Never pairs came within 1 mm)\n";
  bool disagrees = false;  // the given SRDF and the audit differ on some pair
  if (!srdf.empty()) {
    int differ = 0;
    for (const PairAudit& p : audit) {
      const auto it = shipped.find({p.a, p.b});
      const std::string theirs = it == shipped.end() ? "" : it->second;
      if (theirs == p.reason) continue;
      ++differ;
      text << "differs: " << model->link(p.a).name << " " << model->link(p.b).name << ": SRDF "
           << (theirs.empty() ? "checked" : theirs) << ", audit " << (p.reason.empty() ? "checked" : p.reason)
           << evidenceText(p) << "\n";
    }
    text << differ << " pairs differ from " << srdf << "\n";
    disagrees = differ > 0;
  }
  if (!srdf_out.empty()) {
    std::string written;
    try {
      written = auditSrdf(*model, audit, srdf_text);
    } catch (const std::exception& e) {
      std::cerr << "clearway audit: " << srdf << ": " << e.what() << "\n";
      return kExitUsage;
    }
    if (srdf_out == "-") {
      std::cout << written << std::flush;
      if (!std::cout) {
        std::cerr << "clearway audit: error writing the SRDF to stdout\n";
        return kExitUsage;
      }
    } else {
      std::ofstream out(srdf_out);
      out << written;
      out.close();
      if (!out) {
        std::cerr << "clearway audit: cannot write " << srdf_out << "\n";
        return kExitUsage;
      }
    }
  }
  if (!report.empty()) {
    std::string why;
    const bool drawn = writeHeatmap(*model, audit, png.string(), why);
    if (!drawn) std::cerr << "clearway audit: no heat map: " << why << "\n";
    std::ofstream out(report);
    out << "# Self-collision audit of " << model->name() << "\n\n" << options.samples << " samples, seed "
        << options.seed << ".\n\n";
    if (drawn) out << "![link-pair matrix](" << png.filename().string() << ")\n\n";
    out << "| link 1 | link 2 | verdict | colliding | samples | p (95% upper) | min clearance (m) |\n"
        << "|---|---|---|---|---|---|---|\n";
    // Warned pairs first (in the order printed), then the rest; unmeasured cells are "-".
    std::vector<const PairAudit*> rows;
    for (const auto& w : warnings) rows.push_back(w.first);
    for (const PairAudit& p : audit)
      if (std::find(rows.begin(), rows.end(), &p) == rows.end()) rows.push_back(&p);
    for (const PairAudit* p : rows) {
      const bool measured = p->samples > 0;
      std::ostringstream pu;
      pu << p->p_upper;
      out << "| " << model->link(p->a).name << " | " << model->link(p->b).name << " | "
          << (p->reason.empty() ? "checked" : p->reason) << (p->near_miss ? " (near)" : "")
          << (std::find_if(warnings.begin(), warnings.end(), [&](const auto& w) { return w.first == p; }) != warnings.end()
                  ? " (warning)" : "")
          << " | " << (measured ? std::to_string(p->colliding) : "-") << " | " << (measured ? std::to_string(p->samples) : "-")
          << " | " << (measured ? pu.str() : "-") << " | " << clearanceText(p->min_clearance) << " |\n";
    }
    if (!out) {
      std::cerr << "clearway audit: cannot write " << report << "\n";
      return kExitUsage;
    }
  }
  if (check && disagrees) {
    std::cerr << "clearway audit: --check: " << srdf << " disagrees with the audit\n";
    return kExitNo;
  }
  return kExitOk;
}

}  // namespace

Subcommand addAuditCommand(CLI::App& root) {
  auto s = std::make_shared<AuditSettings>();
  s->options.threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));  // 0 when unknown
  CLI::App* app = root.add_subcommand(
      "audit", "self-collision audit of a URDF: Adjacent, Default, Always, Never pairs with evidence; SRDF out");
  app->add_option("URDF", s->urdf, "the robot (a file: its meshes are found relative to it)")->required();
  app->add_option("--srdf", s->srdf, "an SRDF to compare with, and to keep all but its disable_collisions of")
      ->type_name("SRDF");
  app->add_flag("--check", s->check, "exit 1 when the --srdf disagrees with the audit (a CI guard)");
  app->add_option("--samples", s->options.samples, "random configurations")->check(wholeNumber(1, 100000000))
      ->capture_default_str();
  addSeedOption(*app, s->options.seed, "the sampler's seed")->capture_default_str();
  app->add_option("--threads", s->options.threads, "threads (default: one per hardware thread)")
      ->check(wholeNumber(1, 1024));
  app->add_option("--srdf-out", s->srdf_out, "write the SRDF here (- for stdout)")->check(fileName())->type_name("FILE|-");
  app->add_option("--report", s->report, "write a Markdown report here, and its heat map beside it")
      ->check(fileName())->type_name("FILE");
  addLoadOptions(*app, s->load);
  app->footer(std::string(kAuditHelp) + kFormatsHelp);
  return {app, [s] { return runAudit(*s); }};
}

}  // namespace clearway::cli
