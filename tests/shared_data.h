#pragma once
// Where the tests find the shared development data (robots and scenes that are not ours to copy into
// the repository, see DATA.md), and what happens when it is missing: every test that reads it goes
// through here. The folder is $CLEARWAY_SHARED when that is set and not empty, else the path compiled
// in (CLEARWAY_SHARED_DIR, ../shared next to the repository). A test whose data is missing is skipped,
// except when CI=true: CI has the data, so a missing folder there is a broken setup and fails the test
// rather than letting it pass silently.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace clearway::test {

/// The shared data folder: $CLEARWAY_SHARED if set and not empty, else CLEARWAY_SHARED_DIR.
inline std::string sharedDir() {
  const char* env = std::getenv("CLEARWAY_SHARED");
  return env && *env ? std::string(env) : std::string(CLEARWAY_SHARED_DIR);
}

/// True when missing shared data must fail the test instead of skipping it (the environment has CI=true).
inline bool sharedDataRequired() {
  const char* ci = std::getenv("CI");
  return ci && std::string(ci) == "true";
}

/// sharedDir()/rel when it exists (file or folder), else "".
inline std::string sharedPath(const std::string& rel) {
  const std::string p = sharedDir() + "/" + rel;
  return std::filesystem::exists(p) ? p : "";
}

/// The message of a test that cannot find its shared data.
inline std::string sharedMissing(const std::string& rel) {
  return "shared data not found: " + sharedDir() + "/" + rel +
         " (the development data next to the repository, or $CLEARWAY_SHARED; see DATA.md)" +
         (sharedDataRequired() ? ": required because CI=true" : "");
}

/// The shared robots that tests of "every robot" run beside ours (folder-relative URDF paths).
inline const char* const kSharedArms[] = {"robots/panda/panda.urdf", "robots/ur5/ur5.urdf"};

/// Our two arms, then the shared Panda and UR5 (a test requires those first: CLEARWAY_REQUIRE_SHARED_ARMS).
inline std::vector<std::string> allArms() {
  std::vector<std::string> urdfs{std::string(CLEARWAY_SOURCE_DIR) + "/robots/arm6/arm6.urdf",
                                 std::string(CLEARWAY_SOURCE_DIR) + "/robots/twin_arm/twin_arm.urdf"};
  for (const char* rel : kSharedArms) urdfs.push_back(sharedPath(rel));
  return urdfs;
}

}  // namespace clearway::test

/// Fails the test (CI=true) or skips it (otherwise) when sharedDir()/rel is missing. For use in the body
/// of a TEST (it returns from the function).
#define CLEARWAY_REQUIRE_SHARED(rel)                                                                   \
  do {                                                                                               \
    if (::clearway::test::sharedPath(rel).empty()) {                                                 \
      if (::clearway::test::sharedDataRequired()) GTEST_FAIL() << ::clearway::test::sharedMissing(rel); \
      else GTEST_SKIP() << ::clearway::test::sharedMissing(rel);                                     \
    }                                                                                                \
  } while (false)

/// Declares `var` = sharedDir()/rel, failing or skipping the test as CLEARWAY_REQUIRE_SHARED when missing.
#define CLEARWAY_SHARED_OR_SKIP(var, rel)                                                              \
  CLEARWAY_REQUIRE_SHARED(rel);                                                                      \
  const std::string var = ::clearway::test::sharedPath(rel)

/// CLEARWAY_REQUIRE_SHARED for each of the shared arms allArms() lists.
#define CLEARWAY_REQUIRE_SHARED_ARMS() \
  for (const char* rel_ : ::clearway::test::kSharedArms) CLEARWAY_REQUIRE_SHARED(rel_)
