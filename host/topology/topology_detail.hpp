// Internals of the CPU topology construction, shared with tests.
#pragma once

#include <cstdint>
#include <vector>

#include "tetcollapse/topology.hpp"

namespace tc::topology_detail {

struct KeyPayload {
  uint64_t key;
  uint32_t payload;
};

// Stable LSD radix sort by key (equal keys keep their input order).
void radix_sort(std::vector<KeyPayload>& a);

// Counting-sort CSR: entry i (value values[i]) goes to list keys[i], in input order.
void build_csr(int32_t num_lists, const std::vector<int32_t>& keys, const std::vector<int32_t>& values,
               std::vector<int32_t>& offsets, std::vector<int32_t>& indices);

// Index in TC_TET_EDGES of the edge joining local corners i and j (-1 when i == j).
int local_edge(int i, int j);

// The classification rules of topology.hpp, on a Topology whose S-face arrays and CSR lists
// are complete (classify_vertex also needs edge_ridge).
uint8_t classify_edge(const Topology& t, int32_t e, double eps_r);
uint8_t classify_vertex(const Topology& t, int32_t v, double eps_f);

}  // namespace tc::topology_detail
