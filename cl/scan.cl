/* Exclusive scan of 32-bit unsigned integers (mod 2^32) and stream compaction.
 *
 * Three phases over tiles of TC_ITEMS * get_local_size(0) elements:
 *   scan_reduce     one sum per tile (block_sums),
 *   (host)          exclusive scan of block_sums, recursively with the same kernels,
 *   scan_downsweep  each tile is staged in local memory, each work item scans TC_ITEMS
 *                   consecutive values serially, the per-item totals are scanned in local
 *                   memory, and the results are written back with the tile's offset.
 * Integer addition is associative, so results do not depend on the work-group size.
 * With as_flags != 0 the input is read as (x != 0), which is what compaction needs.
 * OpenCL C 1.2 only.
 */
#ifndef TC_ITEMS
#define TC_ITEMS 8
#endif

inline uint tc_load(__global const uint* in, uint i, uint n, uint as_flags) {
  if (i >= n) return 0u;
  uint v = in[i];
  return as_flags ? (v != 0u ? 1u : 0u) : v;
}

/* The tile scan (GPU devices); without it where the host runs the chunked one (TC_SCAN_CHUNKED),
 * which saves a CPU device compiling kernels it never launches. */
#ifndef TC_SCAN_CHUNKED
/* Exclusive scan of s[0..m) in local memory (m = local size); returns the total. */
inline uint tc_local_exclusive_scan(__local uint* s, uint l, uint m) {
  for (uint off = 1; off < m; off <<= 1) {
    uint v = l >= off ? s[l - off] : 0u;
    barrier(CLK_LOCAL_MEM_FENCE);
    s[l] += v;
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  uint total = s[m - 1];
  uint mine = l > 0 ? s[l - 1] : 0u;
  barrier(CLK_LOCAL_MEM_FENCE);
  s[l] = mine;
  barrier(CLK_LOCAL_MEM_FENCE);
  return total;
}

__kernel void scan_reduce(__global const uint* in, uint n, uint as_flags, __global uint* block_sums,
                          __local uint* s) {
  uint l = get_local_id(0), m = get_local_size(0), g = get_group_id(0);
  uint base = g * m * TC_ITEMS;
  uint sum = 0u;
  /* Strided across the work group so neighbouring work items read neighbouring values. */
  for (uint j = 0; j < TC_ITEMS; ++j) sum += tc_load(in, base + j * m + l, n, as_flags);
  s[l] = sum;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint h = m >> 1; h > 0; h >>= 1) {
    if (l < h) s[l] += s[l + h];
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  if (l == 0) block_sums[g] = s[0];
}

/* out may alias in: each group reads its whole tile into local memory before writing it. */
__kernel void scan_downsweep(__global const uint* in, __global uint* out, uint n, uint as_flags,
                             __global const uint* block_offsets, uint use_offsets, __global uint* total,
                             __local uint* tile, __local uint* s) {
  uint l = get_local_id(0), m = get_local_size(0), g = get_group_id(0);
  uint base = g * m * TC_ITEMS;
  for (uint j = 0; j < TC_ITEMS; ++j) tile[j * m + l] = tc_load(in, base + j * m + l, n, as_flags);
  barrier(CLK_LOCAL_MEM_FENCE);
  uint sum = 0u;
  for (uint j = 0; j < TC_ITEMS; ++j) sum += tile[l * TC_ITEMS + j];
  s[l] = sum;
  barrier(CLK_LOCAL_MEM_FENCE);
  uint tile_total = tc_local_exclusive_scan(s, l, m);
  uint offset = (use_offsets ? block_offsets[g] : 0u);
  uint run = offset + s[l];
  for (uint j = 0; j < TC_ITEMS; ++j) {
    uint v = tile[l * TC_ITEMS + j];
    tile[l * TC_ITEMS + j] = run;
    run += v;
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint j = 0; j < TC_ITEMS; ++j) {
    uint i = base + j * m + l;
    if (i < n) out[i] = tile[j * m + l];
  }
  if (g == get_num_groups(0) - 1 && l == 0) total[0] = offset + tile_total;
}
#endif

/* Compaction: positions = exclusive scan of (flags != 0). */
__kernel void compact_indices(__global const uint* flags, __global const uint* positions, uint n,
                              __global uint* out) {
  uint i = get_global_id(0);
  if (i < n && flags[i] != 0u) out[positions[i]] = i;
}

__kernel void compact_u32(__global const uint* values, __global const uint* flags, __global const uint* positions,
                          uint n, __global uint* out) {
  uint i = get_global_id(0);
  if (i < n && flags[i] != 0u) out[positions[i]] = values[i];
}

__kernel void compact_u64(__global const ulong* values, __global const uint* flags, __global const uint* positions,
                          uint n, __global ulong* out) {
  uint i = get_global_id(0);
  if (i < n && flags[i] != 0u) out[positions[i]] = values[i];
}

/* Chunked variant for CPU devices (selected by the host): each work item scans `chunk`
 * consecutive values serially, with no local memory and no barriers. On a CPU work items are
 * iterations of a loop, so barrier-separated local scans cost far more than they save
 * (bench_primitives; measured in bench/README.md).
 *   scan_chunk_sums   sums[g] = sum of chunk g,
 *   (host)            exclusive scan of sums, recursively,
 *   scan_chunk_apply  serial exclusive scan of chunk g starting at offsets[g]; the last chunk
 *                     writes the grand total. */
__kernel void scan_chunk_sums(__global const uint* in, uint n, uint as_flags, uint chunk, uint items,
                              __global uint* sums) {
  uint g = get_global_id(0);
  if (g >= items) return;
  uint begin = g * chunk, end = min(n, begin + chunk);
  uint s = 0u;
  for (uint i = begin; i < end; ++i) s += tc_load(in, i, n, as_flags);
  sums[g] = s;
}

__kernel void scan_chunk_apply(__global const uint* in, __global uint* out, uint n, uint as_flags, uint chunk,
                               uint items, __global const uint* offsets, uint use_offsets, __global uint* total) {
  uint g = get_global_id(0);
  if (g >= items) return;
  uint begin = g * chunk, end = min(n, begin + chunk);
  uint run = use_offsets ? offsets[g] : 0u;
  for (uint i = begin; i < end; ++i) {
    uint v = tc_load(in, i, n, as_flags);
    out[i] = run;
    run += v;
  }
  if (g == items - 1u) total[0] = run;
}
