#include "scene_commands.h"

#include <clearway/scene/scene.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <new>
#include <set>
#include <sstream>

namespace clearway::cli {

namespace {

bool quiet_mode = false;

}  // namespace

bool quiet() { return quiet_mode; }
void setQuiet(bool on) { quiet_mode = on; }

void printWarning(const std::string& text) {
  static std::set<std::string> printed;  // the tool is one thread while it loads
  if (!quiet_mode && printed.insert(text).second) std::cerr << "warning: " << text << "\n";
}

std::shared_ptr<const Scene> openScene(const std::string& path, const SceneOptions& options) {
  if (path != "-") return Scene::load(path, options);
  std::ostringstream text;
  text << std::cin.rdbuf();
  return std::make_shared<const Scene>(parseSceneText(text.str(), "<stdin>", std::filesystem::current_path().string()), options);
}

std::shared_ptr<const Scene> loadScene(const char* command, const std::string& path, const SceneOptions& options) {
  try {
    auto scene = openScene(path, options);
    for (const std::string& w : scene->description().warnings) printWarning(w);
    for (const std::string& w : scene->robot().loadWarnings()) printWarning(w);
    return scene;
  } catch (const std::bad_alloc&) {  // (its what() names neither the file nor the reason)
    std::cerr << "clearway " << command << ": " << path << ": not enough memory to load the scene\n";
    return nullptr;
  } catch (const std::exception& e) {
    std::cerr << "clearway " << command << ": " << e.what() << "\n";
    return nullptr;
  }
}

bool readInputLine(std::istream& in, std::string& line, std::string& error, std::size_t max_bytes) {
  line.clear();
  errno = 0;  // what a failed read leaves: the stream buffer reports it as an end of input
  std::streambuf* buffer = in.rdbuf();
  for (;;) {
    int c = std::char_traits<char>::eof();
    try {
      c = buffer->sbumpc();
    } catch (const std::exception& e) {  // a stream set to throw, or a filebuf that does
      error = std::string("cannot read the input: ") + e.what();
      return false;
    }
    if (c == std::char_traits<char>::eof()) {
      // The end of the input, or a read error that the stream buffer reports only as an end.
      if (errno == EIO || errno == ENOMEM || errno == EISDIR) error = std::string("cannot read the input: ") + std::strerror(errno);
      in.setstate(std::ios::eofbit);
      return !line.empty() && error.empty();
    }
    if (c == '\n') return true;
    if (line.size() >= max_bytes) {
      error = "a line longer than " + std::to_string(max_bytes) + " bytes (no end of line): not a list of states";
      return false;
    }
    line.push_back(static_cast<char>(c));
  }
}

std::istream* openInput(const char* command, const std::string& path, std::ifstream& file) {
  if (path == "-") return &std::cin;
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    std::cerr << "clearway " << command << ": cannot read " << path << ": is a directory\n";
    return nullptr;
  }
  file.open(path);
  if (!file) {
    std::cerr << "clearway " << command << ": cannot open " << path << ": " << std::strerror(errno) << "\n";
    return nullptr;
  }
  return &file;
}

bool parseNumbers(const std::string& line, std::vector<double>& out, std::string& why) {
  out.clear();
  const char* p = line.c_str();
  // A comma stands between two numbers: "1,,2" or ",1" is a value left out, not a separator repeated.
  bool comma_due = false;  // a comma since the last number
  const auto emptyField = [&] {
    why = "an empty field at column " + std::to_string(p - line.c_str() + 1) + " (a comma needs a number on each side)";
    return false;
  };
  while (true) {
    while (*p == ' ' || *p == '\t' || *p == ',' || *p == '\r') {
      if (*p == ',') {
        if (out.empty() || comma_due) return emptyField();
        comma_due = true;
      }
      ++p;
    }
    if (*p == '\0' || *p == '#') return comma_due ? emptyField() : true;
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(p, &end);
    if (end == p) {
      why = "not a number: '" + std::string(p, std::strcspn(p, " \t,")) + "'";
      return false;
    }
    if (*end != '\0' && *end != ' ' && *end != '\t' && *end != ',' && *end != '\r' && *end != '#') {
      why = "not a number: '" + std::string(p, std::strcspn(p, " \t,")) + "'";
      return false;
    }
    out.push_back(v);
    comma_due = false;
    p = end;
  }
}

bool runGnuplot(const std::string& script, std::string& why) {
  if (std::system("command -v gnuplot >/dev/null 2>&1") != 0) {
    why = "gnuplot is not installed (" + script + " written)";
    return false;
  }
  // Single-quoted for the shell: a quote inside becomes '\''.
  auto shell = [](const std::string& s) {
    std::string out = "'";
    for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
  };
  const std::filesystem::path path(script);
  const std::string dir = path.has_parent_path() ? path.parent_path().string() : ".";
  if (std::system(("cd " + shell(dir) + " && gnuplot " + shell(path.filename().string()) + " 2>/dev/null").c_str()) != 0) {
    why = "gnuplot failed on " + script;
    return false;
  }
  return true;
}

}  // namespace clearway::cli
