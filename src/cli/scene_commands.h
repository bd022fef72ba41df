#pragma once
// Subcommands that work on a scene file: check (states), motion (segments) and plan.
#include <clearway/load/robot_loader.h>
#include <clearway/scene/scene.h>

#include <fstream>
#include <istream>
#include <memory>
#include <string>
#include <vector>

namespace clearway::cli {

/// `clearway check SCENE [--states FILE] [--mode mesh|hull]`: one state per line in, one verdict per line out.
int checkCommand(const std::vector<std::string>& args);

/// `clearway plan [SCENE] ...`: plans start → goal with OMPL and the certified motion check.
int planCommand(const std::vector<std::string>& args);

/// `clearway motion SCENE [--motions FILE] [--mode certified|sampled:RES]`: two joint vectors per line in,
/// `free` or `collision F` (F the last valid fraction) out.
int motionCommand(const std::vector<std::string>& args);

/// `clearway audit URDF [--srdf S] [--samples N] [--seed N] [--srdf-out FILE] [--report FILE]`.
int auditCommand(const std::vector<std::string>& args);

/// `clearway bench [SUITE...] [--shard I/N] ...` and `clearway bench merge`: accuracy against time, CSV,
/// table, plots and OMPL logs (see bench_command.cpp).
int benchCommand(const std::vector<std::string>& args);

/// Runs gnuplot on `script` inside the script's folder (so the outputs it names land beside it). False,
/// with `why`, when gnuplot is not installed or fails; the script stays for the user to run.
bool runGnuplot(const std::string& script, std::string& why);

/// The usage lines of the options that every command loading a robot takes (parseLoadOption).
extern const char* const kLoadOptionsUsage;

/// Reads a robot-loading option at args[i] (--package-path DIR, repeatable; --honour-up-axis). True when args[i] was one
/// (i is then at its last word), with `error` set when it is malformed; false for any other argument.
bool parseLoadOption(const std::vector<std::string>& args, std::size_t& i, LoadOptions& options, std::string& error);

/// True after `--quiet` (main.cpp takes it from any command's arguments): warnings and progress lines
/// are not printed; results and errors still are.
bool quiet();
void setQuiet(bool on);

/// Prints "warning: TEXT" on stderr, once per distinct text in a run (a robot loaded twice warns once);
/// nothing when quiet().
void printWarning(const std::string& text);

/// Scene::load, printing the robot's load warnings; on failure prints "clearway COMMAND: reason" and
/// returns null.
std::shared_ptr<const Scene> loadScene(const char* command, const std::string& path, const SceneOptions& options);

/// Standard input for "-", else `file` opened on path; null (with a message) when it cannot be opened.
std::istream* openInput(const char* command, const std::string& path, std::ifstream& file);

/// Parses a line of numbers separated by spaces, tabs or commas; false (and `why`) on anything else.
bool parseNumbers(const std::string& line, std::vector<double>& out, std::string& why);

}  // namespace clearway::cli
