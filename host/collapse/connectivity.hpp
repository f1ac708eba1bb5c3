// Stage 1 of an iteration: the connectivity of the current mesh (cl/collapse_connectivity.cl).
#pragma once

#include <cstdint>

#include "collapse/launch.hpp"
#include "collapse/params.hpp"
#include "collapse/upload.hpp"

namespace tc::collapse_detail {

// Stage 1 output.
struct Connectivity {
  uint32_t ne = 0;
  DeviceBuffer<uint32_t> vt_off;   // nv + 1
  DeviceBuffer<int32_t> vt;        // 4 nt: ring(v), ascending
  DeviceBuffer<uint32_t> nb_off;   // nv + 1
  DeviceBuffer<int32_t> nb;        // N(v), ascending
  DeviceBuffer<int32_t> nb_edge;   // edge id of each N(v) entry
  DeviceBuffer<uint32_t> edge_off; // nv + 1: edges owned by v (v is the smaller end)
  DeviceBuffer<int32_t> edges;     // 2 per edge, sorted lexicographically
  DeviceBuffer<int32_t> tet_nbr;   // 4 per tet: tet across each face (collapse_common.h)
  DeviceBuffer<uint8_t> vflags, vclass, eflags;  // see collapse_common.h
  DeviceBuffer<uint32_t> owns_s;   // per tet: 1 when it owns an S face (the surface guard's tets)
  DeviceBuffer<uint8_t> smask;     // per tet: which faces it owns on S (bit f: the face opposite local vertex f)
  uint64_t generation = 0;         // new (process-wide unique) at every build_connectivity
  // scratch (scratch itself is released at the end of build_connectivity)
  DeviceBuffer<uint32_t> count, cursor, up_count;
  DeviceBuffer<int32_t> scratch;
  DeviceBuffer<uint32_t> dirty_list;  // vertices recomputed when carrying (build_connectivity)
};

struct EdgeState;  // edge_state.hpp

// With s (an EdgeState after note_compaction), the data (N(v), tet_nbr, vclass, eflags) of the
// vertices whose rings did not change is copied from the previous iteration (s->carry) instead
// of recomputed, and the rings and tet_nbr computed by collapse_and_compact are taken over
// (s->compact.upd_*, swapped into c).
void build_connectivity(Context& ctx, DeviceMesh& dm, Connectivity& c, const StageParams& p,
                        EdgeState* s = nullptr);

}  // namespace tc::collapse_detail
