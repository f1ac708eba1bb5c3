// The host tail (host_tail.hpp).
#include "collapse/host_tail.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

#include "collapse/verdict_carry.hpp"

namespace tc::collapse_detail {

namespace {

// CollapseTuning::host_tail on this device (negative: automatic).
double host_tail_fraction(const CollapseOptions& o, const Context& ctx) {
  if (o.tuning.host_tail >= 0) return o.tuning.host_tail;
  if (!ctx.cpu_tuning()) return 0.0;
  return o.conflicts == CollapseOptions::Matching ? CollapseTuning::kHostTailCpuMatching : CollapseTuning::kHostTailCpu;
}

// CollapseTuning::host_tail_min_iterations (negative: automatic).
double host_tail_iterations(const CollapseOptions& o) {
  if (o.tuning.host_tail_min_iterations >= 0) return o.tuning.host_tail_min_iterations;
  return o.conflicts == CollapseOptions::Matching ? CollapseTuning::kHostTailIterationsMatching
                                                  : CollapseTuning::kHostTailIterations;
}

// TETCOLLAPSE_HOST_TAIL_SEED=0 hands the host tail the mesh alone (a switch for the tests, which
// compare both ways: the same output).
bool tail_seed_enabled() {
  const char* e = std::getenv("TETCOLLAPSE_HOST_TAIL_SEED");
  return !(e && std::string(e) == "0");
}

}  // namespace

HostTail::HostTail(const CollapseOptions& options, const Context& ctx)
    : o_(options), fraction_(host_tail_fraction(options, ctx)) {}

// At the ratio r of the last two iterations' counts (at most 0.95), c r^n < 1 takes
// n = ln c / ln(1 / r) >= host_tail_min_iterations more iterations (a tail that dies out fast is
// cheaper on the device than the host's fixed cost). Counts only: the choice is deterministic.
bool HostTail::due(const std::vector<IterationStats>& its) const {
  if (!(fraction_ > 0) || o_.conflicts == CollapseOptions::AtomicMin || o_.eps_c > 1 || o_.has_user_functions() ||
      its.size() < 2)
    return false;
  const IterationStats& s = its.back();
  if (s.iteration + 1 >= o_.max_iterations || !(double(s.collapsed) < fraction_ * double(s.tets))) return false;
  const double c = double(s.collapsed);
  const double r = std::min(0.95, c / double(std::max<int64_t>(its[its.size() - 2].collapsed, 1)));
  return std::log(c) >= host_tail_iterations(o_) * std::log(1 / r);
}

// The seed: the connectivity, the tet neighbours, the flags and classes, and the touched flags
// (tail_touched) where the last iteration's selection was greedy or matching and the verdicts
// are carried; else every vertex counts as touched.
void HostTail::seed(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, bool nothing_collapsed) {
  seeded_ = true;
  if (dm.has_mask) mask_ = dm.vmask.download_range(0, dm.nv);
  if (!tail_seed_enabled()) return;
  seed_.vflags = c.vflags.download_range(0, dm.nv);
  seed_.vclass = c.vclass.download_range(0, dm.nv);
  seed_.tet_nbr = c.tet_nbr.download_range(0, 4 * size_t(dm.nt));
  seed_.edges = c.edges.download_range(0, 2 * size_t(c.ne));
  if (nothing_collapsed && reference_ && o_.tuning.reuse_across_iterations)
    seed_.touched.assign(dm.nv, 0);
  else if (o_.tuning.reuse_across_iterations &&
           (o_.conflicts == CollapseOptions::Greedy || o_.conflicts == CollapseOptions::Matching))
    seed_.touched = tail_touched(ctx, dm, c, s);
  else
    seed_.touched.assign(dm.nv, 1);
  if (reference_)  // the collapses of S the device's carried bound refused, measured now
    for (size_t v = 0; v < seed_.touched.size(); ++v) seed_.touched[v] |= seed_.vflags[v] != 0;
}

void HostTail::finish(Mesh& mesh, const StageParams& p, CollapseReport& report) {
  const int done = int(report.iterations.size());
  CollapseOptions o = o_;
  o.method = CollapseOptions::Sequential;
  o.sequential_skip_invalidated = false;  // greedy: every queued edge has a touched end point
  o.target_length = p.target;
  o.eps_v = p.eps_v;
  o.eps_v_scale = CollapseOptions::Absolute;  // (the device's threshold, in mesh units)
  o.vertex_mask = std::move(mask_);
  o.max_iterations = o_.max_iterations - done;
  o.boundary_reference = reference_;  // (none: the tail's own S is no reference)
  o.tuning.remeasure_boundary_error = reference_ != nullptr;
  auto continued = [done](IterationStats t) {  // numbered on from the device's iterations
    t.iteration += done;
    t.on_host = true;
    return t;
  };
  o.progress = [&](const IterationStats& s) {
    if (o_.progress) o_.progress(continued(s));
  };
  sequential_detail::SequentialRun run(mesh, o, seed_.vflags.empty() ? nullptr : &seed_);
  run.set_greedy(true);
  // the boundary error bound per vertex, in the last vertex field (collapse_bounded)
  if (p.bound > 0) run.seed_boundary_error(mesh.vertex_fields.back().values);
  while (run.step()) {
  }
  const CollapseReport r = run.finish();
  if (p.bound > 0) mesh.vertex_fields.back().values = run.boundary_errors();
  for (const IterationStats& t : r.iterations) report.iterations.push_back(continued(t));
  report.seconds_total += r.seconds_total;
}

}  // namespace tc::collapse_detail
