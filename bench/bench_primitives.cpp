// Device primitives against the standard library and Boost.Compute, in the same run.
//
//   bench_primitives [--device SPEC] [--runs 5] [--sizes 1000000,10000000] [--no-startup]
//
// Prints keys (or values) per second, medians of --runs timed runs after one warm-up, for
//   radix sort  64-bit keys + 32-bit payload: ours (64 and 40 key bits), Boost.Compute
//               stable_sort_by_key and its radix_sort_by_key, std::sort (keys only),
//               std::stable_sort (key, payload pairs);
//   scan        exclusive scan of uint32: ours, Boost.Compute, std::exclusive_scan;
// and the start-up time (Context + first scan/sort/segments) of a fresh process with an empty
// program cache against a second process that finds the cached binaries.
//
// Boost.Compute is used on our own context and queue (it wraps the cl_context /
// cl_command_queue handles).
//
// Include order matters: Boost.Compute defines CL_TARGET_OPENCL_VERSION=120 before <CL/cl.h>
// when it comes first, and <CL/opencl.hpp> (target 3.0) then misses the 2.0 declarations
// ("CL_DEVICE_QUEUE_ON_HOST_PROPERTIES was not declared"). Our header goes first.
#include "device/primitives.hpp"
#include "tetcollapse/device.hpp"

// BOOST_COMPUTE_MAX_CL_VERSION=102 cannot be combined with <CL/opencl.hpp> at target 3.0
// (cl_versions.hpp: "#error CL_TARGET_OPENCL_VERSION definition does not match
// BOOST_COMPUTE_MAX_CL_VERSION"), so Boost.Compute sees the 3.0 headers; it runs on our
// context and queue, which were created with 1.2 calls.
#include <boost/compute/algorithm/exclusive_scan.hpp>
#include <boost/compute/algorithm/stable_sort_by_key.hpp>
#include <boost/compute/algorithm/detail/radix_sort.hpp>
#include <boost/compute/command_queue.hpp>
#include <boost/compute/container/vector.hpp>
#include <boost/compute/context.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace bc = boost::compute;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Median time of `runs` runs of work() after one untimed warm-up; prepare() is untimed.
double median_time(int runs, const std::function<void()>& prepare, const std::function<void()>& work) {
  prepare();
  work();
  std::vector<double> t;
  for (int r = 0; r < runs; ++r) {
    prepare();
    auto t0 = std::chrono::steady_clock::now();
    work();
    t.push_back(seconds_since(t0));
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

void row(const char* what, size_t n, double sec, double ref_sec) {
  std::printf("  %-44s %10zu %10.1f ms %10.1f Mkeys/s %8.2fx\n", what, n, sec * 1e3, n / sec / 1e6, ref_sec / sec);
}

// Child mode: the start-up cost of a process: Context, then one small scan, sort and
// segment pass (which builds scan.cl, sort.cl, segments.cl and runs each kernel once).
int startup(const std::string& spec) {
  auto t0 = std::chrono::steady_clock::now();
  tc::Context ctx(spec);
  std::vector<uint64_t> keys(5000);
  std::mt19937_64 rng(1);
  for (auto& k : keys) k = rng() % 100;
  tc::DeviceBuffer<uint64_t> dk(ctx, keys), uk(ctx, 0);
  tc::DeviceBuffer<uint32_t> dv(ctx, std::vector<uint32_t>(keys.size(), 1)), out(ctx, 0);
  tc::dev::radix_sort(ctx, dk, dv, keys.size(), 64);
  uint32_t segs = tc::dev::reduce_by_key(ctx, dk, dv, keys.size(), uk, out);
  ctx.finish();
  std::printf("%.3f %u\n", seconds_since(t0), segs);
  return 0;
}

double run_startup(const std::string& self, const std::string& env) {
  std::string cmd = env + " '" + self + "' --startup";
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return -1;
  double t = -1;
  unsigned segs = 0;
  if (std::fscanf(p, "%lf %u", &t, &segs) != 2) t = -1;
  pclose(p);
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  std::string spec;
  int runs = 5;
  bool do_startup = true;
  std::vector<size_t> sizes{1'000'000, 10'000'000};
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--startup") return startup(spec);
    if (a == "--device" && i + 1 < argc) spec = argv[++i];
    else if (a == "--runs" && i + 1 < argc) runs = std::max(1, std::atoi(argv[++i]));
    else if (a == "--no-startup") do_startup = false;
    else if (a == "--sizes" && i + 1 < argc) {
      sizes.clear();
      std::stringstream ss(argv[++i]);
      std::string tok;
      while (std::getline(ss, tok, ',')) sizes.push_back(std::stoull(tok));
    } else {
      std::fprintf(stderr, "usage: %s [--device SPEC] [--runs N] [--sizes N,N] [--no-startup]\n", argv[0]);
      return 2;
    }
  }
  try {
    tc::Context ctx(spec);
    std::printf("device: %s (%s, %s, driver %s, %u compute units)\n", ctx.info().name.c_str(),
                ctx.info().platform_name.c_str(), ctx.info().type.c_str(), ctx.info().driver_version.c_str(),
                ctx.info().compute_units);
    std::printf("medians of %d runs after one warm-up; last column: speed relative to the std:: reference row\n",
                runs);

    if (do_startup) {
      // A fresh cache folder and a build option nobody used before make the first process
      // compile everything (our cache and PoCL's own kernel cache both miss); the second
      // process with the same folder and option loads the cached binaries.
      std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
      auto dir = std::filesystem::temp_directory_path() / ("tc-bench-cache-" + std::to_string(std::random_device{}()));
      std::string env = "TETCOLLAPSE_CACHE_DIR='" + dir.string() + "' TETCOLLAPSE_CL_OPTIONS=-DTC_BENCH_NONCE=" +
                        std::to_string(std::random_device{}());
      if (!spec.empty()) env += " TETCOLLAPSE_DEVICE='" + spec + "'";
      double cold = run_startup(self, env);
      double warm = run_startup(self, env);
      double warm2 = run_startup(self, env);
      std::printf("start-up (Context + first scan/sort/segments, separate processes):\n");
      std::printf("  cold (empty program cache)   %8.3f s\n  second start (cached)        %8.3f s\n"
                  "  third start (cached)         %8.3f s\n",
                  cold, warm, warm2);
      std::error_code ec;
      std::filesystem::remove_all(dir, ec);
    }

    bc::context bctx(ctx.context()());
    bc::command_queue bq(ctx.queue()());

    for (size_t n : sizes) {
      std::mt19937_64 rng(n);
      std::vector<uint64_t> keys(n);
      for (auto& k : keys) k = rng();
      std::vector<uint64_t> keys40(keys);
      for (auto& k : keys40) k &= (uint64_t{1} << 40) - 1;
      std::vector<uint32_t> vals(n);
      std::iota(vals.begin(), vals.end(), 0u);
      std::vector<uint32_t> small(n);
      for (auto& v : small) v = static_cast<uint32_t>(rng() % 4);

      std::printf("\nn = %zu\n", n);
      std::printf("  %-44s %10s %13s %17s %9s\n", "sort (64-bit key, 32-bit payload)", "n", "time", "rate", "vs std");
      std::vector<uint64_t> hk;
      std::vector<std::pair<uint64_t, uint32_t>> hp;
      double t_std = median_time(runs, [&] { hk = keys; }, [&] { std::sort(hk.begin(), hk.end()); });
      std::vector<uint64_t> sorted_ref = hk;
      double t_stable = median_time(
          runs,
          [&] {
            hp.resize(n);
            for (size_t i = 0; i < n; ++i) hp[i] = {keys[i], vals[i]};
          },
          [&] { std::stable_sort(hp.begin(), hp.end(), [](auto& a, auto& b) { return a.first < b.first; }); });
      row("std::sort (keys only)", n, t_std, t_std);
      row("std::stable_sort (key, payload pairs)", n, t_stable, t_std);

      tc::DeviceBuffer<uint64_t> dk(ctx, n);
      tc::DeviceBuffer<uint32_t> dv(ctx, n);
      double t_ours = median_time(runs, [&] { dk.upload(keys); dv.upload(vals); ctx.finish(); },
                                  [&] { tc::dev::radix_sort(ctx, dk, dv, n, 64); ctx.finish(); });
      bool ok = dk.download() == sorted_ref;
      row(ok ? "tetcollapse radix_sort, 64 key bits" : "tetcollapse radix_sort, 64 key bits WRONG", n, t_ours, t_std);
      double t_ours40 = median_time(runs, [&] { dk.upload(keys40); dv.upload(vals); ctx.finish(); },
                                    [&] { tc::dev::radix_sort(ctx, dk, dv, n, 40); ctx.finish(); });
      row("tetcollapse radix_sort, 40 key bits", n, t_ours40, t_std);

      bc::vector<cl_ulong> bk(n, bctx);
      bc::vector<cl_uint> bv(n, bctx);
      auto bprep = [&] {
        bc::copy(keys.begin(), keys.end(), bk.begin(), bq);
        bc::copy(vals.begin(), vals.end(), bv.begin(), bq);
        bq.finish();
      };
      try {
        double t_bstable = median_time(runs, bprep, [&] {
          bc::stable_sort_by_key(bk.begin(), bk.end(), bv.begin(), bq);
          bq.finish();
        });
        std::vector<uint64_t> back(n);
        bc::copy(bk.begin(), bk.end(), back.begin(), bq);
        row(back == sorted_ref ? "Boost.Compute stable_sort_by_key" : "Boost.Compute stable_sort_by_key WRONG", n,
            t_bstable, t_std);
        double t_bradix = median_time(runs, bprep, [&] {
          bc::detail::radix_sort_by_key(bk.begin(), bk.end(), bv.begin(), bq);
          bq.finish();
        });
        bc::copy(bk.begin(), bk.end(), back.begin(), bq);
        row(back == sorted_ref ? "Boost.Compute detail::radix_sort_by_key" : "Boost.Compute radix_sort_by_key WRONG",
            n, t_bradix, t_std);
      } catch (const std::exception& e) {
        std::printf("  Boost.Compute sort failed: %s\n", e.what());
      }

      std::printf("  %-44s %10s %13s %17s %9s\n", "exclusive scan (uint32)", "n", "time", "rate", "vs std");
      std::vector<uint32_t> hs(n);
      double t_sscan =
          median_time(runs, [] {}, [&] { std::exclusive_scan(small.begin(), small.end(), hs.begin(), uint32_t{0}); });
      row("std::exclusive_scan", n, t_sscan, t_sscan);
      tc::DeviceBuffer<uint32_t> sin(ctx, small), sout(ctx, n);
      double t_oscan = median_time(runs, [] {}, [&] { tc::dev::exclusive_scan(ctx, sin, sout); ctx.finish(); });
      row(sout.download() == hs ? "tetcollapse exclusive_scan" : "tetcollapse exclusive_scan WRONG", n, t_oscan, t_sscan);
      try {
        bc::vector<cl_uint> bin(small.begin(), small.end(), bq), bout(n, bctx);
        double t_bscan = median_time(runs, [] {}, [&] {
          bc::exclusive_scan(bin.begin(), bin.end(), bout.begin(), bq);
          bq.finish();
        });
        std::vector<uint32_t> back(n);
        bc::copy(bout.begin(), bout.end(), back.begin(), bq);
        row(back == hs ? "Boost.Compute exclusive_scan" : "Boost.Compute exclusive_scan WRONG", n, t_bscan, t_sscan);
      } catch (const std::exception& e) {
        std::printf("  Boost.Compute scan failed: %s\n", e.what());
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_primitives: %s\n", e.what());
    return 3;
  }
  return 0;
}
