#pragma once
// Subcommands that work on a scene file: check (states), and later motion and plan.
#include <string>
#include <vector>

namespace clearway::cli {

/// `clearway check SCENE [--states FILE] [--mode mesh|hull]`: one state per line in, one verdict per line out.
int checkCommand(const std::vector<std::string>& args);

/// `clearway plan [SCENE] ...`: plans start → goal with OMPL and the certified motion check.
int planCommand(const std::vector<std::string>& args);

/// Parses a line of numbers separated by spaces, tabs or commas; false (and `why`) on anything else.
bool parseNumbers(const std::string& line, std::vector<double>& out, std::string& why);

}  // namespace clearway::cli
