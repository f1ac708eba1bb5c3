// What `tetcollapse IN OUT` does, in one call (the command line and the Python module call it):
//
//   coarsen(mesh, options, ctx):
//     a field named by preserve_field or sizing_field drives the collapse's cost (or, with
//       collapse.max_field_error, the field error bound)
//     collapse (collapse.hpp), keeping a share of a boundary error bound for the next phase
//     improve (improve.hpp) with the boundary mode, thresholds and what is left of the bound,
//       unless improve is false, a user predicate or placement states rules the improvement
//       cannot know, or the field error bound is on (the improvement's moves are not checked
//       against it)
//     every vertex field from the input at each vertex's final place (fields.hpp)
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "tetcollapse/collapse.hpp"
#include "tetcollapse/improve.hpp"
#include "tetcollapse/mesh.hpp"

namespace tc {

struct CoarsenOptions {
  CollapseOptions collapse;
  // The improvement phase after the collapse. Its boundary mode, eps_f, eps_r and use_labels are
  // the collapse's, and its boundary error bound what the collapse left of the bound.
  bool improve = true;
  ImproveOptions improvement;
  // The vertices of the coarse mesh the improvement may change (non-zero = yes), e.g. those of
  // a region; unset: every vertex.
  std::function<std::vector<uint8_t>(const Mesh&)> improve_mask;
  // Vertex fields at the end: the input's piecewise linear field at each vertex's final place
  // (true), or the average of a collapsed edge's ends (false).
  bool resample_fields = true;
  // Volume rendering (the paper's Section 4.5): an edge is collapsed when this vertex field
  // differs between its ends by less than field_tolerance x its range, or, with
  // collapse.max_field_error, while the field stays within that bound at every input vertex.
  std::string preserve_field;
  double field_tolerance = 0.02;
  // With preserve_field and field_tolerance (beyond the paper): a collapse is also refused when
  // the field at an end point's old place would change by more than field_check x
  // field_tolerance x the range (CollapseOptions::field_check); 0: the paper's cost alone.
  double field_check = 0.25;
  // A vertex field giving the wanted edge length: an edge is collapsed when shorter than the
  // field's mean at its ends.
  std::string sizing_field;
  // Collapse and improvement, cycles times when the improvement phase runs: the improvement's
  // flips and moves make edges the collapse refused (on a sliver, a link or a shape it would
  // spoil) collapsible, so each later cycle collapses them, with the same target length and
  // from the boundary error bound each vertex spent, under the quality guard
  // kLaterCycleMinQuality, and improves again. A cycle whose collapse removes fewer than
  // kCycleMinShare of the tets is the last (improved, unless it removed none). A collapse's
  // vertex_mask (sized for the input) then needs improve_mask for the later cycles
  // (std::invalid_argument). 1: the collapse and one improvement.
  int cycles = 2;
};

// A later cycle (CoarsenOptions::cycles) stops the cycles when its collapse removes fewer than
// this share of the tets (what is left is not worth another improvement).
constexpr double kCycleMinShare = 0.01;
// A later cycle's collapse refuses to leave a tet below this mean ratio (or min_quality, when
// higher): in a coarser mesh the improvement has fewer ways to mend a sliver, and with the first
// cycle's 0.1 the second left worse angles than the first on the shared meshes measured; 0.15
// kept them, for most of the tets the later cycle removes (figures in the commit that set it).
constexpr double kLaterCycleMinQuality = 0.15;

// What a later cycle did: the tets before it, after its collapse and after its improvement.
struct CycleReport {
  int64_t tets_before = 0, tets_collapsed = 0, tets_after = 0;
  CollapseReport collapse;
  ImproveReport improvement;  // (not run when the collapse removed no tet)
  bool improved = false;
};

struct CoarsenReport {
  CollapseReport collapse;    // the first cycle's (vertices_out, tets_out: the result's)
  bool improved = false;      // whether the improvement phase ran
  ImproveReport improvement;  // its report, when it ran (the first cycle's)
  std::vector<CycleReport> later_cycles;  // CoarsenOptions::cycles past the first
  int64_t outside = 0;        // vertices outside the input whose fields came from the nearest tet
};

// The report of the last improvement that ran (whose `after` is the result's quality when the
// report says improved): the first cycle's, or the last later cycle's that improved.
const ImproveReport& last_improvement(const CoarsenReport& r);

// The boundary error bound (CollapseOptions::max_boundary_error, a share of the bounding-box
// diagonal) that the command lines and the Python module apply in features mode unless told
// otherwise (0 there: none, the paper's method). CollapseOptions itself keeps 0.
constexpr double kDefaultMaxBoundaryError = 0.001;
// That default for a boundary mode: kDefaultMaxBoundaryError in features mode, 0 in the others
// (which refuse a bound).
double default_max_boundary_error(CollapseOptions::Boundary mode);

// The share of a boundary error bound the collapse may use when the improvement phase follows
// (the rest is for the improvement's boundary moves, which remove the slivers at a curved
// surface; the improvement goes on from each vertex's own bound, mostly far below this). 0.9
// rather than less: fewer tets on every curved shared mesh measured, the angles about as good
// (the figures in the commit that set it).
constexpr double kCollapseShareOfBound = 0.9;

// What preserve_field and sizing_field make of the collapse's options `co` for `mesh` (the cost
// and the target; with max_field_error, the bounded field), and the index of the vertex field
// the cost reads, which must come first for the run (0 when none). coarsen() calls it, and so
// does tetcollapse-mpi on the whole mesh before cutting it. std::invalid_argument for a field
// the mesh lacks or a constant one.
size_t apply_field_options(const Mesh& mesh, const CoarsenOptions& options, CollapseOptions& co);
// The cost sizing_field stands for (OpenCL C in the user cost's slot: the edge's length over the
// field's mean at its ends, target 1), for callers that set it on parts of a mesh.
std::string sizing_cost_source();
// Whether the improvement phase follows the collapse: options.improve, unless a user placement
// or predicate, or a field error bound, states rules the improvement cannot know, or its flips,
// relocation and collapse step are all off.
bool improvement_follows(const CoarsenOptions& options);

// Coarsens `mesh` in place as described above. With ctx null, the collapse must use the
// sequential method (CollapseOptions::Sequential) and the improvement runs on the CPU.
// Throws as collapse() and improve() do; std::invalid_argument for a field option naming no
// vertex field or combined with a user cost. `input`: the mesh as it was before the call, when
// the caller keeps a copy anyway (the fields are resampled from it instead of a copy of its own).
CoarsenReport coarsen(Mesh& mesh, const CoarsenOptions& options, Context* ctx, const Mesh* input = nullptr);

}  // namespace tc
