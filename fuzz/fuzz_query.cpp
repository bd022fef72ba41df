// Narrow-phase query lines (JSON Lines, src/cli/query_file.cpp) as `clearway query` runs them: each line
// parsed, checked and run, its result printed. Documented: runQueryLine throws nothing and reports a bad
// line as an error result; an "unexpected error" result means an exception slipped past the checks,
// which is a finding too.
#include "fuzz_support.h"

#include "cli/query_file.h"

#include <sstream>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace clearway;
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  std::string line;
  for (long line_number = 1; std::getline(in, line); ++line_number) {
    QueryLineResult r;
    try {
      r = runQueryLine(line, line_number);
      // The tool prints every result; invalid UTF-8 echoed from the input is replaced, not thrown.
      r.json.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
    } catch (const std::exception& e) {
      fuzz::finding(std::string("runQueryLine threw: ") + e.what());
    }
    if (r.error && r.json["error"].get<std::string>().rfind("unexpected error", 0) == 0)
      fuzz::finding("runQueryLine: " + r.json["error"].get<std::string>());
  }
  return 0;
}
