// What the default boundary rule gains over the paper's: the default lets an interior
// vertex collapse onto a boundary vertex (which stays put); paper_boundary_rule refuses every
// non-boundary edge touching the boundary. Both with --boundary features, target = F x median.
//
//   bench_collapse_rule [--factor F] [MESH ...]
// Without meshes: a set of shared meshes of various kinds. Prints tets in/out, reduction,
// iterations and collapse() wall time of both rules per mesh, and a Markdown table.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "tetcollapse/collapse.hpp"
#include "tetcollapse/io.hpp"

using namespace tc;

int main(int argc, char** argv) {
  double factor = 1;
  std::vector<std::string> paths;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--factor") && i + 1 < argc) factor = std::atof(argv[++i]);
    else paths.push_back(argv[i]);
  }
  if (paths.empty())
    for (const char* n : {"polyfem_screw.msh", "polyfem_bimetal.msh", "mmg_tinyBoxt.mesh", "gen_gmsh_wrenchnut_27k.msh",
                          "gen_gmsh_Angled_43k.msh", "ipc_hollowCat7.5K.msh", "gen_gmsh_917_fusee_88k.msh"})
      paths.push_back(std::string(TC_SHARED_MESHES) + "/" + n);
  Context ctx;
  std::printf("device %s, target %g x median edge length, boundary features\n", ctx.info().name.c_str(), factor);
  std::string table =
      "| mesh | tets in | tets out (default) | tets out (paper rule) | default removes more | iterations (default / paper) |\n"
      "|---|---:|---:|---:|---:|---:|\n";
  for (const std::string& path : paths) {
    Mesh in;
    try {
      in = read_mesh(path);
    } catch (const std::exception& e) {
      std::printf("skipping %s: %s\n", path.c_str(), e.what());
      continue;
    }
    CollapseReport r[2];
    double wall[2];
    for (int rule = 0; rule < 2; ++rule) {
      Mesh m = in;
      CollapseOptions o;
      o.target_factor = factor;
      o.paper_boundary_rule = rule == 1;
      auto t = std::chrono::steady_clock::now();
      r[rule] = collapse(m, o, ctx);
      wall[rule] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
    }
    const std::string name = path.substr(path.find_last_of('/') + 1);
    const double removed0 = double(r[0].tets_in - r[0].tets_out), removed1 = double(r[1].tets_in - r[1].tets_out);
    std::printf("%-32s tets %8lld -> default %8lld (%zu it, %.2f s)  paper %8lld (%zu it, %.2f s)\n", name.c_str(),
                (long long)r[0].tets_in, (long long)r[0].tets_out, r[0].iterations.size(), wall[0],
                (long long)r[1].tets_out, r[1].iterations.size(), wall[1]);
    char row[512];
    std::snprintf(row, sizeof row, "| %s | %lld | %lld (-%.1f%%) | %lld (-%.1f%%) | %+.1f%% | %zu / %zu |\n", name.c_str(),
                  (long long)r[0].tets_in, (long long)r[0].tets_out, 100 * removed0 / double(r[0].tets_in),
                  (long long)r[1].tets_out, 100 * removed1 / double(r[1].tets_in),
                  removed1 > 0 ? 100 * (removed0 - removed1) / removed1 : 0.0, r[0].iterations.size(),
                  r[1].iterations.size());
    table += row;
  }
  std::printf("\n%s", table.c_str());
  return 0;
}
