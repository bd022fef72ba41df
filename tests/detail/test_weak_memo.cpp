// WeakMemo (detail/weak_memo.h): a value is found while both its objects live and never after, the memo
// keeps no object alive, and entries of objects gone are swept a constant number of times each.
#include <clearway/detail/weak_memo.h>

#include <gtest/gtest.h>

#include <memory>
#include <optional>
#include <vector>

namespace clearway {
namespace {

using Memo = detail::WeakMemo<int, double, int>;

TEST(WeakMemo, FoundWhileBothObjectsLiveAndNeverAfter) {
  Memo memo;
  auto a = std::make_shared<const int>(1), b = std::make_shared<const int>(2);
  EXPECT_FALSE(memo.find(7).has_value());
  memo.store(7, a, b, 0.5);
  ASSERT_TRUE(memo.find(7).has_value());
  EXPECT_EQ(*memo.find(7), 0.5);
  EXPECT_FALSE(memo.find(8).has_value());
  memo.store(7, a, b, 0.25);  // a new value replaces the old
  EXPECT_EQ(*memo.find(7), 0.25);

  const std::weak_ptr<const int> watch = b;
  b.reset();
  EXPECT_TRUE(watch.expired()) << "the memo keeps no object alive";
  EXPECT_FALSE(memo.find(7).has_value()) << "an entry is found only while both objects live";
  memo.store(9, a, a, 1.0);  // one object may be both
  EXPECT_EQ(*memo.find(9), 1.0);
  a.reset();
  EXPECT_FALSE(memo.find(9).has_value());
}

TEST(WeakMemo, EntriesOfObjectsGoneAreSweptAConstantNumberOfTimesEach) {
  Memo memo;
  const auto kept = std::make_shared<const int>(0);
  const int n = 10000;
  for (int k = 0; k < n; ++k) {
    const auto gone = std::make_shared<const int>(k);
    memo.store(k, kept, gone, k);  // its object dies at once
  }
  const Memo::Stats s = memo.stats();
  EXPECT_EQ(s.stored, n);
  EXPECT_LT(s.entries, 200u) << "entries of objects gone are dropped";
  EXPECT_LE(s.swept, 3LL * n) << "each entry is visited a few times, not once per store";
  EXPECT_GE(s.swept, n - 200LL);
}

}  // namespace
}  // namespace clearway
