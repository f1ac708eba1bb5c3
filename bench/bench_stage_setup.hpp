// The setup the stage benchmarks share (bench_admissible, bench_conflict_rule, bench_selection):
// the common part of their command line, and the mesh on the device with its first connectivity.
//
//   MESH                 the input (default: W1's mesh, the robot 514k, from ../shared/meshes)
//   --runs N             timed repetitions (default 7; not bench_conflict_rule, which counts)
//   --target-factor F    target edge length = F x the median edge length (default 2, W1's)
//   --min-quality Q      the quality guard (default 0, W1's)
//   --priority-levels L  CollapseTuning::priority_levels (default the library's)
#pragma once

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <functional>
#include <string>
#include <vector>

#include "collapse/stages.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/io.hpp"

namespace tc::bench {

struct StageBenchArgs {
  std::string path = std::string(TC_SHARED_MESHES) + "/gen_tetgen_thingi255172_make-robot_514k.msh";
  int runs = 7;
  CollapseOptions options = [] {
    CollapseOptions o;
    o.target_factor = 2;
    o.min_quality = 0;
    return o;
  }();
};

// Parses the command line into `a`. `own(i)`, when given, is asked first about argv[i] and
// returns true when it takes it (moving i past any value it reads); --runs only when
// `timed`. Returns -1 to go on, or the exit code: 2 for an unknown option or a missing value
// (said on stderr, after `prog`).
inline int parse_stage_args(const char* prog, int argc, char** argv, StageBenchArgs& a,
                            const std::function<bool(int&)>& own = {}, bool timed = true) {
  for (int i = 1; i < argc; ++i) {
    if (own && own(i)) continue;
    const bool has_value = i + 1 < argc;
    if (!std::strcmp(argv[i], "--runs") && has_value && timed) a.runs = std::max(1, std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--target-factor") && has_value) a.options.target_factor = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--min-quality") && has_value) a.options.min_quality = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--priority-levels") && has_value) a.options.tuning.priority_levels = std::atof(argv[++i]);
    else if (argv[i][0] == '-') {
      std::fprintf(stderr, "%s: unknown option or missing value: %s\n", prog, argv[i]);
      return 2;
    } else {
      a.path = argv[i];
    }
  }
  return -1;
}

// The mesh, and on the device: the mesh in the spatial order collapse() uses by default
// (vertex_new: its vertices' new numbers), the stage parameters with the target length, and
// the first iteration's connectivity.
struct StageBench {
  Mesh mesh;
  Context ctx;
  collapse_detail::StageParams p;
  collapse_detail::DeviceMesh dm;
  std::vector<int32_t> vertex_new;
  collapse_detail::Connectivity c;
};

// Fills b from a; false (said on stderr, after `prog`) when the mesh cannot be read.
inline bool load_stage_bench(const char* prog, const StageBenchArgs& a, StageBench& b) {
  try {
    b.mesh = read_mesh(a.path);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: cannot read %s: %s\n", prog, a.path.c_str(), e.what());
    return false;
  }
  b.p = collapse_detail::params_from(a.options);
  b.p.target = a.options.target_factor * median_edge_length(b.mesh);
  collapse_detail::upload_mesh(b.ctx, b.mesh, a.options, b.dm, a.options.tuning.spatial_order ? &b.vertex_new : nullptr);
  collapse_detail::build_connectivity(b.ctx, b.dm, b.c, b.p);
  return true;
}

}  // namespace tc::bench
