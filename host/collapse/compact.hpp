// The last stage of an iteration: the collapses applied, the mesh compacted
// (cl/collapse_compact.cl, cl/collapse_update.cl).
#pragma once

#include <cstdint>

#include "collapse/connectivity.hpp"
#include "collapse/params.hpp"
#include "collapse/upload.hpp"

namespace tc::collapse_detail {

// What the compaction leaves for the next iteration's connectivity and verdicts.
struct CompactState {
  // The maps from the compacted mesh's predecessor to it (note_compaction and the carried
  // build_connectivity read them).
  DeviceBuffer<int32_t> prev_verts2new;                      // previous vertex -> current
  DeviceBuffer<uint32_t> prev_tets_are_kept, prev_tets2new;  // previous tet: kept, its index
  // The connectivity carried through the compaction (collapse_update.cl): requested by
  // remember_for_carry (update_next), taken over by build_connectivity (has_update).
  bool update_next = false, has_update = false;
  DeviceBuffer<uint32_t> upd_count, upd_vt_off;
  DeviceBuffer<int32_t> upd_vt, upd_tet_nbr;
};

struct EdgeState;  // edge_state.hpp

// Applies the final collapses (the survivors at p's placement): dm becomes the new mesh (via
// `next`, swapped in); origin (input vertex -> current vertex) is updated when non-empty.
void collapse_and_compact(Context& ctx, const StageParams& p, DeviceMesh& dm, DeviceMesh& next, Connectivity& c,
                          EdgeState& s, DeviceBuffer<int32_t>& origin, uint32_t n_origin);

}  // namespace tc::collapse_detail
