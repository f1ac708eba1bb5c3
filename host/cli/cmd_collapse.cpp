// The main job: tetcollapse IN OUT [options] coarsens a mesh by parallel edge collapse.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>

#include "cli/common.hpp"
#include "cli/improve_cli.hpp"
#include "cli/masks.hpp"
#include "io/io_util.hpp"
#include "json.hpp"
#include "stopwatch.hpp"
#include "tetcollapse/coarsen.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/fields.hpp"

namespace tc::cli {

namespace {

struct CollapseCli {
  std::string in, out;
  InputOptions input;
  OutputOptions output;
  CollapseOptions opt;
  double target_length = 0, target_factor = 0;
  double priority_levels = -1;  // not given
  std::string boundary = "features", method = "parallel", conflicts = "matching", eps_v_scale = "mean-tet";
  std::string region, sizing_field, labels, cost_cl, placement_cl, predicate_cl, device, stats;
  bool check = false, quiet = false, no_labels = false, no_spatial_order = false, no_improve = false,
       average_fields = false, no_merge_features = false;
  std::string preserve_field;
  double field_tolerance = 0.02;
  CLI::Option* field_tolerance_option = nullptr;
  double field_check = CoarsenOptions{}.field_check;
  CLI::Option* field_check_option = nullptr;
  int cycles = CoarsenOptions{}.cycles;
  CLI::Option* bound_options[2] = {nullptr, nullptr};  // --max-boundary-error(-abs)
  ImproveCli improve;
};

std::string stats_json(const CollapseCli& c, const CollapseReport& r, const ImproveReport* ir,
                       const std::vector<CycleReport>& later_cycles, const QualitySummary& quality_in,
                       const QualitySummary& quality_collapsed, double seconds_total, double seconds_read,
                       double seconds_write, const std::string& check_verdict) {
  JsonWriter w;
  w.begin_object()
      .field("input", c.in)
      .field("output", c.out)
      .field("device", r.device)
      .field("vertices_in", r.vertices_in)
      .field("vertices_out", r.vertices_out)
      .field("tets_in", r.tets_in)
      .field("tets_out", r.tets_out)
      .field("tet_reduction", r.tets_in ? 1.0 - double(r.tets_out) / double(r.tets_in) : 0.0)
      .field("target_length", r.target_length)
      .field("median_edge_length", r.median_edge_length)
      .field("eps_c", c.opt.eps_c)
      .field("eps_v", r.eps_v)
      .field("boundary_error_bound", r.boundary_error_bound)
      .field("boundary_error", r.boundary_error)
      .field("field_error_bound", r.field_error_bound)
      .field("field_error", r.field_error)
      .field("min_quality", c.opt.min_quality)
      .field("boundary", c.boundary)
      .field("method", c.method)
      .field("conflicts", c.conflicts)
      .field("spatial_order", c.opt.tuning.spatial_order)
      .field("seconds_total", seconds_total)
      .field("seconds_collapse", r.seconds_total)
      .field("seconds_upload", r.seconds_upload)
      .field("seconds_download", r.seconds_download)
      .field("seconds_read", seconds_read)
      .field("seconds_write", seconds_write);
  if (!check_verdict.empty()) w.field("check", check_verdict);
  write_quality(w, "quality_input", quality_in);
  write_quality(w, "quality_collapsed", quality_collapsed);
  if (ir) write_improve(w, *ir);
  // the cycles past the first (--cycles): tets and seconds of each collapse and improvement
  w.key("later_cycles").begin_array();
  for (const CycleReport& cy : later_cycles) {
    w.begin_object()
        .field("tets_before", cy.tets_before)
        .field("tets_collapsed", cy.tets_collapsed)
        .field("tets_after", cy.tets_after)
        .field("seconds_collapse", cy.collapse.seconds_total)
        .field("seconds_improve", cy.improved ? cy.improvement.seconds_total : 0.0);
    if (cy.improved) write_quality(w, "quality_after", cy.improvement.after);
    w.end_object();
  }
  w.end_array();
  w.key("iterations").begin_array();
  for (const auto& it : r.iterations) {
    w.begin_object()
        .field("iteration", it.iteration)
        .field("on_host", it.on_host)
        .field("vertices", it.vertices)
        .field("tets", it.tets)
        .field("edges", it.edges)
        .field("marked", it.marked)
        .field("candidates", it.candidates)
        .field("tested", it.tested)
        .field("selected", it.selected)
        .field("refused_by_guard", it.refused_by_guard)
        .field("refused_by_bound", it.refused_by_bound)
        .field("collapsed", it.collapsed)
        .field("tets_after", it.tets_after)
        .field("vertices_after", it.vertices_after)
        .field("seconds_connectivity", it.seconds_connectivity)
        .field("seconds_cost", it.seconds_cost)
        .field("seconds_select", it.seconds_select)
        .field("seconds_guard", it.seconds_guard)
        .field("seconds_collapse", it.seconds_collapse)
        .field("seconds_total", it.seconds_total)
        .end_object();
  }
  w.end_array().end_object();
  return w.str();
}

}  // namespace

void register_collapse(CLI::App& app, int& exit_code) {
  auto c = std::make_shared<CollapseCli>();
  app.add_option("IN", c->in, "Input mesh (coarsen mode: tetcollapse IN OUT [options])");
  app.add_option("OUT", c->out, "Output mesh, written to a temporary file and renamed");
  auto* tl = app.add_option("--target-length", c->target_length,
                            "Collapse edges shorter than L (mesh units)");
  auto* tf = app.add_option("--target-factor", c->target_factor,
                            "Collapse edges shorter than F x the input's median edge length (default 1)");
  tl->excludes(tf);
  app.add_option("--eps-c", c->opt.eps_c, "Stop when an iteration collapses fewer than N edges (default 0: until none)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--max-iterations", c->opt.max_iterations, "Stop after N iterations")->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--boundary", c->boundary,
                 "strict: boundary vertices never move; features (default): the paper's protection,\n"
                 "face vertices move along faces, ridge vertices along ridges, corners never, within\n"
                 "--max-boundary-error (default 0.001) of the input's boundary;\n"
                 "free: no protection (e.g. volume-rendering data)")
      ->check(CLI::IsMember({"strict", "features", "free"}));
  app.add_flag("--paper-boundary-rule", c->opt.paper_boundary_rule,
               "Refuse every non-boundary edge that touches the boundary, as the paper does\n"
               "(default: an interior vertex may collapse onto a boundary vertex, which stays put)");
  app.add_flag("--no-labels", c->no_labels, "Do not protect material interfaces between labels");
  app.add_option("--eps-f", c->opt.eps_f,
                 "Face-vertex threshold on 1 - dot of normals (paper: 0.01; not used under a boundary error\n"
                 "bound, the default in features mode)")
      ->capture_default_str();
  app.add_option("--eps-r", c->opt.eps_r, "Ridge-edge threshold on 1 - dot of normals (paper: 0.1)")
      ->capture_default_str();
  c->bound_options[0] =
      app.add_option("--max-boundary-error", c->opt.max_boundary_error,
                     "Features mode: keep the boundary and the material interfaces within E x the input's\n"
                     "bounding-box diagonal of where they were, both ways (a conservative bound on the two-sided\n"
                     "Hausdorff distance, carried per vertex, and where that refuses a change, the change measured\n"
                     "against the input's boundary on the host); smoothly curved faces then coarsen (--eps-f is not\n"
                     "used). The carried bound is tested on the device, which then selects by --conflicts greedy;\n"
                     "the measured one in the host tail (not with --host-tail 0).\n"
                     "Default 0.001 in features mode; 0: no bound (the paper's method: curved faces stay as\n"
                     "--eps-f says, what moves is not bounded)")
          ->check(CLI::NonNegativeNumber);
  c->bound_options[1] =
      app.add_option("--max-boundary-error-abs", c->opt.max_boundary_error_abs,
                     "The same bound in mesh units (used instead of --max-boundary-error when > 0)")
          ->check(CLI::NonNegativeNumber);
  app.add_flag("--no-merge-features", c->no_merge_features, kNoMergeFeaturesHelp);
  add_volume_options(app, c->opt.eps_v, c->eps_v_scale);
  app.add_option("--min-quality", c->opt.min_quality,
                 "Quality guard: refuse a collapse that makes the worst reshaped tet's mean ratio\n"
                 "(1 regular, 0 flat) fall below min(its value before, Q); 0 = off, as the paper")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--region", c->region, kRegionHelp);
  app.add_option("--sizing-field", c->sizing_field,
                 "Per-vertex field of the input giving the wanted edge length: an edge is collapsed\n"
                 "when shorter than the mean of the field at its ends (replaces --target-*)");
  app.add_option("--labels", c->labels, kLabelsHelp);
  app.add_option("--preserve-field", c->preserve_field,
                 "Coarsen for volume rendering of this per-vertex field (the paper's Section 4.5): an\n"
                 "edge is collapsed when its ends' values differ by less than --field-tolerance x the\n"
                 "field's range (replaces --target-*; use --boundary free for the paper's setting)");
  c->field_tolerance_option =
      app.add_option("--field-tolerance", c->field_tolerance, "With --preserve-field: T (the paper: 0.02)")
          ->capture_default_str()
          ->check(CLI::PositiveNumber);
  c->field_check_option =
      app.add_option("--field-check", c->field_check,
                     "With --preserve-field (beyond the paper): also refuse a collapse that would change the\n"
                     "field at an end point's old place by more than K x T x the range (the edge's two ends\n"
                     "alike says nothing where the field bends, e.g. at a peak); 0: the paper's cost alone")
          ->capture_default_str()
          ->check(CLI::NonNegativeNumber);
  app.add_option("--max-field-error", c->opt.max_field_error,
                 "With --preserve-field NAME, in place of --field-tolerance: collapse every edge (up to\n"
                 "--target-length or --target-factor when given) while each input vertex keeps its value of\n"
                 "NAME, in the output's piecewise linear field, within E x the field's range. The error is\n"
                 "measured at the input vertices the collapse's tets hold, not estimated. The collapses run\n"
                 "on the host; the improvement phase does not run (its moves would change the values)")
      ->check(CLI::PositiveNumber);
  app.add_flag("--average-fields", c->average_fields,
               "Vertex fields at a survivor: the average of the collapsed edge's ends (default: the\n"
               "input's piecewise linear field at the vertex's final place, by point location in the\n"
               "input, after the improvement phase too)");
  app.add_option("--cost-cl", c->cost_cl,
                 "OpenCL C file defining double tc_user_cost(double3 p0, double3 p1, double f0, double f1);\n"
                 "edges with a cost below --target-length are collapsed (see docs/cli.md)");
  app.add_option("--placement-cl", c->placement_cl,
                 "OpenCL C file defining double3 tc_user_placement(double3 p0, double3 p1, double f0, double f1);\n"
                 "where the survivor goes instead of the midpoint, on edges with both ends off the boundary\n"
                 "and interfaces (every edge with --boundary free); vertex fields are interpolated there.\n"
                 "Which end is p0 is the pipeline's choice: write it symmetric in the two ends");
  app.add_option("--predicate-cl", c->predicate_cl,
                 "OpenCL C file defining int tc_user_predicate(double3 p0, double3 p1, double f0, double f1);\n"
                 "0 refuses the collapse of the edge (besides the built-in checks)");
  app.add_option("--method", c->method, kMethodHelp)
      ->check(CLI::IsMember({"parallel", "sequential"}));
  app.add_flag("--sequential-skip-invalidated", c->opt.sequential_skip_invalidated,
               "Sequential method: skip (until the next iteration) an edge whose star an earlier\n"
               "collapse of the iteration changed, as the paper's baseline; default: re-check it");
  app.add_option("--conflicts", c->conflicts,
                 "Conflict detection of the parallel method: matching (default: the edges taken in cost\n"
                 "order, each tested on the mesh with the earlier ones collapsed, skipping only those\n"
                 "sharing an end point with one taken), greedy (one selection under both of the paper's\n"
                 "conflict rules: no two collapses share a tet; about a quarter of matching's collapses\n"
                 "per iteration), two-pass (the paper's pass 1 over edges, then pass 2 over tets) or\n"
                 "atomic-min (Gautron and Kenzel 2023; needs 64-bit atomics on the device). Under a boundary\n"
                 "error bound (the default in features mode) the selection is greedy whatever this says")
      ->check(CLI::IsMember({"greedy", "two-pass", "atomic-min", "matching"}));
  app.add_option("--priority-levels", c->priority_levels,
                 "Matching and greedy conflicts: edges are ordered by their cost in steps of target / N,\n"
                 "and within a step in a fixed pseudo-random order (default 64; 0: exact cost order, many\n"
                 "more parallel rounds)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--no-spatial-order", c->no_spatial_order,
               "Parallel method: keep the input's numbering on the device (default: vertices along a\n"
               "Morton curve, tets by their smallest vertex, for memory locality; the output then\n"
               "follows that order)");
  app.add_option("--host-tail", c->opt.tuning.host_tail,
                 "Parallel method with --eps-c 0 or 1: once an iteration collapses fewer than F x its\n"
                 "tets (and the counts shrink slowly: a long tail), finish on the host with the\n"
                 "sequential method's checks, greedily (the last iterations collapse a few edges each\n"
                 "at the price of passes over the whole mesh).\n"
                 "Default: 0.005 with the matching conflict detection and 0.002 with the others on CPU\n"
                 "devices, 0 (all on the device) on GPUs and others ($TETCOLLAPSE_TUNING=cpu|gpu\n"
                 "overrides the device type)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--device", c->device, "OpenCL device: index or name substring (see 'tetcollapse devices');\n"
                                        "default: $TETCOLLAPSE_DEVICE, else the first GPU, else the first CPU");
  app.add_option("--stats", c->stats, "Write the run's statistics as JSON to this file ('-' for stdout)");
  app.add_flag("--check", c->check, "Check the result (validity, unchanged boundary topology) and fail if invalid");
  app.add_flag("--no-improve", c->no_improve,
               "Coarsen only, as the paper (default: end with the improvement phase of 'tetcollapse\n"
               "improve': flips, vertex relocation and collapses that raise the worst element quality;\n"
               "only within --region/--labels when given; not with --predicate-cl or --placement-cl;\n"
               "the relocation on the device, or with --method sequential on the CPU)");
  add_improve_options(app, c->improve);
  app.add_option("--cycles", c->cycles,
                 "Collapse and improve N times: the improvement's flips and moves make collapsible edges the\n"
                 "collapse refused, so each later cycle collapses them (the same target length, within what\n"
                 "is left of the boundary error bound) and improves again; a cycle removing fewer than 1%\n"
                 "of the tets is the last. Not with --no-improve")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_flag("-q,--quiet", c->quiet, "No progress lines, only errors");
  add_input_options(app, c->input);
  add_output_options(app, c->output);

  app.callback([c, &app, &exit_code] {
    if (!app.get_subcommands().empty()) return;
    if (c->in.empty() || c->out.empty())
      throw CLI::RequiredError("IN and OUT (or a subcommand; see --help)");
    check_output_path(c->out, &c->output);
    check_output_path(c->stats, nullptr);
    const Stopwatch total;
    Stopwatch stage;
    Mesh mesh = read_input(c->in, c->input, c->quiet);
    double seconds_read = stage.lap();
    Mesh input;  // for --check, and the vertex fields' values at new places
    const bool resample = !mesh.vertex_fields.empty() && !c->average_fields;
    if (c->check || resample) input = mesh;

    CollapseOptions& opt = c->opt;
    opt.boundary = boundary_mode(c->boundary);
    opt.eps_v_scale = volume_scale(c->eps_v_scale);
    opt.use_labels = !c->no_labels;
    opt.tuning.spatial_order = !c->no_spatial_order;
    opt.tuning.merge_features_within_bound = !c->no_merge_features;
    opt.method = method_mode(c->method);
    opt.conflicts = conflicts_mode(c->conflicts);
    if (c->priority_levels >= 0) {
      if (opt.method == CollapseOptions::Sequential ||
          (opt.conflicts != CollapseOptions::Greedy && opt.conflicts != CollapseOptions::Matching))
        throw CLI::ValidationError("--priority-levels",
                                   "applies to the greedy and matching conflict detections only (--conflicts greedy|matching)");
      opt.tuning.priority_levels = c->priority_levels;
    }
    // the default bound, in features mode only (the other modes refuse one given)
    if (c->bound_options[0]->count() == 0 && c->bound_options[1]->count() == 0)
      opt.max_boundary_error = default_max_boundary_error(opt.boundary);
    if (opt.bounds_boundary_error()) {
      if (opt.boundary != CollapseOptions::Features)
        throw CLI::ValidationError("--max-boundary-error",
                                   "applies to --boundary features (strict keeps the boundary exactly, free does not bound it)");
    }
    if (opt.max_field_error > 0 && c->preserve_field.empty())
      throw CLI::ValidationError("--max-field-error", "needs --preserve-field NAME (the field it bounds)");
    check_method(c->method, c->device,
                 {{"--cost-cl", &c->cost_cl},
                  {"--sizing-field", &c->sizing_field},
                  {"--placement-cl", &c->placement_cl},
                  {"--predicate-cl", &c->predicate_cl}});
    if (!c->placement_cl.empty()) opt.placement_cl_source = cl_file(c->placement_cl);
    if (!c->predicate_cl.empty()) opt.predicate_cl_source = cl_file(c->predicate_cl);
    if (c->target_length > 0) opt.target_length = c->target_length;
    if (c->target_factor > 0) opt.target_factor = c->target_factor;
    combine(opt.vertex_mask, region_and_label_mask(mesh, c->region, c->labels));
    CoarsenOptions co;
    co.preserve_field = c->preserve_field;
    co.sizing_field = c->sizing_field;
    co.field_tolerance = c->field_tolerance;
    co.field_check = c->field_check;
    co.resample_fields = !c->average_fields;
    if (!c->cost_cl.empty()) {
      if (!c->sizing_field.empty() || !c->preserve_field.empty())
        throw CLI::ValidationError("--cost-cl", "cannot be combined with --sizing-field or --preserve-field");
      opt.cost_cl_source = cl_file(c->cost_cl);
      if (opt.target_length <= 0) throw CLI::ValidationError("--cost-cl", "needs --target-length");
    }
    if (!c->preserve_field.empty() && !c->sizing_field.empty())
      throw CLI::ValidationError("--preserve-field", "cannot be combined with --sizing-field");
    for (const std::string* name : {&c->preserve_field, &c->sizing_field})
      if (!name->empty() && !mesh.find_vertex_field(*name))
        throw InputError(c->in, "no vertex field named '" + *name + "'");
    if (opt.max_field_error > 0) {
      if (c->field_tolerance_option->count() > 0)
        throw CLI::ValidationError("--field-tolerance", "cannot be combined with --max-field-error (the bound decides)");
      if (c->field_check_option->count() > 0)
        throw CLI::ValidationError("--field-check", "cannot be combined with --max-field-error (the bound decides)");
      // the bound alone decides, unless a target is given
      if (opt.target_length <= 0 && c->target_factor > 0)
        opt.target_length = c->target_factor * median_edge_length(mesh);
    }
    if (!c->quiet)
      opt.progress = [](const IterationStats& it) {
        std::fprintf(stderr,
                     "iteration %3d: marked %9lld  tested %9lld  selected %8lld  refused %6lld  collapsed %8lld  "
                     "tets %9lld  %.3f s%s\n",
                     it.iteration + 1, (long long)it.marked, (long long)it.tested, (long long)it.selected,
                     (long long)(it.refused_by_guard + it.refused_by_bound), (long long)it.collapsed, (long long)it.tets_after, it.seconds_total,
                     it.on_host ? "  (host tail)" : "");
      };

    // The quality before and after each phase, for the summary and --stats.
    const bool report_quality = !c->quiet || !c->stats.empty();
    QualitySummary quality_in, quality_collapsed;
    if (report_quality) quality_in = quality_summary(mesh);
    std::unique_ptr<Context> ctx;
    if (opt.method == CollapseOptions::Sequential) {
      if (!c->quiet) std::cerr << "method: sequential (CPU)\n";
    } else {
      ctx = open_device(c->device, c->quiet);
    }
    co.collapse = opt;
    co.improve = !c->no_improve;
    co.improvement = improve_options(c->improve, c->quiet);
    co.cycles = c->cycles;
    // --region, --labels: improve there only (the masks of the coarse mesh)
    co.improve_mask = [c](const Mesh& coarse) { return region_and_label_mask(coarse, c->region, c->labels); };
    const CoarsenReport cr = coarsen(mesh, co, ctx.get(), input.num_tets() > 0 ? &input : nullptr);
    const CollapseReport& r = cr.collapse;
    const ImproveReport& ir = cr.improvement;
    c->no_improve = !cr.improved;
    if (report_quality) quality_collapsed = cr.improved ? ir.before : quality_summary(mesh);
    if (cr.outside > 0 && !c->quiet)
      std::fprintf(stderr, "note: %lld vertices lie outside the input; their fields come from the nearest tet\n",
                   (long long)cr.outside);

    const std::string verdict =
        c->check ? check_result(mesh, input, opt.boundary == CollapseOptions::Strict, c->quiet, exit_code) : "";
    stage.lap();
    if (exit_code != kCheckFailed) write_mesh(c->out, mesh, write_options(c->output));
    double seconds_write = stage.lap();
    double seconds_total = total.peek();
    if (!c->quiet) {
      double stage[5] = {0, 0, 0, 0, 0};
      for (const auto& it : r.iterations) {
        stage[0] += it.seconds_connectivity;
        stage[1] += it.seconds_cost;
        stage[2] += it.seconds_select;
        stage[3] += it.seconds_guard;
        stage[4] += it.seconds_collapse;
      }
      std::fprintf(stderr,
                   "%s -> %s\n  vertices %lld -> %lld, tets %lld -> %lld (%.1f%% fewer), %zu iterations, "
                   "target length %.6g\n  collapse %.3f s (connectivity %.3f, cost %.3f, select %.3f, "
                   "guard %.3f, collapse %.3f), read %.3f s, write %.3f s, total %.3f s\n",
                   c->in.c_str(), c->out.c_str(), (long long)r.vertices_in, (long long)r.vertices_out,
                   (long long)r.tets_in, (long long)r.tets_out,
                   r.tets_in ? 100.0 * (1.0 - double(r.tets_out) / double(r.tets_in)) : 0.0, r.iterations.size(),
                   r.target_length, r.seconds_total, stage[0], stage[1], stage[2], stage[3], stage[4],
                   seconds_read, seconds_write, seconds_total);
      std::fprintf(stderr, "  quality in:             %s\n  quality after collapse: %s\n", quality_line(quality_in).c_str(),
                   quality_line(quality_collapsed).c_str());
      if (r.field_error_bound > 0)
        std::fprintf(stderr, "  field error at the input's vertices: %.4g%% of the range (bound %.4g%%)\n",
                     100 * r.field_error, 100 * r.field_error_bound);
      if (!c->no_improve)
        std::fprintf(stderr, "  quality after improve:  %s (%.3f s)\n", quality_line(ir.after).c_str(), ir.seconds_total);
      // (each later cycle's quality after its improvement, the last one the result's)
      for (size_t k = 0; k < cr.later_cycles.size(); ++k) {
        const CycleReport& cy = cr.later_cycles[k];
        std::fprintf(stderr, "  cycle %zu: collapse %lld -> %lld tets (%.3f s)", k + 2, (long long)cy.tets_before,
                     (long long)cy.tets_collapsed, cy.collapse.seconds_total);
        if (cy.improved)
          std::fprintf(stderr, ", improve -> %lld tets (%.3f s): %s", (long long)cy.tets_after,
                       cy.improvement.seconds_total, quality_line(cy.improvement.after).c_str());
        std::fprintf(stderr, "\n");
      }
    }
    if (!c->stats.empty())
      write_report(c->stats, stats_json(*c, r, c->no_improve ? nullptr : &ir, cr.later_cycles, quality_in, quality_collapsed,
                                        seconds_total, seconds_read, seconds_write, verdict));
    if (exit_code != kCheckFailed) exit_code = kOk;
  });
}

}  // namespace tc::cli
