// `clearway query FILE|-`: narrow-phase queries on shape pairs, one JSON case per line (docs/query-format.md).
#include "commands.h"
#include "exit_codes.h"
#include "query_file.h"
#include "scene_commands.h"

#include <iostream>
#include <memory>

namespace clearway::cli {

namespace {

const char* const kQueryHelp =
    "Runs narrow-phase queries on shape pairs, one JSON case per line (docs/query-format.md), and prints\n"
    "one JSON result per line in input order. A bad line yields {\"id\", \"line\", \"status\": \"error\",\n"
    "\"error\"} and the next line still runs.\n"
    "Exit status: 0 when every case ran, 1 when any line was an error, 2 on a usage error or an\n"
    "unreadable file.\n";

// Results that never reached stdout (a closed pipe, a full disk) must not pass for success.
int finishOutput(int status) {
  std::cout.flush();
  if (!std::cout) {
    std::cerr << "clearway query: error writing results to stdout\n";
    return kExitUsage;
  }
  return status;
}

int runQuery(const std::string& file) {
  std::ifstream in;
  std::istream* input = openInput("query", file, in);
  if (!input) return kExitUsage;
  // From a pipe, each result goes out as soon as its line is read (an interactive or streaming caller).
  const int status = runQueryStream(*input, std::cout, /*flush_each_line=*/file == "-");
  if (input->bad()) {
    std::cerr << "clearway query: error while reading " << file << "\n";
    return kExitUsage;
  }
  return finishOutput(status);
}

}  // namespace

Subcommand addQueryCommand(CLI::App& root) {
  auto file = std::make_shared<std::string>();
  CLI::App* app = root.add_subcommand("query", "narrow-phase queries on shape pairs from a JSON Lines file");
  app->add_option("FILE", *file, "the query file (JSON Lines; - for stdin)")->required()->type_name("FILE|-");
  app->footer(std::string(kQueryHelp) + kFormatsHelp);
  return {app, [file] { return runQuery(*file); }};
}

}  // namespace clearway::cli
