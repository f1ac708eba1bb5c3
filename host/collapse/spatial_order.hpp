// A locality-improving renumbering of a mesh for the device run: vertices along a Morton
// (Z-order) curve of their positions, tets by their smallest new vertex index. The stages
// gather rings, neighbours and points of nearby vertices; in file order (e.g. TetGen's, where
// the two ends of an edge are often thousands of indices apart) nearly every such
// access misses the cache. The collapse keeps relative order, so the locality lasts the run.
// Ties (points closer than 2^-21 of the extent share a code; tets with the same smallest
// vertex) keep the input's order.
#pragma once

#include <cstdint>
#include <vector>

#include "tetcollapse/mesh.hpp"

namespace tc::collapse_detail {

struct SpatialOrder {
  std::vector<int32_t> vertex_old;  // new vertex -> input vertex
  std::vector<int32_t> vertex_new;  // input vertex -> new vertex
  std::vector<int32_t> tet_old;     // new tet -> input tet
  std::vector<int32_t> tets;        // 4 per tet: the tets in the new order, with new vertex indices
};

// Assumes check_collapse_input(mesh) passed (tet indices in range).
SpatialOrder spatial_order(const Mesh& mesh);

}  // namespace tc::collapse_detail
