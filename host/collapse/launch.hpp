// How the stages launch their kernels. Every argument is set by the name its parameter has in
// the kernel's OpenCL C signature, read back from the compiled kernel (clGetKernelArgInfo), never
// by position: a parameter added, removed, reordered or renamed in a .cl file is an error that
// names it, not a silent shift. A scalar is converted to the parameter's declared type (uint,
// int, double, ...) with a range check; a launch with a parameter left unset throws.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "tetcollapse/device.hpp"

namespace tc::collapse_detail {

struct StageParams;

// One named argument: arg("edges", c.edges), arg("n", ne).
template <class T>
struct Arg {
  const char* name;
  const T& value;
};
template <class T>
Arg<T> arg(const char* name, const T& value) {
  return {name, value};
}

// A kernel object with its parameters' names, types and which are set.
class Kernel {
 public:
  Kernel() = default;
  // `file`: the .cl file the kernel is defined in; its parameters are read once per file and
  // name (a kernel object is made per launch, reading them each time is measurable).
  Kernel(cl::Kernel k, std::string name, const std::string& file);

  template <class... T>
  Kernel& set(const Arg<T>&... args) {
    (set_one(args.name, args.value), ...);
    return *this;
  }
  // n work items (Context::launch); with TETCOLLAPSE_PROFILE set, waits and prints the time.
  void launch(Context& ctx, size_t n);
  // One work-group (Context::launch_one_group), for the kernels that loop with barriers.
  void launch_one_group(Context& ctx);
  const std::string& name() const { return name_; }

  enum class Kind : uint8_t { Buffer, Int, Uint, Long, Ulong, Uchar, Char, Double, Float, Other };
  struct Param {
    std::string name;
    Kind kind;
  };

 private:
  size_t index(const char* param) const;
  void set_buffer(const char* param, const cl::Buffer& b);
  void set_number(const char* param, long double v, bool integral);
  template <class T>
  void set_one(const char* param, const T& v) {
    if constexpr (std::is_same_v<T, cl::Buffer>) {
      set_buffer(param, v);
    } else if constexpr (requires { v.buffer(); }) {
      set_buffer(param, v.buffer());
    } else {
      static_assert(std::is_arithmetic_v<T>, "a kernel argument is a buffer or a number");
      set_number(param, static_cast<long double>(v), std::is_integral_v<T>);
    }
  }
  void check_all_set() const;

  cl::Kernel k_;
  std::string name_;
  std::shared_ptr<const std::vector<Param>> params_;
  std::vector<bool> set_;  // per parameter
};

// Kernel `name` of the embedded file `file` (Context::kernel).
Kernel kernel(Context& ctx, const std::string& file, const char* name);
// Kernel `name` of the stage file `file`, compiled with the user's placement and predicate
// (p.user_source) when there are any: a program of its own per source, cached by the Context.
Kernel stage_kernel(Context& ctx, const StageParams& p, const std::string& file, const char* name);
// Kernel `name` of `file` compiled after the user's OpenCL C `user`, with the -D options
// `defines` (the program is named `what` in messages and build errors).
Kernel user_kernel(Context& ctx, const std::string& what, const std::string& file, const char* name,
                   const std::string& user, const std::string& defines);

// Sets the arguments and launches n work items.
template <class... T>
void run(Context& ctx, const std::string& file, const char* name, size_t n, const Arg<T>&... args) {
  kernel(ctx, file, name).set(args...).launch(ctx, n);
}
// The same for the kernels that see the user's placement or predicate (stage_kernel).
template <class... T>
void run_stage(Context& ctx, const StageParams& p, const std::string& file, const char* name, size_t n,
               const Arg<T>&... args) {
  stage_kernel(ctx, p, file, name).set(args...).launch(ctx, n);
}

// TETCOLLAPSE_PROFILE set: the stages print the wall time of every launch on stderr.
extern const bool kProfile;
// With kProfile: waits for the queue and prints `what`, n and the seconds since t0 (a
// Stopwatch::now()).
void profile_line(Context& ctx, const char* what, size_t n, double t0, const char* note = "");

// A device buffer of n elements: allocated on first use, else resized (DeviceBuffer::resize).
template <class T>
void ensure(DeviceBuffer<T>& b, Context& ctx, size_t n) {
  if (!b.buffer()()) b = DeviceBuffer<T>(ctx, n);
  else b.resize(n);
}

// Exclusive scan of counts[0..n) into off[0..n], off[n] = total; returns the total.
uint32_t scan_offsets(Context& ctx, DeviceBuffer<uint32_t>& counts, DeviceBuffer<uint32_t>& off, size_t n);

}  // namespace tc::collapse_detail
