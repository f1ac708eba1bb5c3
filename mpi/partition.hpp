// Cutting the mesh into one part per rank: the dual graph (tets adjacent across a face) split
// by METIS's k-way partitioner, as ParMmg's first partition does.
//
// Why METIS: a well-kept serial graph partitioner packaged by Debian (libmetis-dev), whose
// multilevel k-way partitioning of the dual graph gives balanced parts with a small cut (few
// interface faces, so few frozen vertices), is deterministic for a fixed seed, takes edge
// weights (which steer the next round's cut away from the last one's) and runs in well under a
// second on a 500k-tet dual graph. A parallel partitioner (ParMETIS, PT-Scotch) would only pay
// off once rank 0 no longer holds the whole mesh, and ParMETIS is not free software.
#pragma once

#include <cstdint>
#include <vector>

#include "tetcollapse/mesh.hpp"

namespace tc::mpi {

struct PartitionOptions {
  int nparts = 1;
  int seed = 1;  // METIS_OPTION_SEED: the same seed, the same parts
  // Faces with a vertex in `avoid` (the vertices frozen in the round before) weigh this much in
  // the cut, other faces 1, so that METIS cuts elsewhere and the old interface is coarsened.
  int avoid_weight = 50;
  // Meshes of more tets are cut as clusters of tets, at most about this many (partition.cpp).
  int64_t max_graph_nodes = 1 << 20;
};

// One part index per tet, in [0, nparts). Throws std::runtime_error when METIS fails.
std::vector<int32_t> partition_tets(const Mesh& mesh, const PartitionOptions& options,
                                    const std::vector<uint8_t>& avoid);

}  // namespace tc::mpi
