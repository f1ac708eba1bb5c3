// OpenCL runtime: listing, selection, context, program build with the on-disk binary cache.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>
#include <vector>

#include "device/compile_pool.hpp"
#include "device/program_cache.hpp"
#include "tetcollapse/device.hpp"

namespace tc::kernels {
const char* find(const char* name);
}

namespace tc {

const char* cl_error_name(int code) {
  switch (code) {
#define TC_CASE(x) \
  case x:          \
    return #x;
    TC_CASE(CL_SUCCESS)
    TC_CASE(CL_DEVICE_NOT_FOUND)
    TC_CASE(CL_DEVICE_NOT_AVAILABLE)
    TC_CASE(CL_COMPILER_NOT_AVAILABLE)
    TC_CASE(CL_MEM_OBJECT_ALLOCATION_FAILURE)
    TC_CASE(CL_OUT_OF_RESOURCES)
    TC_CASE(CL_OUT_OF_HOST_MEMORY)
    TC_CASE(CL_PROFILING_INFO_NOT_AVAILABLE)
    TC_CASE(CL_MEM_COPY_OVERLAP)
    TC_CASE(CL_IMAGE_FORMAT_MISMATCH)
    TC_CASE(CL_IMAGE_FORMAT_NOT_SUPPORTED)
    TC_CASE(CL_BUILD_PROGRAM_FAILURE)
    TC_CASE(CL_MAP_FAILURE)
    TC_CASE(CL_MISALIGNED_SUB_BUFFER_OFFSET)
    TC_CASE(CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST)
    TC_CASE(CL_COMPILE_PROGRAM_FAILURE)
    TC_CASE(CL_LINKER_NOT_AVAILABLE)
    TC_CASE(CL_LINK_PROGRAM_FAILURE)
    TC_CASE(CL_DEVICE_PARTITION_FAILED)
    TC_CASE(CL_KERNEL_ARG_INFO_NOT_AVAILABLE)
    TC_CASE(CL_INVALID_VALUE)
    TC_CASE(CL_INVALID_DEVICE_TYPE)
    TC_CASE(CL_INVALID_PLATFORM)
    TC_CASE(CL_INVALID_DEVICE)
    TC_CASE(CL_INVALID_CONTEXT)
    TC_CASE(CL_INVALID_QUEUE_PROPERTIES)
    TC_CASE(CL_INVALID_COMMAND_QUEUE)
    TC_CASE(CL_INVALID_HOST_PTR)
    TC_CASE(CL_INVALID_MEM_OBJECT)
    TC_CASE(CL_INVALID_IMAGE_FORMAT_DESCRIPTOR)
    TC_CASE(CL_INVALID_IMAGE_SIZE)
    TC_CASE(CL_INVALID_SAMPLER)
    TC_CASE(CL_INVALID_BINARY)
    TC_CASE(CL_INVALID_BUILD_OPTIONS)
    TC_CASE(CL_INVALID_PROGRAM)
    TC_CASE(CL_INVALID_PROGRAM_EXECUTABLE)
    TC_CASE(CL_INVALID_KERNEL_NAME)
    TC_CASE(CL_INVALID_KERNEL_DEFINITION)
    TC_CASE(CL_INVALID_KERNEL)
    TC_CASE(CL_INVALID_ARG_INDEX)
    TC_CASE(CL_INVALID_ARG_VALUE)
    TC_CASE(CL_INVALID_ARG_SIZE)
    TC_CASE(CL_INVALID_KERNEL_ARGS)
    TC_CASE(CL_INVALID_WORK_DIMENSION)
    TC_CASE(CL_INVALID_WORK_GROUP_SIZE)
    TC_CASE(CL_INVALID_WORK_ITEM_SIZE)
    TC_CASE(CL_INVALID_GLOBAL_OFFSET)
    TC_CASE(CL_INVALID_EVENT_WAIT_LIST)
    TC_CASE(CL_INVALID_EVENT)
    TC_CASE(CL_INVALID_OPERATION)
    TC_CASE(CL_INVALID_GL_OBJECT)
    TC_CASE(CL_INVALID_BUFFER_SIZE)
    TC_CASE(CL_INVALID_MIP_LEVEL)
    TC_CASE(CL_INVALID_GLOBAL_WORK_SIZE)
    TC_CASE(CL_INVALID_PROPERTY)
    TC_CASE(CL_INVALID_IMAGE_DESCRIPTOR)
    TC_CASE(CL_INVALID_COMPILER_OPTIONS)
    TC_CASE(CL_INVALID_LINKER_OPTIONS)
    TC_CASE(CL_INVALID_DEVICE_PARTITION_COUNT)
#undef TC_CASE
    case -1001:
      return "CL_PLATFORM_NOT_FOUND_KHR";
    default: {
      thread_local char buf[32];
      std::snprintf(buf, sizeof buf, "CL_ERROR(%d)", code);
      return buf;
    }
  }
}

namespace detail {
void rethrow_cl_error(const cl::Error& e, const char* what) {
  std::string call = e.what() ? e.what() : "OpenCL call";
  throw DeviceError(call + "(" + what + "): " + cl_error_name(e.err()));
}
}  // namespace detail

namespace {

const char* kNoDriver =
    "no OpenCL device found: install an OpenCL driver (e.g. the Debian package pocl-opencl-icd for the CPU, "
    "or your GPU vendor's OpenCL ICD) and check `clinfo -l`";

bool has_token(const std::string& list, const char* token) {
  std::istringstream in(list);
  std::string t;
  while (in >> t)
    if (t == token) return true;
  return false;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string trim(std::string s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  size_t i = 0;
  while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
  return s.substr(i);
}

struct Found {
  DeviceInfo info;
  cl::Platform platform;
  cl::Device device;
};

// PoCL compiles, besides a work-group function that takes any local size, one specialised for
// each local size a kernel is launched with: on a first run (empty kernel caches) that doubles
// the compile time, which dominates (the bundled bracket: 22 s against 15 s), for no speed we
// can measure (W1 the same). Off unless the user set it; read by PoCL when it compiles.
void prefer_generic_work_groups() {
  static const bool done = [] {
    setenv("POCL_WORK_GROUP_SPECIALIZATION", "0", /*overwrite=*/0);
    return true;
  }();
  (void)done;
}

std::vector<Found> enumerate() {
  prefer_generic_work_groups();
  std::vector<cl::Platform> platforms;
  try {
    cl::Platform::get(&platforms);
  } catch (const cl::Error& e) {
    // The ICD loader reports CL_PLATFORM_NOT_FOUND_KHR when no driver is installed.
    throw DeviceError(std::string(kNoDriver) + " [clGetPlatformIDs: " + cl_error_name(e.err()) + "]");
  }
  std::vector<Found> out;
  int pi = 0;
  for (cl::Platform& p : platforms) {
    std::vector<cl::Device> devices;
    try {
      p.getDevices(CL_DEVICE_TYPE_ALL, &devices);
    } catch (const cl::Error&) {
      devices.clear();  // CL_DEVICE_NOT_FOUND: a platform without devices
    }
    for (cl::Device& d : devices) {
      detail::cl_call("clGetDeviceInfo", [&] {
        DeviceInfo i;
        i.index = static_cast<int>(out.size());
        i.platform_index = pi;
        i.platform_name = trim(p.getInfo<CL_PLATFORM_NAME>());
        i.platform_vendor = trim(p.getInfo<CL_PLATFORM_VENDOR>());
        i.platform_version = trim(p.getInfo<CL_PLATFORM_VERSION>());
        i.name = trim(d.getInfo<CL_DEVICE_NAME>());
        i.vendor = trim(d.getInfo<CL_DEVICE_VENDOR>());
        i.driver_version = trim(d.getInfo<CL_DRIVER_VERSION>());
        i.device_version = trim(d.getInfo<CL_DEVICE_VERSION>());
        i.opencl_c_version = trim(d.getInfo<CL_DEVICE_OPENCL_C_VERSION>());
        cl_device_type t = d.getInfo<CL_DEVICE_TYPE>();
        i.type = (t & CL_DEVICE_TYPE_GPU)           ? "GPU"
                 : (t & CL_DEVICE_TYPE_CPU)         ? "CPU"
                 : (t & CL_DEVICE_TYPE_ACCELERATOR) ? "ACCELERATOR"
                                                    : "OTHER";
        i.compute_units = d.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
        i.global_mem_bytes = d.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
        i.local_mem_bytes = d.getInfo<CL_DEVICE_LOCAL_MEM_SIZE>();
        i.max_alloc_bytes = d.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
        i.max_work_group_size = d.getInfo<CL_DEVICE_MAX_WORK_GROUP_SIZE>();
        std::string ext = d.getInfo<CL_DEVICE_EXTENSIONS>();
        cl_device_fp_config fp = 0;
        try {
          fp = d.getInfo<CL_DEVICE_DOUBLE_FP_CONFIG>();
        } catch (const cl::Error&) {
          fp = 0;  // a 1.2 device without fp64 may reject the query
        }
        i.fp64 = has_token(ext, "cl_khr_fp64") || fp != 0;
        i.int64_atomics_base = has_token(ext, "cl_khr_int64_base_atomics");
        i.int64_atomics_extended = has_token(ext, "cl_khr_int64_extended_atomics");
        out.push_back({std::move(i), p, d});
      });
    }
    ++pi;
  }
  if (out.empty()) throw DeviceError(kNoDriver);
  return out;
}

std::string describe_all(const std::vector<Found>& all) {
  std::string s;
  for (const Found& f : all)
    s += "\n  " + std::to_string(f.info.index) + ": " + f.info.name + " (" + f.info.vendor + ", " + f.info.platform_name +
         ", " + f.info.type + (f.info.fp64 ? "" : ", no fp64") + ")";
  return s;
}

const Found& choose(const std::vector<Found>& all, std::string spec) {
  std::string origin = "--device";
  if (trim(spec).empty()) {
    const char* env = std::getenv("TETCOLLAPSE_DEVICE");
    if (env && *env) {
      spec = env;
      origin = "TETCOLLAPSE_DEVICE";
    }
  }
  spec = trim(spec);
  const Found* pick = nullptr;
  if (!spec.empty()) {
    bool digits = std::all_of(spec.begin(), spec.end(), [](unsigned char c) { return std::isdigit(c); });
    if (digits) {
      unsigned long idx = spec.size() > 9 ? ~0ul : std::stoul(spec);
      if (idx >= all.size())
        throw DeviceError(origin + " " + spec + ": no device with that index; devices are:" + describe_all(all));
      pick = &all[idx];
    } else {
      std::string needle = lower(spec);
      for (const Found& f : all) {
        if (lower(f.info.name).find(needle) != std::string::npos ||
            lower(f.info.vendor).find(needle) != std::string::npos ||
            lower(f.info.platform_name).find(needle) != std::string::npos) {
          pick = &f;
          break;
        }
      }
      if (!pick)
        throw DeviceError(origin + " '" + spec + "': no device name, vendor or platform contains it; devices are:" +
                          describe_all(all));
    }
    if (!pick->info.fp64)
      throw DeviceError("device " + std::to_string(pick->info.index) + " '" + pick->info.name +
                        "' has no double precision (cl_khr_fp64), which tetcollapse needs; choose another with "
                        "--device or TETCOLLAPSE_DEVICE:" + describe_all(all));
    return *pick;
  }
  // Automatic choice: the first GPU with fp64, else the first CPU with fp64, else any with fp64.
  for (const char* type : {"GPU", "CPU"})
    for (const Found& f : all)
      if (f.info.type == type && f.info.fp64) return f;
  for (const Found& f : all)
    if (f.info.fp64) return f;
  throw DeviceError("no OpenCL device with double precision (cl_khr_fp64) found; tetcollapse needs fp64. Devices are:" +
                    describe_all(all));
}

// Replaces each line `#include "name"` by the embedded text of name (once per name), since
// kernels are compiled from memory and have no file path to include from.
void expand_text(const std::string& text, std::string& out, std::set<std::string>& seen, int depth);

void expand(const std::string& name, std::string& out, std::set<std::string>& seen, int depth) {
  const char* text = kernels::find(name.c_str());
  if (!text) throw DeviceError("#include \"" + name + "\": no such embedded kernel file (is it in cl/?)");
  if (depth > 16) throw DeviceError("kernel file '" + name + "': #include nesting too deep");
  expand_text(text, out, seen, depth);
}

void expand_text(const std::string& text, std::string& out, std::set<std::string>& seen, int depth) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    std::string t = trim(line);
    if (t.rfind("#include", 0) == 0) {
      size_t a = t.find('"'), b = a == std::string::npos ? a : t.find('"', a + 1);
      if (b != std::string::npos) {
        std::string inc = t.substr(a + 1, b - a - 1);
        if (seen.insert(inc).second) expand(inc, out, seen, depth + 1);
        out += "\n";
        continue;
      }
    }
    out += line;
    out += '\n';
  }
}

}  // namespace

std::vector<DeviceInfo> list_devices() {
  std::vector<DeviceInfo> out;
  for (Found& f : enumerate()) out.push_back(std::move(f.info));
  return out;
}

DeviceInfo select_device(const std::string& spec) {
  auto all = enumerate();
  return choose(all, spec).info;
}

Context::Context(const std::string& spec) {
  auto all = enumerate();
  const Found& f = choose(all, spec);
  info_ = f.info;
  platform_ = f.platform;
  device_ = f.device;
  init(info_);
}

Context::Context(const DeviceInfo& info) {
  auto all = enumerate();
  if (info.index < 0 || static_cast<size_t>(info.index) >= all.size() || all[info.index].info.name != info.name)
    throw DeviceError("device " + std::to_string(info.index) + " '" + info.name + "' is no longer present");
  const Found& f = all[info.index];
  if (!f.info.fp64) throw DeviceError("device '" + f.info.name + "' has no double precision (cl_khr_fp64)");
  info_ = f.info;
  platform_ = f.platform;
  device_ = f.device;
  init(info_);
}

Context::~Context() = default;

int run_compile_helper(int device_index) {
  try {
    auto all = enumerate();
    if (device_index < 0 || size_t(device_index) >= all.size()) return 2;
    return device_detail::serve_compile_requests(all[size_t(device_index)].device);
  } catch (const std::exception&) {
    return 3;
  }
}

void Context::init(const DeviceInfo&) {
  cpu_tuning_ = info_.type == "CPU";
  // TETCOLLAPSE_TUNING=gpu|cpu overrides the device type's choice (e.g. the whole test suite
  // on PoCL with the GPU choices); anything else is an error, not a silent default
  if (const char* t = std::getenv("TETCOLLAPSE_TUNING"); t && *t) {
    const std::string v = t;
    if (v != "gpu" && v != "cpu")
      throw DeviceError("TETCOLLAPSE_TUNING must be 'gpu' or 'cpu', not '" + v + "'");
    cpu_tuning_ = v == "cpu";
  }
  // TETCOLLAPSE_TEST_GLOBAL_MEM=BYTES: the device's global memory as if it were at most BYTES,
  // so that the tests can reach the refusal of a mesh too large for the device (docs/cli.md)
  if (const char* m = std::getenv("TETCOLLAPSE_TEST_GLOBAL_MEM"); m && *m) {
    char* end = nullptr;
    const unsigned long long v = std::strtoull(m, &end, 10);
    if (end == m || *end != '\0')
      throw DeviceError("TETCOLLAPSE_TEST_GLOBAL_MEM must be a number of bytes, not '" + std::string(m) + "'");
    info_.global_mem_bytes = std::min<uint64_t>(info_.global_mem_bytes, v);
  }
  detail::cl_call("clCreateContext", [&] { context_ = cl::Context(device_); });
  detail::cl_call("clCreateCommandQueue", [&] { queue_ = cl::CommandQueue(context_, device_); });
}

size_t Context::group_size_for(const cl::Kernel& kernel) const {
  size_t limit = info_.max_work_group_size;
  detail::cl_call("clGetKernelWorkGroupInfo", [&] {
    limit = std::min(limit, kernel.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(device_));
  });
  size_t want = work_group_size_ ? work_group_size_ : 128;
  want = std::min(want, std::max<size_t>(limit, 1));
  size_t p = 1;
  while (p * 2 <= want) p *= 2;
  return p;
}

namespace {
// TETCOLLAPSE_PROFILE_KERNELS=1: every launch waits for its kernel, and the wall time is summed
// per launch name; the table (slowest first) goes to stderr when the process ends. For finding
// where a run's time goes: the waits remove the overlap of launches with the host, so totals run
// a little above a normal run's.
struct KernelProfile {
  struct Entry {
    double seconds = 0;
    long launches = 0;
    long items = 0;
  };
  std::mutex m;
  std::map<std::string, Entry> table;
  ~KernelProfile() {
    if (table.empty()) return;
    std::vector<std::pair<std::string, Entry>> rows(table.begin(), table.end());
    std::sort(rows.begin(), rows.end(), [](const auto& x, const auto& y) { return x.second.seconds > y.second.seconds; });
    double total = 0;
    for (const auto& r : rows) total += r.second.seconds;
    std::fprintf(stderr, "kernel profile (TETCOLLAPSE_PROFILE_KERNELS): %.4f s in %zu kernels\n", total, rows.size());
    std::fprintf(stderr, "  %-36s %10s %6s %10s %12s\n", "launch", "seconds", "share", "launches", "launched");
    for (const auto& [name, e] : rows)
      std::fprintf(stderr, "  %-36s %10.4f %5.1f%% %10ld %12ld\n", name.c_str(), e.seconds,
                   total > 0 ? 100 * e.seconds / total : 0.0, e.launches, e.items);
  }
};
KernelProfile* kernel_profile() {
  static const bool on = [] {
    const char* e = std::getenv("TETCOLLAPSE_PROFILE_KERNELS");
    return e && *e && std::strcmp(e, "0") != 0;
  }();
  if (!on) return nullptr;
  static KernelProfile profile;
  return &profile;
}
}  // namespace

void Context::launch_one_group(cl::Kernel& kernel, const char* what) {
  const size_t local = group_size_for(kernel);
  launch(kernel, local, what, local);
}

namespace {
constexpr size_t kSmallGroup = 8;  // the local size of a small launch on a CPU device
}  // namespace

void Context::launch(cl::Kernel& kernel, size_t n, const char* what, size_t local) {
  if (n == 0) return;
  if (local == 0) {
    local = group_size_for(kernel);
    if (work_group_size_ == 0 && cpu_tuning_) {
      // A small launch in few large groups would leave cores idle: it takes one small size
      // instead. One, not a halving per size class: CPU drivers (PoCL) compile a work-group
      // function per kernel and local size on the first run, which each extra size slows.
      const size_t min_groups = 4 * size_t(std::max<uint32_t>(info_.compute_units, 1));
      if ((n + local - 1) / local < min_groups) local = std::max<size_t>(1, std::min<size_t>(local, kSmallGroup));
    }
  }
  size_t global = (n + local - 1) / local * local;
  KernelProfile* prof = kernel_profile();
  if (prof) finish();  // the time of this launch alone
  const auto t0 = std::chrono::steady_clock::now();
  detail::cl_call(what, [&] {
    queue_.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(global), cl::NDRange(local));
  });
  if (!prof) return;
  finish();
  const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::lock_guard<std::mutex> lock(prof->m);
  KernelProfile::Entry& e = prof->table[what];
  e.seconds += dt;
  e.launches += 1;
  e.items += long(n);
}

void Context::finish() {
  detail::cl_call("queue", [&] { queue_.finish(); });
}

std::string Context::cache_dir() {
  if (const char* d = std::getenv("TETCOLLAPSE_CACHE_DIR"); d && *d) return d;
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return (std::filesystem::path(x) / "tetcollapse").string();
  if (const char* h = std::getenv("HOME"); h && *h) return (std::filesystem::path(h) / ".cache" / "tetcollapse").string();
  return "";
}

namespace {

// Files built as one program. Why: each program costs a compiler front end of its own (with PoCL
// about 0.2 s: the shared headers parsed, the kernel library linked), and a first run compiles
// the programs it uses in helper processes, one per core; the collapse's files make two large
// programs and the selection's a third (a run uses one of them: the matching selection, or the
// greedy one under a boundary error bound) (bench/README.md, the first run). The files stay one
// per stage.
const std::vector<std::vector<std::string>> kProgramGroups = {
    {"collapse_connectivity.cl", "collapse_cost.cl", "collapse_verdicts.cl"},
    {"collapse_admissible.cl", "collapse_guard_applied.cl", "collapse_guard.cl", "collapse_compact.cl",
     "collapse_update.cl"},
};

// The program that holds `file`: its name and its text (#include lines, expanded as any include).
std::pair<std::string, std::string> program_of(const std::string& file) {
  const char* text = kernels::find(file.c_str());
  if (!text) throw DeviceError("embedded kernel file '" + file + "' not found (is it in cl/?)");
  for (const auto& group : kProgramGroups)
    if (std::find(group.begin(), group.end(), file) != group.end()) {
      std::string name, source;
      for (const std::string& f : group) {
        name += (name.empty() ? "" : "+") + f;
        source += "#include \"" + f + "\"\n";
      }
      return {name, source};
    }
  return {file, text};
}

}  // namespace

cl::Program& Context::program(const std::string& file, const std::string& options) {
  const auto [name, text] = program_of(file);
  return build(name, text, options);
}

std::string Context::options_as_built(const std::string& name, const std::string& text,
                                      const std::string& options) const {
  std::string opts = "-cl-std=CL1.2";
  // CPU devices run a work-group's items one after another, so a kernel may prefetch for its
  // next items (the selections' decisions and match_apply: tcc_prefetch_test in
  // cl/collapse_select.h, tcc_prefetch_decide and tcc_prefetch_apply in cl/collapse_matching.cl).
  // Measured on PoCL; a CPU runtime that runs work items side by side in vector lanes would make
  // those loads for nothing (no result changes either way).
  if (cpu_tuning_) opts += " -DTCC_PREFETCH";
  // the kernels' parameter names, by which the collapse stages set their arguments
  // (host/collapse/launch.hpp)
  opts += " -cl-kernel-arg-info";
  if (!options.empty()) opts += " " + options;
  if (!run_options_.empty()) {
    bool applies = run_header_.empty();
    if (!applies) {
      const std::string key = name + '\n' + std::to_string(std::hash<std::string>{}(text));
      auto it = includes_.find(key);
      if (it == includes_.end()) {
        std::set<std::string> seen{name};
        std::string expanded;
        expand_text(text, expanded, seen, 0);
        it = includes_.emplace(key, std::move(seen)).first;
      }
      applies = it->second.count(run_header_) > 0;
    }
    if (applies) opts += " " + run_options_;
  }
  if (const char* extra = std::getenv("TETCOLLAPSE_CL_OPTIONS"); extra && *extra) opts += std::string(" ") + extra;
  return opts;
}

Context::Unit Context::unit(const std::string& file, const std::string& text, const std::string& options) const {
  Unit u;
  u.opts = options_as_built(file, text, options);
  std::set<std::string> seen{file};
  expand_text(text, u.source, seen, 0);
  u.cache_key = info_.name + '\n' + info_.vendor + '\n' + info_.driver_version + '\n' + info_.platform_version + '\n' +
                u.opts + '\n' + u.source;
  return u;
}

device_detail::CompilePool& Context::pool() {
  if (!pool_) {
    const unsigned cores = std::thread::hardware_concurrency();
    pool_ = std::make_unique<device_detail::CompilePool>(device_, info_.index, std::clamp(cores, 1u, 4u));
  }
  return *pool_;
}

void Context::prefetch(const std::string& file_in, const std::string& options) {
  const auto [file, text] = program_of(file_in);
  if (programs_.count({file, options_as_built(file, text, options)})) return;
  Unit u = unit(file, text, options);
  device_detail::ProgramCache cache(cache_dir(), u.cache_key);
  std::error_code ec;
  if (!cache.path().empty() && std::filesystem::exists(cache.path(), ec)) return;
  const std::string pool_key = u.opts + '\n' + file;
  if (pool().has(pool_key)) return;
  ++compiles_total_;
  if (compile_notice_) compile_notice_(file, compiles_done_, compiles_total_);
  pool().prefetch(pool_key, {u.source, u.opts, cache_dir(), u.cache_key});
}

cl::Program& Context::build(const std::string& file, const std::string& text, const std::string& options) {
  // in memory under the options as built: a change of cpu_tuning or of the environment's
  // options between two calls builds again
  const std::string opts = options_as_built(file, text, options);
  auto key = std::make_pair(file, opts);
  if (auto it = programs_.find(key); it != programs_.end()) {
    last_build_source_ = BuildSource::Memory;
    return it->second;
  }
  const Unit u = unit(file, text, options);
  device_detail::ProgramCache cache(cache_dir(), u.cache_key);

  // a program from a binary (the disk cache's or a compile worker's); false if it will not load
  auto from_binary = [&](const std::vector<unsigned char>& binary, cl::Program& prog) {
    try {
      cl::Program::Binaries bins{binary};
      std::vector<cl_int> status;
      prog = cl::Program(context_, {device_}, bins, &status);
      prog.build({device_}, opts.c_str());
      // a driver may keep no argument names in a binary: then from source
      std::vector<cl::Kernel> kernels;
      prog.createKernels(&kernels);
      if (!kernels.empty() && kernels[0].getInfo<CL_KERNEL_NUM_ARGS>() > 0)
        (void)kernels[0].getArgInfo<CL_KERNEL_ARG_NAME>(0);
      return true;
    } catch (const cl::Error&) {
      return false;  // a stale or corrupt binary
    }
  };

  cl::Program prog;
  const std::string pool_key = opts + '\n' + file;
  const bool prefetched = pool_ && pool_->has(pool_key);  // then from the pool, which holds its binary
  if (auto binary = prefetched ? std::nullopt : cache.load(); binary && from_binary(*binary, prog)) {
    last_build_source_ = BuildSource::DiskCache;
    return programs_.emplace(key, std::move(prog)).first->second;
  }
  if (!prefetched) {
    ++compiles_total_;
    if (compile_notice_) compile_notice_(file, compiles_done_, compiles_total_);
  }
  last_build_source_ = BuildSource::Source;
  auto compiled = [&]() -> cl::Program& {
    ++compiles_done_;
    if (compile_notice_) compile_notice_(file, compiles_done_, compiles_total_);
    return programs_.emplace(key, std::move(prog)).first->second;
  };
  // on a worker (which also stores the binary on disk), while the others compile what was
  // prefetched; from source here when that gives no binary, with the build log on failure
  if (auto binary = pool().take(pool_key, {u.source, u.opts, cache_dir(), u.cache_key});
      !binary.empty() && from_binary(binary, prog))
    return compiled();
  detail::cl_call(("clCreateProgramWithSource(" + file + ")").c_str(), [&] { prog = cl::Program(context_, u.source); });
  try {
    prog.build({device_}, opts.c_str());
  } catch (const cl::Error& e) {
    std::string log;
    try {
      log = prog.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device_);
    } catch (const cl::Error&) {
      log = "(no build log)";
    }
    throw DeviceError("clBuildProgram(" + file + "): " + cl_error_name(e.err()) + " on '" + info_.name +
                      "' with options '" + opts + "'; build log:\n" + log);
  }
  return compiled();
}

cl::Kernel Context::kernel(const std::string& file, const std::string& name, const std::string& options) {
  cl::Program& p = program(file, options);
  cl::Kernel k;
  detail::cl_call(("clCreateKernel(" + name + ")").c_str(), [&] { k = cl::Kernel(p, name.c_str()); });
  return k;
}

}  // namespace tc
