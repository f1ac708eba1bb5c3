// The mesh model shared by every part of tetcollapse.
//
// Plain arrays, in the style of libigl: positions as 3 doubles per vertex, tetrahedra as
// 4 x int32 per tet (zero-based, positively oriented after normalisation), plus optional
// attributes that are carried through read -> process -> write.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace tc {

// A per-vertex or per-tet field of `components` doubles per entity (1 = scalar,
// 3 = vector, 6 = symmetric tensor in Medit order, 9 = full tensor).
struct Field {
  std::string name;
  int components = 1;
  std::vector<double> values;  // size = entities * components
};

// A per-tet integer attribute: material, subdomain, Gmsh physical or elementary tag,
// Medit reference. The first label array of a mesh is its primary label.
struct Labels {
  std::string name;
  std::vector<int32_t> values;  // size = tets
};

struct Mesh {
  std::vector<double> points;   // 3 per vertex
  std::vector<int32_t> tets;    // 4 per tet, zero-based vertex indices

  std::vector<Labels> tet_labels;     // each of size num_tets()
  std::vector<Field> vertex_fields;   // each of size num_vertices() * components
  std::vector<Field> tet_fields;      // each of size num_tets() * components

  // Tagged boundary (or interface) triangles as given by the input file, zero-based.
  std::vector<int32_t> tris;          // 3 per triangle
  std::vector<int32_t> tri_tags;      // one per triangle (0 when the file has none)

  // Tagged feature edges as given by the input file (Gmsh lines, Medit Edges/Ridges).
  std::vector<int32_t> edges;         // 2 per edge
  std::vector<int32_t> edge_tags;     // one per edge

  int64_t num_vertices() const { return static_cast<int64_t>(points.size() / 3); }
  int64_t num_tets() const { return static_cast<int64_t>(tets.size() / 4); }
  int64_t num_tris() const { return static_cast<int64_t>(tris.size() / 3); }

  std::array<double, 3> point(int64_t v) const {
    return {points[3 * v], points[3 * v + 1], points[3 * v + 2]};
  }
  const Labels* find_labels(const std::string& name) const;
  const Field* find_vertex_field(const std::string& name) const;
};

// What the readers noticed and did not treat as an error (skipped element types,
// quadratic tets reduced to their corners, ...). Printed as notes by the CLI.
struct ReadNotes {
  std::vector<std::string> notes;
  int64_t skipped_elements = 0;        // non-tetrahedral volume/other elements dropped
  int64_t reduced_quadratic_tets = 0;  // tet10 etc. kept as their 4 corners
};

// Orientation of the input tets, decided with exact arithmetic on the signs.
struct OrientationReport {
  int64_t positive = 0;
  int64_t negative = 0;
  int64_t degenerate = 0;  // exactly zero volume
  bool flipped_all = false;  // the whole mesh was negatively oriented and got flipped
  int64_t flipped = 0;       // tets flipped one by one (fix policy)
};

enum class OrientationPolicy {
  Refuse,  // mixed orientation is an error (consistently negative is still flipped)
  Fix,     // flip each negative tet; degenerate tets are left as they are and reported
  Keep,    // leave a mixed orientation as it is (reported; the checker's reading)
};

// The length of the diagonal of the mesh's bounding box (0 without vertices): what relative
// distances (ImproveOptions::max_boundary_move, ...) are shares of.
double bbox_diagonal(const Mesh& mesh);

// The mean of the tets' unsigned volumes, the tets that `skip` marks (non-zero) left out (0
// without tets): what the volume thresholds (CollapseOptions::eps_v, CheckOptions::eps_volume)
// are shares of by default.
double mean_tet_volume(const Mesh& mesh, const std::vector<uint8_t>* skip = nullptr);

// Bring the mesh to positive orientation. A consistently negative mesh is flipped
// (swap of the last two vertices of each tet). Mixed orientation: with Refuse, throws
// tc::InputError naming the counts; with Fix, flips the negative tets.
OrientationReport normalize_orientation(Mesh& mesh, OrientationPolicy policy);

// The unit cube [0,1]^3 cut into n^3 cells of 6 positively oriented Kuhn tets: a mesh with
// a known answer for tests, benchmarks and examples ((n+1)^3 vertices, 6 n^3 tets).
Mesh make_cube_mesh(int n);

// Basic structural validation used by every reader before returning a mesh:
// indices in range, finite coordinates, field/label sizes consistent.
// Throws tc::InputError with `source` as the file name.
void validate_structure(const Mesh& mesh, const std::string& source);
// Its part that the checker's reading keeps (ReadOptions::as_is): the arrays' sizes, labels and
// fields against the counts, triangles and edges against the vertices; not the coordinates'
// finiteness nor the tets' indices.
void validate_arrays(const Mesh& mesh, const std::string& source);
// Whether every coordinate is finite and every tet refers to an existing vertex.
bool geometry_is_sound(const Mesh& mesh);

}  // namespace tc
