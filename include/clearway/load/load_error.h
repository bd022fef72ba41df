#pragma once
// The one exception of the load stage: bad input (a robot or mesh file) named by file, element and reason,
// so that a user can go straight to the offending line.
#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>

namespace clearway {

/// Thrown when a URDF, SRDF or mesh cannot be loaded. what() is "FILE: ELEMENT: REASON"
/// (the element part is left out when the problem concerns the whole file).
class LoadError : public std::runtime_error {
 public:
  /// what() is format(file, element, reason); the three parts are kept as given.
  LoadError(std::string file, std::string element, std::string reason)
      : std::runtime_error(format(file, element, reason)),
        file_(std::move(file)),
        element_(std::move(element)),
        reason_(std::move(reason)) {}

  /// The file at fault, as the caller named it (a URDF, SRDF or mesh path).
  const std::string& file() const noexcept { return file_; }
  /// The element at fault, e.g. "joint 'elbow' (line 12)"; empty when the whole file is at fault.
  const std::string& element() const noexcept { return element_; }
  /// What is wrong, in words.
  const std::string& reason() const noexcept { return reason_; }

  /// The "FILE: ELEMENT: REASON" form also used for load warnings.
  static std::string format(const std::string& file, const std::string& element, const std::string& reason) {
    std::string s = file;
    if (!element.empty()) s += (s.empty() ? "" : ": ") + element;
    return s + (s.empty() ? "" : ": ") + reason;
  }

 private:
  std::string file_, element_, reason_;
};

/// Input text as a message may quote it: control bytes as `\xNN` (a NUL would end the message), cut after
/// max_chars characters with "..." (a reader quoting the rest of a file must not make a megabyte message).
inline std::string inputExcerpt(const std::string& text, std::size_t max_chars = 40) {
  static const char kHex[] = "0123456789ABCDEF";
  std::string out;
  std::size_t shown = 0;  // characters shown, an escape or a UTF-8 sequence counting as one
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto u = static_cast<unsigned char>(text[i]);
    const bool continuation = (u & 0xC0) == 0x80;
    if (!continuation && shown++ == max_chars) return out + "...";
    if (u < 0x20 || u == 0x7F) {
      out += "\\x";
      out += kHex[u >> 4];
      out += kHex[u & 15];
    } else {
      out += text[i];
    }
  }
  return out;
}

}  // namespace clearway
