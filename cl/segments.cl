/* Segments of equal neighbouring keys (runs in a sorted array): head flags, segment starts,
 * unique keys and per-segment reductions. OpenCL C 1.2 only. */

__kernel void segment_heads(__global const ulong* keys, uint n, __global uint* flags) {
  uint i = get_global_id(0);
  if (i < n) flags[i] = (i == 0u || keys[i] != keys[i - 1]) ? 1u : 0u;
}

/* positions = exclusive scan of flags; starts[count] = n closes the last segment. */
__kernel void segment_starts(__global const uint* flags, __global const uint* positions, uint n, uint count,
                             __global uint* starts) {
  uint i = get_global_id(0);
  if (i < n && flags[i] != 0u) starts[positions[i]] = i;
  if (i == 0u) starts[count] = n;
}

__kernel void gather_keys(__global const ulong* keys, __global const uint* starts, uint count,
                          __global ulong* out) {
  uint s = get_global_id(0);
  if (s < count) out[s] = keys[starts[s]];
}

/* Sum of a segment from the exclusive prefix sums of the values (prefix has n + 1 entries):
 * balanced whatever the segment lengths; exact mod 2^32. */
__kernel void segment_sum(__global const uint* prefix, __global const uint* starts, uint count,
                          __global uint* out) {
  uint s = get_global_id(0);
  if (s < count) out[s] = prefix[starts[s + 1]] - prefix[starts[s]];
}

/* Min / max: one work item walks its segment (segments in meshes are short: valences). */
__kernel void segment_minmax(__global const uint* values, __global const uint* starts, uint count, uint want_max,
                             __global uint* out) {
  uint s = get_global_id(0);
  if (s >= count) return;
  uint b = starts[s], e = starts[s + 1];
  uint r = values[b];
  for (uint i = b + 1; i < e; ++i) r = want_max ? max(r, values[i]) : min(r, values[i]);
  out[s] = r;
}
