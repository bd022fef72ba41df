#pragma once
// What the subcommands share: warnings and --quiet, loading a scene, reading input lines, gnuplot.
#include <clearway/load/robot_loader.h>
#include <clearway/scene/scene.h>

#include <fstream>
#include <istream>
#include <memory>
#include <string>
#include <vector>

namespace clearway::cli {

/// Runs gnuplot on `script` inside the script's folder (so the outputs it names land beside it). False,
/// with `why`, when gnuplot is not installed or fails; the script stays for the user to run.
bool runGnuplot(const std::string& script, std::string& why);

/// True after `--quiet` (an option of the root, accepted after any command): warnings and progress lines
/// are not printed; results and errors still are.
bool quiet();
void setQuiet(bool on);

/// Prints "warning: TEXT" on stderr, once per distinct text in a run (a robot loaded twice warns once);
/// nothing when quiet().
void printWarning(const std::string& text);

/// Scene::load, or for "-" the scene read from stdin (its relative paths from the working directory).
/// Throws LoadError.
std::shared_ptr<const Scene> openScene(const std::string& path, const SceneOptions& options);

/// openScene, printing the robot's load warnings; on failure prints "clearway COMMAND: reason" and
/// returns null.
std::shared_ptr<const Scene> loadScene(const char* command, const std::string& path, const SceneOptions& options);

/// Standard input for "-", else `file` opened on path; null (with a message) when it cannot be opened
/// or is a folder.
std::istream* openInput(const char* command, const std::string& path, std::ifstream& file);

/// Reads the next line of `in` into `line` (without its newline); false at the end of the input, or with
/// `error` set when the input cannot be read or a line exceeds max_bytes (/dev/zero has no end of line):
/// a command then says so and fails instead of stopping early as if every line had run.
bool readInputLine(std::istream& in, std::string& line, std::string& error, std::size_t max_bytes = std::size_t{1} << 24);

/// Parses a line of numbers separated by spaces, tabs or commas; false (and `why`) on anything else.
bool parseNumbers(const std::string& line, std::vector<double>& out, std::string& why);

}  // namespace clearway::cli
