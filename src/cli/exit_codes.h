#pragma once
// The exit status of every `clearway` command, in one place. Scripts and CI test these numbers, so they
// keep the meanings the commands have always documented; a command's --help says which cases apply.

namespace clearway::cli {

/// Success: every input line ran, a certified path was found, the SRDF agrees, the benchmark finished.
constexpr int kExitOk = 0;

/// The command ran but the answer is "no": some input line was bad (the others still ran: check, motion,
/// query), no certified path (plan), the SRDF disagrees (audit --check), a benchmark case failed (bench).
constexpr int kExitNo = 1;

/// A usage error (a bad option or argument), an input that cannot be read or loaded, or an output that
/// cannot be written.
constexpr int kExitUsage = 2;

/// The table of the codes above for --help.
constexpr const char* kExitCodesHelp =
    "Exit status: 0 success; 1 the command ran but the answer is no (a bad input line, the others still\n"
    "ran; no certified path; the SRDF disagrees under --check; a benchmark case failed); 2 a usage error,\n"
    "an input that cannot be read or loaded, or an output that cannot be written.\n";

}  // namespace clearway::cli
