// Mesh files → TriangleMesh through assimp. Assimp reads the file and triangulates it; everything that
// decides what the triangles *are* (node transforms, unit and up axis, scale, welding, degenerate faces)
// is done here in double precision, so that the result does not depend on assimp's post-processing
// choices beyond triangulation.
#include <clearway/load/input_limits.h>
#include <clearway/load/load_error.h>
#include <clearway/load/mesh_loader.h>

#include "load/collada_check.h"

#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <string>
#include <system_error>
#include <unordered_map>
#include <vector>

namespace clearway {
namespace {

// A mesh larger than this (m, largest bounding-box extent after scale) is probably in millimetres.
constexpr double kMillimetreExtent = 10.0;
// A triangle whose height is below this fraction of its longest edge has zero area up to rounding.
constexpr double kDegenerateRelative = 1e-12;

// An affine map x ↦ A·x + b in double precision (node transforms may scale, e.g. a COLLADA <unit>).
struct Affine {
  Mat3 A = Mat3::Identity();
  Vec3 b = Vec3::Zero();
  Affine operator*(const Affine& o) const { return {A * o.A, A * o.b + b}; }
  Vec3 operator*(const Vec3& x) const { return A * x + b; }
};

Affine toAffine(const aiMatrix4x4& m) {
  Affine t;
  t.A << m.a1, m.a2, m.a3, m.b1, m.b2, m.b3, m.c1, m.c2, m.c3;
  t.b << m.a4, m.b4, m.c4;
  return t;
}

// The formats read, by extension. Each has exactly one assimp importer, which assimp then picks by the
// extension alone (no content sniffing that could hand a file to an unchecked importer); COLLADA is
// checked by collada_check.cpp first.
constexpr const char* kFormats[] = {"stl", "obj", "dae", "ply"};
constexpr const char* kFormatList = "STL, OBJ, COLLADA (.dae) or PLY";

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  if (!ext.empty() && ext[0] == '.') ext.erase(0, 1);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

std::string number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", x);
  return buf;
}

// Assimp folds a COLLADA file's <unit> scale s and a rotation R that turns its <up_axis> into y into the
// root node's transform (s·R). The up axis, read from R.
enum class UpAxis { X, Y, Z, Unknown };

UpAxis colladaUpAxis(const Mat3& rotation) {
  Mat3 z_to_y, x_to_y;  // assimp's: (x, y, z) ↦ (x, z, −y) for Z_UP, (−y, x, z) for X_UP
  z_to_y << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  x_to_y << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  auto near = [&](const Mat3& m) { return (rotation - m).cwiseAbs().maxCoeff() < 1e-9; };
  if (near(z_to_y)) return UpAxis::Z;
  if (near(Mat3::Identity())) return UpAxis::Y;
  if (near(x_to_y)) return UpAxis::X;
  return UpAxis::Unknown;
}

const char* upAxisName(UpAxis axis) {
  switch (axis) {
    case UpAxis::X: return "X_UP";
    case UpAxis::Y: return "Y_UP";
    case UpAxis::Z: return "Z_UP";
    default: return "not one of X_UP, Y_UP, Z_UP";
  }
}

// Vertices at bit-identical positions become one (−0 and +0 are one position).
struct PositionKey {
  double x, y, z;
  bool operator==(const PositionKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct PositionHash {
  std::size_t operator()(const PositionKey& k) const noexcept {
    std::uint64_t h = 1469598103934665603ull;
    for (double d : {k.x, k.y, k.z}) {
      std::uint64_t bits;
      std::memcpy(&bits, &d, sizeof bits);
      h = (h ^ bits) * 1099511628211ull;
      h ^= h >> 29;
    }
    return static_cast<std::size_t>(h);
  }
};

class Merger {
 public:
  Merger(const aiScene& scene, const std::string& path, const Vec3& scale) : scene_(scene), path_(path), scale_(scale) {}

  // The node and its subtree; world is the node's own transform in the mesh frame (the root's is chosen
  // by the caller), parent * the node's transform for the others.
  void addNode(const aiNode& node, const Affine& world) {
    for (unsigned i = 0; i < node.mNumMeshes; ++i) addMesh(*scene_.mMeshes[node.mMeshes[i]], world);
    for (unsigned i = 0; i < node.mNumChildren; ++i)
      addNode(*node.mChildren[i], world * toAffine(node.mChildren[i]->mTransformation));
  }

  TriangleMesh mesh;
  std::size_t degenerate = 0, points_and_lines = 0;

 private:
  void addMesh(const aiMesh& m, const Affine& world) {
    // A mirroring transform turns counter-clockwise triangles clockwise; swap two corners to undo it.
    const bool mirrored = world.A.determinant() * scale_.prod() < 0.0;
    index_.assign(m.mNumVertices, -1);
    for (unsigned f = 0; f < m.mNumFaces; ++f) {
      const aiFace& face = m.mFaces[f];
      if (face.mNumIndices != 3) {
        ++points_and_lines;
        continue;
      }
      std::array<std::int32_t, 3> t{};
      for (int k = 0; k < 3; ++k) t[k] = vertex(m, face.mIndices[k], world);  // in range: checkFaceIndices
      if (mirrored) std::swap(t[1], t[2]);
      if (isDegenerate(t)) {
        ++degenerate;
        continue;
      }
      mesh.triangles.push_back(t);
    }
  }

  // The merged index of vertex i of mesh m (transformed, scaled and welded on first use).
  std::int32_t vertex(const aiMesh& m, unsigned i, const Affine& world) {
    if (index_[i] >= 0) return index_[i];
    const aiVector3D& v = m.mVertices[i];
    Vec3 p = (world * Vec3(v.x, v.y, v.z)).cwiseProduct(scale_);
    if (!p.allFinite())
      throw LoadError(path_, "", "vertex " + std::to_string(i) + " of mesh '" + m.mName.C_Str() +
                                     "' has a non-finite coordinate");
    if (!(p.cwiseAbs().maxCoeff() <= kMaxInputLength))
      throw LoadError(path_, "", "vertex " + std::to_string(i) + " of mesh '" + m.mName.C_Str() + "' lies " +
                                     number(p.cwiseAbs().maxCoeff()) + " m from the origin after scale, beyond "
                                     "the largest length an input may give (1e6 m)");
    p += Vec3::Zero();  // −0 → +0
    const auto [it, inserted] = welded_.try_emplace(PositionKey{p.x(), p.y(), p.z()},
                                                    static_cast<std::int32_t>(mesh.vertices.size()));
    if (inserted) mesh.vertices.push_back(p);
    return index_[i] = it->second;
  }

  bool isDegenerate(const std::array<std::int32_t, 3>& t) const {
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) return true;
    const Vec3& a = mesh.vertices[t[0]];
    const Vec3& b = mesh.vertices[t[1]];
    const Vec3& c = mesh.vertices[t[2]];
    const double longest2 = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    // |(b−a)×(c−a)| = longest edge · height.
    return !((b - a).cross(c - a).norm() > kDegenerateRelative * longest2);
  }

  const aiScene& scene_;
  const std::string& path_;
  Vec3 scale_;
  std::vector<std::int32_t> index_;
  std::unordered_map<PositionKey, std::int32_t, PositionHash> welded_;
};

// Edges (as sorted vertex pairs) with the number of triangles using them: one count per open or
// non-manifold edge.
void countBadEdges(const TriangleMesh& mesh, std::size_t* open, std::size_t* non_manifold) {
  std::unordered_map<std::uint64_t, int> uses;
  uses.reserve(mesh.triangles.size() * 2);
  for (const auto& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      const auto a = static_cast<std::uint32_t>(std::min(t[k], t[(k + 1) % 3]));
      const auto b = static_cast<std::uint32_t>(std::max(t[k], t[(k + 1) % 3]));
      ++uses[(std::uint64_t{a} << 32) | b];
    }
  }
  *open = *non_manifold = 0;
  for (const auto& [edge, n] : uses) {
    if (n == 1) ++*open;
    if (n > 2) ++*non_manifold;
  }
}

struct PlyProperty {
  bool list;
  std::string count_type, item_type, name;
};
struct PlyElement {
  std::string name;
  std::uintmax_t count;
  std::vector<PlyProperty> properties;
};

// Bytes of a PLY scalar type; 0 for a name PLY does not define.
int plyTypeSize(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "int32" || t == "uint32" || t == "float" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

// The data after a PLY header: assimp sizes every list by its count before reading its values (up to
// 2^32 of them, 32 GB for a count of -1). Each count must be a whole number of values the data still
// holds: on its line (ASCII, one element instance per line) or in the bytes left (binary). The walk
// stops where the data no longer follows the header; what assimp makes of the rest is its own check.
void checkPlyLists(const std::string& path, std::istream& in, long header_lines, const std::string& format,
                   const std::vector<PlyElement>& elements) {
  const auto tooMany = [&](const std::string& where, const PlyElement& e, std::uintmax_t i, const PlyProperty& p,
                           const std::string& count, const std::string& left) {
    return LoadError(path, where, "list '" + p.name + "' of " + e.name + " " + std::to_string(i) +
                                      " claims " + count.substr(0, 40) + " values, but " + left);
  };
  if (format == "ascii") {
    long number = header_lines;
    std::string line;
    for (const PlyElement& e : elements)
      for (std::uintmax_t i = 0; i < e.count; ++i) {
        if (!std::getline(in, line)) return;
        ++number;
        std::istringstream words(line);
        std::vector<std::string> tokens{std::istream_iterator<std::string>(words), std::istream_iterator<std::string>()};
        std::size_t next = 0;
        for (const PlyProperty& p : e.properties) {
          if (next >= tokens.size()) break;
          const std::string& token = tokens[next++];
          if (!p.list) continue;
          const std::size_t left = tokens.size() - next;
          const bool whole = std::all_of(token.begin(), token.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
          if (!whole || token.size() > 19 || std::stoull(token) > left)
            throw tooMany("line " + std::to_string(number), e, i, p, token,
                          "the line holds " + std::to_string(left) + " more");
          next += std::stoull(token);
        }
      }
    return;
  }
  const bool big = format == "binary_big_endian";
  if (!big && format != "binary_little_endian") return;
  const std::uintmax_t start = static_cast<std::uintmax_t>(in.tellg());
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  std::uintmax_t at = start;
  for (const PlyElement& e : elements)
    for (std::uintmax_t i = 0; i < e.count; ++i)
      for (const PlyProperty& p : e.properties) {
        const int item = plyTypeSize(p.item_type);
        if (item == 0) return;
        if (!p.list) {
          at += static_cast<std::uintmax_t>(item);
          continue;
        }
        const int n = plyTypeSize(p.count_type);
        unsigned char bytes[8];
        if (n == 0 || at + static_cast<std::uintmax_t>(n) > size) return;
        in.seekg(static_cast<std::streamoff>(at));
        if (!in.read(reinterpret_cast<char*>(bytes), n)) return;
        at += static_cast<std::uintmax_t>(n);
        std::uintmax_t count = 0;
        for (int k = 0; k < n; ++k) count = count << 8 | bytes[big ? k : n - 1 - k];
        // A signed count below 0 is, to assimp, a count near 2^32.
        const bool negative = p.count_type[0] != 'u' && (bytes[big ? 0 : n - 1] & 0x80) != 0;
        const std::uintmax_t left = (size - std::min(size, at)) / static_cast<std::uintmax_t>(item);
        if (negative || count > left)
          throw tooMany("byte " + std::to_string(at - static_cast<std::uintmax_t>(n)), e, i, p,
                        negative ? "a negative number of" : std::to_string(count),
                        "the file holds " + std::to_string(left) + " more");
        at += count * static_cast<std::uintmax_t>(item);
      }
}

// Assimp's PLY reader reads header lines until `end_header` without looking for the end of the file:
// a header without that line never ends. Nor does one whose `end_header` is the file's last bytes,
// without a line end, after a longer line (its line buffer then never reaches the end). The PLY header
// is text, one keyword per line, each line ended.
//
// Its element lines too: assimp allocates an element's count N up front (read as its leading digits,
// wrapping around 2^32), sizes the mesh by the first non-empty `element vertex` and face list (`element
// face` or `element tristrips`), and writes every later one's instances into those arrays, over the
// first's or past their end (heap corruption that ASan cannot see in the uninstrumented library).
// `comment` lines are checked like element lines, as assimp's header parser may take them for one.
void checkPlyHeader(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw LoadError(path, "", "cannot open the file");
  std::error_code ec;
  const std::uintmax_t file_size = std::filesystem::file_size(path, ec);
  long vertex_line = 0, face_line = 0;
  std::string first_faces, format;
  std::vector<PlyElement> elements;
  std::optional<LoadError> bad_element;  // reported once the header is known to end
  std::string line;
  for (long number = 1; std::getline(in, line); ++number) {
    std::istringstream words(line);
    std::string keyword, name, count;
    words >> keyword >> name >> count;
    if (keyword == "format") format = name;
    if (keyword == "property" && !elements.empty()) {
      std::string item_type, property;
      words >> item_type >> property;
      if (name == "list") elements.back().properties.push_back({true, count, item_type, property});
      else elements.back().properties.push_back({false, "", name, count});
    }
    if ((keyword == "element" || keyword == "comment") && !bad_element) try {
      const std::string where = "line " + std::to_string(number);
      std::uintmax_t n = 0;
      for (std::size_t i = 0; i < count.size() && std::isdigit(static_cast<unsigned char>(count[i])) && n <= file_size; ++i)
        n = 10 * n + static_cast<std::uintmax_t>(count[i] - '0');
      if (n > file_size)
        throw LoadError(path, where, "element '" + name + "' has " + count.substr(0, 40) +
                                         " instances, more than the file has bytes (" + std::to_string(file_size) + ")");
      if (keyword == "element") elements.push_back({name, n, {}});
      if (name == "vertex" && n > 0) {
        if (vertex_line != 0)
          throw LoadError(path, where, "a second 'element vertex' (the first is on line " + std::to_string(vertex_line) +
                                           "): Clearway reads one vertex list per PLY file");
        vertex_line = number;
      }
      if ((name == "face" || name == "tristrips") && n > 0) {
        if (face_line != 0)
          throw LoadError(path, where, "a second face list 'element " + name + "' (the first, 'element " + first_faces +
                                           "', is on line " + std::to_string(face_line) +
                                           "): Clearway reads one face list per PLY file");
        face_line = number;
        first_faces = name;
      }
    } catch (const LoadError& e) {
      bad_element = e;
    }
    const std::size_t end = line.find_last_not_of(" \t\r");
    if (end != std::string::npos && line.compare(0, end + 1, "end_header") == 0) {
      if (in.eof() && line.back() != '\r')
        throw LoadError(path, "line " + std::to_string(number),
                        "the PLY header's 'end_header' line has no line end (the file ends there)");
      if (bad_element) throw *bad_element;
      checkPlyLists(path, in, number, format, elements);
      return;
    }
  }
  throw LoadError(path, "", "the PLY header has no 'end_header' line");
}

// Assimp's PLY reader passes faces on unchecked, and its post-processing (triangulation) reads through
// their indices and aborts on an empty one: check them in the scene as read, before any step runs.
void checkFaceIndices(const aiScene& scene, const std::string& path) {
  for (unsigned i = 0; i < scene.mNumMeshes; ++i) {
    const aiMesh& m = *scene.mMeshes[i];
    for (unsigned f = 0; f < m.mNumFaces; ++f) {
      // A face without vertices (a PLY list of length 0) aborts assimp's triangulation.
      if (m.mFaces[f].mNumIndices == 0)
        throw LoadError(path, "", "face " + std::to_string(f) + " of mesh '" + m.mName.C_Str() + "' has no vertices");
      for (unsigned k = 0; k < m.mFaces[f].mNumIndices; ++k)
        if (m.mFaces[f].mIndices[k] >= m.mNumVertices)
          throw LoadError(path, "", "face " + std::to_string(f) + " of mesh '" + m.mName.C_Str() + "' uses vertex " +
                                        std::to_string(m.mFaces[f].mIndices[k]) + ", but the mesh has " +
                                        std::to_string(m.mNumVertices) + " vertices");
    }
  }
}

}  // namespace

bool isClosed(const TriangleMesh& mesh) {
  std::size_t open = 0, non_manifold = 0;
  countBadEdges(mesh, &open, &non_manifold);
  return !mesh.triangles.empty() && open == 0 && non_manifold == 0;
}

TriangleMesh loadMesh(const std::string& path, const Vec3& scale, std::vector<std::string>* warnings,
                      const MeshOptions& options) {
  auto warn = [&](const std::string& reason) {
    if (warnings) warnings->push_back(LoadError::format(path, "", reason));
  };
  if (!scale.allFinite() || (scale.array() == 0.0).any())
    throw LoadError(path, "", "scale must be finite and non-zero in every component");

  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw LoadError(path, "", "mesh file not found");
  if (std::filesystem::file_size(path, ec) == 0) throw LoadError(path, "", "empty mesh: the file is empty");

  const std::string ext = lowerExtension(path);
  Assimp::Importer importer;
  if (std::none_of(std::begin(kFormats), std::end(kFormats), [&](const char* f) { return ext == f; }))
    throw LoadError(path, "", "unsupported mesh format '" + ext + "' (Clearway reads " + kFormatList + ")");
  if (ext == "dae") detail::checkCollada(path);
  if (ext == "ply") checkPlyHeader(path);

  // Only positions matter. Vertices are joined below by exact position, not by assimp's
  // JoinIdenticalVertices: on every mesh of ../shared/robots both give the same vertices, ours in a
  // third of the time (assimp compares every attribute through a spatial sort).
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS,
                              aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS | aiComponent_COLORS |
                                  aiComponent_TEXCOORDS | aiComponent_BONEWEIGHTS | aiComponent_ANIMATIONS |
                                  aiComponent_TEXTURES | aiComponent_LIGHTS | aiComponent_CAMERAS |
                                  aiComponent_MATERIALS);
  const aiScene* scene = importer.ReadFile(path, 0);
  if (scene == nullptr || scene->mRootNode == nullptr)
    throw LoadError(path, "", std::string("assimp cannot read it: ") + importer.GetErrorString());
  checkFaceIndices(*scene, path);
  scene = importer.ApplyPostProcessing(aiProcess_Triangulate | aiProcess_RemoveComponent);
  if (scene == nullptr || scene->mRootNode == nullptr)
    throw LoadError(path, "", std::string("assimp cannot read it: ") + importer.GetErrorString());

  Affine root = toAffine(scene->mRootNode->mTransformation);
  if (ext == "dae") {
    // root = s·R (see colladaUpAxis). ROS (geometric_shapes for MoveIt, RViz) drops assimp's root
    // transform: a mesh's coordinates are the link's, z up whatever <up_axis> says. We keep the same
    // geometry, but with the <unit> scale s, which is a unit and not a convention.
    const double s = std::cbrt(root.A.determinant());
    if (!std::isfinite(s) || s == 0.0)
      throw LoadError(path, "<unit>", "the unit scale is zero or not finite");
    const UpAxis up = colladaUpAxis(root.A / s);
    if (options.honour_up_axis) {
      // Assimp has made the scene y-up; turn it z-up: y → z, z → −y.
      Affine y_to_z;
      y_to_z.A << 1, 0, 0, 0, 0, -1, 0, 1, 0;
      root = y_to_z * root;
      if (up != UpAxis::Z)
        warn(std::string("COLLADA <up_axis> is ") + upAxisName(up) +
             ": rotated so that the file's up axis is z (as asked; ROS, RViz and MoveIt ignore <up_axis> "
             "and use this mesh unrotated)");
    } else {
      root.A = s * Mat3::Identity();
      if (up != UpAxis::Z)
        warn(std::string("COLLADA <up_axis> is ") + upAxisName(up) +
             ": ignored as ROS, RViz and MoveIt ignore it (the mesh is not rotated; its <unit> is applied); "
             "honour_up_axis (clearway --honour-up-axis) rotates the file's up axis to z");
    }
  }

  Merger merger(*scene, path, scale);
  merger.addNode(*scene->mRootNode, root);
  TriangleMesh mesh = std::move(merger.mesh);

  if (merger.points_and_lines > 0)
    warn(std::to_string(merger.points_and_lines) + " point and line primitives ignored");
  if (merger.degenerate > 0) warn(std::to_string(merger.degenerate) + " zero-area triangles dropped");
  if (mesh.triangles.empty()) throw LoadError(path, "", "empty mesh: no triangles");

  // Keep only vertices that some triangle uses (corners of dropped triangles may be left over).
  std::vector<std::int32_t> remap(mesh.vertices.size(), -1);
  std::vector<Vec3> used;
  used.reserve(mesh.vertices.size());
  for (auto& t : mesh.triangles) {
    for (std::int32_t& i : t) {
      if (remap[i] < 0) {
        remap[i] = static_cast<std::int32_t>(used.size());
        used.push_back(mesh.vertices[i]);
      }
      i = remap[i];
    }
  }
  mesh.vertices = std::move(used);

  std::size_t open = 0, non_manifold = 0;
  countBadEdges(mesh, &open, &non_manifold);
  if (open > 0 || non_manifold > 0)
    warn("not closed (" + std::to_string(open) + " edges with one triangle, " + std::to_string(non_manifold) +
         " with more than two): a piece with an edge of one triangle is a surface, not a solid (a body wholly inside it does not collide)");

  Vec3 lo = mesh.vertices[0], hi = mesh.vertices[0];
  for (const Vec3& v : mesh.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const double extent = (hi - lo).maxCoeff();
  if (!(extent >= kMinInputLength))
    throw LoadError(path, "", "the mesh spans " + number(extent) + " m after scale, below the smallest length an "
                              "input may give (1e-9 m)");
  if (extent > kMillimetreExtent)
    warn("largest extent is " + number(extent) + " m after scale: probably millimetres (scale=\"0.001 0.001 0.001\"?)");
  return mesh;
}

}  // namespace clearway
