#include "partition.hpp"

#include <metis.h>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace tc::mpi {

namespace {

// The dual graph in METIS's CSR form: two tets are adjacent when they share a face.
struct DualGraph {
  std::vector<idx_t> xadj, adjncy, adjwgt;
};

// Tets around each vertex (CSR), to find the tet across each face without a table of all faces:
// 4 ints per tet where sorting the faces took 16 bytes per face (rank 0's peak memory).
struct Incidence {
  std::vector<int64_t> offset;
  std::vector<int32_t> tets;
};

Incidence incidence(const Mesh& mesh) {
  const int64_t nv = mesh.num_vertices(), nt = mesh.num_tets();
  Incidence inc;
  inc.offset.assign(size_t(nv + 1), 0);
  for (int32_t v : mesh.tets) ++inc.offset[size_t(v) + 1];
  for (int64_t v = 0; v < nv; ++v) inc.offset[size_t(v + 1)] += inc.offset[size_t(v)];
  inc.tets.resize(mesh.tets.size());
  std::vector<int64_t> fill(inc.offset.begin(), inc.offset.end() - 1);
  for (int64_t t = 0; t < nt; ++t)
    for (int k = 0; k < 4; ++k) inc.tets[size_t(fill[size_t(mesh.tets[size_t(4 * t + k)])]++)] = int32_t(t);
  return inc;
}

bool has(const int32_t* q, int32_t v) { return q[0] == v || q[1] == v || q[2] == v || q[3] == v; }

DualGraph dual_graph(const Mesh& mesh, const std::vector<uint8_t>& avoid, int avoid_weight) {
  const int64_t nt = mesh.num_tets();
  const Incidence inc = incidence(mesh);
  DualGraph g;
  g.xadj.assign(size_t(nt + 1), 0);
  g.adjncy.reserve(size_t(4 * nt));
  g.adjwgt.reserve(size_t(4 * nt));
  for (int64_t t = 0; t < nt; ++t) {
    const int32_t* q = &mesh.tets[size_t(4 * t)];
    for (int skip = 0; skip < 4; ++skip) {
      int32_t f[3];
      for (int k = 0, j = 0; k < 4; ++k)
        if (k != skip) f[j++] = q[k];
      // The first two tets around f[0] (in tet order) that have f[1] and f[2] too: t and its
      // neighbour (a face in more than two tets, a defective input, links its first two only,
      // the same from both sides).
      int32_t pair[2] = {-1, -1}, n = 0;
      for (int64_t i = inc.offset[size_t(f[0])]; i < inc.offset[size_t(f[0]) + 1] && n < 2; ++i) {
        const int32_t s = inc.tets[size_t(i)];
        const int32_t* r = &mesh.tets[size_t(4 * s)];
        if (has(r, f[1]) && has(r, f[2])) pair[n++] = s;
      }
      if (n < 2 || (pair[0] != t && pair[1] != t)) continue;
      const bool near = !avoid.empty() && (avoid[size_t(f[0])] || avoid[size_t(f[1])] || avoid[size_t(f[2])]);
      g.adjncy.push_back(pair[0] == t ? pair[1] : pair[0]);
      g.adjwgt.push_back(near ? avoid_weight : 1);
    }
    g.xadj[size_t(t + 1)] = idx_t(g.adjncy.size());
  }
  return g;
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
  DualGraph g = dual_graph(mesh, avoid, options.avoid_weight);
  idx_t nvtxs = idx_t(nt), ncon = 1, nparts = options.nparts, objval = 0;
  idx_t metis[METIS_NOPTIONS];
  METIS_SetDefaultOptions(metis);
  metis[METIS_OPTION_SEED] = options.seed;
  metis[METIS_OPTION_NUMBERING] = 0;
  std::vector<idx_t> out(static_cast<size_t>(nt));
  const int rc = METIS_PartGraphKway(&nvtxs, &ncon, g.xadj.data(), g.adjncy.data(), nullptr, nullptr,
                                     g.adjwgt.data(), &nparts, nullptr, nullptr, metis, &objval, out.data());
  if (rc != METIS_OK) throw std::runtime_error("METIS_PartGraphKway failed (code " + std::to_string(rc) + ")");
  for (int64_t t = 0; t < nt; ++t) part[size_t(t)] = int32_t(out[size_t(t)]);
  return part;
}

}  // namespace tc::mpi
