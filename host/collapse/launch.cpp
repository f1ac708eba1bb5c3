// Named kernel arguments (launch.hpp).
#include "collapse/launch.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <mutex>

#include "collapse/stages.hpp"
#include "device/primitives.hpp"
#include "stopwatch.hpp"
#include "tetcollapse/error.hpp"

namespace tc::collapse_detail {

const bool kProfile = std::getenv("TETCOLLAPSE_PROFILE") != nullptr;

void profile_line(Context& ctx, const char* what, size_t n, double t0, const char* note) {
  if (!kProfile) return;
  ctx.finish();
  std::fprintf(stderr, "  %-28s n=%-9zu %8.4f s%s\n", what, n, Stopwatch::now() - t0, note);
}

namespace {

// The parameters of kernel k, read from the compiled kernel.
std::vector<Kernel::Param> read_params(cl::Kernel& k) {
  using Kind = Kernel::Kind;
  std::vector<Kernel::Param> params(k.getInfo<CL_KERNEL_NUM_ARGS>());
  for (cl_uint i = 0; i < params.size(); ++i) {
    Kernel::Param& p = params[i];
    p.name = k.getArgInfo<CL_KERNEL_ARG_NAME>(i);
    // (the strings may carry a terminating NUL)
    p.name.erase(std::find(p.name.begin(), p.name.end(), '\0'), p.name.end());
    // PoCL reports a parameter named like a built-in function (round) as _cl_round
    if (p.name.rfind("_cl_", 0) == 0) p.name.erase(0, 4);
    std::string type = k.getArgInfo<CL_KERNEL_ARG_TYPE_NAME>(i);
    type.erase(std::find(type.begin(), type.end(), '\0'), type.end());
    const bool global = k.getArgInfo<CL_KERNEL_ARG_ADDRESS_QUALIFIER>(i) == CL_KERNEL_ARG_ADDRESS_GLOBAL;
    p.kind = global              ? Kind::Buffer
             : type == "int"     ? Kind::Int
             : type == "uint"    ? Kind::Uint
             : type == "long"    ? Kind::Long
             : type == "ulong"   ? Kind::Ulong
             : type == "uchar"   ? Kind::Uchar
             : type == "char"    ? Kind::Char
             : type == "double"  ? Kind::Double
             : type == "float"   ? Kind::Float
                                 : Kind::Other;
  }
  return params;
}

}  // namespace

// A kernel's signature is its file's, whatever the program it is built in (the user's
// functions, the tuning's -D options): cached by (file, name), read again should the number of
// parameters differ.
Kernel::Kernel(cl::Kernel k, std::string name, const std::string& file) : k_(std::move(k)), name_(std::move(name)) {
  static std::mutex mutex;
  static std::map<std::pair<std::string, std::string>, std::shared_ptr<const std::vector<Param>>> cache;
  detail::cl_call(("clGetKernelArgInfo(" + name_ + ")").c_str(), [&] {
    const size_t n = k_.getInfo<CL_KERNEL_NUM_ARGS>();
    const std::lock_guard<std::mutex> lock(mutex);
    auto& params = cache[{file, name_}];
    if (!params || params->size() != n) params = std::make_shared<const std::vector<Param>>(read_params(k_));
    params_ = params;
  });
  set_.assign(params_->size(), false);
}

size_t Kernel::index(const char* param) const {
  const std::vector<Param>& params = *params_;
  for (size_t i = 0; i < params.size(); ++i)
    if (params[i].name == param) return i;
  std::string names;
  for (const Param& p : params) names += (names.empty() ? "" : ", ") + p.name;
  throw DeviceError("kernel " + name_ + " has no parameter '" + param + "' (its parameters: " + names + ")");
}

void Kernel::set_buffer(const char* param, const cl::Buffer& b) {
  const size_t i = index(param);
  if ((*params_)[i].kind != Kind::Buffer)
    throw DeviceError("kernel " + name_ + ": parameter '" + param + "' is not a global buffer");
  detail::cl_call(name_.c_str(), [&] { k_.setArg(cl_uint(i), b); });
  set_[i] = true;
}

void Kernel::set_number(const char* param, long double v, bool integral) {
  const size_t i = index(param);
  auto fail = [&](const char* why) {
    throw DeviceError("kernel " + name_ + ": parameter '" + param + "' " + why);
  };
  auto in = [&](long double lo, long double hi) {
    if (!integral) fail("takes an integer");
    if (v < lo || v > hi) fail("out of its type's range");
  };
  detail::cl_call(name_.c_str(), [&] {
    switch ((*params_)[i].kind) {
      case Kind::Int: in(INT32_MIN, INT32_MAX); k_.setArg(cl_uint(i), cl_int(v)); break;
      case Kind::Uint: in(0, UINT32_MAX); k_.setArg(cl_uint(i), cl_uint(v)); break;
      case Kind::Long: in(INT64_MIN, INT64_MAX); k_.setArg(cl_uint(i), cl_long(v)); break;
      case Kind::Ulong: in(0, UINT64_MAX); k_.setArg(cl_uint(i), cl_ulong(v)); break;
      case Kind::Uchar: in(0, UINT8_MAX); k_.setArg(cl_uint(i), cl_uchar(v)); break;
      case Kind::Char: in(INT8_MIN, INT8_MAX); k_.setArg(cl_uint(i), cl_char(v)); break;
      case Kind::Double: k_.setArg(cl_uint(i), cl_double(v)); break;
      case Kind::Float: k_.setArg(cl_uint(i), cl_float(v)); break;
      default: fail("is neither a buffer nor a number");
    }
  });
  set_[i] = true;
}

void Kernel::check_all_set() const {
  for (size_t i = 0; i < set_.size(); ++i)
    if (!set_[i]) throw DeviceError("kernel " + name_ + ": parameter '" + (*params_)[i].name + "' is not set");
}

void Kernel::launch(Context& ctx, size_t n) {
  check_all_set();
  const double t0 = kProfile ? Stopwatch::now() : 0;
  ctx.launch(k_, n, name_.c_str());
  profile_line(ctx, name_.c_str(), n, t0);
}

void Kernel::launch_one_group(Context& ctx) {
  check_all_set();
  ctx.launch_one_group(k_, name_.c_str());
}

Kernel kernel(Context& ctx, const std::string& file, const char* name) {
  return Kernel(ctx.kernel(file, name), name, file);
}

Kernel user_kernel(Context& ctx, const std::string& what, const std::string& file, const char* name,
                   const std::string& user, const std::string& defines) {
  // the shared helpers (which declare the user functions), the user's source, the file; the
  // Context caches programs by (name, options): the program's name carries a hash of the source
  const std::string src = "#include \"collapse_common.h\"\n" + user + "\n#include \"" + file + "\"\n";
  cl::Program& prog =
      ctx.build(what + " (" + file + " " + std::to_string(std::hash<std::string>{}(src)) + ")", src, defines);
  return Kernel(detail::cl_call(("clCreateKernel(" + std::string(name) + ")").c_str(),
                                [&] { return cl::Kernel(prog, name); }),
                name, file);
}

Kernel stage_kernel(Context& ctx, const StageParams& p, const std::string& file, const char* name) {
  if (p.user_source.empty()) return kernel(ctx, file, name);
  return user_kernel(ctx, "user placement / predicate", file, name, p.user_source, p.user_defines);
}

uint32_t scan_offsets(Context& ctx, DeviceBuffer<uint32_t>& counts, DeviceBuffer<uint32_t>& off, size_t n) {
  ensure(off, ctx, n + 1);
  uint32_t total = dev::exclusive_scan(ctx, counts, off, n);
  off.upload(&total, 1, n);
  return total;
}

}  // namespace tc::collapse_detail
