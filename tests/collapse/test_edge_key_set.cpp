// EdgeKeySet (host/collapse/edge_key_set.hpp), the host tail's set of queued edges: the same
// answers as std::unordered_set over random inserts and erases, with keys crowded into few
// home slots (long probe runs, erases from their middle) and through growths.
#include <gtest/gtest.h>

#include <cstdint>
#include <algorithm>
#include <random>
#include <unordered_set>
#include <vector>

#include "collapse/edge_key_set.hpp"

using tc::sequential_detail::EdgeKeySet;

namespace {
uint64_t key(int32_t a, int32_t b) { return uint64_t(uint32_t(a)) << 32 | uint32_t(b); }
}  // namespace

TEST(EdgeKeySet, AnswersAsUnorderedSet) {
  for (int range : {40, 3000, 200000}) {  // few distinct keys (many repeats), then many (growth)
    SCOPED_TRACE(range);
    std::mt19937 rng(7 + range);
    std::uniform_int_distribution<int32_t> v(0, range);
    EdgeKeySet set;
    std::unordered_set<uint64_t> ref;
    for (int op = 0; op < 300000; ++op) {
      const int32_t a = v(rng), b = v(rng);
      const uint64_t k = key(std::min(a, b), std::max(a, b));
      if (rng() % 3 == 0) {
        ASSERT_EQ(set.erase(k), ref.erase(k) == 1) << "op " << op;
      } else {
        ASSERT_EQ(set.insert(k), ref.insert(k).second) << "op " << op;
      }
      ASSERT_EQ(set.size(), ref.size());
    }
    for (const uint64_t k : ref) ASSERT_TRUE(set.contains(k));
    for (int i = 0; i < 1000; ++i) {
      const uint64_t k = key(v(rng), v(rng));
      ASSERT_EQ(set.contains(k), ref.count(k) == 1);
    }
    set.clear();
    EXPECT_EQ(set.size(), 0u);
    for (const uint64_t k : ref) ASSERT_FALSE(set.contains(k));
  }
}

// Keys that differ only in their high bits (the hash keeps the high bits of a product): runs of
// neighbours, erased in every order from the middle of their run.
TEST(EdgeKeySet, ErasesFromLongRuns) {
  std::vector<uint64_t> keys;
  for (int32_t a = 0; a < 600; ++a) keys.push_back(key(a, 0));
  for (uint64_t k = 1; k < 600; ++k) keys.push_back(k);  // a = 0: homes crowd together
  std::mt19937 rng(11);
  for (int round = 0; round < 20; ++round) {
    EdgeKeySet set;
    for (uint64_t k : keys) ASSERT_TRUE(set.insert(k));
    std::vector<uint64_t> order = keys;
    std::shuffle(order.begin(), order.end(), rng);
    for (size_t i = 0; i < order.size(); ++i) {
      ASSERT_TRUE(set.erase(order[i]));
      ASSERT_FALSE(set.contains(order[i]));
      if (i % 97 != 0) continue;
      for (size_t j = i + 1; j < order.size(); ++j) {
        ASSERT_TRUE(set.contains(order[j])) << i << " " << j;
      }
    }
    EXPECT_EQ(set.size(), 0u);
  }
}
