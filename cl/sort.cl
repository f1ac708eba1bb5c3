/* Stable LSD radix sort of 64-bit keys with an optional 32-bit payload, TC_RADIX_BITS per pass.
 *
 * Each work item owns a fixed chunk of `chunk` consecutive elements (the chunk does not depend
 * on the work-group size, so neither do the results):
 *   radix_count    counts the digits of its chunk: hist[digit * items + item],
 *   (host)         exclusive scan of hist (digit-major, then item order) = first output slot
 *                  of each (digit, item) pair,
 *   radix_scatter  walks its chunk again in order and writes each element to the next slot of
 *                  its digit. Chunks are visited in order within a digit and each chunk in
 *                  order, which makes every pass stable, hence the whole LSD sort.
 * OpenCL C 1.2 only.
 */
#ifndef TC_RADIX_BITS
#define TC_RADIX_BITS 4
#endif
#define TC_RADIX (1u << TC_RADIX_BITS)

/* mask selects the digit's bits: all TC_RADIX_BITS, or fewer in the last pass so bits above
 * key_bits are never looked at. */
__kernel void radix_count(__global const ulong* keys, uint n, uint shift, uint mask, uint chunk, uint items,
                          __global uint* hist) {
  uint g = get_global_id(0);
  if (g >= items) return;
  uint count[TC_RADIX];
  for (uint d = 0; d < TC_RADIX; ++d) count[d] = 0u;
  uint begin = g * chunk;
  uint end = min(n, begin + chunk);
  for (uint i = begin; i < end; ++i) count[(uint)(keys[i] >> shift) & mask]++;
  for (uint d = 0; d < TC_RADIX; ++d) hist[d * items + g] = count[d];
}

__kernel void radix_scatter(__global const ulong* keys, __global const uint* values, __global ulong* keys_out,
                            __global uint* values_out, uint has_values, uint n, uint shift, uint mask, uint chunk, uint items,
                            __global const uint* offsets) {
  uint g = get_global_id(0);
  if (g >= items) return;
  uint next[TC_RADIX];
  for (uint d = 0; d < TC_RADIX; ++d) next[d] = offsets[d * items + g];
  uint begin = g * chunk;
  uint end = min(n, begin + chunk);
  for (uint i = begin; i < end; ++i) {
    ulong k = keys[i];
    uint slot = next[(uint)(k >> shift) & mask]++;
    keys_out[slot] = k;
    if (has_values) values_out[slot] = values[i];
  }
}
