// The host tail (CollapseTuning::host_tail): once the iterations on the device collapse few
// edges each and would go on for many more, the rest runs on the host with the sequential
// method, greedily, from the device's connectivity (a TailSeed).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "collapse/connectivity.hpp"
#include "collapse/params.hpp"
#include "collapse/sequential_run.hpp"
#include "collapse/upload.hpp"
#include "tetcollapse/collapse.hpp"

namespace tc::collapse_detail {

struct EdgeState;  // edge_state.hpp

class HostTail {
 public:
  HostTail(const CollapseOptions& options, const Context& ctx);
  // After an iteration and the next connectivity: does the rest run on the host? When the last
  // iteration collapsed fewer than the fraction x its tets, and the collapses shrink slowly.
  bool due(const std::vector<IterationStats>& iterations) const;
  // Takes over the current mesh's connectivity (built and, with reuse, its verdicts carried) and
  // the vertex mask, before the mesh is downloaded.
  // nothing_collapsed: the last iteration collapsed nothing (c is the mesh's connectivity and
  // every marked edge was refused there: no vertex counts as touched but those the reference
  // makes so).
  void seed(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, bool nothing_collapsed = false);
  // Runs the rest on the downloaded mesh (current numbering; its triangles and edges remapped);
  // its iterations continue the report's.
  void finish(Mesh& mesh, const StageParams& p, CollapseReport& report);
  bool seeded() const { return seeded_; }
  // Under a boundary error bound: the tail measures the changes of S the carried bound refuses
  // against this surface (CollapseTuning::remeasure_boundary_error), those the device refused
  // included (their end points count as touched).
  void set_reference(std::shared_ptr<const std::vector<double>> r) { reference_ = std::move(r); }

 private:
  const CollapseOptions& o_;
  double fraction_ = 0;
  bool seeded_ = false;
  sequential_detail::TailSeed seed_;
  std::vector<uint8_t> mask_;
  std::shared_ptr<const std::vector<double>> reference_;
};

}  // namespace tc::collapse_detail
