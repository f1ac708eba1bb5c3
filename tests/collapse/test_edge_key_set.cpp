// EdgeKeySet (host/collapse/edge_key_set.hpp), the host tail's set of queued edges: the same
// answers as std::unordered_set over random inserts and erases; erases from long and wrapping
// probe runs (keys made for chosen home slots); growth.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
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

// Keys made to land on chosen home slots (the inverse of the hash's multiplier): long runs of
// keys sharing a home, runs that wrap around the end of the table, runs mixing keys that may
// move back at an erase with keys that may not; erased in random orders, every other key checked
// after each erase. The table keeps its first size (1024 slots) for at most 511 keys.
TEST(EdgeKeySet, ErasesFromCrowdedAndWrappingRuns) {
  const uint64_t mul = 0x9E3779B97F4A7C15ull;  // EdgeKeySet's hash: the top 10 bits of key * mul
  uint64_t inv = mul;
  for (int i = 0; i < 6; ++i) inv *= 2 - mul * inv;  // Newton: mul * inv == 1 mod 2^64
  ASSERT_EQ(mul * inv, 1ull);
  std::mt19937_64 rng(5);
  auto with_home = [&](uint64_t h) {  // a key whose home slot in 1024 is h
    for (;;) {
      const uint64_t k = ((h << 54) | (rng() >> 10)) * inv;
      if (k != ~0ull) return k;
    }
  };
  std::vector<uint64_t> keys;
  const std::pair<uint64_t, int> homes[] = {{1019, 3}, {1021, 6}, {1023, 5}, {0, 4}, {2, 2},  // wrapping
                                            {500, 7},  {501, 1},  {503, 4},  {505, 1}, {506, 3},
                                            {700, 1},  {701, 1},  {702, 1}};
  for (auto [h, count] : homes)
    for (int i = 0; i < count; ++i) keys.push_back(with_home(h));
  for (int i = 0; i < 300; ++i) keys.push_back(with_home(rng() % 1024));  // and the rest of the table
  for (int round = 0; round < 30; ++round) {
    EdgeKeySet set;
    std::vector<uint64_t> order = keys;
    std::shuffle(order.begin(), order.end(), rng);
    for (uint64_t k : order) ASSERT_TRUE(set.insert(k));
    for (uint64_t k : order) ASSERT_FALSE(set.insert(k));
    std::shuffle(order.begin(), order.end(), rng);
    for (size_t i = 0; i < order.size(); ++i) {
      ASSERT_TRUE(set.erase(order[i]));
      ASSERT_FALSE(set.erase(order[i]));
      ASSERT_FALSE(set.contains(order[i]));
      for (size_t j = i + 1; j < order.size(); ++j) {
        ASSERT_TRUE(set.contains(order[j])) << "round " << round << ", after erase " << i;
      }
    }
    EXPECT_EQ(set.size(), 0u);
  }
}

// Growth: the keys of a crowded 1024-slot table, then enough others to grow it twice; all found,
// and erased, after.
TEST(EdgeKeySet, KeepsItsKeysThroughGrowth) {
  const uint64_t mul = 0x9E3779B97F4A7C15ull;
  uint64_t inv = mul;
  for (int i = 0; i < 6; ++i) inv *= 2 - mul * inv;
  std::mt19937_64 rng(9);
  std::vector<uint64_t> keys;
  for (int i = 0; i < 400; ++i) keys.push_back(((uint64_t(1020 + i % 8) << 54) | (rng() >> 10)) * inv);
  for (int i = 0; i < 3000; ++i) keys.push_back(rng() >> 1);
  EdgeKeySet set;
  for (uint64_t k : keys) ASSERT_TRUE(set.insert(k));
  EXPECT_EQ(set.size(), keys.size());
  for (uint64_t k : keys) ASSERT_TRUE(set.contains(k));
  std::shuffle(keys.begin(), keys.end(), rng);
  for (size_t i = 0; i < keys.size(); ++i) {
    ASSERT_TRUE(set.erase(keys[i]));
    if (i % 500 != 0) continue;
    for (size_t j = i + 1; j < keys.size(); ++j) {
      ASSERT_TRUE(set.contains(keys[j]));
    }
  }
  EXPECT_EQ(set.size(), 0u);
}
