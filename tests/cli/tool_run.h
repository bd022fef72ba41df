#pragma once
// Runs the built clearway tool (CLEARWAY_TOOL_PATH) with arguments and captures its exit status, stdout
// and stderr, for the tests of its subcommands.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>

/// Expects `text` to contain `key`, showing the whole text when it does not.
#define EXPECT_MENTIONS(text, key) EXPECT_NE((text).find(key), std::string::npos) << "\"" << (text) << "\" should name " << (key)

namespace clearway_test {
struct ToolRun {
  int exit_code;
  std::string out, err;
};
inline std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}
inline ToolRun runTool(const std::string& args) {
  // CTest runs tests in parallel processes: name the capture files after this process.
  const std::string stem = testing::TempDir() + "clearway_query_" + std::to_string(::getpid());
  const std::string out = stem + ".out", err = stem + ".err";
  const int raw = std::system((std::string("'") + CLEARWAY_TOOL_PATH + "' " + args + " >'" + out + "' 2>'" + err + "'").c_str());
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, slurp(out), slurp(err)};
}
}  // namespace clearway_test
