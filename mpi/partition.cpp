#include "partition.hpp"

#include <metis.h>

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>

namespace tc::mpi {

namespace {

// The dual graph in METIS's CSR form: two tets are adjacent when they share a face.
struct DualGraph {
  std::vector<idx_t> xadj, adjncy, adjwgt;
};

DualGraph dual_graph(const Mesh& mesh, const std::vector<uint8_t>& avoid, int avoid_weight) {
  const int64_t nt = mesh.num_tets();
  // Every face by its sorted vertices; equal neighbours in sorted order are the shared faces.
  struct Face {
    std::array<int32_t, 3> v;
    int32_t tet;
    bool operator<(const Face& o) const { return v < o.v || (v == o.v && tet < o.tet); }
  };
  std::vector<Face> faces;
  faces.reserve(size_t(4 * nt));
  for (int64_t t = 0; t < nt; ++t) {
    std::array<int32_t, 4> q;
    for (int k = 0; k < 4; ++k) q[size_t(k)] = mesh.tets[size_t(4 * t + k)];
    std::sort(q.begin(), q.end());
    for (int skip = 0; skip < 4; ++skip) {
      Face f{{}, int32_t(t)};
      for (int k = 0, j = 0; k < 4; ++k)
        if (k != skip) f.v[size_t(j++)] = q[size_t(k)];
      faces.push_back(f);
    }
  }
  std::sort(faces.begin(), faces.end());
  // Pairs (a, b, weight), counted per tet first, then placed.
  std::vector<std::array<int32_t, 3>> pairs;
  for (size_t i = 0; i + 1 < faces.size(); ++i) {
    if (faces[i].v != faces[i + 1].v) continue;
    bool near = false;
    for (int32_t v : faces[i].v) near = near || (!avoid.empty() && avoid[size_t(v)]);
    pairs.push_back({faces[i].tet, faces[i + 1].tet, near ? avoid_weight : 1});
    ++i;  // a face in more than two tets (a defective input) links its first two only
  }
  faces = {};
  DualGraph g;
  g.xadj.assign(size_t(nt + 1), 0);
  for (const auto& p : pairs) {
    ++g.xadj[size_t(p[0]) + 1];
    ++g.xadj[size_t(p[1]) + 1];
  }
  for (int64_t t = 0; t < nt; ++t) g.xadj[size_t(t + 1)] += g.xadj[size_t(t)];
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
