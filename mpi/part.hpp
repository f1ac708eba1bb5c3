// One rank's share of the mesh in a round of tetcollapse-mpi, and how rank 0 cuts the whole
// mesh into parts and puts the coarsened parts together again.
#pragma once

#include <cstdint>
#include <vector>

#include "tetcollapse/mesh.hpp"

namespace tc::mpi {

struct Part {
  Mesh mesh;                    // local numbering; labels, fields, tagged triangles and edges
  std::vector<int64_t> gid;     // per local vertex: its index in the whole mesh of the round
                                // (-1 after coarsening for a vertex that is not frozen)
  std::vector<uint8_t> frozen;  // per local vertex: 1 on the partition interface (kept as is)
  // Per local vertex: 1 where this round may coarsen and improve (empty: everywhere). After the
  // first round only the band around the last round's interface is still to do: coarsening
  // what is done already again would coarsen more than one run of `tetcollapse` does.
  std::vector<uint8_t> select;
  // Under --max-field-error: the input's vertices that the part's tets hold, where its round
  // measures the bound (CollapseOptions::field_points, field_point_values, field_point_tets:
  // local tet indices); empty otherwise. Sent to the ranks, not back (rank 0 locates them anew
  // in each round's mesh).
  std::vector<double> field_points, field_values;
  std::vector<int32_t> field_tets;
};

// How rank 0 cuts `whole` along `tet_part` (one part index per tet, nparts parts): which
// vertices lie in tets of more than one part (frozen), and the part of each tagged triangle and
// edge (that of the first tet having it as a face or edge; -1: none has, it is dropped).
class Splitter {
 public:
  Splitter(const Mesh& whole, const std::vector<int32_t>& tet_part, int nparts);
  int64_t interface_vertices() const { return interface_vertices_; }
  int64_t dropped_tris() const { return dropped_tris_; }
  int64_t dropped_edges() const { return dropped_edges_; }
  const std::vector<uint8_t>& shared() const { return shared_; }
  // Part p: its tets in their order, their vertices in increasing global order; `select` (per
  // vertex of the whole mesh, empty: all) goes with the vertices.
  Part extract(int p, const std::vector<uint8_t>& select) const;

 private:
  const Mesh& whole_;
  const std::vector<int32_t>& tet_part_;
  std::vector<uint8_t> shared_;
  std::vector<int32_t> tri_part_, edge_part_;
  int64_t interface_vertices_ = 0, dropped_tris_ = 0, dropped_edges_ = 0;
};

// Rank 0 puts the coarsened parts together, one after the other in rank order: frozen vertices
// (the same global id in several parts, bit-identical positions) become one vertex, every other
// vertex a new one. The result is numbered afresh: vertices in order of first appearance.
// The vertices within `rings` tets of a vertex in `seed` (seed included).
std::vector<uint8_t> grow(const Mesh& mesh, std::vector<uint8_t> seed, int rings);

class Merger {
 public:
  // band: per vertex of the round's whole mesh, where the round was to coarsen (empty: all).
  Merger(int64_t whole_vertices, const std::vector<uint8_t>& band);
  void add(Part&& part);  // throws std::runtime_error when a frozen vertex moved
  Mesh finish();
  // Per vertex of the result: 1 when it was frozen in this round though in its band: what is
  // left to do (a frozen vertex outside the band was done in an earlier round).
  std::vector<uint8_t> was_frozen() { return std::move(was_frozen_); }

 private:
  const std::vector<uint8_t>& band_;
  std::vector<int32_t> new_index_;  // per global id of the round: its vertex in the result
  std::vector<uint8_t> was_frozen_;
  Mesh out_;
  bool first_ = true;
};

}  // namespace tc::mpi
