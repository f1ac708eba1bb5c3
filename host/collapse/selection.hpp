// The selection of an iteration (the paper's Sections 3.2 and 3.3, within collapseEdges of
// Algorithm 1): which marked edges collapse. Four implementations, one per conflict detection, each in the file of
// its kernels' host side:
//   TwoPass    the paper's: the lazy admissible filter with conflict pass 1 over edges, then
//              pass 2 over tets (select_two_pass.cpp)
//   Greedy     one priority-ordered pass under both passes' conflicts (select_greedy.cpp)
//   Matching   priority order, each edge tested on the mesh with the earlier collapses applied;
//              only edges sharing an end point conflict (select_matching.cpp)
//   AtomicMin  every admissible edge, then Gautron and Kenzel's 64-bit atomic minima
//              (select_atomic_min.cpp)
// The surface guard then tests the chosen collapses; the refused edges are unmarked and the
// selection runs again (the matching selection undoes them instead), until none is refused.
#pragma once

#include <cstdint>
#include <memory>

#include "collapse/connectivity.hpp"
#include "collapse/guard_surface.hpp"
#include "collapse/params.hpp"
#include "collapse/upload.hpp"
#include "tetcollapse/collapse.hpp"

namespace tc::collapse_detail {

struct EdgeState;  // edge_state.hpp

class Selection {
 public:
  virtual ~Selection() = default;
  // This iteration's collapses in s.result (edges_are_final, edges2dir, verts2collapse), tested by
  // the surface guard; returns how many. Fills stats' candidates, tested, selected,
  // refused_by_guard, seconds_select and seconds_guard.
  uint32_t select(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                  IterationStats& stats);
  // Frees what only the selection reads (its rounds' lists and flags, the cost and priorities,
  // the surface guard's queries and its own state), keeping what the compaction, the verdict
  // carry and the host tail read (edges2dir, verts2collapse, tets_are_dead, the verdicts). The
  // next select allocates them again, at its smaller mesh's size: at scale, the compaction's
  // buffers would otherwise come on top of these.
  virtual void release(EdgeState& s);

 protected:
  // What one run of the selection chose and counted: the collapses, the marked edges passing
  // Q, the tests run.
  struct Chosen {
    uint32_t selected = 0, candidates = 0, tested = 0;
  };
  // Before the first selection of an iteration.
  virtual void begin(Context&, DeviceMesh&, EdgeState&) {}
  // The admissible filter and the conflict detection.
  virtual Chosen choose(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                        const IterationStats& stats) = 0;
  // The surface guard on the `chosen` collapses: returns how many it refused; `chosen` becomes
  // how many are left. Unless guard_leaves_final(), a refusal has the selection run again.
  virtual uint32_t guard(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                         uint32_t& chosen);
  virtual bool guard_leaves_final() const { return false; }

  SurfaceGuard guard_;
};

std::unique_ptr<Selection> make_two_pass_selection(int rounds);
std::unique_ptr<Selection> make_greedy_selection();
std::unique_ptr<Selection> make_matching_selection();
std::unique_ptr<Selection> make_atomic_min_selection();
// The selection options.conflicts names.
std::unique_ptr<Selection> make_selection(const CollapseOptions& options);

}  // namespace tc::collapse_detail
