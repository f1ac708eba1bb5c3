#include "driver.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <stdexcept>

#include "agree.hpp"
#include "cli/common.hpp"
#include "cli/masks.hpp"
#include "field_points.hpp"
#include "report.hpp"
#include "rounds.hpp"
#include "tetcollapse/coarsen.hpp"
#include "stopwatch.hpp"
#include "tetcollapse/fields.hpp"

namespace tc::mpi {

namespace {

void bcast(double* values, int n, MPI_Comm comm) { MPI_Bcast(values, n, MPI_DOUBLE, 0, comm); }

// The settings every rank runs with; rank 0 fills the absolute values from the whole mesh.
Settings make_settings(Options& o) {
  Settings s;
  CollapseOptions& c = s.collapse;
  c.boundary = cli::boundary_mode(o.boundary);
  c.use_labels = !o.no_labels;
  c.eps_f = o.eps_f;
  c.eps_r = o.eps_r;
  c.eps_v = o.eps_v;
  c.eps_v_scale = cli::volume_scale(o.eps_v_scale);
  c.min_quality = o.min_quality;
  if (o.target_factor > 0) c.target_factor = o.target_factor;
  c.eps_c = o.eps_c;
  c.max_iterations = o.max_iterations;
  c.paper_boundary_rule = o.paper_boundary_rule;
  // the cost of the field options on every rank (rank 0 adds the target from the whole mesh:
  // tc::apply_field_options)
  if (!o.sizing_field.empty()) c.cost_cl_source = sizing_cost_source();
  c.max_field_error = o.max_field_error;
  if (o.max_field_error > 0) c.bounded_field = o.preserve_field;
  c.field_difference_cost = !o.preserve_field.empty() && !(o.max_field_error > 0);
  c.field_check = o.field_check;
  c.conflicts = cli::conflicts_mode(o.conflicts);
  c.method = cli::method_mode(o.method);
  if (o.priority_levels >= 0) c.tuning.priority_levels = o.priority_levels;
  c.tuning.spatial_order = !o.no_spatial_order;
  c.tuning.merge_features_within_bound = !o.no_merge_features;
  if (o.host_tail >= 0) c.tuning.host_tail = o.host_tail;
  s.region = o.region, s.labels = o.labels;
  ImproveOptions& i = s.improve;
  i = cli::improve_options(o.improve, true);  // (no progress lines: they would come from every rank)
  i.boundary = c.boundary;
  i.eps_f = c.eps_f;
  i.eps_r = c.eps_r;
  i.use_labels = c.use_labels;
  return s;
}

}  // namespace

int run(Options& o, MPI_Comm comm) {
  int rank = 0, nranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &nranks);
  const bool talk = rank == 0 && !o.quiet;
  const Stopwatch total;
  Settings s = make_settings(o);
  RunStats stats;
  stats.input = o.in, stats.output = o.out, stats.ranks = nranks, stats.boundary = o.boundary;
  Mesh whole, input;  // rank 0: the mesh of the round; the input for --check and the fields
  size_t field_front = 0;  // rank 0, the field options' field: its place, which it leaves for the run
  const bool field_bound = o.max_field_error > 0;

  // Rank 0 reads the input and turns every bound relative to the whole mesh into an absolute one.
  int code = guarded(rank, [&] {
    resolve_defaults(o);
    validate(o);
    // the user's OpenCL C, read by every rank (a missing file is an input error on each)
    if (!o.cost_cl.empty()) s.collapse.cost_cl_source = cli::cl_file(o.cost_cl);
    if (!o.placement_cl.empty()) s.collapse.placement_cl_source = cli::cl_file(o.placement_cl);
    if (!o.predicate_cl.empty()) s.collapse.predicate_cl_source = cli::cl_file(o.predicate_cl);
    if (rank != 0) return;
    cli::check_output_path(o.out, &o.output);
    cli::check_output_path(o.stats, nullptr);
    Stopwatch clock;
    whole = cli::read_input(o.in, o.input, o.quiet);
    stats.seconds_read = clock.lap();
    if (o.check || (!whole.vertex_fields.empty() && !o.average_fields) || field_bound) input = whole;
    stats.vertices_in = whole.num_vertices(), stats.tets_in = whole.num_tets();
    if (!o.labels.empty()) cli::require_labels(whole);
    stats.median_edge_length = median_edge_length(whole);
    // (under the field error bound without a target, the bound alone decides: 0, which the
    // library reads as +infinity)
    s.collapse.target_length = o.target_length > 0                       ? o.target_length
                               : field_bound && !(o.target_factor > 0) ? 0.0
                                                                       : s.collapse.target_factor * stats.median_edge_length;
    if (!(s.collapse.target_length > 0) && !(field_bound && stats.median_edge_length > 0))
      throw InputError(o.in, "the mesh has no edges: nothing to coarsen");
    // the field options' target over the whole mesh, their field first for the run (the
    // library's field cost reads the first vertex field), as tc::coarsen does
    CoarsenOptions fo;
    fo.preserve_field = o.preserve_field, fo.sizing_field = o.sizing_field, fo.field_tolerance = o.field_tolerance;
    fo.field_check = o.field_check;
    try {
      field_front = apply_field_options(whole, fo, s.collapse);
    } catch (const std::invalid_argument& e) {
      throw InputError(o.in, e.what());
    }
    if (field_front > 0) std::swap(whole.vertex_fields[0], whole.vertex_fields[field_front]);
    s.collapse.eps_v = volume_threshold(whole, s.collapse);
    s.whole_diagonal = bbox_diagonal(whole);
    if (field_bound) s.field_range = field_range(whole, o.preserve_field);
  });
  if ((code = agree(code, comm))) return code;
  double shared[3] = {s.collapse.target_length, s.collapse.eps_v, s.whole_diagonal};
  bcast(shared, 3, comm);
  s.collapse.target_length = shared[0], s.collapse.eps_v = shared[1], s.whole_diagonal = shared[2];
  s.collapse.eps_v_scale = CollapseOptions::Absolute;
  stats.target_length = s.collapse.target_length;
  if (field_bound) {
    uint64_t nc = s.field_range.size();
    MPI_Bcast(&nc, 1, MPI_UINT64_T, 0, comm);
    s.field_range.resize(size_t(nc));
    bcast(s.field_range.data(), int(nc), comm);
    stats.field_error_bound = o.max_field_error;
  }

  // Every rank its own device context: the device chosen now (a --device naming none fails
  // before any work), the context opened when the rank first coarsens.
  code = guarded(rank, [&] {
    stats.device = s.collapse.method == CollapseOptions::Sequential ? "cpu-sequential" : select_device(o.device).name;
  });
  if ((code = agree(code, comm))) return code;
  LazyDevice device(o.device, talk);
  if (talk)
    std::fprintf(stderr, "%d ranks, target length %.6g (median edge length %.6g)\n", nranks, s.collapse.target_length,
                 stats.median_edge_length);

  // The collapse phase, then the improvement phase, each in rounds until nothing is left to do.
  // A boundary error bound is shared as tc::coarsen shares it: kCollapseShareOfBound of it for
  // the collapse, all of it for the improvement, which goes on from what each vertex spent (a
  // vertex field from round to round).
  const double bound = o.max_boundary_error_abs > 0 ? o.max_boundary_error_abs : o.max_boundary_error * s.whole_diagonal;
  stats.boundary_error_bound = bound;
  if (bound > 0 && rank == 0) whole.vertex_fields.push_back({kSpentField, 1, std::vector<double>(size_t(whole.num_vertices()), 0.0)});
  // the input's S, which every round's collapse measures against (rank 0 has the input)
  if (bound > 0 && s.collapse.tuning.remeasure_boundary_error) {
    std::vector<double> tris;
    if (rank == 0) tris = feature_surface_triangles(whole, s.collapse.use_labels);
    uint64_t n = tris.size();
    MPI_Bcast(&n, 1, MPI_UINT64_T, 0, comm);
    tris.resize(size_t(n));
    for (uint64_t at = 0; at < n; at += uint64_t(1) << 30)  // (MPI counts are ints)
      bcast(tris.data() + at, int(std::min<uint64_t>(n - at, uint64_t(1) << 30)), comm);
    s.boundary_reference = std::make_shared<const std::vector<double>>(std::move(tris));
  }
  // (none after a user's placement or predicate, or with every operation off, as tc::coarsen)
  CoarsenOptions as_coarsen;
  as_coarsen.collapse = s.collapse, as_coarsen.improve = !o.no_improve, as_coarsen.improvement = s.improve;
  const bool improve_phase = improvement_follows(as_coarsen);
  Round state{whole, {}, 0, nullptr, {}};
  if (field_bound && rank == 0) state.field_input = &input, state.field_name = o.preserve_field;
  // --cycles: collapse and improve again, as tc::coarsen does, until a collapse phase removes
  // fewer than kCycleMinShare of the tets (improved still, unless it removed none)
  for (int cycle = 0; code == cli::kOk && cycle < (improve_phase ? o.cycles : 1); ++cycle) {
    s.boundary_bound = improve_phase ? kCollapseShareOfBound * bound : bound;
    if (cycle > 0) s.collapse.min_quality = std::max(o.min_quality, kLaterCycleMinQuality);
    double removed[2] = {double(whole.num_tets()), 0};
    code = run_phase(Phase::Collapse, state, s, o, device, stats, comm);
    if (code != cli::kOk || !improve_phase) break;
    removed[1] = removed[0] - double(whole.num_tets());
    bcast(removed, 2, comm);
    if (cycle > 0 && removed[1] == 0) break;
    // the improvement's collapse step reaches as far as tc::improve's default on the whole mesh
    if (rank == 0) s.collapse_length = 1.5 * median_edge_length(whole);
    bcast(&s.collapse_length, 1, comm);
    s.boundary_bound = bound;
    code = run_phase(Phase::Improve, state, s, o, device, stats, comm);
    if (cycle > 0 && removed[1] < kCycleMinShare * removed[0]) break;
  }
  if (code) return code;
  if (bound > 0 && rank == 0) {
    for (double e : whole.vertex_fields.back().values) stats.boundary_error = std::max(stats.boundary_error, e);
    whole.vertex_fields.pop_back();  // (kSpentField)
  }

  // Peak memory per rank over the run, then rank 0 finishes: fields, check, write, stats.
  int64_t peak = peak_rss_kb();
  stats.peak_rss_kb.resize(size_t(nranks));
  MPI_Gather(&peak, 1, MPI_INT64_T, stats.peak_rss_kb.data(), 1, MPI_INT64_T, 0, comm);
  int exit_code = cli::kOk;
  code = guarded(rank, [&] {
    if (rank != 0) return;
    if (field_front > 0) std::swap(whole.vertex_fields[0], whole.vertex_fields[field_front]);
    // Under the field error bound the vertex fields are those the rounds checked: after the first
    // round a survivor's values come from the round's mesh, not the input, and resampling them
    // from the input would change what the bound was measured on.
    if (field_bound) stats.field_error = measured_field_error(input, o.preserve_field, whole, s.field_range);
    if (!whole.vertex_fields.empty() && !o.average_fields && !field_bound) {
      const int64_t outside = resample_vertex_fields(input, whole);
      if (outside > 0 && talk)
        std::fprintf(stderr, "note: %lld vertices lie outside the input; their fields come from the nearest tet\n",
                     (long long)outside);
    }
    if (o.check)
      stats.check = cli::check_result(whole, input, s.collapse.boundary == CollapseOptions::Strict, o.quiet, exit_code);
    Stopwatch clock;
    if (exit_code == cli::kOk) write_mesh(o.out, whole, cli::write_options(o.output));
    stats.seconds_write = clock.lap();
    stats.vertices_out = whole.num_vertices(), stats.tets_out = whole.num_tets();
    stats.seconds_total = total.peek();
    if (talk)
      std::fprintf(stderr, "%s -> %s: tets %lld -> %lld (%.1f%% fewer) in %zu rounds, %.2f s\n", o.in.c_str(),
                   o.out.c_str(), (long long)stats.tets_in, (long long)stats.tets_out,
                   stats.tets_in ? 100.0 * (1.0 - double(stats.tets_out) / double(stats.tets_in)) : 0.0,
                   stats.rounds.size(), stats.seconds_total);
    if (talk && field_bound)
      std::fprintf(stderr, "  field error at the input's vertices: %.4g%% of the range (bound %.4g%%)\n",
                   100 * stats.field_error, 100 * o.max_field_error);
    if (!o.stats.empty()) cli::write_report(o.stats, stats_json(stats));
  });
  if (code == cli::kOk) code = exit_code;
  return agree(code, comm);
}

}  // namespace tc::mpi
