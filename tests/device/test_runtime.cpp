// OpenCL runtime: listing, selection, error translation, program build with includes and the
// on-disk binary cache, DeviceBuffer.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <random>
#include <string>

#include "test_support.hpp"
#include "tetcollapse/device.hpp"
#include "geometry.h"

namespace {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

using tc::test::EnvVar;

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const tc::DeviceError& e) {
    return e.what();
  }
  return "(no DeviceError)";
}

TEST(Runtime, ListsDevicesWithTheirProperties) {
  auto devices = tc::list_devices();
  ASSERT_FALSE(devices.empty());
  for (size_t i = 0; i < devices.size(); ++i) {
    const auto& d = devices[i];
    EXPECT_EQ(d.index, static_cast<int>(i));
    EXPECT_FALSE(d.name.empty());
    EXPECT_FALSE(d.platform_name.empty());
    EXPECT_FALSE(d.driver_version.empty());
    EXPECT_GT(d.compute_units, 0u);
    EXPECT_GT(d.global_mem_bytes, 0u);
    EXPECT_GT(d.local_mem_bytes, 0u);
    EXPECT_GE(d.max_work_group_size, 1u);
    EXPECT_TRUE(d.type == "GPU" || d.type == "CPU" || d.type == "ACCELERATOR" || d.type == "OTHER");
  }
}

TEST(Runtime, SelectsByIndexSubstringAndEnvironment) {
  auto devices = tc::list_devices();
  const auto& first = devices[0];
  if (!first.fp64) GTEST_SKIP() << "device 0 has no fp64";
  EnvVar clear("TETCOLLAPSE_DEVICE", "");
  EXPECT_EQ(tc::select_device("0").name, first.name);
  // Case-insensitive substring of the name, of the vendor, of the platform.
  std::string part = first.name.substr(0, std::min<size_t>(first.name.size(), 6));
  EXPECT_EQ(tc::select_device(lower(part)).name, first.name);
  EXPECT_EQ(tc::select_device(lower(first.platform_name)).platform_name, first.platform_name);
  {
    EnvVar env("TETCOLLAPSE_DEVICE", "0");
    EXPECT_EQ(tc::select_device().index, 0);
  }
  {
    EnvVar env("TETCOLLAPSE_DEVICE", "no-such-device-xyz");
    std::string m = message_of([] { tc::select_device(); });
    EXPECT_NE(m.find("TETCOLLAPSE_DEVICE"), std::string::npos) << m;
    EXPECT_NE(m.find("no-such-device-xyz"), std::string::npos) << m;
    // An explicit spec wins over the environment.
    EXPECT_EQ(tc::select_device("0").index, 0);
  }
  std::string m = message_of([&] { tc::select_device(std::to_string(devices.size())); });
  EXPECT_NE(m.find("no device with that index"), std::string::npos) << m;
  EXPECT_NE(m.find(first.name), std::string::npos) << "the message lists the devices: " << m;
  m = message_of([] { tc::select_device("zzz-not-a-device"); });
  EXPECT_NE(m.find("zzz-not-a-device"), std::string::npos) << m;
  // The automatic choice prefers a GPU with fp64, then a CPU with fp64.
  auto chosen = tc::select_device();
  EXPECT_TRUE(chosen.fp64);
  bool gpu_fp64 = false;
  for (const auto& d : devices) gpu_fp64 |= d.type == "GPU" && d.fp64;
  EXPECT_EQ(chosen.type, gpu_fp64 ? "GPU" : "CPU");
}

// Re-runs this test binary with no OpenCL driver visible to the ICD loader.
TEST(Runtime, NoDriverSaysToInstallOne) {
  if (std::getenv("TC_TEST_EXPECT_NO_DRIVER")) {
    std::string m = message_of([] { tc::list_devices(); });
    EXPECT_NE(m.find("install an OpenCL driver"), std::string::npos) << m;
    m = message_of([] { tc::Context ctx; });
    EXPECT_NE(m.find("install an OpenCL driver"), std::string::npos) << m;
    return;
  }
  tc::test::TempDir empty;
  std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  std::string out;
  int rc = tc::test::run_command("OCL_ICD_VENDORS=" + empty.path().string() + " OCL_ICD_FILENAMES= TC_TEST_EXPECT_NO_DRIVER=1 '" +
                                     self + "' --gtest_filter=Runtime.NoDriverSaysToInstallOne",
                                 &out);
  EXPECT_EQ(rc, 0) << out;
  EXPECT_NE(out.find("[  PASSED  ] 1 test"), std::string::npos) << out;
}

TEST(Runtime, ErrorNames) {
  EXPECT_STREQ(tc::cl_error_name(CL_OUT_OF_RESOURCES), "CL_OUT_OF_RESOURCES");
  EXPECT_STREQ(tc::cl_error_name(CL_INVALID_WORK_GROUP_SIZE), "CL_INVALID_WORK_GROUP_SIZE");
  EXPECT_STREQ(tc::cl_error_name(-1001), "CL_PLATFORM_NOT_FOUND_KHR");
  EXPECT_STREQ(tc::cl_error_name(-12345), "CL_ERROR(-12345)");
}

class RuntimeCtx : public ::testing::Test {
 protected:
  void SetUp() override {
    cache_ = std::make_unique<EnvVar>("TETCOLLAPSE_CACHE_DIR", dir_.path().string());
    ctx_ = std::make_unique<tc::Context>();
  }
  tc::test::TempDir dir_;
  std::unique_ptr<EnvVar> cache_;
  std::unique_ptr<tc::Context> ctx_;
};

TEST_F(RuntimeCtx, LaunchErrorsNameTheCallTheKernelAndTheError) {
  const char* src = "__kernel void fill(__global uint* a, uint n) { uint i = get_global_id(0); if (i < n) a[i] = i; }";
  cl::Program& p = ctx_->build("fill_test", src);
  cl::Kernel k(p, "fill");
  tc::DeviceBuffer<uint32_t> a(*ctx_, 16);
  k.setArg(0, a.buffer());
  k.setArg(1, cl_uint(16));
  size_t too_big = ctx_->info().max_work_group_size * 2;
  std::string m = message_of([&] { ctx_->launch(k, too_big, "fill", too_big); });
  EXPECT_NE(m.find("clEnqueueNDRangeKernel(fill): CL_INVALID_WORK_"), std::string::npos) << m;
  ctx_->launch(k, 16, "fill");
  auto v = a.download();
  for (uint32_t i = 0; i < 16; ++i) EXPECT_EQ(v[i], i);
}

// The work-group layout of launches. On a CPU device with no size set, a small launch is split
// into at least 4 work-groups per compute unit (the drivers run a group on one thread); a
// launch given its size keeps it; launch_one_group makes one group of group_size_for items.
// tcc_spread_index (collapse_select.h) is a bijection on the launch that puts the first m
// entries of a list, for any m, as evenly as it can over every group.
TEST_F(RuntimeCtx, WorkGroupLayoutOfSmallLaunchesAndTheSpreadIndex) {
  const char* src = R"(#include "collapse_select.h"
__kernel void layout(__global uint* out, uint n) {
  uint i = get_global_id(0);
  if (i == 0) { out[0] = (uint)get_num_groups(0); out[1] = (uint)get_local_size(0); }
  if (i < get_global_size(0)) { out[2 + 2 * i] = tcc_spread_index(); out[3 + 2 * i] = (uint)get_group_id(0); }
})";
  cl::Program& p = ctx_->build("layout_test", src);
  cl::Kernel k(p, "layout");
  const size_t cap = 2 + 2 * 4096;
  tc::DeviceBuffer<uint32_t> out(*ctx_, cap);
  k.setArg(0, out.buffer());
  const bool cpu = ctx_->cpu_tuning();
  const size_t cu = std::max<uint32_t>(ctx_->info().compute_units, 1), full = ctx_->group_size_for(k);
  for (size_t n : {size_t(1), size_t(7), size_t(126), size_t(1000), size_t(4096)}) {
    k.setArg(1, cl_uint(n));
    out.fill(0xffffffffu);
    ctx_->launch(k, n, "layout");
    std::vector<uint32_t> v = out.download();
    const size_t groups = v[0], local = v[1], global = groups * local;
    ASSERT_GE(global, n);
    ASSERT_LE(global, cap / 2 - 1);
    // on a CPU, one small size (8) when the full size would give too few groups: one size
    // more to compile per kernel, not one per halving
    size_t want = full;
    if (cpu && (n + full - 1) / full < 4 * cu) want = std::min<size_t>(full, 8);
    EXPECT_EQ(local, want) << "n " << n;
    if (cpu && local < full && n >= 4 * cu * local) {
      EXPECT_GE(groups, 4 * cu) << "n " << n << ": " << groups << " groups of " << local;
    }
    // the spread index: a permutation of 0 .. global-1; the first m of it in every group or
    // none, for m = groups (one each) and m = 2 x groups (two each, where local >= 2)
    std::vector<int> seen(global, 0), per_group(groups, 0);
    for (size_t i = 0; i < global; ++i) {
      const uint32_t j = v[2 + 2 * i];
      ASSERT_LT(j, global);
      ++seen[j];
      if (j < groups) ++per_group[v[3 + 2 * i]];
    }
    for (size_t j = 0; j < global; ++j) EXPECT_EQ(seen[j], 1) << "index " << j << " taken " << seen[j] << " times";
    for (size_t g = 0; g < groups; ++g) EXPECT_EQ(per_group[g], 1) << "group " << g;
  }
  // a launch given its work-group size keeps it; one group on request
  k.setArg(1, cl_uint(64));
  const size_t small = std::min<size_t>(full, 8);
  ctx_->launch(k, 64, "layout", small);
  std::vector<uint32_t> v = out.download();
  EXPECT_EQ(v[1], small);
  EXPECT_EQ(v[0], (64 + small - 1) / small);
  ctx_->launch_one_group(k, "layout");
  v = out.download();
  EXPECT_EQ(v[0], 1u);
  EXPECT_EQ(v[1], full);
}

TEST_F(RuntimeCtx, ABufferBeyondTheDevicesLargestAllocationIsRefusedWithTheSizes) {
  const uint64_t limit = ctx_->info().max_alloc_bytes;
  ASSERT_GT(limit, 0u);
  try {
    tc::DeviceBuffer<double> b(*ctx_, size_t(limit / sizeof(double)) + 1);
    FAIL() << "a buffer over CL_DEVICE_MAX_MEM_ALLOC_SIZE was allocated";
  } catch (const tc::DeviceError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("too large for device"), std::string::npos) << what;
    EXPECT_NE(what.find(std::to_string(limit >> 20) + " MiB"), std::string::npos) << what;
  }
}

TEST_F(RuntimeCtx, BuildFailureCarriesTheBuildLog) {
  std::string m = message_of([&] { ctx_->build("broken_test", "__kernel void k(__global int* a) { a[0] = undeclared_thing; }"); });
  EXPECT_NE(m.find("clBuildProgram(broken_test): CL_BUILD_PROGRAM_FAILURE"), std::string::npos) << m;
  EXPECT_NE(m.find("build log"), std::string::npos) << m;
  EXPECT_NE(m.find("undeclared_thing"), std::string::npos) << "the log names the bad identifier: " << m;
  m = message_of([&] { ctx_->build("bad_include", "#include \"no_such_file.h\"\n"); });
  EXPECT_NE(m.find("no_such_file.h"), std::string::npos) << m;
  m = message_of([&] { ctx_->program("no_such_stage.cl"); });
  EXPECT_NE(m.find("no_such_stage.cl"), std::string::npos) << m;
}

// geometry.h is included textually from the embedded copy and gives the same numbers as the
// C++ compilation of the same header.
TEST_F(RuntimeCtx, IncludesEmbeddedGeometryHeader) {
  const char* src = R"(#include "geometry.h"
__kernel void orient(__global const double* p, __global double* out) {
  out[0] = tc_orient3d(tc_point(p, 0), tc_point(p, 1), tc_point(p, 2), tc_point(p, 3));
})";
  cl::Program& p = ctx_->build("orient_test", src);
  cl::Kernel k(p, "orient");
  std::vector<double> pts{0.1, 0.2, 0.3, 1.7, 0.1, -0.4, 0.3, 2.1, 0.9, -0.2, 0.5, 1.3};
  tc::DeviceBuffer<double> dp(*ctx_, pts), out(*ctx_, 1);
  k.setArg(0, dp.buffer());
  k.setArg(1, out.buffer());
  ctx_->launch(k, 1, "orient", 1);
  using namespace tc::geo;
  double ref = tc_orient3d(tc_point(pts.data(), 0), tc_point(pts.data(), 1), tc_point(pts.data(), 2),
                           tc_point(pts.data(), 3));
  EXPECT_NE(ref, 0.0);
  EXPECT_DOUBLE_EQ(out.download()[0], ref);
}

// cpu_tuning: the device's type unless TETCOLLAPSE_TUNING says gpu or cpu; another value is
// refused by name.
TEST(Runtime, TuningFollowsTheDeviceTypeOrTheEnvironment) {
  {
    EnvVar v("TETCOLLAPSE_TUNING", "");
    tc::Context c;
    EXPECT_EQ(c.cpu_tuning(), c.info().type == "CPU");
  }
  {
    EnvVar v("TETCOLLAPSE_TUNING", "gpu");
    EXPECT_FALSE(tc::Context().cpu_tuning());
  }
  {
    EnvVar v("TETCOLLAPSE_TUNING", "cpu");
    EXPECT_TRUE(tc::Context().cpu_tuning());
  }
  EnvVar v("TETCOLLAPSE_TUNING", "fast");
  const std::string m = message_of([] { tc::Context c; });
  EXPECT_NE(m.find("TETCOLLAPSE_TUNING"), std::string::npos) << m;
  EXPECT_NE(m.find("'fast'"), std::string::npos) << m;
}

// The in-memory cache is keyed by the options as built: switching cpu_tuning (which adds or drops
// the prefetching define) builds the program again instead of handing back the other variant.
TEST_F(RuntimeCtx, CpuTuningSwitchBuildsItsOwnProgram) {
  const std::string opts = "-DTC_TEST_NONCE=" + std::to_string(std::random_device{}());
  // the prefetching define is in the options a program was built with exactly when cpu_tuning
  auto prefetching = [&](cl::Program& p) {
    return p.getBuildInfo<CL_PROGRAM_BUILD_OPTIONS>(ctx_->device()).find("-DTCC_PREFETCH") != std::string::npos;
  };
  const bool cpu = ctx_->cpu_tuning();
  cl::Program& first = ctx_->program("scan.cl", opts);
  EXPECT_EQ(ctx_->last_build_source(), tc::Context::BuildSource::Source);
  EXPECT_EQ(prefetching(first), cpu);
  ctx_->set_cpu_tuning(!cpu);
  cl::Program& other = ctx_->program("scan.cl", opts);
  EXPECT_EQ(ctx_->last_build_source(), tc::Context::BuildSource::Source);
  EXPECT_NE(&other, &first);
  EXPECT_EQ(prefetching(other), !cpu);
  EXPECT_EQ(&ctx_->program("scan.cl", opts), &other);
  EXPECT_EQ(ctx_->last_build_source(), tc::Context::BuildSource::Memory);
  ctx_->set_cpu_tuning(cpu);
  EXPECT_EQ(&ctx_->program("scan.cl", opts), &first);
  EXPECT_EQ(ctx_->last_build_source(), tc::Context::BuildSource::Memory);
}

TEST_F(RuntimeCtx, BinaryCacheIsUsedOnSecondStartAndSurvivesCorruption) {
  // A unique option makes a fresh cache key even if the folder were shared.
  std::string opts = "-DTC_TEST_NONCE=" + std::to_string(std::random_device{}());
  auto entries = [&] {
    std::vector<std::filesystem::path> v;
    for (auto& e : std::filesystem::directory_iterator(dir_.path())) v.push_back(e.path());
    return v;
  };
  ctx_->program("scan.cl", opts);
  EXPECT_EQ(ctx_->last_build_source(), tc::Context::BuildSource::Source);
  ctx_->program("scan.cl", opts);
  EXPECT_EQ(ctx_->last_build_source(), tc::Context::BuildSource::Memory);
  ASSERT_EQ(entries().size(), 1u) << "one cache entry, no temporary left behind";
  auto file = entries()[0];

  auto second = std::make_unique<tc::Context>();
  second->program("scan.cl", opts);
  EXPECT_EQ(second->last_build_source(), tc::Context::BuildSource::DiskCache);
  second->kernel("scan.cl", "scan_reduce", opts);  // the cached binary holds the kernels

  // Flip a byte inside the binary: the checksum rejects it and the source build takes over.
  {
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(40);
    char c = 0;
    f.read(&c, 1);
    f.seekp(40);
    c = static_cast<char>(c ^ 0x5a);
    f.write(&c, 1);
  }
  auto third = std::make_unique<tc::Context>();
  third->program("scan.cl", opts);
  EXPECT_EQ(third->last_build_source(), tc::Context::BuildSource::Source);
  // ... which rewrote a good entry.
  auto fourth = std::make_unique<tc::Context>();
  fourth->program("scan.cl", opts);
  EXPECT_EQ(fourth->last_build_source(), tc::Context::BuildSource::DiskCache);

  // A truncated entry and garbage are ignored too.
  std::filesystem::resize_file(file, 20);
  auto fifth = std::make_unique<tc::Context>();
  fifth->program("scan.cl", opts);
  EXPECT_EQ(fifth->last_build_source(), tc::Context::BuildSource::Source);
  tc::test::write_text(file.string(), "garbage");
  auto sixth = std::make_unique<tc::Context>();
  sixth->program("scan.cl", opts);
  EXPECT_EQ(sixth->last_build_source(), tc::Context::BuildSource::Source);
}

// A first run compiles the programs it will use in helper processes (tc::set_compile_helper; the
// command line tool names itself): they come back as binaries, land in the disk cache and run.
// A helper that cannot start, or ends at once, leaves the build to this process.
TEST_F(RuntimeCtx, PrefetchedProgramsCompileInHelperProcesses) {
  const std::string opts = "-DTC_TEST_NONCE=" + std::to_string(std::random_device{}());
  const std::string log = (dir_.path() / "helpers.log").string();
  struct Restore {
    ~Restore() { tc::set_compile_helper({}); }
  } restore;
  // the helper as a shell that notes its start, then the tool (the device index is its $0)
  tc::set_compile_helper({"/bin/sh", "-c", "echo started >> '" + log + "'; exec '" TC_CLI "' __compile-helper \"$0\""});
  ctx_->prefetch("segments.cl", opts);
  ctx_->prefetch("scan.cl", opts);
  cl::Kernel k = ctx_->kernel("scan.cl", "compact_indices", opts);
  EXPECT_EQ(ctx_->last_build_source(), tc::Context::BuildSource::Source);
  ctx_->kernel("segments.cl", "segment_heads", opts);
  EXPECT_EQ(ctx_->last_build_source(), tc::Context::BuildSource::Source);
  // the kernel runs: positions of the set flags
  tc::DeviceBuffer<uint32_t> flags(*ctx_, std::vector<uint32_t>{1, 0, 1, 1}), pos(*ctx_, std::vector<uint32_t>{0, 1, 1, 2}),
      out(*ctx_, 3);
  k.setArg(0, flags.buffer());
  k.setArg(1, pos.buffer());
  k.setArg(2, cl_uint(4));
  k.setArg(3, out.buffer());
  ctx_->launch(k, 4, "compact_indices");
  EXPECT_EQ(out.download(), (std::vector<uint32_t>{0, 2, 3}));
  std::ifstream in(log);
  const std::string started((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(started.find("started"), std::string::npos) << "no helper process ran";
  // their binaries are in the disk cache
  auto second = std::make_unique<tc::Context>();
  second->program("scan.cl", opts);
  EXPECT_EQ(second->last_build_source(), tc::Context::BuildSource::DiskCache);
  second->program("segments.cl", opts);
  EXPECT_EQ(second->last_build_source(), tc::Context::BuildSource::DiskCache);

  for (const std::vector<std::string>& helper :
       {std::vector<std::string>{"/no/such/helper"}, std::vector<std::string>{"/bin/sh", "-c", "exit 0"}}) {
    tc::set_compile_helper(helper);
    const std::string o = opts + "1" + std::to_string(helper.size());
    auto third = std::make_unique<tc::Context>();
    third->prefetch("scan.cl", o);
    third->kernel("scan.cl", "compact_indices", o);
    EXPECT_EQ(third->last_build_source(), tc::Context::BuildSource::Source) << helper[0];
  }
}

// The collapse's stage files are built as two programs (one compiler front end each): a file of
// a group gives its group's program, which holds every kernel of the group's files.
TEST_F(RuntimeCtx, FilesOfAGroupShareOneProgram) {
  cl::Program& cost = ctx_->program("collapse_cost.cl");
  EXPECT_EQ(&ctx_->program("collapse_verdicts.cl"), &cost);
  EXPECT_EQ(ctx_->last_build_source(), tc::Context::BuildSource::Memory);
  EXPECT_NE(&ctx_->program("collapse_matching.cl"), &cost) << "a selection is a program of its own";
  ctx_->kernel("collapse_connectivity.cl", "conn_count");
  ctx_->kernel("collapse_cost.cl", "cost_and_mark");
  cl::Program& guard = ctx_->program("collapse_guard.cl");
  EXPECT_NE(&guard, &cost);
  EXPECT_EQ(&ctx_->program("collapse_update.cl"), &guard);
  EXPECT_NE(&ctx_->program("scan.cl"), &cost) << "a file of no group is a program of its own";
}

// Options set for a scope reach every program built in it (or, given a header, those that
// include it), after the call's own; the scope ends, the programs without them come back; the
// innermost scope applies.
TEST_F(RuntimeCtx, ProgramOptionsApplyToEveryProgramOfTheirScope) {
  const auto options = [&](cl::Program& p) { return p.getBuildInfo<CL_PROGRAM_BUILD_OPTIONS>(ctx_->device()); };
  cl::Program& plain = ctx_->program("scan.cl");
  EXPECT_EQ(options(plain).find("-DTCC_VARIANT"), std::string::npos);
  {
    const tc::Context::ProgramOptions variant(*ctx_, "-DTCC_VARIANT");
    cl::Program& scan = ctx_->program("scan.cl");
    EXPECT_NE(&scan, &plain);
    EXPECT_NE(options(scan).find("-DTCC_VARIANT"), std::string::npos) << options(scan);
    EXPECT_NE(options(ctx_->program("scan.cl", "-DTCC_OWN")).find("-DTCC_OWN -DTCC_VARIANT"), std::string::npos);
    {
      const tc::Context::ProgramOptions none(*ctx_, "");
      EXPECT_EQ(&ctx_->program("scan.cl"), &plain);
    }
    EXPECT_EQ(&ctx_->program("scan.cl"), &scan);
  }
  EXPECT_EQ(&ctx_->program("scan.cl"), &plain);
  // with a header: only the programs that include it
  cl::Program& select = ctx_->program("collapse_select_greedy.cl");
  {
    const tc::Context::ProgramOptions variant(*ctx_, "-DTCC_VARIANT", "collapse_select.h");
    EXPECT_EQ(&ctx_->program("scan.cl"), &plain) << "scan.cl does not include collapse_select.h";
    cl::Program& with = ctx_->program("collapse_select_greedy.cl");
    EXPECT_NE(&with, &select);
    EXPECT_NE(options(with).find("-DTCC_VARIANT"), std::string::npos) << options(with);
  }
  EXPECT_EQ(&ctx_->program("collapse_select_greedy.cl"), &select);
}

TEST(Runtime, CacheDirFollowsTheEnvironment) {
  EnvVar a("TETCOLLAPSE_CACHE_DIR", "/tmp/tc-a");
  EXPECT_EQ(tc::Context::cache_dir(), "/tmp/tc-a");
  EnvVar b("TETCOLLAPSE_CACHE_DIR", "");
  EnvVar c("XDG_CACHE_HOME", "/tmp/xdg");
  EXPECT_EQ(tc::Context::cache_dir(), "/tmp/xdg/tetcollapse");
  EnvVar d("XDG_CACHE_HOME", "");
  EnvVar e("HOME", "/home/someone");
  EXPECT_EQ(tc::Context::cache_dir(), "/home/someone/.cache/tetcollapse");
}

TEST_F(RuntimeCtx, DeviceBufferRoundTripsAndChecksRanges) {
  std::vector<uint64_t> v{1, 2, 3, ~uint64_t{0}};
  tc::DeviceBuffer<uint64_t> b(*ctx_, v);
  EXPECT_EQ(b.size(), 4u);
  EXPECT_EQ(b.download(), v);
  EXPECT_EQ(b.download_range(1, 2), (std::vector<uint64_t>{2, 3}));
  uint64_t x = 9;
  b.upload(&x, 1, 3);
  EXPECT_EQ(b.download()[3], 9u);
  EXPECT_THROW(b.upload(&x, 1, 4), tc::DeviceError);
  EXPECT_THROW(b.download_range(3, 2), tc::DeviceError);
  b.fill(7);
  EXPECT_EQ(b.download(), (std::vector<uint64_t>(4, 7)));
  tc::DeviceBuffer<uint64_t> empty(*ctx_, 0);
  EXPECT_EQ(empty.size(), 0u);
  EXPECT_TRUE(empty.download().empty());
  empty.resize(3);
  EXPECT_EQ(empty.size(), 3u);
}

}  // namespace
