// Data-parallel primitives on the device, used by every later stage.
//
// Each takes device buffers and a logical element count n (buffers may be larger). Results are
// identical whatever the context's work-group size. Temporary buffers are allocated per call.
#pragma once

#include <cstddef>
#include <cstdint>

#include "tetcollapse/device.hpp"

namespace tc::dev {

// Sets a kernel's arguments in order (the device's own kernels; the collapse stages name theirs,
// collapse/launch.hpp); an OpenCL failure is a DeviceError naming `what`.
template <class... A>
void set_args(cl::Kernel& k, const char* what, const A&... a) {
  detail::cl_call(what, [&] {
    cl_uint i = 0;
    (k.setArg(i++, a), ...);
  });
}

// How the primitives map onto a device. The default depends on Context::cpu_tuning (see
// default_tuning); set_tuning_override lets tests and benches run every variant on any device.
struct Tuning {
  bool chunked_scan = false;  // true: per-work-item serial chunks (CPU); false: local-memory tiles (GPU)
  int radix_bits = 4;         // digit width of the radix sort: 4 (16 private counters) or 8
  unsigned sort_chunk = 256;  // elements per work item in a radix sort pass
};
Tuning default_tuning(bool cpu);
// Process-wide; nullptr restores the per-device default.
void set_tuning_override(const Tuning* tuning);
Tuning tuning_for(const Context& ctx);

// out[i] = in[0] + ... + in[i-1] (mod 2^32); returns the total of all n values (mod 2^32).
// in and out may be the same buffer. out must hold at least n values.
// Queues the scan's program (Context::prefetch).
void prefetch_scan(Context& ctx);
// Queues the radix sort's program (Context::prefetch).
void prefetch_sort(Context& ctx);
uint32_t exclusive_scan(Context& ctx, const DeviceBuffer<uint32_t>& in, DeviceBuffer<uint32_t>& out, size_t n);
inline uint32_t exclusive_scan(Context& ctx, const DeviceBuffer<uint32_t>& in, DeviceBuffer<uint32_t>& out) {
  return exclusive_scan(ctx, in, out, in.size());
}

// Stream compaction, order preserving: out receives the indices i < n with flags[i] != 0, in
// increasing order; returns their count. out is resized when too small.
uint32_t compact_indices(Context& ctx, const DeviceBuffer<uint32_t>& flags, DeviceBuffer<uint32_t>& out, size_t n);
// Same, but out receives values[i] for those i.
uint32_t compact(Context& ctx, const DeviceBuffer<uint32_t>& values, const DeviceBuffer<uint32_t>& flags,
                 DeviceBuffer<uint32_t>& out, size_t n);
uint32_t compact(Context& ctx, const DeviceBuffer<uint64_t>& values, const DeviceBuffer<uint32_t>& flags,
                 DeviceBuffer<uint64_t>& out, size_t n);

// Stable LSD radix sort of the first n keys, ascending, carrying values along. Only the low
// key_bits bits are sorted (keys must be < 2^key_bits; 1..64). Sorts in place.
void radix_sort(Context& ctx, DeviceBuffer<uint64_t>& keys, DeviceBuffer<uint32_t>& values, size_t n, int key_bits = 64);
void radix_sort(Context& ctx, DeviceBuffer<uint64_t>& keys, size_t n, int key_bits = 64);

// Segments of equal keys in a sorted array (any order works: a segment is a maximal run of
// equal neighbours). head_flags[i] = 1 when i == 0 or keys[i] != keys[i-1], else 0;
// starts[s] = first index of segment s, with starts[count] = n (starts is resized to count+1);
// returns count.
uint32_t segment_heads(Context& ctx, const DeviceBuffer<uint64_t>& keys, size_t n, DeviceBuffer<uint32_t>& head_flags,
                       DeviceBuffer<uint32_t>& starts);

// Unique by key: unique_keys[s] = key of segment s, starts as above; returns the segment count.
uint32_t unique_by_key(Context& ctx, const DeviceBuffer<uint64_t>& keys, size_t n, DeviceBuffer<uint64_t>& unique_keys,
                       DeviceBuffer<uint32_t>& starts);

// Segmented reduce over runs of equal keys: out[s] = op(values[starts[s]] .. values[starts[s+1]-1]),
// where starts comes from segment_heads / unique_by_key (count+1 entries). out is resized to count.
enum class ReduceOp { Sum, Min, Max };
void reduce_by_segment(Context& ctx, const DeviceBuffer<uint32_t>& values, const DeviceBuffer<uint32_t>& starts,
                       uint32_t count, DeviceBuffer<uint32_t>& out, ReduceOp op = ReduceOp::Sum);

// Convenience: unique keys, their segment starts and per-segment reduction in one call;
// returns the segment count.
uint32_t reduce_by_key(Context& ctx, const DeviceBuffer<uint64_t>& keys, const DeviceBuffer<uint32_t>& values, size_t n,
                       DeviceBuffer<uint64_t>& unique_keys, DeviceBuffer<uint32_t>& out, ReduceOp op = ReduceOp::Sum);

}  // namespace tc::dev
