// The `clearway` tool: one binary, one subcommand per task, one argument parser (CLI11) for them all.
// Results go to stdout; reasons, warnings and progress to stderr (--quiet: no warnings or progress).
// Exit statuses are those of exit_codes.h. Adding a command is adding an add*Command (commands.h).
#include "commands.h"
#include "exit_codes.h"
#include "scene_commands.h"

#include <CLI/CLI.hpp>

#include <iostream>
#include <string>
#include <vector>

namespace {

using namespace clearway::cli;

// "clearway plan", "clearway bench merge": the deepest command the parser reached, for messages.
std::string commandName(const CLI::App& root) {
  std::string name = "clearway";
  const CLI::App* app = &root;
  while (!app->get_subcommands().empty()) {
    app = app->get_subcommands().front();
    name += " " + app->get_name();
  }
  return name;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App root("Clearway: certified collision checking for motion planning.", "clearway");
  // Set before the subcommands are added, which inherit it: the root's --quiet and --version are then
  // accepted after any command too.
  root.fallthrough();
  // An option given twice takes its last value, as the hand-written parsers did: scripts that append
  // "$@" after their defaults (scripts/main.sh) may override them. Lists opt out (TakeAll).
  root.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  root.set_version_flag("--version", "clearway " CLEARWAY_VERSION, "print the version and exit");
  bool quiet_flag = false;
  root.add_flag("--quiet", quiet_flag, "no warnings or progress lines on stderr (results and errors stay)");
  root.require_subcommand(1);
  root.footer(std::string("Run 'clearway COMMAND --help' for a command's options and input formats.\n"
                          "Options take their value as --opt VALUE or --opt=VALUE; a FILE given as - is stdin\n"
                          "(stdout for an output). Warnings are printed once each.\n") +
              kFormatsHelp + kExitCodesHelp);
  const std::vector<Subcommand> commands = {addPlanCommand(root),  addCheckCommand(root), addMotionCommand(root),
                                            addAuditCommand(root), addBenchCommand(root), addQueryCommand(root)};
  if (argc < 2) {
    std::cerr << root.help();
    return kExitUsage;
  }
  try {
    root.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return root.exit(e);  // help on stdout, status 0
  } catch (const CLI::CallForAllHelp& e) {
    return root.exit(e);
  } catch (const CLI::CallForVersion& e) {
    std::cout << e.what() << std::endl;
    return std::cout ? kExitOk : kExitUsage;
  } catch (const CLI::ParseError& e) {
    const std::string name = commandName(root);
    // A first word that is no command reaches the parser as an extra argument: say which.
    const std::vector<std::string> rest = root.remaining();
    if (name == "clearway" && !rest.empty() && rest.front().rfind("-", 0) != 0)
      std::cerr << "clearway: unknown command '" << rest.front() << "'\n";
    else
      std::cerr << name << ": " << e.what() << "\n";
    std::cerr << "usage: " << name << (name == "clearway" ? " COMMAND" : "") << " [OPTIONS]...; run '" << name
              << " --help' for more\n";
    return kExitUsage;
  }
  setQuiet(quiet_flag);
  printDeprecations();
  for (const Subcommand& c : commands)
    if (c.app->parsed()) return c.run();
  return kExitUsage;  // (require_subcommand makes this unreachable)
}
