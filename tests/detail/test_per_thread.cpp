// PerThread: each thread its own value per owner, made once; a copy is a new owner; a gone owner's values
// are freed, and a new owner at the same address never sees them.
#include <clearway/per_thread.h>

#include <gtest/gtest.h>

#include <memory>
#include <thread>
#include <vector>

namespace clearway {
namespace {

TEST(PerThread, OneValuePerThreadAndOwner) {
  const PerThread<std::vector<int>> owner;
  int made = 0;
  std::vector<int>& mine = owner.get([&] {
    ++made;
    return std::vector<int>{1};
  });
  mine.push_back(2);
  EXPECT_EQ(&owner.get([&] {
    ++made;
    return std::vector<int>{};
  }),
            &mine)
      << "found again, not made again";
  EXPECT_EQ(made, 1);
  // Another thread makes its own.
  std::vector<int>* theirs = nullptr;
  std::thread([&] { theirs = &owner.get([] { return std::vector<int>{7}; }); }).join();
  ASSERT_NE(theirs, nullptr);
  EXPECT_NE(theirs, &mine);
  EXPECT_EQ(mine, (std::vector<int>{1, 2}));
  // A copy is a new owner: it makes its own value on this thread.
  const PerThread<std::vector<int>> copy = owner;
  EXPECT_EQ(copy.get([] { return std::vector<int>{3}; }), std::vector<int>{3});
  EXPECT_EQ(owner.get([] { return std::vector<int>{}; }), (std::vector<int>{1, 2}));
}

TEST(PerThread, AGoneOwnersValuesAreNeverSeenAgain) {
  // Owners made and dropped at (likely) the same address: each sees only what it made.
  for (int i = 0; i < 100; ++i) {
    auto owner = std::make_unique<PerThread<int>>();
    EXPECT_EQ(owner->get([i] { return i; }), i);
    owner->get([] { return -1; }) += 1000;
    EXPECT_EQ(owner->get([] { return -1; }), i + 1000);
  }
  // The values of the 99 gone owners were freed as each next one made its own.
  EXPECT_LE(PerThread<int>::heldByThisThread(), 1u);
}

}  // namespace
}  // namespace clearway
