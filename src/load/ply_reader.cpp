// PLY → vertices and triangles. The header is read line by line; the data by one cursor that knows
// where each value lies (ASCII: one element instance per line, values separated by spaces or tabs;
// binary: the declared sizes, in the declared byte order). Every loop over an element's instances or a
// list's values consumes at least one byte or one token per step, or throws: it ends with the file.
#include "load/ply_reader.h"
#include "load/mesh_uri.h"

#include <clearway/load/load_error.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <limits>
#include <string_view>
#include <system_error>

namespace clearway::detail {
namespace {

// A turn smaller than this fraction of its two edges' product counts as straight (rounding of float
// corners), when telling convex polygons and crossing edges.
constexpr double kStraight = 1e-12;

enum class Type { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64, None };

Type typeNamed(const std::string& t) {
  if (t == "char" || t == "int8") return Type::Int8;
  if (t == "uchar" || t == "uint8") return Type::UInt8;
  if (t == "short" || t == "int16") return Type::Int16;
  if (t == "ushort" || t == "uint16") return Type::UInt16;
  if (t == "int" || t == "int32") return Type::Int32;
  if (t == "uint" || t == "uint32") return Type::UInt32;
  if (t == "float" || t == "float32") return Type::Float32;
  if (t == "double" || t == "float64") return Type::Float64;
  return Type::None;
}

std::size_t sizeOf(Type t) {
  switch (t) {
    case Type::Int8: case Type::UInt8: return 1;
    case Type::Int16: case Type::UInt16: return 2;
    case Type::Int32: case Type::UInt32: case Type::Float32: return 4;
    case Type::Float64: return 8;
    default: return 0;
  }
}

bool isInteger(Type t) { return t != Type::Float32 && t != Type::Float64; }

struct Property {
  std::string name;
  bool list = false;
  Type count = Type::None, item = Type::None;
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
  long line = 0;
};

enum class Format { Ascii, Little, Big };

std::vector<std::string> words(std::string_view line) {
  std::vector<std::string> out;
  std::size_t i = 0;
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; };
  while (i < line.size()) {
    while (i < line.size() && space(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !space(line[i])) ++i;
    if (i > start) out.emplace_back(line.substr(start, i - start));
  }
  return out;
}

// A whole token as a number of the given kind (an integer for integer types, whatever its size: assimp
// reads 300 for a uchar as 300); false when the token is not one. A float beyond the type's range is
// ±∞ or ±0, as strtod gives it (a coordinate's ∞ is refused later, naming the vertex).
bool parse(const std::string& token, Type type, double* value) {
  const char* first = token.data();
  const char* last = first + token.size();
  const bool minus = first != last && *first == '-';
  if (last - first > 1 && *first == '+' && (std::isdigit(static_cast<unsigned char>(first[1])) || first[1] == '.')) ++first;
  if (isInteger(type)) {
    std::int64_t v = 0;
    const auto [end, ec] = std::from_chars(first, last, v);
    if (ec != std::errc() || end != last) return false;
    *value = static_cast<double>(v);
    return true;
  }
  const auto outOfRange = [&] {
    const bool tiny = token.find("e-") != std::string::npos || token.find("E-") != std::string::npos;
    *value = (minus ? -1.0 : 1.0) * (tiny ? 0.0 : std::numeric_limits<double>::infinity());
    return true;
  };
  if (type == Type::Float32) {  // rounded once, to the float the file declares
    float v = 0.0f;
    const auto [end, ec] = std::from_chars(first, last, v);
    if (end != last || (ec != std::errc() && ec != std::errc::result_out_of_range)) return false;
    if (ec == std::errc::result_out_of_range) return outOfRange();
    *value = v;
    return true;
  }
  const auto [end, ec] = std::from_chars(first, last, *value);
  if (end != last || (ec != std::errc() && ec != std::errc::result_out_of_range)) return false;
  return ec == std::errc::result_out_of_range ? outOfRange() : true;
}

// A name as messages show it (and as it is kept: no name PLY or Clearway looks for is longer).
std::string shown(const std::string& name) { return inputExcerpt(name); }

const char* kTypeList = "char, uchar, short, ushort, int, uint, float, double, int8, uint8, int16, uint16, int32, "
                        "uint32, float32 or float64";

class Reader {
 public:
  Reader(std::string path, std::vector<std::string>* warnings) : path_(std::move(path)), warnings_(warnings) {}

  PlyMesh read() {
    bytes_ = readRegularFile(path_);
    readHeader();
    for (std::size_t e = 0; e < elements_.size(); ++e) readElement(e);
    return finish();
  }

 private:
  void warn(const std::string& where, const std::string& reason) {
    if (warnings_) warnings_->push_back(LoadError::format(path_, where, reason));
  }
  static std::string lineName(long n) { return "line " + std::to_string(n); }

  // The header, up to the byte after end_header's line end (at_).
  void readHeader() {
    bool have_format = false;
    for (long number = 1;; ++number) {
      const std::size_t end = bytes_.find('\n', at_);
      if (end == std::string::npos) {
        const std::vector<std::string> last = words(std::string_view(bytes_).substr(at_));
        if (!last.empty() && last[0] == "end_header")
          throw LoadError(path_, lineName(number), "the PLY header's 'end_header' line has no line end (the file ends there)");
        throw LoadError(path_, "", "the PLY header has no 'end_header' line");
      }
      const std::vector<std::string> w = words(std::string_view(bytes_).substr(at_, end - at_));
      at_ = end + 1;
      line_ = number + 1;
      if (number == 1) {
        std::string first = w.size() == 1 ? w[0] : "";
        for (char& c : first) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        if (first != "ply") throw LoadError(path_, lineName(1), "not a PLY file: the first line is not 'ply'");
        continue;
      }
      if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
      const std::string where = lineName(number);
      if (w[0] == "end_header") {
        if (!have_format) throw LoadError(path_, where, "the PLY header has no 'format' line");
        if (unknown_lines_ > kWarnedLines)
          warn("", std::to_string(unknown_lines_ - kWarnedLines) + " more header lines that are not PLY skipped");
        return;
      }
      if (w[0] == "format") {
        if (w.size() < 2 || (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian"))
          throw LoadError(path_, where, "the format is not ascii, binary_little_endian or binary_big_endian");
        format_ = w[1] == "ascii" ? Format::Ascii : w[1] == "binary_little_endian" ? Format::Little : Format::Big;
        have_format = true;
      } else if (w[0] == "element") {
        readElementLine(w, number);
      } else if (w[0] == "property") {
        readPropertyLine(w, where);
      } else {
        if (++unknown_lines_ <= kWarnedLines) warn(where, "header line '" + shown(w[0]) + "' is not PLY; skipped");
      }
    }
  }

  void readElementLine(const std::vector<std::string>& w, long number) {
    const std::string where = lineName(number);
    if (w.size() < 3) throw LoadError(path_, where, "'element' needs a name and a count");
    const std::string& count = w[2];
    std::uint64_t n = 0;
    const bool digits = std::all_of(count.begin(), count.end(), [](char c) { return c >= '0' && c <= '9'; });
    for (std::size_t i = 0; digits && i < count.size() && n <= bytes_.size(); ++i) n = 10 * n + static_cast<std::uint64_t>(count[i] - '0');
    if (!digits) throw LoadError(path_, where, "element '" + shown(w[1]) + "' has count '" + shown(count) + "', not a whole number");
    // Every instance takes at least one byte (see readElement): a larger count cannot be the file's.
    if (n > bytes_.size())
      throw LoadError(path_, where, "element '" + shown(w[1]) + "' has " + shown(count) +
                                        " instances, more than the file has bytes (" + std::to_string(bytes_.size()) + ")");
    const bool faces = w[1] == "face" || w[1] == "tristrips";
    if (n > 0 && (w[1] == "vertex" || faces)) {
      long& first = w[1] == "vertex" ? vertex_line_ : face_line_;
      if (first != 0) {
        if (w[1] == "vertex")
          throw LoadError(path_, where, "a second 'element vertex' (the first is on line " + std::to_string(first) +
                                            "): Clearway reads one vertex list per PLY file");
        throw LoadError(path_, where, "a second face list 'element " + w[1] + "' (the first, 'element " +
                                          elements_[face_element_].name + "', is on line " + std::to_string(first) +
                                          "): Clearway reads one face list per PLY file");
      }
      first = number;
      (w[1] == "vertex" ? vertex_element_ : face_element_) = elements_.size();
    }
    elements_.push_back({shown(w[1]), n, {}, number});
  }

  void readPropertyLine(const std::vector<std::string>& w, const std::string& where) {
    if (elements_.empty()) {
      if (++unknown_lines_ <= kWarnedLines) warn(where, "a property before any element; skipped");
      return;
    }
    Property p;
    p.list = w.size() > 1 && w[1] == "list";
    const std::size_t need = p.list ? 5 : 3;
    if (w.size() < need)
      throw LoadError(path_, where, p.list ? "'property list' needs a count type, an item type and a name"
                                           : "'property' needs a type and a name");
    p.name = shown(w[need - 1]);
    const std::size_t first_type = p.list ? 2 : 1;
    for (std::size_t k = first_type; k < need - 1; ++k) {
      const Type t = typeNamed(w[k]);
      if (t == Type::None)
        throw LoadError(path_, where, "property '" + p.name + "' has type '" + shown(w[k]) +
                                          "', which PLY does not define (" + kTypeList + ")");
      if (p.list && k == first_type && !isInteger(t))
        throw LoadError(path_, where, "list '" + p.name + "' is counted by a " + shown(w[k]) +
                                          ", not by an integer type");
      (p.list && k == first_type ? p.count : p.item) = t;
    }
    elements_.back().properties.push_back(p);
  }

  // The next instance's values on an ASCII line (blank lines skipped), or false at the end of the file.
  bool nextLine() {
    while (at_ < bytes_.size()) {
      const std::size_t end = std::min(bytes_.find('\n', at_), bytes_.size());
      tokens_ = words(std::string_view(bytes_).substr(at_, end - at_));
      at_ = end + 1;
      token_line_ = line_++;
      next_token_ = 0;
      if (!tokens_.empty()) return true;
    }
    return false;
  }

  std::string instanceName(const Element& e, std::uint64_t i) const { return e.name + " " + std::to_string(i); }

  // One value of the given type at the cursor. Values nothing reads (`used` false) need only be there:
  // assimp skips what it does not know, whatever it holds.
  double value(Type type, const Element& e, std::uint64_t i, const Property& p, bool used = true) {
    if (format_ == Format::Ascii) {
      if (next_token_ >= tokens_.size())
        throw LoadError(path_, lineName(token_line_), instanceName(e, i) + " ends before its property '" + p.name + "'");
      const std::string& token = tokens_[next_token_++];
      double v = 0.0;
      if (used && !parse(token, type, &v))
        throw LoadError(path_, lineName(token_line_), "'" + shown(token) + "' (property '" + p.name + "' of " +
                                                          instanceName(e, i) + ") is not " +
                                                          (isInteger(type) ? "an integer" : "a number"));
      return v;
    }
    const std::size_t n = sizeOf(type);
    if (bytes_.size() - std::min(bytes_.size(), at_) < n)
      throw LoadError(path_, "byte " + std::to_string(at_),
                      "the file ends inside " + instanceName(e, i) + " (property '" + p.name + "')");
    unsigned char b[8];
    std::memcpy(b, bytes_.data() + at_, n);
    at_ += n;
    if ((format_ == Format::Big) == littleEndianMachine()) std::reverse(b, b + n);
    return decode(type, b);
  }

  static bool littleEndianMachine() {
    const std::uint16_t one = 1;
    unsigned char first = 0;
    std::memcpy(&first, &one, 1);
    return first == 1;
  }

  static double decode(Type type, const unsigned char* b) {
    switch (type) {
      case Type::Int8: { std::int8_t v; std::memcpy(&v, b, 1); return v; }
      case Type::UInt8: return b[0];
      case Type::Int16: { std::int16_t v; std::memcpy(&v, b, 2); return v; }
      case Type::UInt16: { std::uint16_t v; std::memcpy(&v, b, 2); return v; }
      case Type::Int32: { std::int32_t v; std::memcpy(&v, b, 4); return v; }
      case Type::UInt32: { std::uint32_t v; std::memcpy(&v, b, 4); return v; }
      case Type::Float32: { float v; std::memcpy(&v, b, 4); return v; }
      default: { double v; std::memcpy(&v, b, 8); return v; }
    }
  }

  // A list's length, refused when negative or longer than the data left for it (its line's tokens, or the
  // file's bytes).
  std::uint64_t listLength(const Element& e, std::uint64_t i, const Property& p) {
    const std::size_t count_at = at_, count_token = next_token_;
    const double n = value(p.count, e, i, p);
    const auto claims = [&](const std::string& count, const std::string& where, const std::string& left) {
      return LoadError(path_, where, "list '" + p.name + "' of " + instanceName(e, i) + " claims " + count +
                                         " values, but " + left);
    };
    if (format_ == Format::Ascii) {
      const std::size_t left = tokens_.size() - next_token_;
      if (!(n >= 0.0 && n <= static_cast<double>(left)))
        throw claims(shown(tokens_[count_token]), lineName(token_line_), "the line holds " + std::to_string(left) + " more");
    } else {
      const std::size_t left = (bytes_.size() - std::min(bytes_.size(), at_)) / sizeOf(p.item);
      if (!(n >= 0.0 && n <= static_cast<double>(left)))
        throw claims(n < 0 ? "a negative number of" : std::to_string(static_cast<std::uint64_t>(n)),
                     "byte " + std::to_string(count_at), "the file holds " + std::to_string(left) + " more");
    }
    return static_cast<std::uint64_t>(n);
  }

  // Where the instance being read starts: "line N" (ASCII) or "byte N" (binary).
  std::string here(std::uint64_t at) const { return (format_ == Format::Ascii ? "line " : "byte ") + std::to_string(at); }

  void readElement(std::size_t index) {
    const Element& e = elements_[index];
    const bool vertices = index == vertex_element_, faces = index == face_element_;
    int xyz[3] = {-1, -1, -1};
    int corners = -1;
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const Property& p = e.properties[k];
      for (int a = 0; a < 3 && vertices && !p.list; ++a)
        if (xyz[a] < 0 && p.name == std::string(1, static_cast<char>('x' + a))) xyz[a] = static_cast<int>(k);
      if (faces && p.list && corners < 0 && (p.name == "vertex_indices" || p.name == "vertex_index")) corners = static_cast<int>(k);
    }
    if (vertices)
      for (int a = 0; a < 3; ++a)
        if (xyz[a] < 0)
          throw LoadError(path_, lineName(e.line), "element 'vertex' has no property '" + std::string(1, static_cast<char>('x' + a)) + "'");
    if (faces && corners < 0)
      throw LoadError(path_, lineName(e.line), "element '" + e.name + "' has no list 'vertex_indices' (or 'vertex_index')");
    // An instance without properties holds no values: no bytes, and in ASCII an empty line at most, which
    // reading skips as it skips every blank line.
    if (e.properties.empty()) return;

    std::vector<double> list;
    for (std::uint64_t i = 0; i < e.count; ++i) {
      if (format_ == Format::Ascii && !nextLine())
        throw LoadError(path_, "", "the file ends before " + instanceName(e, i) + " (the header declares " +
                                       std::to_string(e.count) + ")");
      const std::uint64_t start = format_ == Format::Ascii ? static_cast<std::uint64_t>(token_line_) : at_;
      Vec3 point = Vec3::Zero();
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const Property& p = e.properties[k];
        const bool coordinate = vertices && (xyz[0] == static_cast<int>(k) || xyz[1] == static_cast<int>(k) ||
                                             xyz[2] == static_cast<int>(k));
        if (!p.list) {
          const double v = value(p.item, e, i, p, coordinate);
          for (int a = 0; a < 3; ++a)
            if (coordinate && xyz[a] == static_cast<int>(k)) point[a] = v;
          continue;
        }
        const std::uint64_t n = listLength(e, i, p);
        const bool keep = faces && corners == static_cast<int>(k);
        list.clear();
        for (std::uint64_t j = 0; j < n; ++j) {
          const double v = value(p.item, e, i, p, keep);
          if (keep) list.push_back(v);
        }
        if (keep) addFace(e, i, start, list);
      }
      if (vertices) mesh_.vertices.push_back(point);
    }
  }

  struct Face {
    std::uint64_t instance, at;  // its number and where it starts (here())
    std::size_t first, size;     // its corners in corners_
  };

  // A face's corners (or a strip's indices), checked when every vertex is known (finish).
  void addFace(const Element& e, std::uint64_t i, std::uint64_t at, const std::vector<double>& list) {
    const bool strip = e.name == "tristrips";
    if (list.empty() && !strip) throw LoadError(path_, here(at), e.name + " " + std::to_string(i) + " has no vertices");
    for (const double v : list)
      if (v != std::floor(v)) throw LoadError(path_, here(at), e.name + " " + std::to_string(i) + " uses vertex " + written(v) + ", not a whole number");
    faces_.push_back({i, at, corners_.size(), list.size()});
    corners_.insert(corners_.end(), list.begin(), list.end());
  }

  // A strip's restart: -1, or its unsigned 32-bit form (assimp reads every index as an int).
  static bool restart(double v) { return v == -1.0 || v == 4294967295.0; }

  PlyMesh finish() {
    const bool strips = face_element_ < elements_.size() && elements_[face_element_].name == "tristrips";
    const double vertex_count = static_cast<double>(mesh_.vertices.size());
    const std::string face_name = face_element_ < elements_.size() ? elements_[face_element_].name : "face";
    for (const Face& f : faces_)
      for (std::size_t k = 0; k < f.size; ++k) {
        const double v = corners_[f.first + k];
        if (strips && restart(v)) continue;
        if (!(v >= 0.0 && v < vertex_count))
          throw LoadError(path_, here(f.at), face_name + " " + std::to_string(f.instance) + " uses vertex " + written(v) +
                                                 ", but the mesh has " + std::to_string(mesh_.vertices.size()) + " vertices");
      }
    for (const Face& f : faces_) strips ? unrollStrip(f) : triangulate(f);
    return std::move(mesh_);
  }

  // An index as written ("-1", "4000000000", "1.5", "1e+30"), never cast beyond a type's range.
  static std::string written(double v) {
    if (std::abs(v) < 1e15 && v == std::floor(v)) return std::to_string(static_cast<long long>(v));
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
  }

  std::uint32_t corner(const Face& f, std::size_t k) const { return static_cast<std::uint32_t>(corners_[f.first + k]); }

  // Triangle strips, restarted at each -1; every other triangle turned to keep one winding.
  void unrollStrip(const Face& f) {
    std::size_t run = 0;
    for (std::size_t k = 0; k < f.size; ++k) {
      if (restart(corners_[f.first + k])) {
        run = 0;
        continue;
      }
      if (++run < 3) continue;
      const std::uint32_t a = corner(f, k - 2), b = corner(f, k - 1), c = corner(f, k);
      mesh_.triangles.push_back(run % 2 == 1 ? std::array<std::uint32_t, 3>{a, b, c} : std::array<std::uint32_t, 3>{b, a, c});
    }
  }

  // A polygon in its plane: a fan when convex (up to rounding), ear clipping otherwise, without corners
  // that repeat the one before (exporters write them; kept, they blocked the ears beside them and left
  // zero-area triangles). The file's budget of clipping work (kClipWork per byte) ends any loop through
  // crafted polygons with an error instead of seconds of work.
  void triangulate(const Face& f) {
    if (f.size < 3) {
      ++mesh_.points_and_lines;
      return;
    }
    const auto fan = [&](const std::vector<std::uint32_t>& ring) {
      for (std::size_t k = 1; k + 1 < ring.size(); ++k) mesh_.triangles.push_back({ring[0], ring[k], ring[k + 1]});
    };
    const auto at = [&](std::uint32_t i) -> const Vec3& { return mesh_.vertices[i]; };
    std::vector<std::uint32_t> ring;
    ring.reserve(f.size);
    for (std::size_t k = 0; k < f.size; ++k)
      if (ring.empty() || at(ring.back()) != at(corner(f, k))) ring.push_back(corner(f, k));
    while (ring.size() > 1 && at(ring.back()) == at(ring.front())) ring.pop_back();
    if (ring.size() < 3) {  // no area: the corners as written, every triangle dropped as degenerate
      ring.clear();
      for (std::size_t k = 0; k < f.size; ++k) ring.push_back(corner(f, k));
      return fan(ring);
    }
    if (ring.size() == 3) return fan(ring);
    // Newell's normal; the plane's 2-D coordinates drop its largest axis, the second turned so that the
    // polygon runs counter-clockwise.
    Vec3 normal = Vec3::Zero();
    for (std::size_t k = 0; k < ring.size(); ++k) {
      const Vec3& p = at(ring[k]);
      const Vec3& q = at(ring[(k + 1) % ring.size()]);
      normal += Vec3((p.y() - q.y()) * (p.z() + q.z()), (p.z() - q.z()) * (p.x() + q.x()), (p.x() - q.x()) * (p.y() + q.y()));
    }
    int axis = 0;
    normal.cwiseAbs().maxCoeff(&axis);
    if (!(std::abs(normal[axis]) > 0.0)) return fan(ring);  // no area: every triangle is dropped as degenerate
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const double turn = normal[axis] > 0 ? 1.0 : -1.0;
    std::vector<std::array<double, 2>> points(ring.size());
    for (std::size_t k = 0; k < ring.size(); ++k) points[k] = {at(ring[k])[u], turn * at(ring[k])[v]};
    // Convex up to rounding: a turn below kStraight of its edges' product is straight (corners along a
    // slanted edge, written in floats).
    bool convex = true;
    for (std::size_t k = 0; k < ring.size() && convex; ++k) {
      const std::size_t a = k, b = (k + 1) % ring.size(), c = (k + 2) % ring.size();
      const double cross = (points[b][0] - points[a][0]) * (points[c][1] - points[a][1]) -
                           (points[b][1] - points[a][1]) * (points[c][0] - points[a][0]);
      convex = cross >= -kStraight * (at(ring[b]) - at(ring[a])).norm() * (at(ring[c]) - at(ring[b])).norm();
    }
    if (convex) return fan(ring);
    const double budget = kClipWork * static_cast<double>(bytes_.size()) + 1e6;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    const EarClip end = clipEars(points, false, budget, clip_work_, triangles);
    if (end == EarClip::OverBudget)
      throw LoadError(path_, here(f.at), "face " + std::to_string(f.instance) + " (" + std::to_string(f.size) +
                                             " corners, not convex) takes more work to triangulate than the file's "
                                             "size allows");
    if (end == EarClip::Crossed)
      warn(here(f.at), "face " + std::to_string(f.instance) + " crosses itself; the rest of it is triangulated as a fan");
    for (const auto& t : triangles) mesh_.triangles.push_back({ring[t[0]], ring[t[1]], ring[t[2]]});
  }

  // Clipping work (clipEars) per byte of the file. A simple polygon's clipping costs about 40 to 250 per
  // corner, and a corner takes at least 16 bytes in binary (its vertex and its index); a crafted file,
  // reusing its vertices in face after face, is refused after 32 per byte (at most about 0.35 s per MB in
  // a Release build, where 1,000 inside tests per byte took 5 s).
  static constexpr double kClipWork = 32.0;
  static constexpr int kWarnedLines = 3;        // header lines warned of one by one

  std::string path_;
  std::vector<std::string>* warnings_;
  std::string bytes_;
  std::size_t at_ = 0;  // the next byte to read
  long line_ = 1;       // the line at_ starts (ASCII)
  Format format_ = Format::Ascii;
  std::vector<Element> elements_;
  std::size_t vertex_element_ = std::numeric_limits<std::size_t>::max();
  std::size_t face_element_ = std::numeric_limits<std::size_t>::max();
  long vertex_line_ = 0, face_line_ = 0;
  int unknown_lines_ = 0;
  std::vector<std::string> tokens_;
  std::size_t next_token_ = 0;
  long token_line_ = 0;
  std::vector<double> corners_;
  std::vector<Face> faces_;
  double clip_work_ = 0.0;
  PlyMesh mesh_;
};

}  // namespace

PlyMesh readPly(const std::string& path, std::vector<std::string>* warnings) { return Reader(path, warnings).read(); }

EarClip clipEars(const std::vector<std::array<double, 2>>& points, bool exact, double budget, double& work,
                 std::vector<std::array<std::uint32_t, 3>>& out) {
  const std::uint32_t n = static_cast<std::uint32_t>(points.size());
  if (n < 3) return EarClip::Done;
  // The ring as a linked list: clipping an ear unlinks its middle corner.
  std::vector<std::uint32_t> prev(n), next(n);
  for (std::uint32_t i = 0; i < n; ++i) prev[i] = (i + n - 1) % n, next[i] = (i + 1) % n;
  std::vector<char> gone(n, 0);
  using Point = std::array<double, 2>;
  const auto turn = [](const Point& p, const Point& q, const Point& r) {
    return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
  };
  const auto cross = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) { return turn(points[a], points[b], points[c]); };
  // In the closed triangle, and not at one of its corners (a polygon that touches itself there, as a
  // hole's bridge does, keeps its ear).
  const auto inside = [&](std::uint32_t p, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    return points[p] != points[a] && points[p] != points[b] && points[p] != points[c] && cross(a, b, p) >= 0.0 &&
           cross(b, c, p) >= 0.0 && cross(c, a, p) >= 0.0;
  };
  const auto convex = [&](std::uint32_t b) { return cross(prev[b], b, next[b]) > 0.0; };
  // The corners that are not convex in a k-d tree (boxes halved at the median across their longer side,
  // down to kLeaf corners): a test visits only the boxes that may meet the ear's triangle, so it costs
  // about the logarithm of their number however they lie. A corner that stops being convex later (only in
  // a polygon that crosses itself) joins `late`, which every test reads.
  struct Node {
    Point lo, hi;
    std::uint32_t begin, end, child;  // its corners in `items`; its first child (0: a leaf)
  };
  constexpr std::uint32_t kLeaf = 8;
  std::vector<Node> nodes;
  std::vector<std::uint32_t> items, late;
  std::vector<char> listed(n, 0);
  // (Coordinates that are not numbers, which the loader refuses anyway, would break the median's order.)
  const bool scan = exact || !std::all_of(points.begin(), points.end(), [](const Point& p) { return p[0] == p[0] && p[1] == p[1]; });
  if (!scan) {
    for (std::uint32_t i = 0; i < n; ++i)
      if (!convex(i)) items.push_back(i), listed[i] = 1;
    if (!items.empty()) nodes.push_back({{}, {}, 0, static_cast<std::uint32_t>(items.size()), 0});
    for (std::size_t k = 0; k < nodes.size(); ++k) {  // (breadth first: children follow)
      Node node = nodes[k];
      node.lo = node.hi = points[items[node.begin]];
      for (std::uint32_t j = node.begin; j < node.end; ++j)
        for (int axis = 0; axis < 2; ++axis) {
          node.lo[axis] = std::min(node.lo[axis], points[items[j]][axis]);
          node.hi[axis] = std::max(node.hi[axis], points[items[j]][axis]);
        }
      if (node.end - node.begin > kLeaf) {
        const int axis = node.hi[0] - node.lo[0] >= node.hi[1] - node.lo[1] ? 0 : 1;
        const std::uint32_t mid = node.begin + (node.end - node.begin) / 2;
        std::nth_element(items.begin() + node.begin, items.begin() + mid, items.begin() + node.end,
                         [&](std::uint32_t x, std::uint32_t y) { return points[x][axis] < points[y][axis]; });
        node.child = static_cast<std::uint32_t>(nodes.size());
        nodes.push_back({{}, {}, node.begin, mid, 0});
        nodes.push_back({{}, {}, mid, node.end, 0});
      }
      nodes[k] = node;
    }
  }
  std::vector<std::uint32_t> stack;
  const auto blocked = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    if (scan) {
      for (std::uint32_t p = next[c]; p != a; p = next[p]) {
        work += 1.0;
        if (inside(p, a, b, c)) return true;
      }
      return false;
    }
    const auto test = [&](std::uint32_t p) {
      work += 1.0;
      return !gone[p] && p != a && p != b && p != c && inside(p, a, b, c);
    };
    if (std::any_of(late.begin(), late.end(), test)) return true;
    const Point* corner[3] = {&points[a], &points[b], &points[c]};
    Point lo = *corner[0], hi = *corner[0];
    for (const Point* q : corner)
      for (int axis = 0; axis < 2; ++axis) lo[axis] = std::min(lo[axis], (*q)[axis]), hi[axis] = std::max(hi[axis], (*q)[axis]);
    // A box lies wholly outside the triangle when it misses the triangle's box, or when all its corners
    // lie beyond one edge's line by more than the rounding of the turns the test computes.
    const auto misses = [&](const Node& node) {
      if (node.hi[0] < lo[0] || node.lo[0] > hi[0] || node.hi[1] < lo[1] || node.lo[1] > hi[1]) return true;
      for (int e = 0; e < 3; ++e) {
        const Point &p = *corner[e], &q = *corner[(e + 1) % 3];
        const double edge = std::abs(q[0] - p[0]) + std::abs(q[1] - p[1]);
        bool beyond = true;
        for (int k = 0; k < 4 && beyond; ++k) {
          const Point x = {k & 1 ? node.hi[0] : node.lo[0], k & 2 ? node.hi[1] : node.lo[1]};
          const double reach =
              std::abs(x[0] - p[0]) + std::abs(x[1] - p[1]) + (node.hi[0] - node.lo[0]) + (node.hi[1] - node.lo[1]);
          beyond = turn(p, q, x) < -kStraight * edge * reach;
        }
        if (beyond) return true;
      }
      return false;
    };
    stack.clear();
    if (!nodes.empty()) stack.push_back(0);
    while (!stack.empty()) {
      const Node& node = nodes[stack.back()];
      stack.pop_back();
      work += 1.0;
      if (misses(node)) continue;
      if (node.child != 0) {
        stack.push_back(node.child);
        stack.push_back(node.child + 1);
        continue;
      }
      for (std::uint32_t j = node.begin; j < node.end; ++j)
        if (test(items[j])) return true;
    }
    return false;
  };
  std::uint32_t size = n, k = 0;  // k: where the search for the next ear starts, next to the last one
  EarClip end = EarClip::Done;
  while (size > 3) {
    bool clipped = false;
    for (std::uint32_t tried = 0; tried < size && !clipped; ++tried, k = next[k]) {
      work += 1.0;
      if (work > budget) return EarClip::OverBudget;
      const std::uint32_t a = prev[k], b = k, c = next[k];
      if (!convex(b) || blocked(a, b, c)) continue;
      out.push_back({a, b, c});
      gone[b] = 1;
      next[a] = c;
      prev[c] = a;
      --size;
      for (const std::uint32_t turned : {a, c})
        if (!scan && !listed[turned] && !convex(turned)) late.push_back(turned), listed[turned] = 1;
      k = prev[a];  // (the loop's step then starts at a)
      clipped = true;
    }
    if (work > budget) return EarClip::OverBudget;
    if (!clipped) {
      end = EarClip::Crossed;
      break;
    }
  }
  // The last triangle, or the rest as a fan: from the first corner left.
  std::uint32_t first = 0;
  while (gone[first]) ++first;
  for (std::uint32_t j = next[first]; next[j] != first; j = next[j]) out.push_back({first, j, next[j]});
  return end;
}

}  // namespace clearway::detail
