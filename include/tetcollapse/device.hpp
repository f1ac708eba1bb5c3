// OpenCL runtime: device listing and selection, a context with its queue, programs built
// from the embedded kernels (cached on disk), and a typed device buffer.
//
// Everything targets OpenCL 1.2 with fp64 so that the same code runs on PoCL and on any GPU.
// Every OpenCL failure surfaces as tc::DeviceError whose message names the call and the
// error, e.g. "clEnqueueNDRangeKernel(scan_blocks): CL_INVALID_WORK_GROUP_SIZE".
#pragma once

// Include <CL/opencl.hpp> only through this header. The Debian bindings (opencl-clhpp-headers
// 3.0~2023.02.06) fail to compile with TARGET=300 and MINIMUM=120: CommandQueue calls
// detail::getContextPlatformVersion, which the header only defines when MINIMUM < 120. With
// MINIMUM=110 the bindings decide at run time (per platform) whether the 2.0 entry points exist,
// which is what an OpenCL 1.2 baseline needs anyway.
#if defined(CL_HPP_MINIMUM_OPENCL_VERSION) && CL_HPP_MINIMUM_OPENCL_VERSION == 120 && \
    defined(CL_HPP_TARGET_OPENCL_VERSION) && CL_HPP_TARGET_OPENCL_VERSION >= 200
#undef CL_HPP_MINIMUM_OPENCL_VERSION
#define CL_HPP_MINIMUM_OPENCL_VERSION 110
#endif
#include <CL/opencl.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "tetcollapse/error.hpp"

namespace tc {

namespace device_detail {
class CompilePool;
}

// One OpenCL device as listed by `tetcollapse devices`.
struct DeviceInfo {
  int index = 0;                 // global index over all platforms, as used by --device INDEX
  int platform_index = 0;
  std::string platform_name, platform_vendor, platform_version;
  std::string name, vendor, driver_version, device_version, opencl_c_version;
  std::string type;              // "GPU", "CPU", "ACCELERATOR" or "OTHER"
  uint32_t compute_units = 0;
  uint64_t global_mem_bytes = 0, local_mem_bytes = 0, max_alloc_bytes = 0;
  size_t max_work_group_size = 0;
  bool fp64 = false;                   // cl_khr_fp64 or a non-zero CL_DEVICE_DOUBLE_FP_CONFIG
  bool int64_atomics_base = false;     // cl_khr_int64_base_atomics
  bool int64_atomics_extended = false; // cl_khr_int64_extended_atomics
};

// Every device of every platform. Throws DeviceError (telling to install an OpenCL driver such
// as pocl-opencl-icd) when there is no platform or no device at all.
std::vector<DeviceInfo> list_devices();

// Chooses a device: spec = "INDEX" (global index of list_devices) or a case-insensitive
// substring of the device name, vendor or platform name; an empty spec falls back to the
// environment variable TETCOLLAPSE_DEVICE, then to the first GPU, then to the first CPU.
// A device without fp64 is refused with DeviceError.
DeviceInfo select_device(const std::string& spec = "");

// Translates an OpenCL error code into its name ("CL_OUT_OF_RESOURCES"); "CL_ERROR(<code>)"
// for codes it does not know.
const char* cl_error_name(int code);

// A first run on a device compiles its programs in helper processes, one per core, when a
// command for them is set: the argv of a program that, given these arguments followed by a device
// index, returns run_compile_helper(index) (the command line tool sets itself). Why processes:
// PoCL compiles one program at a time in a process. Without one (the default) the programs are
// compiled in threads of this process. Process-wide.
void set_compile_helper(std::vector<std::string> argv);
// The helper's side: serves a parent's compile requests on its standard input (a socket) until
// it closes; the exit code.
int run_compile_helper(int device_index);

// A context, a device and one in-order command queue. Programs are compiled once per context
// (in memory) and once per machine (the on-disk binary cache).
class Context {
 public:
  // Selects the device as select_device(spec) does.
  explicit Context(const std::string& spec = "");
  explicit Context(const DeviceInfo& info);
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;
  ~Context();

  const DeviceInfo& info() const { return info_; }
  cl::Context& context() { return context_; }
  cl::Device& device() { return device_; }
  cl::CommandQueue& queue() { return queue_; }

  // Work-group size used by the library's kernels: 0 (default) picks one per kernel from the
  // device limits. Results never depend on it; tests set it to check exactly that.
  void set_work_group_size(size_t wg) { work_group_size_ = wg; }
  size_t work_group_size() const { return work_group_size_; }
  // Whether the library tunes itself for a CPU device (default: the device's type is "CPU"):
  // kernels that prefetch for their next work items, the rings built on the host, the
  // primitives' CPU variants (tc::dev::Tuning; a process-wide dev::set_tuning_override comes
  // first), at least 4 work-groups per compute unit per launch (with work_group_size() 0), and
  // the automatic host tail (CollapseTuning::host_tail). Otherwise the GPU choices. Results
  // depend on it only through the automatic host tail (a CPU device runs one, a GPU none; with
  // host_tail set, never): tests set it to false to run the GPU code paths on PoCL. The environment
  // variable TETCOLLAPSE_TUNING=gpu|cpu sets it for every new context (DeviceError for another
  // value). It may change at any time; the next program of a variant not built yet in this
  // context is compiled (or read from the disk cache) then.
  void set_cpu_tuning(bool cpu) { cpu_tuning_ = cpu; }
  bool cpu_tuning() const { return cpu_tuning_; }
  // The work-group size a launch of `kernel` uses: the set one (clamped to what the kernel
  // and the device allow) or the default, always a power of two >= 1.
  size_t group_size_for(const cl::Kernel& kernel) const;

  // The program made of the embedded file `file` (e.g. "scan.cl"), or, for a stage file of the
  // collapse, of the group of files built with it as one program (host/device/runtime.cpp,
  // kProgramGroups); `#include "x.h"` lines are replaced by the embedded text of x.h. Options are appended to "-cl-std=CL1.2", followed by
  // the environment variable TETCOLLAPSE_CL_OPTIONS when set (e.g. "-cl-opt-disable"). Built from
  // the cache when possible; a build failure throws DeviceError with the build log.
  cl::Program& program(const std::string& file, const std::string& options = "");
  // The same from source text given here (named `name` in messages); #include lines still refer
  // to embedded files. Cached in memory under (name, the options as built: with cpu_tuning's
  // and the environment's) and on disk like program().
  cl::Program& build(const std::string& name, const std::string& source, const std::string& options = "");
  // A fresh kernel object of that program (kernels hold their arguments, so callers own them).
  cl::Kernel kernel(const std::string& file, const std::string& name, const std::string& options = "");
  // Starts compiling program(file, options) on another thread when it is in neither the memory
  // nor the disk cache, so that a first run compiles the programs it will use on every core
  // while it waits for the first of them; program() then takes the result.
  void prefetch(const std::string& file, const std::string& options = "");
  // Build options added, after the call's own, to every program built or prefetched while it
  // lives whose source includes the embedded file `header` (empty: every program): the variant
  // a whole run needs of the programs that test it (the collapse under a boundary error bound:
  // -DTCC_BOUND for those with collapse_select.h), set once for the run, so that each program is
  // built once, and those that do not test it are the same program with or without. Scopes
  // nest; the innermost applies.
  class ProgramOptions {
   public:
    ProgramOptions(Context& ctx, std::string options, std::string header = "")
        : ctx_(ctx), saved_(std::move(ctx.run_options_)), saved_header_(std::move(ctx.run_header_)) {
      ctx.run_options_ = std::move(options);
      ctx.run_header_ = std::move(header);
    }
    ~ProgramOptions() {
      ctx_.run_options_ = std::move(saved_);
      ctx_.run_header_ = std::move(saved_header_);
    }
    ProgramOptions(const ProgramOptions&) = delete;
    ProgramOptions& operator=(const ProgramOptions&) = delete;

   private:
    Context& ctx_;
    std::string saved_, saved_header_;
  };

  // Enqueues a 1-D launch of n work items: the global size is n rounded up to a multiple of the
  // work-group size, so kernels must check their global id against n. `what` names the kernel
  // in error messages. local = 0 means group_size_for(kernel), on a CPU device with no size set
  // (set_work_group_size) 8 when the launch would have fewer than 4 work-groups per compute
  // unit: the CPU drivers run a work-group on one thread, so a small launch in one or two large
  // groups (a chunked scan's, say) would leave cores idle; one small size, because they compile
  // a work-group function per local size on the first run.
  void launch(cl::Kernel& kernel, size_t n, const char* what, size_t local = 0);
  // Enqueues one work-group of group_size_for(kernel) items (kernels that loop with barriers).
  void launch_one_group(cl::Kernel& kernel, const char* what);
  void finish();

  // Where compiled binaries are cached: $TETCOLLAPSE_CACHE_DIR, else $XDG_CACHE_HOME/tetcollapse,
  // else ~/.cache/tetcollapse.
  static std::string cache_dir();
  // How the last program() call that compiled something was satisfied (for tests and benches).
  enum class BuildSource { Memory, DiskCache, Source };
  BuildSource last_build_source() const { return last_build_source_; }
  // Progress of the compiles from source (programs not in the disk cache): on a new device, a new
  // driver or a cleared cache, the first run compiles every kernel it uses, which takes seconds
  // (the CLI says so on stderr). Called with the program's file when it is queued or begun
  // (done < total), and when it is compiled (done counts it); total counts those queued so far.
  void set_compile_notice(std::function<void(const std::string& file, int done, int total)> fn) {
    compile_notice_ = std::move(fn);
  }
  // The largest buffer allocated in this context so far, in bytes (DeviceBuffer). No buffer is
  // split over CL_DEVICE_MAX_MEM_ALLOC_SIZE: OpenCL grants at least a quarter of the global
  // memory per allocation, and the largest buffer of a run stays below a quarter of the memory
  // the run is checked to need (a test holds both to that), so a mesh that passes the memory
  // check needs no split on a conforming device; past the limit a buffer is refused (DeviceError).
  uint64_t largest_allocation() const { return largest_allocation_; }
  void note_allocation(uint64_t bytes) { largest_allocation_ = std::max(largest_allocation_, bytes); }

 private:
  void init(const DeviceInfo& info);
  // What build() compiles: the options as built, the source with its includes, the disk cache key.
  struct Unit {
    std::string opts, source, cache_key;
  };
  Unit unit(const std::string& file, const std::string& text, const std::string& options) const;
  // The options a program is built with: the call's, cpu_tuning's, the run's (ProgramOptions,
  // when `text`, the program `name`'s source, includes its header) and the environment's.
  std::string options_as_built(const std::string& name, const std::string& text, const std::string& options) const;
  device_detail::CompilePool& pool();
  DeviceInfo info_;
  cl::Platform platform_;
  cl::Device device_;
  cl::Context context_;
  cl::CommandQueue queue_;
  size_t work_group_size_ = 0;
  uint64_t largest_allocation_ = 0;
  bool cpu_tuning_ = false;
  std::map<std::pair<std::string, std::string>, cl::Program> programs_;
  BuildSource last_build_source_ = BuildSource::Memory;
  std::function<void(const std::string&, int, int)> compile_notice_;
  int compiles_done_ = 0, compiles_total_ = 0;
  std::string run_options_, run_header_;  // (ProgramOptions)
  // Per program (name and a hash of its text), the embedded files its source includes
  // (ProgramOptions' header test).
  mutable std::map<std::string, std::set<std::string>> includes_;
  std::unique_ptr<device_detail::CompilePool> pool_;  // made at the first compile from source
};

namespace detail {
// Runs f() and turns a cl::Error into DeviceError("<call>(<what>): <CL_NAME>").
[[noreturn]] void rethrow_cl_error(const cl::Error& e, const char* what);
template <class F>
decltype(auto) cl_call(const char* what, F&& f) {
  try {
    return f();
  } catch (const cl::Error& e) {
    rethrow_cl_error(e, what);
  }
}
}  // namespace detail

// A device array of n values of T (T trivially copyable). A zero-size buffer holds a one-element
// allocation so it can always be passed to kernels. Transfers are blocking.
template <class T>
class DeviceBuffer {
 public:
  DeviceBuffer() = default;
  DeviceBuffer(Context& ctx, size_t n) : ctx_(&ctx) { allocate(n); }
  DeviceBuffer(Context& ctx, const std::vector<T>& host) : ctx_(&ctx) {
    allocate(host.size());
    upload(host);
  }

  size_t size() const { return n_; }
  size_t bytes() const { return n_ * sizeof(T); }
  cl::Buffer& buffer() { return buf_; }
  const cl::Buffer& buffer() const { return buf_; }
  Context& context() const { return *ctx_; }

  // Reallocates when n exceeds the capacity (contents are then lost); never shrinks memory.
  void resize(size_t n) {
    if (n > capacity_) allocate(n);
    n_ = n;
  }
  void upload(const std::vector<T>& host) {
    resize(host.size());
    upload(host.data(), host.size());
  }
  void upload(const T* data, size_t count, size_t offset = 0) {
    if (count == 0) return;
    check_range(offset, count, "upload");
    detail::cl_call("DeviceBuffer::upload", [&] {
      ctx_->queue().enqueueWriteBuffer(buf_, CL_TRUE, offset * sizeof(T), count * sizeof(T), data);
    });
  }
  std::vector<T> download() const { return download_range(0, n_); }
  std::vector<T> download_range(size_t offset, size_t count) const {
    std::vector<T> out(count);
    download(out.data(), count, offset);
    return out;
  }
  void download(T* data, size_t count, size_t offset = 0) const {
    if (count == 0) return;
    check_range(offset, count, "download");
    detail::cl_call("DeviceBuffer::download", [&] {
      ctx_->queue().enqueueReadBuffer(buf_, CL_TRUE, offset * sizeof(T), count * sizeof(T), data);
    });
  }
  // Becomes a copy of the first count elements of src (a copy on the device), resized to count.
  void copy_from(const DeviceBuffer& src, size_t count) {
    src.check_range(0, count, "copy_from");
    resize(count);
    if (count == 0) return;
    detail::cl_call("DeviceBuffer::copy_from", [&] {
      ctx_->queue().enqueueCopyBuffer(src.buf_, buf_, 0, 0, count * sizeof(T));
    });
  }
  // Sets every element to value.
  void fill(const T& value) {
    if (n_ == 0) return;
    detail::cl_call("DeviceBuffer::fill", [&] {
      ctx_->queue().enqueueFillBuffer(buf_, value, 0, n_ * sizeof(T));
    });
  }

 private:
  void allocate(size_t n) {
    size_t cap = n == 0 ? 1 : n;
    if (cap > SIZE_MAX / sizeof(T)) throw DeviceError("DeviceBuffer: size overflow");
    // A buffer the device cannot hold: say so with the sizes (the driver's error names none).
    const uint64_t bytes = uint64_t(cap) * sizeof(T), limit = ctx_->info().max_alloc_bytes;
    if (limit > 0 && bytes > limit)
      throw DeviceError("the mesh is too large for device '" + ctx_->info().name + "': one of its buffers needs " +
                        std::to_string(bytes >> 20) + " MiB, and the device allocates at most " +
                        std::to_string(limit >> 20) + " MiB at once (CL_DEVICE_MAX_MEM_ALLOC_SIZE; global memory " +
                        std::to_string(ctx_->info().global_mem_bytes >> 20) +
                        " MiB); use a larger device or --method sequential");
    detail::cl_call("clCreateBuffer", [&] { buf_ = cl::Buffer(ctx_->context(), CL_MEM_READ_WRITE, cap * sizeof(T)); });
    ctx_->note_allocation(bytes);
    capacity_ = cap;
    n_ = n;
  }
  void check_range(size_t offset, size_t count, const char* op) const {
    if (offset > n_ || count > n_ - offset)
      throw DeviceError(std::string("DeviceBuffer::") + op + ": range [" + std::to_string(offset) + ", " +
                        std::to_string(offset + count) + ") outside a buffer of " + std::to_string(n_));
  }
  Context* ctx_ = nullptr;
  cl::Buffer buf_;
  size_t n_ = 0, capacity_ = 0;
};

}  // namespace tc
