// The `clearway` tool: one binary, one subcommand per task (DESIGN.md "The `clearway` tool").
// Results go to stdout, reasons, warnings and progress to stderr (--quiet: no warnings or progress). Exit status: 0 success, 1 when some input
// line was bad (the others still ran), 2 on a usage error or an unreadable input.
// A subcommand is a function of its own arguments; adding one is adding a row to kCommands.
#include "query_file.h"
#include "scene_commands.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

namespace {

using Args = std::vector<std::string>;

constexpr int kExitOk = 0;
constexpr int kExitUsage = 2;

bool isHelp(const std::string& a) { return a == "-h" || a == "--help"; }

const char* const kQueryUsage =
    "usage: clearway query FILE.jsonl   (FILE may be - for stdin)\n"
    "\n"
    "Runs narrow-phase queries on shape pairs, one JSON case per line, and prints one JSON result\n"
    "per line in input order. A bad line yields {\"id\", \"line\", \"status\": \"error\", \"error\"} and\n"
    "the next line still runs. Exit status: 0 when every case ran, 1 when any line was an error,\n"
    "2 on a usage error or an unreadable file.\n";

// Results that never reached stdout (a closed pipe, a full disk) must not pass for success.
int finishOutput(int status) {
  std::cout.flush();
  if (!std::cout) {
    std::cerr << "clearway: error writing results to stdout\n";
    return kExitUsage;
  }
  return status;
}

int queryCommand(const Args& args) {
  if (args.size() == 1 && isHelp(args[0])) {
    std::cout << kQueryUsage;
    return kExitOk;
  }
  if (args.size() != 1) {
    std::cerr << "clearway query: expected exactly one FILE argument\n" << kQueryUsage;
    return kExitUsage;
  }
  const std::string& file = args[0];
  if (file == "-") return finishOutput(clearway::runQueryStream(std::cin, std::cout, /*flush_each_line=*/true));
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) {
    std::cerr << "clearway query: cannot read " << file << ": is a directory\n";
    return kExitUsage;
  }
  std::ifstream in(file);
  if (!in) {
    std::cerr << "clearway query: cannot open " << file << ": " << std::strerror(errno) << "\n";
    return kExitUsage;
  }
  const int status = clearway::runQueryStream(in, std::cout);
  if (in.bad()) {
    std::cerr << "clearway query: error while reading " << file << "\n";
    return kExitUsage;
  }
  return finishOutput(status);
}

struct Command {
  const char* name;
  const char* summary;
  int (*run)(const Args& args);
};

const Command kCommands[] = {
    {"plan", "plan start -> goal on a scene with OMPL (a bundled scene when none is given)", clearway::cli::planCommand},
    {"check", "classify joint vectors of a scene: free or which links collide", clearway::cli::checkCommand},
    {"motion", "check joint-space segments of a scene: free, or the last valid fraction", clearway::cli::motionCommand},
    {"audit", "self-collision audit of a URDF: Adjacent, Default, Always, Never pairs with evidence; SRDF out", clearway::cli::auditCommand},
    {"bench", "accuracy against time per suite, mode and tolerance, FCL side by side: CSV, table, plots; shards", clearway::cli::benchCommand},
    {"query", "narrow-phase queries on shape pairs from a JSON Lines file", queryCommand},
};

void printUsage(std::ostream& os) {
  os << "usage: clearway COMMAND [ARGS...]\n"
        "       clearway COMMAND --help\n"
        "       clearway --version\n\ncommands:\n";
  for (const Command& c : kCommands) os << "  " << c.name << std::string(10 - std::strlen(c.name), ' ') << c.summary << "\n";
  os << "\n--quiet (anywhere, any command): no warnings or progress lines on stderr; results and errors stay.\n"
        "Warnings are printed once each.\n";
}

}  // namespace

int main(int argc, char** argv) {
  // --quiet is the one option of every command: taken out here, wherever it stands.
  Args all;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quiet") == 0) clearway::cli::setQuiet(true);
    else all.emplace_back(argv[i]);
  }
  if (all.empty()) {
    printUsage(std::cerr);
    return kExitUsage;
  }
  const std::string name = all[0];
  if (isHelp(name) || name == "help") {
    printUsage(std::cout);
    return kExitOk;
  }
  if (name == "--version") {
    std::cout << "clearway " CLEARWAY_VERSION "\n";
    return finishOutput(kExitOk);
  }
  for (const Command& c : kCommands)
    if (name == c.name) return c.run(Args(all.begin() + 1, all.end()));
  std::cerr << "clearway: unknown command '" << name << "'\n";
  printUsage(std::cerr);
  return kExitUsage;
}
