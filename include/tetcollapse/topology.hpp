// Mesh connectivity and boundary classification (paper, Section 3.1).
//
// This is the plain single-threaded construction. It is the reference the collapse's device
// connectivity (host/collapse/connectivity.cpp, cl/collapse_connectivity.cl) is checked against,
// for the arrays that one keeps (tests/collapse/test_collapse_connectivity.cpp), and the CPU
// fallback. Every array's order is defined here:
//
//   edges        sort the 6 keys (v0 << 32 | v1), v0 < v1, of every tet; the distinct keys, in
//                ascending order, are the edges, so `edges` is sorted lexicographically.
//   faces        a triangle a < b < c is keyed (edge_id(a, b) << 32 | c): 64 bits identify it
//                whatever the vertex count, because the edge (a, b) and c determine the face.
//                Faces with one tet are boundary faces; faces with two tets of different
//                labels are material-interface faces. Both together form the "feature
//                surface" S and are listed in one array, in ascending face-key order.
//   CSR lists    every adjacency list is sorted ascending (vertex -> tets, vertex -> edges,
//                edge -> tets, vertex -> S-faces, edge -> S-faces).
//
// Material interfaces. With labels (the mesh's first label array, unless
// TopologyOptions::use_labels is false), a face between two tets of different labels is an
// internal boundary. It is listed ONCE, flagged in `sface_interface`, owned by the tet of the
// smaller label (ties impossible: labels differ) and oriented outward from that tet, i.e. its
// normal points from the smaller label into the larger one. With this rule an interface sheet
// between the same two materials is consistently oriented, like the outer boundary.
//
// Classification (vertex_class, edge_ridge). Let S be the feature surface above and n_i the
// unit normals of its triangles.
//   Ridge edge: an edge of S is a ridge (feature) edge when
//     (a) it has a number of S-triangles other than two (a non-manifold edge: where an
//         interface meets the outer boundary or another interface, or where two parts of the
//         boundary touch along an edge), or
//     (b) it has exactly two S-triangles that do not traverse it in opposite directions (they
//         are not consistently oriented), or
//     (c) it has exactly two consistently oriented S-triangles with 1 - dot(n_1, n_2) > eps_R.
//   Vertex classes, for a vertex v on S with r ridge edges among its edges:
//     Face:   r == 0, the S-triangles at v form a single closed fan (one disk around v), and
//             1 - dot(n_i, n_j) <= eps_F for every pair of S-triangles at v.
//     Ridge:  r == 2 (the paper: "only two adjacent edges are included by boundary triangles
//             with normals differing by more than eps_R").
//     Corner: every other vertex of S. In particular a smoothly but strongly curved vertex
//             (no ridge edge, yet two normals differing by more than eps_F), a vertex where
//             three or more ridges meet, a ridge that ends (r == 1), and a vertex where S is
//             pinched (several fans meeting only at v, r == 0).
//   Interior: vertices not on S.
// The paper uses eps_F = 0.01 and eps_R = 0.1 throughout; so do the defaults here.
#pragma once

#include <cstdint>
#include <vector>

#include "tetcollapse/mesh.hpp"

namespace tc {

enum class VertexClass : uint8_t { Interior = 0, Face = 1, Ridge = 2, Corner = 3 };
const char* vertex_class_name(VertexClass c);

// Bits of vertex_boundary / edge_boundary.
enum : uint8_t {
  kOnBoundary = 1,   // on a face with a single tet (the outer boundary)
  kOnInterface = 2,  // on a material-interface face
};

struct TopologyOptions {
  double eps_f = 0.01;     // face threshold on 1 - dot(n_i, n_j)
  double eps_r = 0.1;      // ridge threshold on 1 - dot(n_1, n_2) across an edge
  bool use_labels = true;  // material interfaces from the first label array, when present
};

struct Topology {
  int32_t num_vertices = 0;
  int32_t num_tets = 0;

  std::vector<int32_t> edges;      // 2 per edge: v0 < v1, sorted lexicographically
  std::vector<int32_t> tet_edges;  // 6 per tet, in TC_TET_EDGES order

  // CSR adjacency: the list of entity i is indices[offsets[i] .. offsets[i+1]), ascending.
  std::vector<int32_t> vertex_tets_offsets, vertex_tets;    // num_vertices + 1
  std::vector<int32_t> vertex_edges_offsets, vertex_edges;  // num_vertices + 1
  std::vector<int32_t> edge_tets_offsets, edge_tets;        // num_edges + 1

  // The feature surface S: outer boundary faces and interface faces, ascending face key.
  std::vector<int32_t> sfaces;           // 3 per face, oriented outward (TC_TET_FACES of the owner)
  std::vector<int32_t> sface_tet;        // owning tet
  std::vector<int8_t> sface_local;       // local face index in the owner (face i is opposite vertex i)
  std::vector<uint8_t> sface_interface;  // 1 for a material-interface face, 0 for a boundary face
  std::vector<double> sface_normals;     // 3 per face, unit length (zero for a degenerate face)
  std::vector<int32_t> vertex_sfaces_offsets, vertex_sfaces;  // num_vertices + 1
  std::vector<int32_t> edge_sfaces_offsets, edge_sfaces;      // num_edges + 1

  std::vector<uint8_t> vertex_boundary;  // kOnBoundary | kOnInterface bits, per vertex
  std::vector<uint8_t> edge_boundary;    // the same bits, per edge (edge of an S-face)
  std::vector<uint8_t> vertex_class;     // VertexClass per vertex
  std::vector<uint8_t> edge_ridge;       // 1 for a ridge (feature) edge

  int32_t num_edges() const { return static_cast<int32_t>(edges.size() / 2); }
  int32_t num_sfaces() const { return static_cast<int32_t>(sface_tet.size()); }
};

// Wall time of each construction stage in seconds.
struct TopologyTimings {
  double check = 0, edges = 0, vertex_lists = 0, faces = 0, sface_lists = 0, flags = 0, classify = 0;
  double total() const { return check + edges + vertex_lists + faces + sface_lists + flags + classify; }
};

// Builds everything above. Throws tc::InputError (file "<mesh>") when a tet has an index out
// of range or a repeated vertex, or when the mesh is too large for 32-bit indices.
Topology build_topology(const Mesh& mesh, const TopologyOptions& options = {}, TopologyTimings* timings = nullptr);

// What `tetcollapse info` prints about a mesh.
struct TopologySummary {
  int64_t vertices = 0, tets = 0, edges = 0;
  int64_t boundary_faces = 0, interface_faces = 0;
  int64_t boundary_vertices = 0, boundary_edges = 0;  // on S (outer boundary or interface)
  double edge_length_min = 0, edge_length_median = 0, edge_length_max = 0;
  double total_volume = 0;
  double min_dihedral_deg = 0, max_dihedral_deg = 0;
  int64_t interior_vertices = 0, face_vertices = 0, ridge_vertices = 0, corner_vertices = 0;
  int64_t ridge_edges = 0;
};
TopologySummary summarize(const Mesh& mesh, const Topology& topo);

}  // namespace tc
