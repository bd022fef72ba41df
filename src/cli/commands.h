#pragma once
// The subcommands of `clearway`: each adds its parser to the root and returns what runs it (main.cpp).
#include "options.h"

#include <CLI/CLI.hpp>

namespace clearway::cli {

/// `clearway plan [SCENE]`: plans start → goal with OMPL and the certified motion check.
Subcommand addPlanCommand(CLI::App& root);

/// `clearway check SCENE [--states FILE|-]`: one state per line in, one verdict per line out.
Subcommand addCheckCommand(CLI::App& root);

/// `clearway motion SCENE [--motions FILE|-]`: two joint vectors per line in, `free` or `collision F` out.
Subcommand addMotionCommand(CLI::App& root);

/// `clearway audit URDF`: the self-collision audit, an SRDF and a report out.
Subcommand addAuditCommand(CLI::App& root);

/// `clearway query FILE|-`: narrow-phase queries from JSON Lines.
Subcommand addQueryCommand(CLI::App& root);

/// `clearway bench [SUITE...]` and `clearway bench merge`: accuracy against time, CSV, plots, OMPL logs.
Subcommand addBenchCommand(CLI::App& root);

}  // namespace clearway::cli
