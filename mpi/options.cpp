#include "options.hpp"

#include "cli/common.hpp"
#include "cli/masks.hpp"
#include "tetcollapse/coarsen.hpp"

namespace tc::mpi {

void add_options(CLI::App& app, Options& o) {
  app.add_option("IN", o.in, "Input mesh (any format tetcollapse reads), read by rank 0")->required();
  app.add_option("OUT", o.out, "Output mesh, written by rank 0 to a temporary file and renamed")->required();
  auto* tl = app.add_option("--target-length", o.target_length, "Collapse edges shorter than L (mesh units)");
  auto* tf = app.add_option("--target-factor", o.target_factor,
                            "Collapse edges shorter than F x the whole input's median edge length (default 1)");
  tl->excludes(tf);
  app.add_option("--boundary", o.boundary,
                 "strict: boundary vertices never move; features (default): face vertices move along faces,\n"
                 "ridge vertices along ridges, corners never; free: no protection")
      ->check(CLI::IsMember({"strict", "features", "free"}));
  app.add_flag("--no-labels", o.no_labels, "Do not protect material interfaces between labels");
  app.add_option("--region", o.region, cli::kRegionHelp);
  app.add_option("--labels", o.labels, cli::kLabelsHelp);
  app.add_option("--eps-f", o.eps_f, "Face-vertex threshold on 1 - dot of normals")->capture_default_str();
  app.add_option("--eps-r", o.eps_r, "Ridge-edge threshold on 1 - dot of normals")->capture_default_str();
  cli::add_volume_options(app, o.eps_v, o.eps_v_scale);
  app.add_option("--min-quality", o.min_quality,
                 "Quality guard: refuse a collapse that makes the worst reshaped tet's mean ratio fall below\n"
                 "min(its value before, Q); 0 = off")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--max-boundary-error", o.max_boundary_error,
                 "Features mode: keep the boundary and the material interfaces within E x the whole input's\n"
                 "bounding-box diagonal of where they were, both ways, as tetcollapse does (each vertex carries\n"
                 "the bound it reached from round to round, every rank measures against the input's boundary;\n"
                 "the partition interfaces are frozen). Default\n"
                 "0.001 in features mode; 0: no bound (the paper's method)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--max-boundary-error-abs", o.max_boundary_error_abs,
                 "The same bound in mesh units (used instead of --max-boundary-error when > 0)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--no-merge-features", o.no_merge_features, cli::kNoMergeFeaturesHelp);
  app.add_flag("--no-improve", o.no_improve,
               "Coarsen only (default: each rank improves its part after coarsening it, the interface\n"
               "frozen)");
  cli::add_improve_options(app, o.improve);
  app.add_option("--cycles", o.cycles,
                 "As tetcollapse: collapse and improve N times (each later cycle collapses the edges the\n"
                 "improvement made collapsible, the same target, within what is left of the boundary error\n"
                 "bound, in rounds as the first); a cycle removing fewer than 1% of the tets is the last")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--preserve-field", o.preserve_field,
                 "Direct volume rendering (the paper's Section 4.5), as tetcollapse: collapse the edges whose\n"
                 "two ends differ in vertex field NAME by less than --field-tolerance x its range over the\n"
                 "whole input (instead of --target-length / --target-factor)");
  app.add_option("--max-field-error", o.max_field_error,
                 "With --preserve-field NAME, in place of --field-tolerance, as tetcollapse: collapse every\n"
                 "edge (up to --target-length or --target-factor when given) while each input vertex keeps\n"
                 "its value of NAME, in the output's piecewise linear field, within E x the field's range\n"
                 "over the whole input. Every round measures at the input's vertices (rank 0 locates them in\n"
                 "the round's mesh and sends each part those its tets hold), so the rounds keep the bound as\n"
                 "one run does. The collapses run on the CPU; no improvement phase; the vertex fields are\n"
                 "those the rounds checked (not resampled from the input at the end)")
      ->check(CLI::PositiveNumber);
  app.add_option("--field-tolerance", o.field_tolerance, "With --preserve-field: T (the paper's 0.02)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber)
      ->each([&o](const std::string&) { o.field_tolerance_given = true; });
  app.add_option("--field-check", o.field_check,
                 "With --preserve-field, as tetcollapse: also refuse a collapse that would change the field at an\n"
                 "end point's old place by more than K x T x the range; 0: the paper's cost alone")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber)
      ->each([&o](const std::string&) { o.field_check_given = true; });
  app.add_option("--sizing-field", o.sizing_field,
                 "As tetcollapse: a vertex field giving the wanted edge length; an edge is collapsed when\n"
                 "shorter than the field's mean at its ends");
  app.add_option("--cost-cl", o.cost_cl,
                 "As tetcollapse: an OpenCL C file defining double tc_user_cost(double3 p0, double3 p1,\n"
                 "double f0, double f1); edges with a cost below --target-length are collapsed");
  app.add_option("--placement-cl", o.placement_cl,
                 "As tetcollapse: an OpenCL C file defining double3 tc_user_placement(...) (no improvement\n"
                 "phase then)");
  app.add_option("--predicate-cl", o.predicate_cl,
                 "As tetcollapse: an OpenCL C file defining int tc_user_predicate(...); 0 refuses the\n"
                 "collapse (no improvement phase then)");
  app.add_option("--method", o.method, cli::kMethodHelp)->check(CLI::IsMember({"parallel", "sequential"}));
  app.add_option("--conflicts", o.conflicts,
                 "Conflict detection of the parallel method, as tetcollapse's: matching (default), greedy,\n"
                 "two-pass or atomic-min (needs 64-bit atomics on the device)")
      ->capture_default_str()
      ->check(CLI::IsMember({"greedy", "two-pass", "atomic-min", "matching"}));
  app.add_option("--priority-levels", o.priority_levels,
                 "Matching and greedy conflicts: edges ordered by their cost in steps of target / N, within a\n"
                 "step in a fixed pseudo-random order (default 64; 0: exact cost order)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--no-spatial-order", o.no_spatial_order,
               "Keep each part's numbering on the device (default: vertices along a Morton curve)");
  app.add_option("--host-tail", o.host_tail,
                 "With --eps-c 0 or 1: once an iteration collapses fewer than F x its tets, finish on the\n"
                 "host (default: the device type's, as tetcollapse)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--eps-c", o.eps_c, "Stop when an iteration collapses fewer than N edges (default 0: until none)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--max-iterations", o.max_iterations, "Stop after N iterations (in each rank's part, per round)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_flag("--paper-boundary-rule", o.paper_boundary_rule,
               "Refuse every non-boundary edge that touches the boundary, as the paper does\n"
               "(default: an interior vertex may collapse onto a boundary vertex, which stays put)");
  app.add_flag("--average-fields", o.average_fields,
               "Vertex fields at a survivor: the average of the collapsed edge's ends (default: the\n"
               "input's piecewise linear field at the vertex's final place, on rank 0 at the end)");
  app.add_option("--rounds", o.max_rounds,
                 "At most N rounds of partition, coarsening and gathering; each round after the first cuts\n"
                 "elsewhere, so the faces frozen before are coarsened")
      ->capture_default_str()
      ->check(CLI::Range(1, 100));
  app.add_option("--round-threshold", o.round_threshold,
                 "Stop after a round that removed fewer than this share of its tets")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--rings", o.rings,
                 "After the first round, coarsen and improve only within N tets of the vertices frozen in\n"
                 "the round before (coarsening again what is done would coarsen more than tetcollapse does)")
      ->capture_default_str()
      ->check(CLI::Range(1, 100));
  app.add_option("--seed", o.seed, "METIS seed of the first round (round r uses seed + r - 1)")->capture_default_str();
  app.add_option("--avoid-weight", o.avoid_weight,
                 "Weight in METIS's cut of a face touching the band still to coarsen (other faces: 1);\n"
                 "higher keeps the next cut further from the last")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000000));
  app.add_option("--partition-nodes", o.partition_nodes,
                 "A mesh of more tets is cut by METIS as about N clusters of nearby tets (cells of a grid),\n"
                 "each weighted by its tets, instead of tet by tet: METIS's time and memory on rank 0 grow\n"
                 "with its graph")
      ->capture_default_str()
      ->check(CLI::Range(int64_t(1), int64_t(1) << 30));
  app.add_option("--device", o.device,
                 "OpenCL device of every rank: index or name substring (see 'tetcollapse devices');\n"
                 "default: $TETCOLLAPSE_DEVICE, else the first GPU, else the first CPU");
  app.add_option("--stats", o.stats,
                 "Write the run's statistics as JSON to this file ('-' for stdout): per round and per rank\n"
                 "the seconds, tets and peak resident memory (VmHWM)");
  app.add_flag("--check", o.check,
               "Check the result on rank 0 against the input (validity, unchanged boundary topology; in\n"
               "strict mode the boundary distance too) and fail (exit 1, nothing written) if invalid");
  app.add_flag("-q,--quiet", o.quiet, "No progress lines, only errors");
  cli::add_input_options(app, o.input);
  cli::add_output_options(app, o.output);
}

void resolve_defaults(Options& o) {
  if (o.max_boundary_error < 0)
    o.max_boundary_error = o.max_boundary_error_abs > 0 ? 0 : default_max_boundary_error(cli::boundary_mode(o.boundary));
}

void validate(const Options& o) {
  cli::check_region_and_labels(o.region, o.labels);
  cli::check_method(o.method, o.device,
                    {{"--cost-cl", &o.cost_cl},
                     {"--sizing-field", &o.sizing_field},
                     {"--placement-cl", &o.placement_cl},
                     {"--predicate-cl", &o.predicate_cl}});
  if (o.max_field_error > 0) {
    if (o.preserve_field.empty())
      throw CLI::ValidationError("--max-field-error", "needs --preserve-field NAME (the field it bounds)");
    if (o.field_tolerance_given)
      throw CLI::ValidationError("--field-tolerance", "cannot be combined with --max-field-error (the bound decides)");
    if (o.field_check_given)
      throw CLI::ValidationError("--field-check", "cannot be combined with --max-field-error (the bound decides)");
  }
  if (!o.preserve_field.empty() && !o.sizing_field.empty())
    throw CLI::ValidationError("--preserve-field", "cannot be combined with --sizing-field");
  if (!o.cost_cl.empty() && (!o.preserve_field.empty() || !o.sizing_field.empty()))
    throw CLI::ValidationError("--cost-cl", "cannot be combined with --sizing-field or --preserve-field");
  if (!o.cost_cl.empty() && !(o.target_length > 0))
    throw CLI::ValidationError("--cost-cl", "needs --target-length");
  if (o.priority_levels >= 0 &&
      (o.method == "sequential" || (o.conflicts != "greedy" && o.conflicts != "matching")))
    throw CLI::ValidationError("--priority-levels",
                               "applies to the greedy and matching conflict detections only (--conflicts greedy|matching)");
  if ((o.max_boundary_error > 0 || o.max_boundary_error_abs > 0) && o.boundary != "features")
    throw CLI::ValidationError("--max-boundary-error",
                               "applies to --boundary features (strict keeps the boundary exactly, free does not bound it)");
}

}  // namespace tc::mpi
