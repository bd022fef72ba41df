#pragma once
// Helpers for tests that read robot files: a private temporary folder to write small (often broken)
// URDF, SRDF and mesh files into, paths to the robots in robots/ and ../shared/robots, and a check
// that a LoadError names what it should.
#include <clearway/load/load_error.h>

#include "shared_data.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

namespace clearway::test {

/// A folder under the system temp folder, removed (with its content) when the object goes away.
class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() /
            ("clearway-test-" + std::to_string(::getpid()) + "-" + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  /// The absolute path of name inside the folder.
  std::string path(const std::string& name) const { return (path_ / name).string(); }
  /// Writes text (bytes as given) to name, creating folders; returns its path.
  std::string write(const std::string& name, const std::string& text) const {
    const std::filesystem::path p = path_ / name;
    std::filesystem::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }

 private:
  std::filesystem::path path_;
};

/// robots/<rel> in the source tree.
inline std::string sourceRobot(const std::string& rel) { return std::string(CLEARWAY_SOURCE_DIR) + "/robots/" + rel; }

/// <shared>/robots/<rel> (shared_data.h), or "" when the shared data is not there.
inline std::string sharedRobot(const std::string& rel) { return sharedPath("robots/" + std::string(rel)); }

/// Declares `var` = <shared>/robots/<rel>; a missing file skips the test, or fails it when CI=true.
#define CLEARWAY_SHARED_ROBOT_OR_SKIP(var, rel) CLEARWAY_SHARED_OR_SKIP(var, "robots/" + std::string(rel))

/// One facet of an ASCII STL with corners a, b, c (each "x y z").
inline std::string stlFacet(const char* a, const char* b, const char* c) {
  return std::string("facet normal 0 0 0\nouter loop\nvertex ") + a + "\nvertex " + b + "\nvertex " + c +
         "\nendloop\nendfacet\n";
}

/// A closed unit-free tetrahedron as an ASCII STL (4 outward triangles), then extra_facets.
inline std::string tetrahedronStl(const std::string& extra_facets = "") {
  return "solid tet\n" + stlFacet("0 0 0", "0 1 0", "1 0 0") + stlFacet("0 0 0", "1 0 0", "0 0 1") +
         stlFacet("0 0 0", "0 0 1", "0 1 0") + stlFacet("1 0 0", "0 1 0", "0 0 1") + extra_facets + "endsolid tet\n";
}

/// A COLLADA file holding one closed box [lo, hi] (outward triangles) in the file's coordinates, under a
/// node with the given transform elements (e.g. "<translate>0 0 1</translate>"), with <unit meter> and
/// <up_axis> (none when up_axis is empty).
inline std::string colladaBox(const std::array<double, 3>& lo, const std::array<double, 3>& hi, const std::string& up_axis,
                              double meter = 1.0, const std::string& node_transform = "") {
  std::string positions;
  for (int k = 0; k < 8; ++k) {
    // Corner k: x from bit 0 (after the y flip below), y from bit 1, z from bit 2, in the order
    // (x0,y0,z0) (x1,y0,z0) (x1,y1,z0) (x0,y1,z0), then the same at z1.
    const int xbit = (k & 1) ^ ((k >> 1) & 1), ybit = (k >> 1) & 1, zbit = (k >> 2) & 1;
    for (const double v : {xbit ? hi[0] : lo[0], ybit ? hi[1] : lo[1], zbit ? hi[2] : lo[2]})
      positions += std::to_string(v) + " ";
  }
  return "<?xml version=\"1.0\"?>\n<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">\n"
         "<asset><unit meter=\"" + std::to_string(meter) + "\"/>" +
         (up_axis.empty() ? "" : "<up_axis>" + up_axis + "</up_axis>") + "</asset>\n"
         "<library_geometries><geometry id=\"g\"><mesh>\n"
         "<source id=\"p\"><float_array id=\"pa\" count=\"24\">" + positions + "</float_array>\n"
         "<technique_common><accessor source=\"#pa\" count=\"8\" stride=\"3\"><param name=\"X\" type=\"float\"/>"
         "<param name=\"Y\" type=\"float\"/><param name=\"Z\" type=\"float\"/></accessor></technique_common></source>\n"
         "<vertices id=\"v\"><input semantic=\"POSITION\" source=\"#p\"/></vertices>\n"
         "<triangles count=\"12\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/>\n"
         "<p>0 3 2 0 2 1 4 5 6 4 6 7 0 1 5 0 5 4 2 3 7 2 7 6 1 2 6 1 6 5 3 0 4 3 4 7</p></triangles>\n"
         "</mesh></geometry></library_geometries>\n"
         "<library_visual_scenes><visual_scene id=\"s\"><node id=\"n\">" + node_transform +
         "<instance_geometry url=\"#g\"/></node></visual_scene></library_visual_scenes>\n"
         "<scene><instance_visual_scene url=\"#s\"/></scene>\n</COLLADA>\n";
}

/// Runs statement, which must throw LoadError whose file() is file, whose element() contains element
/// and whose reason() contains reason.
#define EXPECT_LOAD_ERROR(statement, file_, element_, reason_)                                          \
  do {                                                                                               \
    try {                                                                                            \
      statement;                                                                                     \
      ADD_FAILURE() << "no LoadError from " #statement;                                              \
    } catch (const ::clearway::LoadError& e) {                                                       \
      EXPECT_EQ(e.file(), (file_)) << e.what();                                                      \
      EXPECT_NE(e.element().find(element_), std::string::npos) << "element: " << e.what();           \
      EXPECT_NE(e.reason().find(reason_), std::string::npos) << "reason: " << e.what();              \
      EXPECT_EQ(std::string(e.what()), ::clearway::LoadError::format(e.file(), e.element(), e.reason())); \
    }                                                                                                \
  } while (false)

}  // namespace clearway::test
