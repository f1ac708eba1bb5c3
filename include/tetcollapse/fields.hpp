// Vertex fields from the original mesh (the paper's Section 4.5: a new vertex takes the value
// of the original piecewise linear field at its position, not an average of two end points).
//
//   tc::Mesh original = mesh;               // before coarsening
//   tc::collapse(mesh, options, device);
//   tc::resample_vertex_fields(original, mesh);
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tetcollapse/mesh.hpp"

namespace tc {

// Point location in a tet mesh: a uniform grid of cells about the size of a tet, each listing
// the tets whose bounding box meets it. Why not a library: the grid is the simplest structure
// that answers in about constant time for meshes whose tets vary in size by a few orders of
// magnitude, and it needs no dependency in the core library (CGAL's AABB tree lives in the
// checker).
class TetLocator {
 public:
  explicit TetLocator(const Mesh& mesh);

  // The tet holding p (every barycentric coordinate >= -1e-12), else the tet nearest to p;
  // bary receives p's barycentric coordinates in it (for a point outside the mesh, those of
  // the nearest point of the tet: all >= 0). -1 for a mesh without tets. *outside (when given):
  // whether p lies in no tet.
  int64_t locate(const double p[3], double bary[4], bool* outside = nullptr) const;

 private:
  const Mesh& mesh_;
  double lo_[3] = {0, 0, 0}, cell_ = 1;
  int64_t dim_[3] = {1, 1, 1};
  std::vector<int64_t> offsets_;  // per cell, into tets_
  std::vector<int64_t> tets_;
  int64_t cell_index(int64_t i, int64_t j, int64_t k) const { return (k * dim_[1] + j) * dim_[0] + i; }
};

// Sets every vertex field of `mesh` that `original` has (by name and component count) to the
// original's piecewise linear field at the vertex; a vertex outside the original takes the
// value at the nearest point of the nearest tet. Returns how many vertices lay outside.
int64_t resample_vertex_fields(const Mesh& original, Mesh& mesh);

// How far a mesh's piecewise linear vertex field is from the reference's, per field both have
// (first component), measured at every reference vertex and at `random_points` points drawn
// uniformly in the reference's volume (fixed seed): the largest and the root-mean-square
// difference, and both as a share of the reference field's range; and the largest difference at
// the reference's vertices alone (what CollapseOptions::max_field_error bounds).
struct FieldError {
  std::string name;
  double range = 0;
  double max_abs = 0, rms_abs = 0;
  double max_rel = 0, rms_rel = 0;
  double max_vertex_abs = 0, max_vertex_rel = 0;
  int64_t samples = 0;
};
std::vector<FieldError> field_errors(const Mesh& reference, const Mesh& mesh, int64_t random_points = 100000);

}  // namespace tc
