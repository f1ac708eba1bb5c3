// Device primitives: scan, compaction, radix sort, segments. Kernels: cl/scan.cl, cl/sort.cl,
// cl/segments.cl.
//
// Why our own kernels rather than Boost.Compute (bench/bench_primitives.cpp; measured in
// bench/README.md):
//  - sort of 64-bit keys with a 32-bit payload: ours beats Boost.Compute's stable_sort_by_key
//    (a merge sort on CPU devices) and radix_sort_by_key, and std::sort of the keys alone, so
//    the sort is ours.
//  - exclusive scan: Boost.Compute is faster here, but we still keep ours: Boost.Compute
//    compiles its programs in every process (its offline cache needs Boost.Filesystem), so it
//    would bypass our binary cache and add a compilation to every start; its headers only
//    compile after <CL/opencl.hpp> and without BOOST_COMPUTE_MAX_CL_VERSION (target 3.0
//    clash); its errors are not DeviceError; and the scan is a small share of every stage that
//    uses it. A CPU variant with a few long chunks per compute unit, Boost's layout, was slower
//    on PoCL and was dropped.
#include "device/primitives.hpp"

#include <algorithm>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

namespace tc::dev {

namespace {

constexpr unsigned kScanItems = 8;      // values per work item in a scan tile (TC_ITEMS)
constexpr unsigned kScanChunk = 4096;   // values per work item in the chunked (CPU) scan

const std::string kScanOptions = "-DTC_ITEMS=" + std::to_string(kScanItems);

std::optional<Tuning> g_override;

// The scan program as the device runs it: without the tile scan's kernels where the host runs the
// chunked scan (cl/scan.cl).
std::string scan_options(const Context& ctx) {
  return tuning_for(ctx).chunked_scan ? kScanOptions + " -DTC_SCAN_CHUNKED" : kScanOptions;
}

void check_n(size_t n, const char* what) {
  // Kernels index with 32-bit unsigned integers; tiles may run past n by one tile.
  if (n > (size_t{1} << 31)) throw std::invalid_argument(std::string(what) + ": more than 2^31 elements");
}

template <class B>
void check_size(const B& buf, size_t n, const char* what, const char* name) {
  if (buf.size() < n)
    throw std::invalid_argument(std::string(what) + ": buffer '" + name + "' holds " + std::to_string(buf.size()) +
                                " values, needs " + std::to_string(n));
}

cl_uint u32(size_t v) { return static_cast<cl_uint>(v); }

// Work-group size for the scan kernels: the context's choice, shrunk until the tile and the
// per-item sums fit in half the local memory.
size_t scan_group_size(Context& ctx, const cl::Kernel& k) {
  size_t wg = ctx.group_size_for(k);
  while (wg > 1 && (kScanItems + 1) * wg * sizeof(cl_uint) > ctx.info().local_mem_bytes / 2) wg /= 2;
  return wg;
}

uint32_t scan_chunked(Context& ctx, const cl::Buffer& in, cl::Buffer& out, size_t n, bool as_flags) {
  size_t items = (n + kScanChunk - 1) / kScanChunk;
  cl::Kernel apply = ctx.kernel("scan.cl", "scan_chunk_apply", scan_options(ctx));
  DeviceBuffer<uint32_t> total(ctx, 1);
  uint32_t result = 0;
  if (items == 1) {
    set_args(apply, "scan_chunk_apply", in, out, u32(n), u32(as_flags), u32(kScanChunk), u32(items), total.buffer(),
             u32(0), total.buffer());
    ctx.launch(apply, items, "clEnqueueNDRangeKernel(scan_chunk_apply)");
    total.download(&result, 1);
    return result;
  }
  cl::Kernel sums_k = ctx.kernel("scan.cl", "scan_chunk_sums", scan_options(ctx));
  DeviceBuffer<uint32_t> sums(ctx, items);
  set_args(sums_k, "scan_chunk_sums", in, u32(n), u32(as_flags), u32(kScanChunk), u32(items), sums.buffer());
  ctx.launch(sums_k, items, "clEnqueueNDRangeKernel(scan_chunk_sums)");
  result = scan_chunked(ctx, sums.buffer(), sums.buffer(), items, false);
  set_args(apply, "scan_chunk_apply", in, out, u32(n), u32(as_flags), u32(kScanChunk), u32(items), sums.buffer(),
           u32(1), total.buffer());
  ctx.launch(apply, items, "clEnqueueNDRangeKernel(scan_chunk_apply)");
  return result;
}

uint32_t scan_impl(Context& ctx, const cl::Buffer& in, cl::Buffer& out, size_t n, bool as_flags) {
  if (n == 0) return 0;
  if (tuning_for(ctx).chunked_scan) return scan_chunked(ctx, in, out, n, as_flags);
  cl::Kernel reduce = ctx.kernel("scan.cl", "scan_reduce", scan_options(ctx));
  cl::Kernel down = ctx.kernel("scan.cl", "scan_downsweep", scan_options(ctx));
  size_t wg = std::min(scan_group_size(ctx, reduce), scan_group_size(ctx, down));
  size_t tile = wg * kScanItems;
  size_t groups = (n + tile - 1) / tile;
  DeviceBuffer<uint32_t> total(ctx, 1);
  uint32_t result = 0;
  if (groups == 1) {
    set_args(down, "scan_downsweep", in, out, u32(n), u32(as_flags), total.buffer(), u32(0), total.buffer(),
             cl::Local(tile * sizeof(cl_uint)), cl::Local(wg * sizeof(cl_uint)));
    ctx.launch(down, wg, "clEnqueueNDRangeKernel(scan_downsweep)", wg);
    total.download(&result, 1);
    return result;
  }
  DeviceBuffer<uint32_t> sums(ctx, groups);
  set_args(reduce, "scan_reduce", in, u32(n), u32(as_flags), sums.buffer(), cl::Local(wg * sizeof(cl_uint)));
  ctx.launch(reduce, groups * wg, "clEnqueueNDRangeKernel(scan_reduce)", wg);
  result = scan_impl(ctx, sums.buffer(), sums.buffer(), groups, false);
  set_args(down, "scan_downsweep", in, out, u32(n), u32(as_flags), sums.buffer(), u32(1), total.buffer(),
           cl::Local(tile * sizeof(cl_uint)), cl::Local(wg * sizeof(cl_uint)));
  ctx.launch(down, groups * wg, "clEnqueueNDRangeKernel(scan_downsweep)", wg);
  return result;
}

template <class T>
uint32_t compact_values(Context& ctx, const DeviceBuffer<T>& values, const DeviceBuffer<uint32_t>& flags,
                        DeviceBuffer<T>& out, size_t n, const char* kernel_name) {
  check_n(n, "compact");
  check_size(values, n, "compact", "values");
  check_size(flags, n, "compact", "flags");
  if (n == 0) {
    out.resize(0);
    return 0;
  }
  DeviceBuffer<uint32_t> pos(ctx, n);
  uint32_t count = scan_impl(ctx, flags.buffer(), pos.buffer(), n, true);
  out.resize(count);
  cl::Kernel k = ctx.kernel("scan.cl", kernel_name, scan_options(ctx));
  set_args(k, kernel_name, values.buffer(), flags.buffer(), pos.buffer(), u32(n), out.buffer());
  ctx.launch(k, n, kernel_name);
  return count;
}

std::string sort_options(Context& ctx) { return "-DTC_RADIX_BITS=" + std::to_string(tuning_for(ctx).radix_bits); }

void radix_sort_impl(Context& ctx, DeviceBuffer<uint64_t>& keys, DeviceBuffer<uint32_t>* values, size_t n,
                     int key_bits) {
  check_n(n, "radix_sort");
  if (key_bits < 1 || key_bits > 64) throw std::invalid_argument("radix_sort: key_bits must be in 1..64");
  check_size(keys, n, "radix_sort", "keys");
  if (values) check_size(*values, n, "radix_sort", "values");
  if (n <= 1) return;
  Tuning t = tuning_for(ctx);
  const unsigned kRadixBits = static_cast<unsigned>(t.radix_bits), kSortChunk = t.sort_chunk;
  const std::string kSortOptions = sort_options(ctx);
  size_t items = (n + kSortChunk - 1) / kSortChunk;
  size_t radix = size_t{1} << kRadixBits;
  DeviceBuffer<uint64_t> keys_tmp(ctx, n);
  DeviceBuffer<uint32_t> values_tmp(ctx, values ? n : 0);
  DeviceBuffer<uint32_t> hist(ctx, radix * items);
  cl::Kernel count = ctx.kernel("sort.cl", "radix_count", kSortOptions);
  cl::Kernel scatter = ctx.kernel("sort.cl", "radix_scatter", kSortOptions);

  cl::Buffer* kin = &keys.buffer();
  cl::Buffer* kout = &keys_tmp.buffer();
  cl::Buffer* vin = values ? &values->buffer() : &values_tmp.buffer();
  cl::Buffer* vout = &values_tmp.buffer();
  if (!values) vin = vout;  // unused by the kernel (has_values = 0) but must be a valid buffer
  int passes = (key_bits + static_cast<int>(kRadixBits) - 1) / static_cast<int>(kRadixBits);
  for (int p = 0; p < passes; ++p) {
    cl_uint shift = static_cast<cl_uint>(p * kRadixBits);
    cl_uint bits = std::min<cl_uint>(kRadixBits, static_cast<cl_uint>(key_bits) - shift);
    cl_uint mask = (1u << bits) - 1u;
    set_args(count, "radix_count", *kin, u32(n), shift, mask, u32(kSortChunk), u32(items), hist.buffer());
    ctx.launch(count, items, "clEnqueueNDRangeKernel(radix_count)");
    scan_impl(ctx, hist.buffer(), hist.buffer(), radix * items, false);
    set_args(scatter, "radix_scatter", *kin, *vin, *kout, *vout, u32(values != nullptr), u32(n), shift, mask,
             u32(kSortChunk), u32(items), hist.buffer());
    ctx.launch(scatter, items, "clEnqueueNDRangeKernel(radix_scatter)");
    std::swap(kin, kout);
    if (values) std::swap(vin, vout);
  }
  if (passes % 2 == 1) {  // the result is in the temporaries
    detail::cl_call("clEnqueueCopyBuffer(radix_sort)", [&] {
      ctx.queue().enqueueCopyBuffer(keys_tmp.buffer(), keys.buffer(), 0, 0, n * sizeof(uint64_t));
      if (values) ctx.queue().enqueueCopyBuffer(values_tmp.buffer(), values->buffer(), 0, 0, n * sizeof(uint32_t));
    });
  }
}

}  // namespace

void prefetch_scan(Context& ctx) { ctx.prefetch("scan.cl", scan_options(ctx)); }
void prefetch_sort(Context& ctx) { ctx.prefetch("sort.cl", sort_options(ctx)); }

Tuning default_tuning(bool cpu) {
  Tuning t;
  if (cpu) {
    // Work items are loop iterations on a CPU: long serial chunks, no barriers, and 8-bit
    // digits (half the passes; 256 counters per work item are cheap in CPU memory).
    t.chunked_scan = true;
    t.radix_bits = 8;
    t.sort_chunk = 4096;
  }
  return t;
}

void set_tuning_override(const Tuning* tuning) {
  if (tuning) {
    if (tuning->radix_bits != 4 && tuning->radix_bits != 8) throw std::invalid_argument("Tuning: radix_bits must be 4 or 8");
    if (tuning->sort_chunk == 0) throw std::invalid_argument("Tuning: sort_chunk must be positive");
    g_override = *tuning;
  } else {
    g_override.reset();
  }
}

Tuning tuning_for(const Context& ctx) { return g_override ? *g_override : default_tuning(ctx.cpu_tuning()); }

uint32_t exclusive_scan(Context& ctx, const DeviceBuffer<uint32_t>& in, DeviceBuffer<uint32_t>& out, size_t n) {
  check_n(n, "exclusive_scan");
  check_size(in, n, "exclusive_scan", "in");
  check_size(out, n, "exclusive_scan", "out");
  return scan_impl(ctx, in.buffer(), out.buffer(), n, false);
}

uint32_t compact_indices(Context& ctx, const DeviceBuffer<uint32_t>& flags, DeviceBuffer<uint32_t>& out, size_t n) {
  check_n(n, "compact_indices");
  check_size(flags, n, "compact_indices", "flags");
  if (n == 0) {
    out.resize(0);
    return 0;
  }
  DeviceBuffer<uint32_t> pos(ctx, n);
  uint32_t count = scan_impl(ctx, flags.buffer(), pos.buffer(), n, true);
  out.resize(count);
  cl::Kernel k = ctx.kernel("scan.cl", "compact_indices", scan_options(ctx));
  set_args(k, "compact_indices", flags.buffer(), pos.buffer(), u32(n), out.buffer());
  ctx.launch(k, n, "clEnqueueNDRangeKernel(compact_indices)");
  return count;
}

uint32_t compact(Context& ctx, const DeviceBuffer<uint32_t>& values, const DeviceBuffer<uint32_t>& flags,
                 DeviceBuffer<uint32_t>& out, size_t n) {
  return compact_values(ctx, values, flags, out, n, "compact_u32");
}

uint32_t compact(Context& ctx, const DeviceBuffer<uint64_t>& values, const DeviceBuffer<uint32_t>& flags,
                 DeviceBuffer<uint64_t>& out, size_t n) {
  return compact_values(ctx, values, flags, out, n, "compact_u64");
}

void radix_sort(Context& ctx, DeviceBuffer<uint64_t>& keys, DeviceBuffer<uint32_t>& values, size_t n, int key_bits) {
  radix_sort_impl(ctx, keys, &values, n, key_bits);
}

void radix_sort(Context& ctx, DeviceBuffer<uint64_t>& keys, size_t n, int key_bits) {
  radix_sort_impl(ctx, keys, nullptr, n, key_bits);
}

uint32_t segment_heads(Context& ctx, const DeviceBuffer<uint64_t>& keys, size_t n, DeviceBuffer<uint32_t>& head_flags,
                       DeviceBuffer<uint32_t>& starts) {
  check_n(n, "segment_heads");
  check_size(keys, n, "segment_heads", "keys");
  head_flags.resize(n);
  if (n == 0) {
    starts.resize(1);
    starts.fill(0);
    return 0;
  }
  cl::Kernel heads = ctx.kernel("segments.cl", "segment_heads");
  set_args(heads, "segment_heads", keys.buffer(), u32(n), head_flags.buffer());
  ctx.launch(heads, n, "clEnqueueNDRangeKernel(segment_heads)");
  DeviceBuffer<uint32_t> pos(ctx, n);
  uint32_t count = scan_impl(ctx, head_flags.buffer(), pos.buffer(), n, false);
  starts.resize(size_t{count} + 1);
  cl::Kernel st = ctx.kernel("segments.cl", "segment_starts");
  set_args(st, "segment_starts", head_flags.buffer(), pos.buffer(), u32(n), count, starts.buffer());
  ctx.launch(st, n, "clEnqueueNDRangeKernel(segment_starts)");
  return count;
}

uint32_t unique_by_key(Context& ctx, const DeviceBuffer<uint64_t>& keys, size_t n, DeviceBuffer<uint64_t>& unique_keys,
                       DeviceBuffer<uint32_t>& starts) {
  DeviceBuffer<uint32_t> flags(ctx, n);
  uint32_t count = segment_heads(ctx, keys, n, flags, starts);
  unique_keys.resize(count);
  if (count == 0) return 0;
  cl::Kernel g = ctx.kernel("segments.cl", "gather_keys");
  set_args(g, "gather_keys", keys.buffer(), starts.buffer(), count, unique_keys.buffer());
  ctx.launch(g, count, "clEnqueueNDRangeKernel(gather_keys)");
  return count;
}

void reduce_by_segment(Context& ctx, const DeviceBuffer<uint32_t>& values, const DeviceBuffer<uint32_t>& starts,
                       uint32_t count, DeviceBuffer<uint32_t>& out, ReduceOp op) {
  check_size(starts, size_t{count} + 1, "reduce_by_segment", "starts");
  out.resize(count);
  if (count == 0) return;
  uint32_t n = 0;
  starts.download(&n, 1, count);  // starts[count] = number of values
  check_size(values, n, "reduce_by_segment", "values");
  if (op == ReduceOp::Sum) {
    DeviceBuffer<uint32_t> prefix(ctx, size_t{n} + 1);
    uint32_t total = scan_impl(ctx, values.buffer(), prefix.buffer(), n, false);
    prefix.upload(&total, 1, n);
    cl::Kernel k = ctx.kernel("segments.cl", "segment_sum");
    set_args(k, "segment_sum", prefix.buffer(), starts.buffer(), count, out.buffer());
    ctx.launch(k, count, "clEnqueueNDRangeKernel(segment_sum)");
  } else {
    cl::Kernel k = ctx.kernel("segments.cl", "segment_minmax");
    set_args(k, "segment_minmax", values.buffer(), starts.buffer(), count, u32(op == ReduceOp::Max), out.buffer());
    ctx.launch(k, count, "clEnqueueNDRangeKernel(segment_minmax)");
  }
}

uint32_t reduce_by_key(Context& ctx, const DeviceBuffer<uint64_t>& keys, const DeviceBuffer<uint32_t>& values, size_t n,
                       DeviceBuffer<uint64_t>& unique_keys, DeviceBuffer<uint32_t>& out, ReduceOp op) {
  check_size(values, n, "reduce_by_key", "values");
  DeviceBuffer<uint32_t> starts(ctx, 1);
  uint32_t count = unique_by_key(ctx, keys, n, unique_keys, starts);
  reduce_by_segment(ctx, values, starts, count, out, op);
  return count;
}

}  // namespace tc::dev
