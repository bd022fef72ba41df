// OctoMap files (.bt binary, .ot full) into boxes. OctoMap's readers trust their input: its node readers
// recurse without a depth limit and keep going on a failed stream with uninitialised bytes, so a truncated
// or foreign file can hang or overflow the stack. The file is therefore read into memory, its header
// parsed and its node stream walked here first (bounded by the tree depth and the byte count); OctoMap
// then reads exactly the checked node bytes (its data readers, not its file readers), and its node count
// must agree.
//
// Boxes come from one descent of the parsed tree in integer key space (a cube at depth d spans 2^(16−d)
// keys), so neighbouring leaves and unknown cubes share their faces exactly: key·resolution is the same
// double on both sides.
#include <clearway/environment/environment.h>
#include <clearway/load/input_limits.h>

#include <octomap/OcTree.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

namespace clearway {
namespace {

constexpr int kTreeDepth = 16;             // OctoMap's fixed depth: leaves at depth 16 are one resolution wide
constexpr int kRootHalfKeys = 1 << 15;     // the root cube spans keys [−2^15, 2^15) around the origin
constexpr std::size_t kMaxHeaderLines = 256;
const std::string kBinaryMagic = "# Octomap OcTree binary file";
const std::string kFullMagic = "# Octomap OcTree file";

enum class Format { Binary, Full };

[[noreturn]] void fail(const std::string& path, const std::string& reason) { throw LoadError(path, "", reason); }

std::string lowercase(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

void requireFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) fail(path, "OctoMap file not found");
  if (!std::filesystem::is_regular_file(path, ec)) fail(path, "not a regular file");
}

std::string readWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open the file for reading");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) fail(path, "read error");
  return buffer.str();
}

struct Header {
  std::string id;
  double resolution = std::nan("");
  long long size = -1;  // nodes, root included
  std::size_t data_offset = 0;
};

// The header grammar of OctoMap's AbstractOcTree::readHeader: after the magic line, lines of
// "# comment", "id NAME", "size N", "res R", ending with a line "data"; unknown keywords are skipped.
Header parseHeader(const std::string& path, const std::string& bytes, Format format) {
  const std::size_t first_end = bytes.find('\n');
  const std::string first = bytes.substr(0, std::min(first_end, std::size_t{256}));
  const std::string& magic = format == Format::Binary ? kBinaryMagic : kFullMagic;
  const std::string& other = format == Format::Binary ? kFullMagic : kBinaryMagic;
  if (first.compare(0, magic.size(), magic) != 0) {
    // The binary magic starts with the full one, so test the longer one first when telling them apart.
    if (first.compare(0, other.size(), other) == 0 && other.size() > magic.size())
      fail(path, "this is a binary OctoMap ('" + other + "'): name it .bt");
    if (first.compare(0, other.size(), other) == 0)
      fail(path, "this is a full OctoMap ('" + other + "'): name it .ot");
    fail(path, "not an OctoMap file: the first line is not '" + magic + "'");
  }
  if (first_end == std::string::npos) fail(path, "truncated file: the header ends after its first line");
  Header h;
  std::size_t pos = first_end + 1;
  for (std::size_t line = 0; line < kMaxHeaderLines; ++line) {
    if (pos >= bytes.size()) fail(path, "truncated file: the header has no 'data' line");
    std::size_t end = bytes.find('\n', pos);
    if (end == std::string::npos) end = bytes.size();
    std::istringstream words(bytes.substr(pos, end - pos));
    pos = end + 1;
    std::string key, value, extra;
    if (!(words >> key) || key[0] == '#') continue;
    if (key == "data") {
      if (end == bytes.size()) fail(path, "truncated file: no node data after the header");
      h.data_offset = pos;
      if (h.id.empty()) fail(path, "the header has no 'id' line");
      if (!(h.resolution > 0.0) || !std::isfinite(h.resolution))
        fail(path, "the header has no valid 'res' line (a finite resolution > 0)");
      // The map spans resolution · 2^16 around the origin; its cubes must stay within the input limits.
      char res[32], span[32];
      std::snprintf(res, sizeof res, "%g", h.resolution);
      std::snprintf(span, sizeof span, "%g", h.resolution * std::ldexp(1.0, kTreeDepth));
      if (h.resolution * std::ldexp(1.0, kTreeDepth) > 2.0 * kMaxInputLength)
        fail(path, std::string("resolution ") + res + " m: the map would span " + span +
                       " m, beyond the largest length an input may give (1e6 m)");
      if (h.resolution < kMinInputLength)
        fail(path, std::string("resolution ") + res + " m is below the smallest length an input may give (1e-9 m)");
      if (h.size < 0) fail(path, "the header has no valid 'size' line");
      return h;
    }
    const bool has_value = static_cast<bool>(words >> value);
    if (key == "id") {
      if (!has_value) fail(path, "the header's 'id' line has no value");
      h.id = value;
    } else if (key == "res" || key == "size") {
      char* stop = nullptr;
      const double x = has_value ? std::strtod(value.c_str(), &stop) : std::nan("");
      if (!has_value || *stop != '\0' || !std::isfinite(x))
        fail(path, "the header's '" + key + "' value '" + value + "' is not a number");
      if (key == "res") {
        h.resolution = x;
      } else {
        if (x < 0.0 || x != std::floor(x) || x > 4e9) fail(path, "the header's node count '" + value + "' is invalid");
        h.size = static_cast<long long>(x);
      }
    }
  }
  fail(path, "the header has no 'data' line within " + std::to_string(kMaxHeaderLines) + " lines");
}

// Walks the node stream as OctoMap will read it, without building anything. Recursion is bounded by
// the tree depth; every step consumes bytes, so the walk is linear in the file size.
class NodeStreamCheck {
 public:
  NodeStreamCheck(const std::string& path, const std::string& bytes, std::size_t offset)
      : path_(path), p_(reinterpret_cast<const unsigned char*>(bytes.data()) + offset),
        begin_(p_), end_(reinterpret_cast<const unsigned char*>(bytes.data()) + bytes.size()) {}

  // Binary: per inner node two bytes, two bits per child (01 occupied leaf, 10 free leaf, 11 inner,
  // 00 absent), then the inner children in child order. The root is an inner node.
  void binaryNode(int depth) {
    const unsigned char* bits = take(2);
    ++nodes_;
    int n_inner = 0, n_children = 0;
    for (int i = 0; i < 8; ++i) {
      const unsigned b = bits[i / 4] >> (2 * (i % 4));
      const bool lo = b & 1u, hi = b & 2u;
      if (lo || hi) ++n_children;
      if (lo && hi) ++n_inner;
    }
    if (depth == 0 && n_children == 0) fail(path_, "malformed node data: the root has no children");
    nodes_ += n_children - n_inner;  // leaves count here, inner children when visited
    if (n_inner > 0 && depth + 1 >= kTreeDepth)
      fail(path_, "malformed node data: a cell at the finest depth has children (a foreign or corrupt file)");
    for (int k = 0; k < n_inner; ++k) binaryNode(depth + 1);
  }

  // Full (OcTree): per node its log-odds (a float) and a byte of child flags, then its children in order.
  void fullNode(int depth) {
    const unsigned char* data = take(sizeof(float) + 1);
    float value;
    std::memcpy(&value, data, sizeof(float));
    if (!std::isfinite(value)) fail(path_, "malformed node data: a non-finite occupancy value");
    ++nodes_;
    const unsigned children = data[sizeof(float)];
    if (children != 0 && depth + 1 > kTreeDepth)
      fail(path_, "malformed node data: a cell at the finest depth has children (a foreign or corrupt file)");
    for (int i = 0; i < 8; ++i)
      if (children & (1u << i)) fullNode(depth + 1);
  }

  long long nodes() const noexcept { return nodes_; }
  std::size_t consumed() const noexcept { return static_cast<std::size_t>(p_ - begin_); }

 private:
  const unsigned char* take(std::size_t n) {
    if (static_cast<std::size_t>(end_ - p_) < n)
      fail(path_, "truncated file: the node data ends after " + std::to_string(end_ - begin_) + " bytes (" +
                      std::to_string(nodes_) + " nodes read)");
    const unsigned char* q = p_;
    p_ += n;
    return q;
  }

  const std::string& path_;
  const unsigned char* p_;
  const unsigned char* begin_;
  const unsigned char* end_;
  long long nodes_ = 0;
};

std::unique_ptr<octomap::OcTree> parseTree(const std::string& path, const std::string& bytes, Format format) {
  const Header h = parseHeader(path, bytes, format);
  if (format == Format::Full && h.id != "OcTree")
    fail(path, "an OctoMap of type '" + h.id + "': only OcTree maps are supported (write the map as an OcTree, or as .bt)");
  long long nodes = 0;
  // OctoMap writes nothing after 'data' for an empty tree: bytes there with 'size 0' are a tree the
  // header forgot, and reading it as empty would call everything in it free.
  if (h.size == 0 && bytes.find_first_not_of(" \t\r\n", h.data_offset) != std::string::npos)
    fail(path, "corrupt file: the header declares 0 nodes, but " + std::to_string(bytes.size() - h.data_offset) +
                   " bytes of node data follow it");
  if (h.size > 0) {
    NodeStreamCheck check(path, bytes, h.data_offset);
    if (format == Format::Binary) check.binaryNode(0);
    else check.fullNode(0);
    nodes = check.nodes();
  }
  if (nodes != h.size)
    fail(path, "corrupt file: the header declares " + std::to_string(h.size) + " nodes, the data holds " +
                   std::to_string(nodes));
  // OctoMap's data readers, past the header we checked: its file readers would parse the header again
  // and log every load on stderr.
  auto tree = std::make_unique<octomap::OcTree>(h.resolution);
  if (h.size > 0) {
    std::istringstream stream(bytes.substr(h.data_offset), std::ios::binary);
    if (format == Format::Binary) tree->readBinaryData(stream);
    else tree->readData(stream);
    if (!stream) fail(path, "OctoMap could not read the node data");
  }
  if (static_cast<long long>(tree->size()) != h.size)
    fail(path, "OctoMap read " + std::to_string(tree->size()) + " nodes where the header declares " +
                   std::to_string(h.size));
  return tree;
}

// One descent of the parsed tree; cubes are given by their lowest key corner and their span in keys.
class BoxCollector {
 public:
  BoxCollector(const octomap::OcTree& tree, OccupancyMap& map) : tree_(tree), map_(map), res_(tree.getResolution()) {}

  void leaves(const octomap::OcTreeNode* node, int depth, const int lo[3]) {
    const int span = 1 << (kTreeDepth - depth);
    if (!tree_.nodeHasChildren(node)) {
      const Aabb box = cube(lo, span);
      map_.known_bounds.merge(box);
      if (tree_.isNodeOccupied(node)) {
        map_.occupied.push_back(box);
        ++map_.occupied_leaves;
      }
      return;
    }
    if (depth >= kTreeDepth) return;  // cannot happen after NodeStreamCheck; keeps the recursion bounded anyway
    for (unsigned i = 0; i < 8; ++i)
      if (tree_.nodeChildExists(node, i)) {
        int child[3];
        childCorner(lo, span, i, child);
        leaves(tree_.getNodeChild(node, i), depth + 1, child);
      }
  }

  // A missing child of an inner node is a cube nobody observed: kept whole (clipped to the known
  // bounds), so unknown space costs one box per missing child, not one per finest voxel.
  void unknown(const octomap::OcTreeNode* node, int depth, const int lo[3]) {
    if (!tree_.nodeHasChildren(node) || depth >= kTreeDepth) return;
    const int span = 1 << (kTreeDepth - depth);
    for (unsigned i = 0; i < 8; ++i) {
      int child[3];
      childCorner(lo, span, i, child);
      if (tree_.nodeChildExists(node, i)) {
        unknown(tree_.getNodeChild(node, i), depth + 1, child);
        continue;
      }
      const Aabb box = cube(child, span / 2);
      const Aabb clipped = Aabb::fromMinMax(box.min.cwiseMax(map_.known_bounds.min), box.max.cwiseMin(map_.known_bounds.max));
      if ((clipped.max.array() > clipped.min.array()).all()) {
        map_.occupied.push_back(clipped);
        ++map_.unknown_boxes;
      }
    }
  }

 private:
  static void childCorner(const int lo[3], int span, unsigned i, int child[3]) {
    // OctoMap's child numbering: bit 0 → +x half, bit 1 → +y, bit 2 → +z.
    for (int k = 0; k < 3; ++k) child[k] = lo[k] + (((i >> k) & 1u) ? span / 2 : 0);
  }
  Aabb cube(const int lo[3], int span) const {
    return Aabb::fromMinMax(Vec3(lo[0] * res_, lo[1] * res_, lo[2] * res_),
                            Vec3((lo[0] + span) * res_, (lo[1] + span) * res_, (lo[2] + span) * res_));
  }

  const octomap::OcTree& tree_;
  OccupancyMap& map_;
  double res_;
};

}  // namespace

OccupancyMap loadOctomap(const std::string& path, UnknownSpace unknown) {
  requireFile(path);
  const std::string ext = lowercase(std::filesystem::path(path).extension().string());
  Format format;
  if (ext == ".bt") format = Format::Binary;
  else if (ext == ".ot") format = Format::Full;
  else fail(path, "unsupported OctoMap extension '" + ext + "' (use .bt or .ot)");
  const std::string bytes = readWholeFile(path);
  if (bytes.empty()) fail(path, "empty file");

  const std::unique_ptr<octomap::OcTree> tree = parseTree(path, bytes, format);
  OccupancyMap map;
  map.resolution = tree->getResolution();
  const octomap::OcTreeNode* root = tree->getRoot();
  if (!root) return map;
  const int root_lo[3] = {-kRootHalfKeys, -kRootHalfKeys, -kRootHalfKeys};
  BoxCollector collect(*tree, map);
  collect.leaves(root, 0, root_lo);
  if (unknown == UnknownSpace::Occupied && !map.known_bounds.isEmpty()) collect.unknown(root, 0, root_lo);
  return map;
}

}  // namespace clearway
