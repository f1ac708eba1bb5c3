// Verdicts of the link and volume tests carried across iterations (cl/collapse_verdicts.cl).
#pragma once

#include <cstdint>
#include <vector>

#include "collapse/connectivity.hpp"
#include "collapse/edge_state.hpp"
#include "collapse/params.hpp"
#include "collapse/upload.hpp"

namespace tc::collapse_detail {

// Verdict carrying around collapse_and_compact: remember_for_carry() before it (dirty vertices:
// the end points of the final edges and their neighbours), note_compaction() right after it
// (previous connectivity and verdicts kept, current -> previous vertex map), carry_verdicts()
// after the next build_connectivity (fills s.edges2verdict for the next lazy_admissible_pass1).
void remember_for_carry(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s);
void note_compaction(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s);
void carry_verdicts(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s);
// After carry_verdicts: per vertex, whether its ring changed in the last iteration or an edge at
// it keeps the surface guard's refusal (cl/collapse_verdicts.cl tail_touched; the host tail's
// TailSeed::touched).
std::vector<uint8_t> tail_touched(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s);

}  // namespace tc::collapse_detail
