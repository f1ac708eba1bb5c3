// The parallel method: the paper's Algorithm 1 over the stages of host/collapse/, one file each
// (the header tetcollapse/collapse.hpp gives the algorithm in pseudocode).
#include <algorithm>
#include <stdexcept>
#include <memory>

#include "collapse/compact.hpp"
#include "collapse/connectivity.hpp"
#include "collapse/cost.hpp"
#include "collapse/edge_state.hpp"
#include "collapse/host_tail.hpp"
#include "collapse/programs.hpp"
#include "collapse/selection.hpp"
#include "collapse/target.hpp"
#include "collapse/upload.hpp"
#include "collapse/verdict_carry.hpp"
#include "device/primitives.hpp"
#include "stopwatch.hpp"
#include "tetcollapse/collapse.hpp"

namespace tc {

using namespace collapse_detail;

namespace {

CollapseReport report_for(const Mesh& mesh, const Context& ctx) {
  CollapseReport r;
  r.device = ctx.info().name;
  r.vertices_in = mesh.num_vertices();
  r.tets_in = mesh.num_tets();
  return r;
}

}  // namespace

namespace {

// The boundary error bound on the parallel method: the device coarsens with S frozen (strict:
// no change of S, so nothing to bound), then the sequential method, which carries the bound,
// coarsens S and what its changes free. Why two phases: the bound's fan test and the per-vertex
// bound are host code so far; the interior, most of the work, still runs on the device.
CollapseReport collapse_bounded(Mesh& mesh, const CollapseOptions& options, Context& ctx) {
  if (options.has_user_functions())
    throw std::invalid_argument(
        "the boundary error bound on the parallel method takes no user cost, placement or predicate yet: use the "
        "sequential method");
  const double bound = boundary_error_bound(mesh, options);
  CollapseOptions inner = options;
  inner.boundary = CollapseOptions::Strict;
  inner.max_boundary_error = inner.max_boundary_error_abs = 0;
  // A vertex mask reaches the second phase through a vertex field, which the device's
  // compaction and renumbering carry to the survivors (a collapse averages it at a midpoint:
  // 1 stays 1 where both ends must be selected; with either end, a survivor of a selected end
  // stays selected).
  const bool masked = !options.vertex_mask.empty();
  if (masked) {
    Field f{"tetcollapse:vertex_mask", 1, {}};
    f.values.assign(options.vertex_mask.begin(), options.vertex_mask.end());
    for (double& x : f.values) x = x != 0 ? 1.0 : 0.0;
    mesh.vertex_fields.push_back(std::move(f));
  }
  CollapseReport report;
  try {
    report = collapse(mesh, inner, ctx);
  } catch (...) {
    if (masked) mesh.vertex_fields.pop_back();
    throw;
  }
  CollapseOptions outer = options;
  if (masked) {
    const std::vector<double>& v = mesh.vertex_fields.back().values;
    outer.vertex_mask.resize(v.size());
    for (size_t i = 0; i < v.size(); ++i)
      outer.vertex_mask[i] = options.mask_either ? v[i] > 0 : v[i] > 1 - 1e-9;
    mesh.vertex_fields.pop_back();
  }
  outer.method = CollapseOptions::Sequential;
  outer.target_length = report.target_length;  // the input's, not the coarse mesh's median
  outer.max_boundary_error = 0;
  outer.max_boundary_error_abs = bound;
  outer.max_iterations = std::max(0, options.max_iterations - int(report.iterations.size()));
  const int offset = int(report.iterations.size());
  if (options.progress)
    outer.progress = [&options, offset](const IterationStats& it) {
      IterationStats c = it;
      c.iteration += offset;
      c.on_host = true;
      options.progress(c);
    };
  const CollapseReport tail = collapse_sequential(mesh, outer);
  for (IterationStats it : tail.iterations) {
    it.iteration += offset;
    it.on_host = true;
    report.iterations.push_back(it);
  }
  report.vertices_out = tail.vertices_out;
  report.tets_out = tail.tets_out;
  report.seconds_total += tail.seconds_total;
  report.boundary_error_bound = bound;
  report.boundary_error = tail.boundary_error;
  report.vertex_boundary_error = tail.vertex_boundary_error;
  return report;
}

}  // namespace

namespace collapse_detail {
void prefetch_programs(Context& ctx, const CollapseOptions& o) {
  ctx.prefetch("collapse_connectivity.cl");
  dev::prefetch_scan(ctx);
  ctx.prefetch("collapse_cost.cl");
  if (o.conflicts == CollapseOptions::Matching) ctx.prefetch("collapse_matching.cl");
  if (o.conflicts == CollapseOptions::AtomicMin) ctx.prefetch("collapse_atomic_min.cl");
  if (o.conflicts == CollapseOptions::TwoPass) ctx.prefetch("collapse_conflict.cl");
  ctx.prefetch("collapse_admissible.cl");
  if (o.boundary != CollapseOptions::Strict) {  // the surface guard
    ctx.prefetch("collapse_guard_applied.cl");
    ctx.prefetch("collapse_guard.cl");
  }
  ctx.prefetch("collapse_verdicts.cl");
  ctx.prefetch("collapse_compact.cl");
  ctx.prefetch("collapse_update.cl");
}
}  // namespace collapse_detail

CollapseReport collapse(Mesh& mesh, const CollapseOptions& options, Context& ctx) {
  // The field error bound's check reads the input vertices of the region a collapse changes,
  // which live on the host (CollapseOptions::max_field_error).
  if (options.method == CollapseOptions::Sequential || options.max_field_error > 0)
    return collapse_sequential(mesh, options);
  if (options.bounds_boundary_error()) return collapse_bounded(mesh, options, ctx);
  check_options(options, ctx);
  check_device_memory(ctx, mesh, options);
  prefetch_programs(ctx, options);
  CollapseReport report = report_for(mesh, ctx);
  StageParams p = params_from(options);
  p.eps_v = report.eps_v = volume_threshold(mesh, options);
  const bool carry = options.tuning.reuse_across_iterations;  // verdicts and connectivity carried
  Stopwatch clock;
  DeviceMesh dm, next;
  DeviceBuffer<int32_t> origin = upload_with_origin(ctx, mesh, options, dm);  // input vertex -> current
  ctx.finish();
  report.seconds_upload = clock.lap();
  Connectivity conn;
  EdgeState st;
  auto connectivity = [&] {
    build_connectivity(ctx, dm, conn, p, carry ? &st : nullptr);
    if (carry) carry_verdicts(ctx, dm, conn, st);
    ctx.finish();
    return clock.lap();
  };
  auto collapse_and_carry = [&] {  // the verdicts and connectivity carried through the compaction
    if (carry) remember_for_carry(ctx, dm, conn, st);
    collapse_and_compact(ctx, p, dm, next, conn, st, origin, uint32_t(origin.size()));
    if (carry) note_compaction(ctx, dm, conn, st);
    ctx.finish();
  };
  const std::unique_ptr<Selection> selection = make_selection(options);
  HostTail tail(options, ctx);
  const Stopwatch run_clock;  // the run without the transfers of the mesh
  double seconds_connectivity = 0;
  p.target = options.target_length;
  if (options.max_iterations > 0 && dm.nt > 0) {
    seconds_connectivity = connectivity();
    p.target = target_length(ctx, dm, conn, st, p, options, report);
  }
  for (int it = 0; it < options.max_iterations && dm.nt > 0; ++it) {
    IterationStats s{.iteration = it, .vertices = dm.nv, .tets = dm.nt, .edges = conn.ne};
    s.seconds_connectivity = seconds_connectivity;
    clock.lap();
    s.marked = cost_and_mark(ctx, dm, conn, st, p);
    s.seconds_cost = clock.lap();
    s.collapsed = selection->select(ctx, dm, conn, st, p, s);
    selection->release(st);
    clock.lap();
    if (s.collapsed > 0) collapse_and_carry();
    s.seconds_collapse = clock.lap();
    s.seconds_total = s.seconds_connectivity + s.seconds_cost + s.seconds_select + s.seconds_guard + s.seconds_collapse;
    s.vertices_after = dm.nv;
    s.tets_after = dm.nt;
    report.iterations.push_back(s);
    if (options.progress) options.progress(s);
    if (s.collapsed < std::max<int64_t>(options.eps_c, 1) || it + 1 >= options.max_iterations || dm.nt == 0) break;
    seconds_connectivity = connectivity();
    if (tail.due(report.iterations)) {
      tail.seed(ctx, dm, conn, st);
      break;
    }
  }
  report.target_length = p.target;
  report.seconds_total = run_clock.peek();
  clock.lap();
  download_result(dm, origin, mesh);
  report.seconds_download = clock.lap();
  if (tail.seeded()) tail.finish(mesh, p, report);
  report.vertices_out = mesh.num_vertices();
  report.tets_out = mesh.num_tets();
  return report;
}

}  // namespace tc
