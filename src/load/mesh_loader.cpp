// Mesh files → TriangleMesh: STL, OBJ and COLLADA through assimp, PLY through ply_reader.cpp. The reader
// reads the file and triangulates it; everything that decides what the triangles *are* (node transforms,
// unit and up axis, scale, welding, degenerate and repeated faces) is done here in double precision, so that the
// result does not depend on the reader's choices beyond triangulation.
#include <clearway/load/input_limits.h>
#include <clearway/load/load_error.h>
#include <clearway/load/mesh_loader.h>

#include "load/collada_check.h"
#include "load/mesh_uri.h"
#include "load/ply_reader.h"

#include <assimp/DefaultIOStream.h>
#include <assimp/DefaultIOSystem.h>
#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <system_error>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace clearway {
namespace {

// A mesh larger than this (m, largest bounding-box extent after scale) is probably in millimetres.
constexpr double kMillimetreExtent = 10.0;
// A triangle whose height is below this fraction of its longest edge has zero area up to rounding.
constexpr double kDegenerateRelative = 1e-12;
// Assimp's messages are cut to this many characters: they may quote the rest of the file.
constexpr std::size_t kReaderChars = 80;
// A path is shown whole up to PATH_MAX, past which no path names a file.
constexpr std::size_t kPathChars = 4096;

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
  constexpr double kSameEntry = 1e-9;  // assimp's matrices are exact: this only absorbs float storage
  auto near = [&](const Mat3& m) { return (rotation - m).cwiseAbs().maxCoeff() < kSameEntry; };
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
struct CornersHash {
  std::size_t operator()(const std::array<std::int32_t, 3>& c) const noexcept {
    std::uint64_t h = 1469598103934665603ull;
    for (const std::int32_t i : c) h = (h ^ static_cast<std::uint32_t>(i)) * 1099511628211ull;
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
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
  Merger(const std::string& path, const Vec3& scale) : path_(path), scale_(scale) {}

  // The node and its subtree; world is the node's own transform in the mesh frame (the root's is chosen
  // by the caller), parent * the node's transform for the others.
  void addNode(const aiScene& scene, const aiNode& node, const Affine& world) {
    for (unsigned i = 0; i < node.mNumMeshes; ++i) addMesh(*scene.mMeshes[node.mMeshes[i]], world);
    for (unsigned i = 0; i < node.mNumChildren; ++i)
      addNode(scene, *node.mChildren[i], world * toAffine(node.mChildren[i]->mTransformation));
  }

  // Triangles over positions as written (indices in range), under world; name labels errors.
  void addTriangles(const std::vector<Vec3>& positions, const std::vector<std::array<std::uint32_t, 3>>& triangles,
                    const std::string& name, const Affine& world) {
    // A mirroring transform turns counter-clockwise triangles clockwise; swap two corners to undo it.
    const bool mirrored = world.A.determinant() * scale_.prod() < 0.0;
    index_.assign(positions.size(), -1);
    for (const auto& corners : triangles) {
      std::array<std::int32_t, 3> t{};
      for (int k = 0; k < 3; ++k) t[k] = vertex(positions, corners[k], name, world);
      if (mirrored) std::swap(t[1], t[2]);
      if (isDegenerate(t)) {
        ++degenerate;
        continue;
      }
      // A triangle over the same three vertices as an earlier one adds no geometry; stacked copies (a few
      // kilobytes of COLLADA instancing one mesh a thousand times) made every ray of the solids' tests
      // cross them all, 8 s to build a link of 600,000 copies of one tetrahedron.
      std::array<std::int32_t, 3> key = t;
      std::sort(key.begin(), key.end());
      if (!seen_.insert(key).second) {
        ++repeated;
        continue;
      }
      mesh.triangles.push_back(t);
    }
  }

  TriangleMesh mesh;
  std::size_t degenerate = 0, repeated = 0, points_and_lines = 0;

 private:
  void addMesh(const aiMesh& m, const Affine& world) {
    std::vector<Vec3> positions(m.mNumVertices);
    for (unsigned i = 0; i < m.mNumVertices; ++i) positions[i] = Vec3(m.mVertices[i].x, m.mVertices[i].y, m.mVertices[i].z);
    std::vector<std::array<std::uint32_t, 3>> triangles;
    triangles.reserve(m.mNumFaces);
    for (unsigned f = 0; f < m.mNumFaces; ++f) {
      const aiFace& face = m.mFaces[f];
      if (face.mNumIndices != 3) {
        ++points_and_lines;
        continue;
      }
      triangles.push_back({face.mIndices[0], face.mIndices[1], face.mIndices[2]});  // in range: checkFaceIndices
    }
    addTriangles(positions, triangles, m.mName.C_Str(), world);
  }

  // The merged index of vertex i (transformed, scaled and welded on first use).
  std::int32_t vertex(const std::vector<Vec3>& positions, std::uint32_t i, const std::string& name, const Affine& world) {
    if (index_[i] >= 0) return index_[i];
    Vec3 p = (world * positions[i]).cwiseProduct(scale_);
    const std::string which = "vertex " + std::to_string(i) + (name.empty() ? "" : " of mesh '" + inputExcerpt(name) + "'");
    if (!p.allFinite()) throw LoadError(path_, "", which + " has a non-finite coordinate");
    if (!(p.cwiseAbs().maxCoeff() <= kMaxInputLength))
      throw LoadError(path_, "", which + " lies " + number(p.cwiseAbs().maxCoeff()) + " m from the origin after scale, beyond "
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

  const std::string& path_;
  Vec3 scale_;
  std::vector<std::int32_t> index_;
  std::unordered_map<PositionKey, std::int32_t, PositionHash> welded_;
  std::unordered_set<std::array<std::int32_t, 3>, CornersHash> seen_;  // the kept triangles' corners, sorted
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

// Assimp's file access, limited to regular files: an OBJ's mtllib naming a FIFO made it wait for a
// writer forever; a material library that is not a regular file is missing to it, and skipped.
class RegularFileIOSystem : public Assimp::DefaultIOSystem {
 public:
  bool Exists(const char* path) const override {
    struct stat st {};
    return ::stat(path, &st) == 0 && S_ISREG(st.st_mode);
  }
  Assimp::IOStream* Open(const char* path, const char* mode) override {
    if (std::strchr(mode, 'w') != nullptr || std::strchr(mode, 'a') != nullptr) return nullptr;  // assimp only reads here
    std::string reason;
    std::FILE* file = detail::openRegularFile(path, &reason);
    return file != nullptr ? new Stream(file, path) : nullptr;
  }

 private:
  // DefaultIOStream's constructor from an open file is protected.
  struct Stream : Assimp::DefaultIOStream {
    Stream(std::FILE* file, const std::string& path) : DefaultIOStream(file, path) {}
  };
};

// Assimp's PLY reader passes faces on unchecked, and its post-processing (triangulation) reads through
// their indices and aborts on an empty one: check them in the scene as read, before any step runs.
void checkFaceIndices(const aiScene& scene, const std::string& path) {
  for (unsigned i = 0; i < scene.mNumMeshes; ++i) {
    const aiMesh& m = *scene.mMeshes[i];
    for (unsigned f = 0; f < m.mNumFaces; ++f) {
      // A face without vertices (a PLY list of length 0) aborts assimp's triangulation.
      if (m.mFaces[f].mNumIndices == 0)
        throw LoadError(path, "", "face " + std::to_string(f) + " of mesh '" + inputExcerpt(m.mName.C_Str()) + "' has no vertices");
      for (unsigned k = 0; k < m.mFaces[f].mNumIndices; ++k)
        if (m.mFaces[f].mIndices[k] >= m.mNumVertices)
          throw LoadError(path, "", "face " + std::to_string(f) + " of mesh '" + inputExcerpt(m.mName.C_Str()) + "' uses vertex " +
                                        std::to_string(m.mFaces[f].mIndices[k]) + ", but the mesh has " +
                                        std::to_string(m.mNumVertices) + " vertices");
    }
  }
}

// Every mesh of a file assimp reads (STL, OBJ, COLLADA), merged under the root transform ROS would use.
void mergeThroughAssimp(const std::string& path, const std::string& ext, const MeshOptions& options,
                        const std::function<void(const std::string&)>& warn, Merger* merger) {
  Assimp::Importer importer;
  importer.SetIOHandler(new RegularFileIOSystem);  // the importer owns it
  if (ext == "dae") detail::checkCollada(path, options.max_expanded_triangles);

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
    throw LoadError(path, "", "assimp cannot read it: " + inputExcerpt(importer.GetErrorString(), kReaderChars));
  checkFaceIndices(*scene, path);
  scene = importer.ApplyPostProcessing(aiProcess_Triangulate | aiProcess_RemoveComponent);
  if (scene == nullptr || scene->mRootNode == nullptr)
    throw LoadError(path, "", "assimp cannot read it: " + inputExcerpt(importer.GetErrorString(), kReaderChars));

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

  merger->addNode(*scene, *scene->mRootNode, root);
}

// The closed axis-aligned cube of half extent `half` about `centre`, outward triangles.
TriangleMesh tinyBoxMesh(const Vec3& centre, double half) {
  TriangleMesh box;
  for (int i = 0; i < 8; ++i)
    box.vertices.push_back(centre + half * Vec3(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1));
  box.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                   {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return box;
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
  // "x.dae\0.stl" would be read as STL by its name, and the system would open x.dae.
  if (const std::string why = detail::controlCharacterReason(path); !why.empty())
    throw LoadError(inputExcerpt(path, kPathChars), "", why);
  if (!scale.allFinite() || (scale.array() == 0.0).any())
    throw LoadError(path, "", "scale must be finite and non-zero in every component");

  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw LoadError(path, "", "mesh file not found");
  std::string not_regular;
  if (std::FILE* file = detail::openRegularFile(path, &not_regular)) std::fclose(file);
  else throw LoadError(path, "", not_regular);
  if (std::filesystem::file_size(path, ec) == 0) throw LoadError(path, "", "empty mesh: the file is empty");

  const std::string ext = lowerExtension(path);
  if (std::none_of(std::begin(kFormats), std::end(kFormats), [&](const char* f) { return ext == f; }))
    throw LoadError(path, "", "unsupported mesh format '" + ext + "' (Clearway reads " + kFormatList + ")");
  Merger merger(path, scale);
  if (ext == "ply") {
    detail::PlyMesh ply = detail::readPly(path, warnings);
    merger.addTriangles(ply.vertices, ply.triangles, "", Affine{});
    merger.points_and_lines += ply.points_and_lines;
  } else {
    mergeThroughAssimp(path, ext, options, warn, &merger);
  }
  TriangleMesh mesh = std::move(merger.mesh);

  if (merger.points_and_lines > 0)
    warn(std::to_string(merger.points_and_lines) + " point and line primitives ignored");
  if (merger.degenerate > 0) warn(std::to_string(merger.degenerate) + " zero-area triangles dropped");
  if (merger.repeated > 0)
    warn(std::to_string(merger.repeated) + " repeated triangles dropped (the same three vertices as an earlier one)");
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

  Vec3 lo = mesh.vertices[0], hi = mesh.vertices[0];
  for (const Vec3& v : mesh.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const double extent = (hi - lo).maxCoeff();
  if (extent < kMinInputLength) {
    // Below this the hull arithmetic has no digits left. The box of half kMinInputLength about the centre
    // holds every vertex (each lies within extent / 2 of it, rounding included): a conservative solid.
    warn("the mesh spans " + number(extent) + " m after scale, below the smallest size Clearway computes with "
         "(1e-9 m): checked as a closed box 2e-9 m wide around it");
    return tinyBoxMesh(0.5 * (lo + hi), kMinInputLength);
  }

  std::size_t open = 0, non_manifold = 0;
  countBadEdges(mesh, &open, &non_manifold);
  if (open > 0 || non_manifold > 0)
    warn("not closed (" + std::to_string(open) + " edges with one triangle, " + std::to_string(non_manifold) +
         " with more than two): a piece with an edge of one triangle is a surface, not a solid (a body wholly inside it does not collide)");

  if (extent > kMillimetreExtent)
    warn("largest extent is " + number(extent) + " m after scale: probably millimetres (scale=\"0.001 0.001 0.001\"?)");
  return mesh;
}

}  // namespace clearway
