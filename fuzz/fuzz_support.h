#pragma once
// What every fuzz target shares: the bytes as a file (the loaders take paths, and pick the format by
// the extension), and the one rule of a finding. A target lets through only the exceptions the API it
// calls documents; anything else is reported here and aborts, so that libFuzzer keeps the input.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <typeinfo>

namespace clearway::fuzz {

/// A private folder of this process (each of libFuzzer's -jobs has its own), removed at exit.
inline const std::filesystem::path& scratchDir() {
  static const std::filesystem::path dir = [] {
    std::string pattern = (std::filesystem::temp_directory_path() / "clearway-fuzz-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) {
      std::perror("clearway fuzz: mkdtemp");
      std::abort();
    }
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(scratchDir(), ec);
    });
    return std::filesystem::path(pattern);
  }();
  return dir;
}

/// Writes the bytes to scratchDir()/name (replacing what an earlier input left there) and returns the path.
inline std::string writeFile(const std::string& name, const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = scratchDir() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  if (!out.flush()) {
    std::fprintf(stderr, "clearway fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
  return path.string();
}

inline std::string writeFile(const std::string& name, const std::string& text) {
  return writeFile(name, reinterpret_cast<const std::uint8_t*>(text.data()), text.size());
}

/// A finding: says what happened, then aborts (libFuzzer saves the input as crash-*).
[[noreturn]] inline void finding(const std::string& what) {
  std::fprintf(stderr, "clearway fuzz finding: %s\n", what.c_str());
  std::abort();
}

/// Runs f and returns true when it returned; an exception of type Documented (what the API promises for
/// bad input) is the expected end of a bad input (false), any other exception a finding.
template <class Documented, class F>
bool expectOnly(const char* call, F&& f) {
  try {
    f();
    return true;
  } catch (const Documented&) {
    return false;
  } catch (const std::exception& e) {
    finding(std::string(call) + " threw an undocumented " + typeid(e).name() + ": " + e.what());
  } catch (...) {
    finding(std::string(call) + " threw something that is not a std::exception");
  }
}

}  // namespace clearway::fuzz
