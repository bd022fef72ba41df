// Mesh input made to crash, hang or exhaust Clearway, each generated here as it was found: a reader's
// error quoting the rest of a file. Each ends in a LoadError naming the file, element and reason, or in
// a mesh; and runs under a timeout, so that a hang fails the test instead of blocking the suite.
#include <clearway/load/mesh_loader.h>

#include "load/robot_files.h"
#include "timeout_guard.h"

#include <gtest/gtest.h>

#include <string>

using namespace clearway;
using clearway::test::endsWithin;
using clearway::test::TempDir;

namespace {

// Long enough for any of these inputs under the sanitizers, short next to a hang.
constexpr double kSeconds = 60.0;

// what() of the LoadError that statement throws ("" when none).
template <class F>
std::string errorOf(F&& statement) {
  try {
    statement();
  } catch (const LoadError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// An ASCII STL with one bad number among 20,000 facets: assimp's message quoted the rest of the file.
TEST(HostileMesh, ErrorsQuoteAFewDozenCharactersOfTheInput) {
  TempDir dir;
  std::string facets;
  for (int i = 0; i < 20000; ++i)
    facets += "facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n";
  const std::string stl = dir.write(
      "bad_number.stl", "solid s\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 x\nendloop\n"
                        "endfacet\n" + facets + "endsolid s\n");
  ASSERT_GT(std::filesystem::file_size(stl), 1000000u);
  std::string message;
  endsWithin(kSeconds, [&] { message = errorOf([&] { loadMesh(stl, Vec3::Ones()); }); });
  ASSERT_NE(message, "");
  EXPECT_LT(message.size(), 400u) << message.substr(0, 1000);
  EXPECT_NE(message.find(stl), std::string::npos) << message.substr(0, 1000);
}
