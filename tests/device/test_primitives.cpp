// Device primitives against the standard library: sizes 0, 1, 2^k, 2^k+1, one 10M case,
// adversarial data, and identical results for different work-group sizes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <numeric>
#include <random>
#include <vector>

#include "device/primitives.hpp"
#include "tetcollapse/device.hpp"

namespace {

tc::Context& ctx() {
  static std::unique_ptr<tc::Context> c = std::make_unique<tc::Context>();
  return *c;
}

struct WorkGroup {  // restores the default work-group size when a test ends
  explicit WorkGroup(size_t wg) { ctx().set_work_group_size(wg); }
  ~WorkGroup() { ctx().set_work_group_size(0); }
};

// Every test runs with the device's default tuning and with both explicit variants (local-memory
// tiles with 4-bit digits, as on GPUs; serial chunks with 8-bit digits, as on CPUs), so both code
// paths are checked on any device. The 10M cases run with the default only.
class Tuned : public ::testing::TestWithParam<int> {
 protected:
  void SetUp() override {
    tc::dev::Tuning t;
    if (GetParam() == 1) {
      t.chunked_scan = false;
      t.radix_bits = 4;
      t.sort_chunk = 256;
    } else if (GetParam() == 2) {
      t.chunked_scan = true;
      t.radix_bits = 8;
      t.sort_chunk = 4096;
    }
    tc::dev::set_tuning_override(GetParam() == 0 ? nullptr : &t);
  }
  void TearDown() override { tc::dev::set_tuning_override(nullptr); }
};

// The 10M cases: instantiated with the default tuning only (their point is size, and the
// explicit variants are covered at the sizes of sizes()).
class TunedLarge : public Tuned {};

std::vector<size_t> sizes() {
  std::vector<size_t> s{0, 1, 2, 3, 7};
  for (int k : {4, 8, 10, 11, 13, 16, 17}) {
    s.push_back(size_t{1} << k);
    s.push_back((size_t{1} << k) + 1);
  }
  s.push_back(100003);
  return s;
}

std::vector<uint32_t> random_u32(size_t n, uint32_t bound, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<uint32_t> d(0, bound);
  std::vector<uint32_t> v(n);
  for (auto& x : v) x = d(rng);
  return v;
}

std::vector<uint64_t> random_u64(size_t n, int bits, uint32_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<uint64_t> v(n);
  uint64_t mask = bits == 64 ? ~uint64_t{0} : (uint64_t{1} << bits) - 1;
  for (auto& x : v) x = rng() & mask;
  return v;
}

void expect_scan(const std::vector<uint32_t>& in) {
  tc::DeviceBuffer<uint32_t> d(ctx(), in), out(ctx(), in.size());
  uint32_t total = tc::dev::exclusive_scan(ctx(), d, out);
  std::vector<uint32_t> ref(in.size());
  std::exclusive_scan(in.begin(), in.end(), ref.begin(), uint32_t{0});
  uint32_t ref_total = std::accumulate(in.begin(), in.end(), uint32_t{0});
  ASSERT_EQ(total, ref_total) << "n=" << in.size();
  ASSERT_EQ(out.download(), ref) << "n=" << in.size();
  // In place gives the same.
  EXPECT_EQ(tc::dev::exclusive_scan(ctx(), d, d), ref_total);
  ASSERT_EQ(d.download(), ref) << "in place, n=" << in.size();
}

// Stable sort reference: std::stable_sort of (key, payload) pairs by key.
void expect_sort(const std::vector<uint64_t>& keys, int bits) {
  size_t n = keys.size();
  std::vector<uint32_t> vals(n);
  std::iota(vals.begin(), vals.end(), 0u);
  std::vector<std::pair<uint64_t, uint32_t>> ref(n);
  for (size_t i = 0; i < n; ++i) ref[i] = {keys[i], vals[i]};
  std::stable_sort(ref.begin(), ref.end(), [](auto& a, auto& b) { return a.first < b.first; });

  tc::DeviceBuffer<uint64_t> dk(ctx(), keys);
  tc::DeviceBuffer<uint32_t> dv(ctx(), vals);
  tc::dev::radix_sort(ctx(), dk, dv, n, bits);
  auto k = dk.download();
  auto v = dv.download();
  for (size_t i = 0; i < n; ++i) {
    ASSERT_EQ(k[i], ref[i].first) << "n=" << n << " i=" << i;
    ASSERT_EQ(v[i], ref[i].second) << "n=" << n << " i=" << i << " (stability)";
  }
  tc::DeviceBuffer<uint64_t> dk2(ctx(), keys);
  tc::dev::radix_sort(ctx(), dk2, n, bits);
  ASSERT_EQ(dk2.download(), k) << "keys-only sort, n=" << n;
}

TEST_P(Tuned, Scan_RandomSizes) {
  for (size_t n : sizes()) expect_scan(random_u32(n, 1000, static_cast<uint32_t>(n)));
}

TEST_P(Tuned, Scan_WrapsModulo2To32AndMaxValues) {
  for (size_t n : {size_t{1}, size_t{5}, size_t{4097}, size_t{70001}}) {
    expect_scan(std::vector<uint32_t>(n, 0xffffffffu));
    expect_scan(random_u32(n, 0xffffffffu, 7));
  }
}

TEST_P(TunedLarge, Scan_TenMillion) { expect_scan(random_u32(10'000'000, 3, 42)); }

TEST_P(Tuned, Scan_RejectsShortBuffers) {
  tc::DeviceBuffer<uint32_t> a(ctx(), 10), b(ctx(), 5);
  EXPECT_THROW(tc::dev::exclusive_scan(ctx(), a, b, 10), std::invalid_argument);
}

TEST_P(Tuned, Compact_MatchesCopyIf) {
  for (size_t n : sizes()) {
    auto flags = random_u32(n, 3, static_cast<uint32_t>(n) + 1);  // 0..3: non-zero means keep
    auto vals = random_u32(n, 0xffffffffu, 3);
    std::vector<uint32_t> ref_idx, ref_val;
    std::vector<uint64_t> ref_val64;
    for (size_t i = 0; i < n; ++i)
      if (flags[i]) {
        ref_idx.push_back(static_cast<uint32_t>(i));
        ref_val.push_back(vals[i]);
        ref_val64.push_back((uint64_t{vals[i]} << 32) | i);
      }
    std::vector<uint64_t> vals64(n);
    for (size_t i = 0; i < n; ++i) vals64[i] = (uint64_t{vals[i]} << 32) | i;
    tc::DeviceBuffer<uint32_t> df(ctx(), flags), dv(ctx(), vals), out(ctx(), 0);
    tc::DeviceBuffer<uint64_t> dv64(ctx(), vals64), out64(ctx(), 0);
    ASSERT_EQ(tc::dev::compact_indices(ctx(), df, out, n), ref_idx.size());
    ASSERT_EQ(out.download(), ref_idx) << "n=" << n;
    ASSERT_EQ(tc::dev::compact(ctx(), dv, df, out, n), ref_val.size());
    ASSERT_EQ(out.download(), ref_val) << "n=" << n;
    ASSERT_EQ(tc::dev::compact(ctx(), dv64, df, out64, n), ref_val64.size());
    ASSERT_EQ(out64.download(), ref_val64) << "n=" << n;
  }
}

TEST_P(Tuned, Compact_AllAndNone) {
  size_t n = 5000;
  tc::DeviceBuffer<uint32_t> all(ctx(), std::vector<uint32_t>(n, 0xffffffffu)), none(ctx(), std::vector<uint32_t>(n, 0));
  tc::DeviceBuffer<uint32_t> out(ctx(), 0);
  EXPECT_EQ(tc::dev::compact_indices(ctx(), all, out, n), n);
  std::vector<uint32_t> iota(n);
  std::iota(iota.begin(), iota.end(), 0u);
  EXPECT_EQ(out.download(), iota);
  EXPECT_EQ(tc::dev::compact_indices(ctx(), none, out, n), 0u);
  EXPECT_EQ(out.size(), 0u);
}

TEST_P(Tuned, RadixSort_RandomSizesAndBitWidths) {
  for (size_t n : sizes()) expect_sort(random_u64(n, 64, static_cast<uint32_t>(n)), 64);
  for (int bits : {1, 3, 4, 17, 33, 63})
    for (size_t n : {size_t{1000}, size_t{65537}}) expect_sort(random_u64(n, bits, bits), bits);
}

TEST_P(Tuned, RadixSort_Adversarial) {
  for (size_t n : {size_t{2}, size_t{257}, size_t{70000}}) {
    expect_sort(std::vector<uint64_t>(n, 12345), 64);               // all equal: order must stay
    expect_sort(std::vector<uint64_t>(n, ~uint64_t{0}), 64);        // all ones bits, max value
    std::vector<uint64_t> rev(n);
    for (size_t i = 0; i < n; ++i) rev[i] = n - i;
    expect_sort(rev, 64);                                           // reversed
    auto few = random_u64(n, 2, 9);                                 // many duplicates
    for (auto& k : few) k <<= 62;                                   // only in the top bits
    expect_sort(few, 64);
  }
}

TEST_P(Tuned, RadixSort_OnlyRequestedBitsAreSorted) {
  // Bits above key_bits are ignored: keys equal in the low 8 bits keep their input order.
  std::vector<uint64_t> keys{0x105, 0x003, 0x205, 0x001};
  tc::DeviceBuffer<uint64_t> dk(ctx(), keys);
  tc::dev::radix_sort(ctx(), dk, keys.size(), 8);
  EXPECT_EQ(dk.download(), (std::vector<uint64_t>{0x001, 0x003, 0x105, 0x205}));
  std::vector<uint64_t> keys2{0x205, 0x105};
  tc::DeviceBuffer<uint64_t> dk2(ctx(), keys2);
  tc::dev::radix_sort(ctx(), dk2, keys2.size(), 8);
  EXPECT_EQ(dk2.download(), keys2);  // same low byte: stable, upper bits not looked at
  std::vector<uint64_t> keys3{0b1010, 0b0001, 0b1001, 0b0011};  // bit 3 lies above key_bits = 3
  tc::DeviceBuffer<uint64_t> dk3(ctx(), keys3);
  tc::dev::radix_sort(ctx(), dk3, keys3.size(), 3);
  EXPECT_EQ(dk3.download(), (std::vector<uint64_t>{0b0001, 0b1001, 0b1010, 0b0011}));
  EXPECT_THROW(tc::dev::radix_sort(ctx(), dk2, 2, 0), std::invalid_argument);
  EXPECT_THROW(tc::dev::radix_sort(ctx(), dk2, 2, 65), std::invalid_argument);
}

TEST_P(TunedLarge, RadixSort_TenMillion) { expect_sort(random_u64(10'000'000, 40, 5), 40); }

TEST_P(Tuned, Segments_UniqueAndReduceByKey) {
  for (size_t n : sizes()) {
    auto keys = random_u64(n, 64, 11);
    for (auto& k : keys) k %= std::max<size_t>(1, n / 3 + 1);  // runs of various lengths
    std::sort(keys.begin(), keys.end());
    auto vals = random_u32(n, 0xffffffffu, 12);
    std::vector<uint64_t> ref_keys;
    std::vector<uint32_t> ref_starts, ref_sum, ref_min, ref_max, ref_flags(n);
    for (size_t i = 0; i < n; ++i) {
      if (i == 0 || keys[i] != keys[i - 1]) {
        ref_flags[i] = 1;
        ref_keys.push_back(keys[i]);
        ref_starts.push_back(static_cast<uint32_t>(i));
        ref_sum.push_back(0);
        ref_min.push_back(vals[i]);
        ref_max.push_back(vals[i]);
      }
      ref_sum.back() += vals[i];
      ref_min.back() = std::min(ref_min.back(), vals[i]);
      ref_max.back() = std::max(ref_max.back(), vals[i]);
    }
    ref_starts.push_back(static_cast<uint32_t>(n));
    uint32_t count_ref = static_cast<uint32_t>(ref_keys.size());

    tc::DeviceBuffer<uint64_t> dk(ctx(), keys), uk(ctx(), 0);
    tc::DeviceBuffer<uint32_t> dv(ctx(), vals), flags(ctx(), 0), starts(ctx(), 0), out(ctx(), 0);
    ASSERT_EQ(tc::dev::segment_heads(ctx(), dk, n, flags, starts), count_ref);
    ASSERT_EQ(flags.download(), ref_flags);
    ASSERT_EQ(starts.download(), ref_starts);
    ASSERT_EQ(tc::dev::unique_by_key(ctx(), dk, n, uk, starts), count_ref);
    ASSERT_EQ(uk.download(), ref_keys);
    ASSERT_EQ(starts.download(), ref_starts);
    tc::dev::reduce_by_segment(ctx(), dv, starts, count_ref, out, tc::dev::ReduceOp::Sum);
    ASSERT_EQ(out.download(), ref_sum) << "n=" << n;
    tc::dev::reduce_by_segment(ctx(), dv, starts, count_ref, out, tc::dev::ReduceOp::Min);
    ASSERT_EQ(out.download(), ref_min) << "n=" << n;
    ASSERT_EQ(tc::dev::reduce_by_key(ctx(), dk, dv, n, uk, out, tc::dev::ReduceOp::Max), count_ref);
    ASSERT_EQ(out.download(), ref_max) << "n=" << n;
  }
}

TEST_P(Tuned, Segments_OneLongSegment) {
  size_t n = 300000;
  tc::DeviceBuffer<uint64_t> dk(ctx(), std::vector<uint64_t>(n, ~uint64_t{0})), uk(ctx(), 0);
  tc::DeviceBuffer<uint32_t> dv(ctx(), std::vector<uint32_t>(n, 3)), out(ctx(), 0);
  ASSERT_EQ(tc::dev::reduce_by_key(ctx(), dk, dv, n, uk, out), 1u);
  EXPECT_EQ(uk.download(), std::vector<uint64_t>{~uint64_t{0}});
  EXPECT_EQ(out.download(), std::vector<uint32_t>{static_cast<uint32_t>(3 * n)});
}

TEST_P(Tuned, WorkGroupSize_ResultsDoNotDependOnIt) {
  size_t n = 40000 + 17;
  auto keys = random_u64(n, 20, 77);
  auto vals = random_u32(n, 5, 78);
  std::vector<std::vector<uint32_t>> scans, sort_vals, compacts, sums;
  std::vector<std::vector<uint64_t>> sort_keys;
  for (size_t wg : {size_t{1}, size_t{2}, size_t{32}, size_t{64}, size_t{256}, size_t{0}}) {
    WorkGroup guard(wg);
    tc::DeviceBuffer<uint32_t> dv(ctx(), vals), out(ctx(), n);
    tc::dev::exclusive_scan(ctx(), dv, out);
    scans.push_back(out.download());
    tc::dev::compact_indices(ctx(), dv, out, n);
    compacts.push_back(out.download());
    tc::DeviceBuffer<uint64_t> dk(ctx(), keys), uk(ctx(), 0);
    tc::DeviceBuffer<uint32_t> payload(ctx(), vals);
    tc::dev::radix_sort(ctx(), dk, payload, n, 20);
    sort_keys.push_back(dk.download());
    sort_vals.push_back(payload.download());
    tc::dev::reduce_by_key(ctx(), dk, payload, n, uk, out);
    sums.push_back(out.download());
  }
  for (size_t i = 1; i < scans.size(); ++i) {
    EXPECT_EQ(scans[i], scans[0]) << "work-group size case " << i;
    EXPECT_EQ(compacts[i], compacts[0]) << "work-group size case " << i;
    EXPECT_EQ(sort_keys[i], sort_keys[0]) << "work-group size case " << i;
    EXPECT_EQ(sort_vals[i], sort_vals[0]) << "work-group size case " << i;
    EXPECT_EQ(sums[i], sums[0]) << "work-group size case " << i;
  }
  EXPECT_TRUE(std::is_sorted(sort_keys[0].begin(), sort_keys[0].end()));
}

INSTANTIATE_TEST_SUITE_P(Tunings, Tuned, ::testing::Values(0, 1, 2),
                         [](const ::testing::TestParamInfo<int>& i) {
                           return std::string(i.param == 0 ? "DeviceDefault" : i.param == 1 ? "TilesRadix4" : "ChunksRadix8");
                         });
INSTANTIATE_TEST_SUITE_P(Tunings, TunedLarge, ::testing::Values(0),
                         [](const ::testing::TestParamInfo<int>&) { return std::string("DeviceDefault"); });

}  // namespace
