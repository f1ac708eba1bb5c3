// Times the checker on a ~1M-tet mesh (the target: under 5 s without Hausdorff).
//
//   bench_check [MESH] [RUNS]
// MESH defaults to the shared gen_tetgen_rocker-arm_964k.msh; when it cannot be read, a
// generated cube of 6 * 55^3 = 998,250 Kuhn tets (tc::make_cube_mesh) is used instead. Prints the median over
// RUNS (default 5) of the total and of every phase the report times, then one run against
// a slightly scaled copy as reference, with the Hausdorff distance.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "tetcollapse/check.hpp"
#include "tetcollapse/io.hpp"

namespace {


double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  std::string path = argc > 1 ? argv[1] : std::string(TC_SHARED_MESHES) + "/gen_tetgen_rocker-arm_964k.msh";
  int runs = argc > 2 ? std::max(1, std::atoi(argv[2])) : 5;
  tc::Mesh mesh;
  try {
    auto t0 = std::chrono::steady_clock::now();
    mesh = tc::read_mesh(path);
    double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("mesh: %s (read in %.2f s)\n", path.c_str(), s);
  } catch (const std::exception& e) {
    std::printf("cannot read %s (%s); using a generated cube instead\n", path.c_str(), e.what());
    mesh = tc::make_cube_mesh(55);
    path = "make_cube_mesh(55)";
  }
  std::printf("%lld vertices, %lld tets; %d runs, check without Hausdorff (no reference)\n",
              (long long)mesh.num_vertices(), (long long)mesh.num_tets(), runs);

  std::vector<double> totals;
  std::map<std::string, std::vector<double>> phases;
  std::vector<std::string> order;
  tc::CheckReport last;
  for (int i = 0; i < runs; ++i) {
    auto t0 = std::chrono::steady_clock::now();
    last = tc::check_mesh(mesh);
    totals.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    for (const auto& [name, s] : last.timings) {
      if (!phases.count(name)) order.push_back(name);
      phases[name].push_back(s);
    }
  }
  std::printf("verdict: %s, %zu errors, %zu warnings; boundary %lld triangles, %lld component(s), Euler %lld\n",
              last.valid ? "valid" : "INVALID", last.errors.size(), last.warnings.size(),
              (long long)last.boundary.faces, (long long)last.boundary.components, (long long)last.boundary.euler);
  for (const auto& e : last.errors) std::printf("  error: %s\n", e.c_str());
  for (const auto& w : last.warnings) std::printf("  warning: %s\n", w.c_str());
  std::printf("%-20s %10s\n", "phase", "median s");
  for (const auto& name : order) std::printf("%-20s %10.3f\n", name.c_str(), median(phases[name]));
  std::printf("%-20s %10.3f   (min %.3f, max %.3f)\n", "total", median(totals), *std::min_element(totals.begin(), totals.end()),
              *std::max_element(totals.begin(), totals.end()));

  // One run with a reference: the mesh itself, scaled by 1.001 about its bbox centre, so
  // the two boundaries differ everywhere and the Hausdorff search has real work to do.
  tc::Mesh ref = mesh;
  for (int a = 0; a < 3; ++a) {
    double c = 0.5 * (last.bbox_min[a] + last.bbox_max[a]);
    for (size_t i = size_t(a); i < ref.points.size(); i += 3) ref.points[i] = c + 1.001 * (ref.points[i] - c);
  }
  auto t0 = std::chrono::steady_clock::now();
  tc::CheckReport r = tc::check_mesh(mesh, {}, &ref);
  double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("\nwith reference (scaled 1.001) and Hausdorff: %.3f s; Hausdorff %.6g (%.3g x diagonal, error bound %.3g)\n",
              total, r.reference.hausdorff, r.reference.hausdorff_rel, r.reference.hausdorff_error_bound);
  for (const auto& [name, sec] : r.timings) std::printf("%-20s %10.3f\n", name.c_str(), sec);
  return 0;
}
