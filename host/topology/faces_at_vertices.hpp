// Every face of a mesh once, at its smallest vertex, from a vertex -> tets list instead of a
// table of all faces (16 bytes per face to sort, 33 MB on W1): the MPI tool's dual graph and the
// reference surface of the boundary error bound (tc::feature_surface_triangles), which rank 0
// builds on top of the whole input. The same list gives tc::median_edge_length its edges.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "tetcollapse/mesh.hpp"

namespace tc::topology_detail {

// The tets at each vertex, by ascending tet: around[offset[v] .. offset[v + 1]) (a counting sort
// of the corners; a corner whose index is out of range is left out).
struct VertexTets {
  std::vector<int64_t> offset;
  std::vector<int32_t> around;
  explicit VertexTets(const Mesh& mesh) {
    const int64_t nv = mesh.num_vertices(), nt = mesh.num_tets();
    const auto valid = [nv](int32_t v) { return v >= 0 && v < nv; };
    offset.assign(size_t(nv + 1), 0);
    for (int32_t v : mesh.tets)
      if (valid(v)) ++offset[size_t(v) + 1];
    for (int64_t v = 0; v < nv; ++v) offset[size_t(v + 1)] += offset[size_t(v)];
    around.resize(static_cast<size_t>(offset[size_t(nv)]));
    std::vector<int64_t> fill(offset.begin(), offset.end() - 1);
    for (int64_t t = 0; t < nt; ++t)
      for (int k = 0; k < 4; ++k)
        if (const int32_t v = mesh.tets[size_t(4 * t + k)]; valid(v)) around[size_t(fill[size_t(v)]++)] = int32_t(t);
  }
};

struct FaceSide {
  int32_t a, b, tet;  // the face's two vertices other than the smallest (a < b), and a tet that has it
};

// fn(v, sides, n) for every face (v, a, b), v < a < b, with the n >= 1 tets that have it in
// sides[0..n), by ascending tet; the faces in ascending (v, a, b). (On a randomly numbered
// mesh, looking each face up around one of its vertices reads 20 times as many tets, out of
// cache.)
template <class Fn>
void each_face_at_smallest_vertex(const Mesh& mesh, Fn&& fn) {
  const int64_t nv = mesh.num_vertices();
  const VertexTets vt(mesh);
  const std::vector<int64_t>& offset = vt.offset;
  const std::vector<int32_t>& around = vt.around;
  std::vector<FaceSide> sides;
  for (int64_t v = 0; v < nv; ++v) {
    sides.clear();
    for (int64_t i = offset[size_t(v)]; i < offset[size_t(v) + 1]; ++i) {
      const int32_t t = around[size_t(i)];
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
    std::sort(sides.begin(), sides.end(), [](const FaceSide& p, const FaceSide& q) {
      return p.a < q.a || (p.a == q.a && (p.b < q.b || (p.b == q.b && p.tet < q.tet)));
    });
    for (size_t i = 0, j; i < sides.size(); i = j) {
      for (j = i + 1; j < sides.size() && sides[j].a == sides[i].a && sides[j].b == sides[i].b; ++j) {
      }
      fn(int32_t(v), &sides[i], j - i);
    }
  }
}

}  // namespace tc::topology_detail
