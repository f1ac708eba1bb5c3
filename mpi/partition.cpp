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

// Tets around each vertex (CSR), to find the tet across each face without a table of all faces
// (16 bytes per face to sort, 33 MB on W1).
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

// Each face is matched among the tets around its smallest vertex: every tet is read once per
// vertex (on W1's randomly numbered input, looking each face up around one of its vertices read
// 20 times as many tets, out of cache: 0.9 s).
DualGraph dual_graph(const Mesh& mesh, const std::vector<uint8_t>& avoid, int avoid_weight) {
  const int64_t nv = mesh.num_vertices(), nt = mesh.num_tets();
  const Incidence inc = incidence(mesh);
  struct Side {
    int32_t a, b, tet;  // the face's two other vertices (a < b), and a tet that has it
    bool operator<(const Side& o) const { return a < o.a || (a == o.a && (b < o.b || (b == o.b && tet < o.tet))); }
  };
  std::vector<Side> sides;
  std::vector<std::array<int32_t, 3>> pairs;  // tet, tet, weight
  for (int64_t v = 0; v < nv; ++v) {
    sides.clear();
    for (int64_t i = inc.offset[size_t(v)]; i < inc.offset[size_t(v) + 1]; ++i) {
      const int32_t t = inc.tets[size_t(i)];
      const int32_t* q = &mesh.tets[size_t(4 * t)];
      // the other three vertices; the faces through v are v and two of them
      int32_t o[3], n = 0;
      for (int k = 0; k < 4; ++k)
        if (q[k] != v) o[n++] = q[k];
      for (int k = 0; k < 3; ++k) {
        const int32_t x = o[k], y = o[(k + 1) % 3];
        if (x > v && y > v) sides.push_back({std::min(x, y), std::max(x, y), t});
      }
    }
    std::sort(sides.begin(), sides.end());
    for (size_t i = 0; i + 1 < sides.size(); ++i) {
      if (sides[i].a != sides[i + 1].a || sides[i].b != sides[i + 1].b) continue;
      const bool near = !avoid.empty() && (avoid[size_t(v)] || avoid[size_t(sides[i].a)] || avoid[size_t(sides[i].b)]);
      pairs.push_back({sides[i].tet, sides[i + 1].tet, near ? avoid_weight : 1});
      // a face in more than two tets (a defective input) links its first two only
      while (i + 1 < sides.size() && sides[i + 1].a == sides[i].a && sides[i + 1].b == sides[i].b) ++i;
    }
  }
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
