// The command line of tetcollapse-mpi: the options of `tetcollapse IN OUT` it supports, under
// the same names, and those of the rounds.
#pragma once

#include <CLI/CLI.hpp>

#include <string>

#include "cli/common.hpp"
#include "cli/improve_cli.hpp"
#include "partition.hpp"
#include "tetcollapse/coarsen.hpp"

namespace tc::mpi {

struct Options {
  std::string in, out, stats, device, boundary = "features";
  double target_length = 0, target_factor = 0;
  double eps_f = 0.01, eps_r = 0.1, eps_v = CollapseOptions{}.eps_v, min_quality = 0.1;
  // features mode only (see validate()); max_boundary_error < 0: not given (resolve_defaults)
  double max_boundary_error = -1, max_boundary_error_abs = 0;
  int64_t eps_c = 0;
  int max_iterations = 1000;
  bool paper_boundary_rule = false, no_spatial_order = false, no_merge_features = false;
  std::string conflicts = "matching", method = "parallel";
  std::string preserve_field;  // the paper's field cost on this vertex field (--field-tolerance)
  std::string sizing_field, cost_cl, placement_cl, predicate_cl;
  std::string region, labels;  // only there (tetcollapse's --region, --labels)
  double field_tolerance = 0.02;
  double max_field_error = 0;  // tetcollapse's --max-field-error, measured at the input's vertices
  bool field_tolerance_given = false, field_check_given = false;  // (refused with the bound)
  double field_check = CoarsenOptions{}.field_check;  // tetcollapse's --field-check
  double priority_levels = -1, host_tail = -1;  // -1: not given (the library's defaults)
  cli::ImproveCli improve;  // the improvement's options, as tetcollapse's
  std::string eps_v_scale = "mean-tet";  // tetcollapse's --eps-v-scale
  bool no_labels = false, no_improve = false, quiet = false, check = false,
       average_fields = false;
  int cycles = CoarsenOptions{}.cycles;  // tetcollapse's --cycles
  int max_rounds = 5;
  double round_threshold = 0.01;
  int seed = 1, avoid_weight = 50, rings = 2;
  int64_t partition_nodes = PartitionOptions{}.max_graph_nodes;
  cli::InputOptions input;
  cli::OutputOptions output;
};

void add_options(CLI::App& app, Options& o);
// What CLI11 cannot check alone; throws CLI::ValidationError.
void validate(const Options& o);
// The defaults that depend on other options, as tetcollapse's: the boundary error bound
// (default_max_boundary_error).
void resolve_defaults(Options& o);

}  // namespace tc::mpi
