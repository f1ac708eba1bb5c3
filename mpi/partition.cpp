#include "partition.hpp"

#include <metis.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "topology/faces_at_vertices.hpp"

namespace tc::mpi {

namespace {

// The dual graph in METIS's CSR form: two tets are adjacent when they share a face.
struct DualGraph {
  std::vector<idx_t> xadj, adjncy, adjwgt;
};

// The graph METIS cuts: with `cluster` empty, the dual graph; else its contraction, one node per
// cluster (cluster[t] of tet t, `nodes` of them), weighted by its tets, and one edge per pair of
// clusters sharing faces, weighted by the faces' weights.
DualGraph dual_graph(const Mesh& mesh, const std::vector<uint8_t>& avoid, int avoid_weight,
                     const std::vector<int32_t>& cluster, int64_t nodes) {
  const int64_t nt = mesh.num_tets();
  std::vector<std::array<int32_t, 3>> pairs;  // tet, tet, weight
  topology_detail::each_face_at_smallest_vertex(mesh, [&](int32_t v, const topology_detail::FaceSide* s, size_t n) {
    if (n < 2) return;  // (a face in more than two tets, a defective input, links its first two only)
    const bool near = !avoid.empty() && (avoid[size_t(v)] || avoid[size_t(s[0].a)] || avoid[size_t(s[0].b)]);
    if (cluster.empty()) {
      pairs.push_back({s[0].tet, s[1].tet, near ? avoid_weight : 1});
    } else {
      const int32_t c0 = cluster[size_t(s[0].tet)], c1 = cluster[size_t(s[1].tet)];
      if (c0 != c1) pairs.push_back({std::min(c0, c1), std::max(c0, c1), near ? avoid_weight : 1});
    }
  });
  const int64_t n = cluster.empty() ? nt : nodes;
  if (!cluster.empty()) {  // one edge per pair of clusters, the faces' weights summed
    std::sort(pairs.begin(), pairs.end());
    size_t m = 0;
    for (size_t i = 0; i < pairs.size(); ++i) {
      if (m > 0 && pairs[m - 1][0] == pairs[i][0] && pairs[m - 1][1] == pairs[i][1]) pairs[m - 1][2] += pairs[i][2];
      else pairs[m++] = pairs[i];
    }
    pairs.resize(m);
  }
  DualGraph g;
  g.xadj.assign(size_t(n + 1), 0);
  for (const auto& p : pairs) {
    ++g.xadj[size_t(p[0]) + 1];
    ++g.xadj[size_t(p[1]) + 1];
  }
  for (int64_t t = 0; t < n; ++t) g.xadj[size_t(t + 1)] += g.xadj[size_t(t)];
  g.adjncy.resize(size_t(g.xadj.back()));
  g.adjwgt.resize(size_t(g.xadj.back()));
  std::vector<idx_t> fill(g.xadj.begin(), g.xadj.end() - 1);
  for (const auto& p : pairs)
    for (int s = 0; s < 2; ++s) {
      const size_t at = size_t(fill[size_t(p[size_t(s)])]++);
      g.adjncy[at] = p[size_t(1 - s)];
      g.adjwgt[at] = p[2];
    }
  return g;
}

// Clusters of about `per` tets: the cells of a uniform grid over the tets' centroids (cells of
// the bounding box's volume x per / tets), numbered in grid order, empty cells dropped. Returns
// the cluster of each tet and their number; vwgt the tets of each.
int64_t grid_clusters(const Mesh& mesh, int64_t per, std::vector<int32_t>& cluster, std::vector<idx_t>& vwgt) {
  const int64_t nt = mesh.num_tets();
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < mesh.points.size(); ++i) {
    lo[i % 3] = std::min(lo[i % 3], mesh.points[i]);
    hi[i % 3] = std::max(hi[i % 3], mesh.points[i]);
  }
  double volume = 1;
  for (int c = 0; c < 3; ++c) volume *= std::max(hi[c] - lo[c], 1e-300);
  const double h = std::cbrt(volume * double(per) / double(nt));
  int64_t dim[3];
  for (int c = 0; c < 3; ++c) dim[c] = std::clamp<int64_t>(int64_t((hi[c] - lo[c]) / h) + 1, 1, 1 << 20);
  std::vector<int64_t> cell(static_cast<size_t>(nt));
  for (int64_t t = 0; t < nt; ++t) {
    int64_t at = 0;
    for (int c = 0; c < 3; ++c) {
      double x = 0;
      for (int k = 0; k < 4; ++k) x += mesh.points[size_t(3 * mesh.tets[size_t(4 * t + k)] + c)];
      at = at * dim[c] + std::clamp<int64_t>(int64_t((x / 4 - lo[c]) / h), 0, dim[c] - 1);
    }
    cell[size_t(t)] = at;
  }
  std::vector<int64_t> used(cell);
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  cluster.resize(size_t(nt));
  vwgt.assign(used.size(), 0);
  for (int64_t t = 0; t < nt; ++t) {
    cluster[size_t(t)] = int32_t(std::lower_bound(used.begin(), used.end(), cell[size_t(t)]) - used.begin());
    ++vwgt[size_t(cluster[size_t(t)])];
  }
  return int64_t(used.size());
}

}  // namespace

std::vector<int32_t> partition_tets(const Mesh& mesh, const PartitionOptions& options,
                                    const std::vector<uint8_t>& avoid) {
  const int64_t nt = mesh.num_tets();
  std::vector<int32_t> part(size_t(nt), 0);
  if (options.nparts <= 1 || nt == 0) return part;
  if (nt <= options.nparts) {  // METIS wants more vertices than parts
    for (int64_t t = 0; t < nt; ++t) part[size_t(t)] = int32_t(t);
    return part;
  }
  // Past kMaxGraphNodes tets METIS cuts clusters of tets instead (grid_clusters, weighted by
  // their tets). Why: its multilevel k-way work and memory grow with the graph, and on rank 0 they
  // came on top of the whole mesh (10.7M tets: 21 s and most of rank 0's peak); clusters of a few
  // dozen tets cut as well at the scale of the parts.
  std::vector<int32_t> cluster;
  std::vector<idx_t> vwgt;
  const int64_t nodes = nt > options.max_graph_nodes
                            ? grid_clusters(mesh, (nt + options.max_graph_nodes - 1) / options.max_graph_nodes, cluster, vwgt)
                            : nt;
  DualGraph g = dual_graph(mesh, avoid, options.avoid_weight, cluster, nodes);
  idx_t nvtxs = idx_t(nodes), ncon = 1, nparts = options.nparts, objval = 0;
  idx_t metis[METIS_NOPTIONS];
  METIS_SetDefaultOptions(metis);
  metis[METIS_OPTION_SEED] = options.seed;
  metis[METIS_OPTION_NUMBERING] = 0;
  std::vector<idx_t> out(static_cast<size_t>(nodes));
  const int rc = nodes <= nparts ? METIS_OK
                                 : METIS_PartGraphKway(&nvtxs, &ncon, g.xadj.data(), g.adjncy.data(),
                                                       vwgt.empty() ? nullptr : vwgt.data(), nullptr, g.adjwgt.data(),
                                                       &nparts, nullptr, nullptr, metis, &objval, out.data());
  if (rc != METIS_OK) throw std::runtime_error("METIS_PartGraphKway failed (code " + std::to_string(rc) + ")");
  if (nodes <= nparts)
    for (int64_t c = 0; c < nodes; ++c) out[size_t(c)] = idx_t(c);
  for (int64_t t = 0; t < nt; ++t) part[size_t(t)] = int32_t(out[size_t(cluster.empty() ? t : cluster[size_t(t)])]);
  return part;
}

}  // namespace tc::mpi
