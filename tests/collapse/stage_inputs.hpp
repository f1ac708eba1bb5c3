// Inputs of the conflict stages' tests (test_collapse_atomic_min.cpp, test_collapse_greedy.cpp).
#pragma once

#include <cstdio>
#include <initializer_list>
#include <string>
#include <vector>

#include "collapse/stages.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/io.hpp"
#include "test_support.hpp"

namespace tc::test {

struct StageInput {
  std::string name;
  Mesh mesh;
  collapse_detail::StageParams params;
  double target;
};

// A cube (many equal costs: ties), a signed user cost (negative and positive costs), a user cost
// of +-0.0 everywhere (the tie order alone), the project's bracket, and the shared meshes named
// when present; with the library's default parameters and twice the median edge length as the
// target (the user costs: fixed targets).
inline std::vector<StageInput> conflict_stage_inputs(std::initializer_list<const char*> shared) {
  std::vector<StageInput> in;
  const collapse_detail::StageParams p = collapse_detail::params_from(CollapseOptions{});
  const Mesh cube = make_cube_mesh(6);
  in.push_back({"cube", cube, p, 2 * median_edge_length(cube)});
  collapse_detail::StageParams signed_cost = p;
  signed_cost.cost_source =
      "double tc_user_cost(double3 p0, double3 p1, double f0, double f1) { return p0.x + p1.x + 0.3 * p0.y - 1.0; }";
  in.push_back({"cube, signed cost", cube, signed_cost, 0.5});
  collapse_detail::StageParams zero_cost = p;
  zero_cost.cost_source =
      "double tc_user_cost(double3 p0, double3 p1, double f0, double f1) { return (p1.x - p0.x - p1.y + p0.y) * 0.0; }";
  in.push_back({"cube, cost +-0", cube, zero_cost, 1.0});
  const Mesh bracket = read_mesh(project_mesh("bracket.msh"));
  in.push_back({"bracket", bracket, p, 2 * median_edge_length(bracket)});
  for (const char* name : shared) {
    const std::string path = shared_mesh(name);
    if (path.empty()) {
      std::printf("skipping %s: absent\n", name);
      continue;
    }
    const Mesh m = read_mesh(path);
    in.push_back({name, m, p, 2 * median_edge_length(m)});
  }
  return in;
}

// One iteration's stages on the device up to admissible() (every marked edge tested), with p's
// target set to `target`.
inline void run_to_admissible(Context& ctx, const Mesh& m, collapse_detail::StageParams& p, double target,
                              collapse_detail::DeviceMesh& dm, collapse_detail::Connectivity& c,
                              collapse_detail::EdgeState& s) {
  p.target = target;
  collapse_detail::upload_mesh(ctx, m, CollapseOptions{}, dm);
  collapse_detail::build_connectivity(ctx, dm, c, p);
  collapse_detail::cost_and_mark(ctx, dm, c, s, p);
  collapse_detail::admissible(ctx, dm, c, s, p);
}

}  // namespace tc::test
