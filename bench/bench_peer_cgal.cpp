// A peer: CGAL's tetrahedral isotropic remeshing on the same input and target as
// tetcollapse, with the boundary (and the interfaces between labels) protected.
//
//   bench_peer_cgal IN OUT TARGET_LENGTH [--iterations N]
//
// Reads IN with tc::read_mesh, builds a CGAL Triangulation_3 from the tet soup (the same
// construction CGAL::IO::read_MEDIT uses: every face with one tet gets an infinite cell, each
// tet keeps its primary label as subdomain index), runs
// CGAL::tetrahedral_isotropic_remeshing(tr, TARGET_LENGTH, remesh_boundaries(false)) and
// writes the finite cells of a non-zero subdomain to OUT (any format tetcollapse writes).
// Prints one JSON object on stdout: seconds_build (tet soup -> triangulation),
// seconds_remesh, seconds (their sum: what bench/peers.py reports), tets_in, tets_out,
// vertices_out. File I/O is not timed.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Mesh_3/tet_soup_to_c3t3.h>
#include <CGAL/Tetrahedral_remeshing/Remeshing_triangulation_3.h>
#include <CGAL/tetrahedral_remeshing.h>

#include "tetcollapse/error.hpp"
#include "tetcollapse/io.hpp"

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Tr = CGAL::Tetrahedral_remeshing::Remeshing_triangulation_3<K>;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Tet soup -> triangulation. Subdomain 0 means "outside" to the remesher, so labels are
// shifted to be >= 1 when the mesh has a label <= 0 (only the partition matters).
bool build(const tc::Mesh& mesh, Tr& tr) {
  std::vector<Tr::Point> points;
  points.reserve(static_cast<size_t>(mesh.num_vertices()));
  for (int64_t v = 0; v < mesh.num_vertices(); ++v)
    points.emplace_back(mesh.points[3 * v], mesh.points[3 * v + 1], mesh.points[3 * v + 2]);

  const std::vector<int32_t>* labels = mesh.tet_labels.empty() ? nullptr : &mesh.tet_labels[0].values;
  int32_t min_label = 1;
  if (labels)
    for (int32_t l : *labels) min_label = std::min(min_label, l);
  std::vector<std::array<int, 5>> cells(static_cast<size_t>(mesh.num_tets()));
  for (int64_t t = 0; t < mesh.num_tets(); ++t) {
    for (int j = 0; j < 4; ++j) cells[t][j] = mesh.tets[4 * t + j];
    cells[t][4] = labels ? (*labels)[t] - min_label + 1 : 1;
  }
  std::map<std::array<int, 3>, Tr::Cell::Surface_patch_index> no_patches;
  std::vector<Tr::Vertex_handle> handles;
  return CGAL::build_triangulation<Tr, true>(tr, points, cells, no_patches, handles);
}

tc::Mesh to_mesh(const Tr& tr) {
  tc::Mesh out;
  std::unordered_map<Tr::Vertex_handle, int32_t> index;
  tc::Labels labels;
  labels.name = "medit:ref";
  for (auto c = tr.finite_cells_begin(); c != tr.finite_cells_end(); ++c) {
    if (c->subdomain_index() == 0) continue;
    for (int j = 0; j < 4; ++j) {
      auto [it, added] = index.emplace(c->vertex(j), static_cast<int32_t>(index.size()));
      if (added) {
        const auto& p = c->vertex(j)->point();
        out.points.insert(out.points.end(), {CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z())});
      }
      out.tets.push_back(it->second);
    }
    labels.values.push_back(c->subdomain_index());
  }
  out.tet_labels.push_back(std::move(labels));
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: bench_peer_cgal IN OUT TARGET_LENGTH [--iterations N]\n");
    return 2;
  }
  const std::string in = argv[1], out = argv[2];
  const double target = std::atof(argv[3]);
  int iterations = 1;  // CGAL's default
  for (int i = 4; i + 1 < argc; i += 2)
    if (std::string(argv[i]) == "--iterations") iterations = std::atoi(argv[i + 1]);
  if (!(target > 0) || iterations < 1) {
    std::fprintf(stderr, "bench_peer_cgal: TARGET_LENGTH must be > 0 and --iterations >= 1\n");
    return 2;
  }
  try {
    tc::Mesh mesh = tc::read_mesh(in);
    auto t0 = std::chrono::steady_clock::now();
    Tr tr;
    if (!build(mesh, tr)) {
      std::fprintf(stderr, "bench_peer_cgal: %s: CGAL could not build a triangulation (a face in more than two tets?)\n",
                   in.c_str());
      return 1;
    }
    const double s_build = seconds_since(t0);
    t0 = std::chrono::steady_clock::now();
    CGAL::tetrahedral_isotropic_remeshing(
        tr, target,
        CGAL::parameters::remesh_boundaries(false).number_of_iterations(static_cast<std::size_t>(iterations)));
    const double s_remesh = seconds_since(t0);
    tc::Mesh result = to_mesh(tr);
    tc::write_mesh(out, result);
    std::printf(
        "{\"seconds_build\": %.6f, \"seconds_remesh\": %.6f, \"seconds\": %.6f, \"tets_in\": %lld, "
        "\"tets_out\": %lld, \"vertices_out\": %lld, \"iterations\": %d}\n",
        s_build, s_remesh, s_build + s_remesh, (long long)mesh.num_tets(), (long long)result.num_tets(),
        (long long)result.num_vertices(), iterations);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_peer_cgal: %s\n", e.what());
    return 2;
  }
  return 0;
}
