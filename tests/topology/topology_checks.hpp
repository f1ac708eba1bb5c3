// Structural checks of a tc::Topology against its mesh, shared by the topology tests.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <utility>

#include "geometry.h"
#include "tetcollapse/topology.hpp"

namespace tc::test {

inline geo::tc_d3 topo_pt(const Mesh& m, int32_t v) { return geo::tc_point(m.points.data(), v); }

inline bool sorted_csr(const std::vector<int32_t>& off, const std::vector<int32_t>& idx) {
  if (off.empty() || off.front() != 0 || size_t(off.back()) != idx.size()) return false;
  for (size_t i = 0; i + 1 < off.size(); ++i) {
    if (off[i] > off[i + 1]) return false;
    for (int32_t j = off[i] + 1; j < off[i + 1]; ++j)
      if (idx[j - 1] >= idx[j]) return false;
  }
  return true;
}

// Checks every relation between the arrays against the mesh, independently of how they were built.
inline void check_invariants(const Mesh& m, const Topology& t) {
  const int32_t nv = t.num_vertices, nt = t.num_tets, ne = t.num_edges(), ns = t.num_sfaces();
  ASSERT_EQ(nv, m.num_vertices());
  ASSERT_EQ(nt, m.num_tets());
  for (int32_t e = 0; e < ne; ++e) {
    ASSERT_LT(t.edges[2 * e], t.edges[2 * e + 1]);
    if (e > 0) {
      ASSERT_TRUE(std::pair(t.edges[2 * e - 2], t.edges[2 * e - 1]) < std::pair(t.edges[2 * e], t.edges[2 * e + 1]));
    }
  }
  ASSERT_EQ(t.tet_edges.size(), size_t(nt) * 6);
  for (int32_t i = 0; i < nt; ++i)
    for (int e = 0; e < 6; ++e) {
      const int32_t id = t.tet_edges[6 * i + e];
      ASSERT_GE(id, 0);
      ASSERT_LT(id, ne);
      int32_t a = m.tets[4 * i + geo::TC_TET_EDGES[e][0]], b = m.tets[4 * i + geo::TC_TET_EDGES[e][1]];
      ASSERT_EQ(std::min(a, b), t.edges[2 * id]);
      ASSERT_EQ(std::max(a, b), t.edges[2 * id + 1]);
    }
  ASSERT_TRUE(sorted_csr(t.vertex_tets_offsets, t.vertex_tets));
  ASSERT_TRUE(sorted_csr(t.vertex_edges_offsets, t.vertex_edges));
  ASSERT_TRUE(sorted_csr(t.edge_tets_offsets, t.edge_tets));
  ASSERT_TRUE(sorted_csr(t.vertex_sfaces_offsets, t.vertex_sfaces));
  ASSERT_TRUE(sorted_csr(t.edge_sfaces_offsets, t.edge_sfaces));
  ASSERT_EQ(t.vertex_tets.size(), size_t(nt) * 4);
  ASSERT_EQ(t.vertex_edges.size(), size_t(ne) * 2);
  ASSERT_EQ(t.edge_tets.size(), size_t(nt) * 6);
  for (int32_t v = 0; v < nv; ++v)
    for (int32_t i = t.vertex_tets_offsets[v]; i < t.vertex_tets_offsets[v + 1]; ++i) {
      const int32_t* tv = &m.tets[4 * size_t(t.vertex_tets[i])];
      ASSERT_TRUE(std::find(tv, tv + 4, v) != tv + 4);
    }
  for (int32_t v = 0; v < nv; ++v)
    for (int32_t i = t.vertex_edges_offsets[v]; i < t.vertex_edges_offsets[v + 1]; ++i) {
      const int32_t e = t.vertex_edges[i];
      ASSERT_TRUE(t.edges[2 * e] == v || t.edges[2 * e + 1] == v);
    }
  for (int32_t e = 0; e < ne; ++e)
    for (int32_t i = t.edge_tets_offsets[e]; i < t.edge_tets_offsets[e + 1]; ++i) {
      const int32_t* te = &t.tet_edges[6 * size_t(t.edge_tets[i])];
      ASSERT_TRUE(std::find(te, te + 6, e) != te + 6);
    }
  // S-faces: outward as the owner's face, unit normal pointing away from the owner's 4th vertex.
  for (int32_t s = 0; s < ns; ++s) {
    const int32_t tet = t.sface_tet[s], f = t.sface_local[s];
    for (int k = 0; k < 3; ++k) ASSERT_EQ(t.sfaces[3 * s + k], m.tets[4 * tet + geo::TC_TET_FACES[f][k]]);
    const double* n = &t.sface_normals[3 * s];
    EXPECT_NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1.0, 1e-12);
    const geo::tc_d3 nn{n[0], n[1], n[2]};
    const geo::tc_d3 away = topo_pt(m, t.sfaces[3 * s]) - topo_pt(m, m.tets[4 * tet + f]);
    ASSERT_GT(geo::dot(nn, away), 0.0) << "S-face " << s << " points into its tet";
  }
}

}  // namespace tc::test
