#pragma once
// The options several commands share, declared once so that every command spells, checks and documents
// them the same way (--geometry, --motion, --seed, the robot-loading options), and the old spellings
// that still work with a warning.
#include <clearway/load/robot_loader.h>
#include <clearway/motion/motion.h>
#include <clearway/scene/scene.h>

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdint>
#include <functional>
#include <string>

namespace clearway::cli {

/// A subcommand's parser (its options bound to its own settings) and what runs it once they are parsed.
struct Subcommand {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

/// Where --help sends readers for the file formats (docs/ in the source tree and the installed package).
extern const char* const kFormatsHelp;

/// `--geometry mesh|hull`; with `mode_alias`, the old `--mode mesh|hull` too (deprecated).
void addGeometryOption(CLI::App& app, GeometryMode& mode, bool mode_alias);

/// `--motion certified|cast|sampled:RES`; with `mode_alias`, the old `--mode` too (deprecated).
void addMotionOption(CLI::App& app, MotionOptions& motion, bool mode_alias);

/// `--seed N`, the tool's one seed parser: a whole number from 0 to 2^64 - 1.
CLI::Option* addSeedOption(CLI::App& app, std::uint64_t& seed, const std::string& what);

/// `--package-path DIR` (repeatable) and `--honour-up-axis`.
void addLoadOptions(CLI::App& app, LoadOptions& load);

/// Accepts a whole number in [lo, hi] and names the range when it rejects one.
CLI::Validator wholeNumber(long long lo, long long hi);

/// Accepts a non-empty file name: "" would name no file, and the output would silently go nowhere.
CLI::Validator fileName();

/// Accepts a finite number above `above` and at most `at_most`, and names the range when it rejects one.
CLI::Validator numberAbove(double above, double at_most = HUGE_VAL);

/// Notes that a deprecated spelling was used; printDeprecations() warns once per spelling.
void noteDeprecated(const std::string& old_spelling, const std::string& new_spelling);

/// Prints the warnings noteDeprecated collected (after parsing, so that --quiet anywhere silences them).
void printDeprecations();

}  // namespace clearway::cli
