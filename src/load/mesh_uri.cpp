#include "load/mesh_uri.h"

#include <clearway/load/load_error.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <system_error>

namespace clearway::detail {
namespace {

namespace fs = std::filesystem;

// How deep below a search path a package folder (one with a package.xml) is looked for.
constexpr int kPackageSearchDepth = 3;

bool startsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

std::vector<std::string> splitPathList(const char* list) {
  std::vector<std::string> out;
  if (list == nullptr) return out;
  std::string item;
  for (const char* p = list;; ++p) {
    if (*p == ':' || *p == '\0') {
      if (!item.empty()) out.push_back(item);
      item.clear();
      if (*p == '\0') break;
    } else {
      item += *p;
    }
  }
  return out;
}

// %XX escapes of a URI path.
std::string percentDecode(const std::string& s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(static_cast<unsigned char>(s[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(s[i + 2]))) {
      out += static_cast<char>(std::stoi(s.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

bool isDirectory(const fs::path& p) {
  std::error_code ec;
  return fs::is_directory(p, ec);
}

// The folder of package name under search path root, or empty.
fs::path findPackage(const fs::path& root, const std::string& name, bool search_below) {
  if (!isDirectory(root)) return {};
  if (root.filename() == name) return root;
  if (isDirectory(root / name)) return root / name;
  if (isDirectory(root / "share" / name)) return root / "share" / name;
  if (!search_below) return {};
  std::error_code ec;
  fs::recursive_directory_iterator it(root, fs::directory_options::skip_permission_denied, ec), end;
  for (; !ec && it != end; it.increment(ec)) {
    if (it.depth() >= kPackageSearchDepth) it.disable_recursion_pending();
    if (!it->is_directory(ec)) continue;
    if (it->path().filename() == name && fs::exists(it->path() / "package.xml", ec)) return it->path();
  }
  return {};
}

}  // namespace

std::string controlCharacterReason(const std::string& path, const std::string& note) {
  for (std::size_t i = 0; i < path.size(); ++i) {
    const auto u = static_cast<unsigned char>(path[i]);
    if (u < 0x20 || u == 0x7F)
      return "the path" + note + " holds the control character " + inputExcerpt(path.substr(i, 1)) + " (byte " +
             std::to_string(i + 1) + "): refused, as the file opened could be another than the one named";
  }
  return "";
}

ResolvedUri resolveMeshUri(const std::string& uri, const std::string& urdf_dir,
                           const std::vector<std::string>& package_paths) {
  ResolvedUri r;
  r.error = controlCharacterReason(uri);
  if (!r.error.empty()) return r;
  if (startsWith(uri, "package://")) {
    const std::string rest = uri.substr(std::string("package://").size());
    const std::size_t slash = rest.find('/');
    const std::string name = rest.substr(0, slash);
    const std::string inside = slash == std::string::npos ? "" : rest.substr(slash + 1);
    if (name.empty() || inside.empty()) {
      r.error = "malformed package URI (expected package://NAME/PATH)";
      return r;
    }
    fs::path package;
    for (const std::string& p : package_paths)
      if (package.empty()) package = findPackage(p, name, true);
    for (const std::string& p : splitPathList(std::getenv("ROS_PACKAGE_PATH")))
      if (package.empty()) package = findPackage(p, name, true);
    for (const std::string& p : splitPathList(std::getenv("AMENT_PREFIX_PATH")))
      if (package.empty() && isDirectory(fs::path(p) / "share" / name)) package = fs::path(p) / "share" / name;
    if (package.empty()) {
      r.error = "unresolved package://" + name + ": no package '" + name +
                "' in the search paths given, ROS_PACKAGE_PATH or AMENT_PREFIX_PATH";
      return r;
    }
    r.path = (package / inside).lexically_normal().string();
    return r;
  }
  if (startsWith(uri, "file://")) {
    std::string rest = uri.substr(std::string("file://").size());
    if (startsWith(rest, "localhost/")) rest = rest.substr(std::string("localhost").size());
    if (!startsWith(rest, "/")) {
      r.error = "file:// URI without an absolute path (expected file:///PATH)";
      return r;
    }
    r.path = percentDecode(rest);
    r.error = controlCharacterReason(r.path, " (its %XX escapes decoded)");
    if (!r.error.empty()) r.path.clear();
    return r;
  }
  const std::size_t scheme = uri.find("://");
  if (scheme != std::string::npos) {
    r.error = "unsupported URI scheme '" + uri.substr(0, scheme) + "://' (use a path, file:// or package://)";
    return r;
  }
  const fs::path p(uri);
  r.path = (p.is_absolute() ? p : fs::path(urdf_dir) / p).lexically_normal().string();
  return r;
}

std::FILE* openRegularFile(const std::string& path, std::string* reason) {
  // Non-blocking, so that opening a FIFO returns at once (a blocking open waits for a writer); what was
  // opened is examined before anything is read from it.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    *reason = std::string("cannot open the file: ") + std::strerror(errno);
    return nullptr;
  }
  struct stat st {};
  const char* kind = nullptr;
  if (::fstat(fd, &st) != 0) kind = "it cannot be examined";
  else if (S_ISFIFO(st.st_mode)) kind = "a FIFO";
  else if (S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode)) kind = "a device";
  else if (S_ISDIR(st.st_mode)) kind = "a folder";
  else if (S_ISSOCK(st.st_mode)) kind = "a socket";
  else if (!S_ISREG(st.st_mode)) kind = "of an unknown kind";
  const int flags = kind == nullptr ? ::fcntl(fd, F_GETFL) : -1;
  std::FILE* file = flags >= 0 && ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) == 0 ? ::fdopen(fd, "rb") : nullptr;
  if (file == nullptr) {
    const int error = errno;
    ::close(fd);
    *reason = kind != nullptr ? std::string("not a regular file (") + kind +
                                    "): only regular files are read, as a FIFO or a device may block or never end"
                              : std::string("cannot open the file: ") + std::strerror(error);
  }
  return file;
}

std::string readRegularFile(const std::string& path) {
  std::string reason;
  std::FILE* file = openRegularFile(path, &reason);
  if (file == nullptr) throw LoadError(path, "", reason);
  std::string bytes;
  char buffer[1 << 16];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, file)) > 0;) bytes.append(buffer, n);
  const bool failed = std::ferror(file) != 0;
  std::fclose(file);
  if (failed) throw LoadError(path, "", "cannot read the file");
  return bytes;
}

}  // namespace clearway::detail
