#pragma once
// Text placed in the gnuplot scripts the tool writes (audit's heat map, bench's plots): every string
// that reaches a script goes through one of these two.
#include <string>

namespace clearway::cli {

/// `text` from an input file (a robot, link, engine or mode name) made inert in a gnuplot script: each
/// character outside [A-Za-z0-9 _.,:+-/()] becomes '?'. The result may stand in a comment or inside '…'
/// or "…".
inline std::string gnuplotSafeText(const std::string& text) {
  // Input files come from anywhere (a URDF off the internet, a shard's results.csv). A quote or a newline
  // would end the string or line the text stands in and make the rest a command (gnuplot's `system`); a
  // backquote runs one inside "…"; a backslash escapes a quote or continues a line. No escaping covers
  // every context, so only characters that mean nothing to gnuplot pass.
  std::string out = text;
  for (char& c : out) {
    const bool safe = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      std::string(" _.,:+-/()").find(c) != std::string::npos;
    if (!safe) c = '?';
  }
  return out;
}

/// `name` (a file the user names) as a gnuplot single-quoted string naming exactly that file, ' doubled
/// as gnuplot reads it; false when it holds a control character, which no such string can hold.
inline bool gnuplotFileName(const std::string& name, std::string& literal) {
  literal = "'";
  for (char c : name) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return false;
    // Inside '…' gnuplot expands nothing (no backquotes, no escapes, no macros): only ' needs doubling.
    literal += c == '\'' ? std::string("''") : std::string(1, c);
  }
  literal += "'";
  return true;
}

}  // namespace clearway::cli
