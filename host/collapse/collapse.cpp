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
#include "collapse/reference.hpp"
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

// reference: under a bound, where the boundary error bound's reference surface goes (computed
// from the device's first connectivity when null) for the host tail, which then always runs.
CollapseReport collapse_on_device(Mesh& mesh, const CollapseOptions& options, Context& ctx,
                                  std::shared_ptr<const std::vector<double>>* reference = nullptr);

// The bound's column in the packed vertex fields: the last component (of kBoundField, last).
uint32_t dm_bound_column(const Mesh& mesh) {
  uint32_t n = 0;
  for (const Field& f : mesh.vertex_fields) n += uint32_t(f.components);
  return n - 1;
}

// The boundary error bound on the parallel method: the selection's test on the device refuses a
// collapse that would change S past the bound (cl/collapse_bound.h, in the programs built with
// kBoundDefines), with the bound per vertex in a last vertex field, which the compaction carries
// and the host tail continues. The selection is the greedy one: the matching selection applies
// its collapses as it takes them, and chains of them within one iteration spend the bound faster
// (bench/README.md).
CollapseReport collapse_bounded(Mesh& mesh, const CollapseOptions& options, Context& ctx) {
  check_boundary_error_options(options);
  if (options.field_difference_cost && mesh.vertex_fields.empty())
    throw std::invalid_argument("field_difference_cost needs an explicit target_length > 0 and a vertex field");
  const double bound = boundary_error_bound(mesh, options);
  CollapseOptions o = options;
  o.max_boundary_error = 0;
  o.max_boundary_error_abs = bound;
  o.conflicts = CollapseOptions::Greedy;
  o.selection_rounds = 1;  // (a two-pass option)
  // The user's functions read the first vertex field as f0 (0 when there is none): a field of
  // zeros keeps the bound's field from being the first.
  Field bound_field{kBoundField, 1, initial_boundary_error(mesh, options)};
  const size_t added = mesh.vertex_fields.empty() && options.has_user_functions() ? 2 : 1;
  Field none{"tetcollapse:none", 1, std::vector<double>(added == 2 ? size_t(mesh.num_vertices()) : 0, 0.0)};
  mesh.vertex_fields.reserve(mesh.vertex_fields.size() + added);  // (the moves below cannot throw)
  if (added == 2) mesh.vertex_fields.push_back(std::move(none));
  mesh.vertex_fields.push_back(std::move(bound_field));
  o.vertex_boundary_error.clear();  // (in the field now)
  const auto drop_added = [&] { mesh.vertex_fields.resize(mesh.vertex_fields.size() - added); };
  // the reference surface: the one given, else the input's own S on a first run
  std::shared_ptr<const std::vector<double>> reference = options.boundary_reference;
  // (on the host, in the tail: not with user functions, nor with the tail off)
  const bool remeasure =
      measures_boundary_error(options) && !options.has_user_functions() && options.tuning.host_tail != 0;
  CollapseReport report;
  try {
    report = collapse_on_device(mesh, o, ctx, remeasure ? &reference : nullptr);
  } catch (...) {
    drop_added();
    throw;
  }
  report.vertex_boundary_error = std::move(mesh.vertex_fields.back().values);
  drop_added();
  report.boundary_error_bound = bound;
  report.boundary_reference = std::move(reference);
  report.boundary_error = 0;
  for (double e : report.vertex_boundary_error) report.boundary_error = std::max(report.boundary_error, e);
  return report;
}

}  // namespace

namespace collapse_detail {
CollapsePath collapse_path(const CollapseOptions& o) {
  if (o.method == CollapseOptions::Sequential || o.max_field_error > 0) return CollapsePath::Host;
  return o.bounds_boundary_error() ? CollapsePath::DeviceBounded : CollapsePath::Device;
}

// Under a bound the programs with the selection's test are built with kBoundDefines, for the
// run (collapse_on_device) and for its prefetch (which tc::coarsen calls earlier).
Context::ProgramOptions program_variant(Context& ctx, const CollapseOptions& o) {
  return {ctx, collapse_path(o) == CollapsePath::DeviceBounded ? kBoundDefines : "", kBoundHeader};
}

void prefetch_programs(Context& ctx, const CollapseOptions& o) {
  const CollapsePath path = collapse_path(o);
  if (path == CollapsePath::Host) return;
  const bool bounded = path == CollapsePath::DeviceBounded;  // (the selection then greedy)
  const Context::ProgramOptions variant = program_variant(ctx, o);
  // the first needed, then the largest (the group of collapse_admissible.cl), so that the
  // compiles of a first run end together
  ctx.prefetch("collapse_connectivity.cl");
  ctx.prefetch("collapse_admissible.cl");
  dev::prefetch_scan(ctx);
  ctx.prefetch("collapse_cost.cl");
  const CollapseOptions::Conflicts conflicts = bounded ? CollapseOptions::Greedy : o.conflicts;
  if (conflicts == CollapseOptions::Matching) ctx.prefetch("collapse_matching.cl");
  if (conflicts == CollapseOptions::AtomicMin) ctx.prefetch("collapse_atomic_min.cl");
  if (conflicts == CollapseOptions::TwoPass) ctx.prefetch("collapse_conflict.cl");
  if (conflicts == CollapseOptions::Greedy) ctx.prefetch("collapse_select_greedy.cl");
  if (bounded) ctx.prefetch("collapse_bound.cl");
  if (bounded && o.tuning.remeasure_boundary_error) ctx.prefetch("collapse_reference.cl");
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
  switch (collapse_path(options)) {
    case CollapsePath::Host: return collapse_sequential(mesh, options);
    case CollapsePath::DeviceBounded: return collapse_bounded(mesh, options, ctx);
    case CollapsePath::Device: break;
  }
  return collapse_on_device(mesh, options, ctx);
}

namespace {

CollapseReport collapse_on_device(Mesh& mesh, const CollapseOptions& options, Context& ctx,
                                  std::shared_ptr<const std::vector<double>>* reference) {
  check_options(options, ctx);
  check_device_memory(ctx, mesh, options);
  const Context::ProgramOptions variant = program_variant(ctx, options);
  prefetch_programs(ctx, options);
  CollapseReport report = report_for(mesh, ctx);
  StageParams p = params_from(options);
  p.eps_v = report.eps_v = volume_threshold(mesh, options);
  if (options.max_boundary_error_abs > 0) {  // (collapse_bounded)
    p.bound = options.max_boundary_error_abs;
    p.eps_col = dm_bound_column(mesh);
    p.eps_f = 2;  // as the sequential method: a smoothly curved face's vertices are face vertices
  }
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
    if (reference) {
      if (!*reference) *reference = reference_surface(ctx, dm, conn);
      tail.set_reference(*reference);
    }
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
    if (s.collapsed < std::max<int64_t>(options.eps_c, 1) || it + 1 >= options.max_iterations || dm.nt == 0) {
      // the collapses of S the carried bound refused, measured on the host
      if (reference && options.eps_c <= 1 && it + 1 < options.max_iterations && dm.nt > 0) {
        if (s.collapsed > 0) connectivity();
        tail.seed(ctx, dm, conn, st, s.collapsed == 0);
      }
      break;
    }
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

}  // namespace

}  // namespace tc
