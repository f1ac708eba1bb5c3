// The field error bound of the sequential method (CollapseOptions::max_field_error), after
// Cignoni et al. 2000 ("Simplification of tetrahedral meshes with accurate error evaluation"):
// every input vertex is carried by the current tet that holds it (or, for a run that goes on from
// an earlier one, every point CollapseOptions::field_points gives); a collapse locates the
// carried vertices of the tets it changes in the tets it makes and is admissible only if the
// bounded field, interpolated there, stays within the bound of each vertex's input value, and
// no carried vertex falls outside the tets it makes. The error is measured, not estimated, so
// the bound holds at every input vertex of the result.
#pragma once

#include <cstdint>
#include <vector>

#include "collapse/sequential_mesh.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/fields.hpp"
#include "tetcollapse/mesh.hpp"

namespace tc::sequential_detail {

class FieldBound {
 public:
  // `mesh` is the input, about to be coarsened through `sm`; it is copied (the bound compares
  // with it). Throws std::invalid_argument for a missing field or a bad bound.
  FieldBound(const Mesh& mesh, const CollapseOptions& options, const SeqMesh& sm);

  // Whether the collapse keeps every carried vertex of the tets it changes within the bound.
  // When it does, apply() right after sm.collapse() with the same edge records it.
  bool admits(SeqMesh& sm, const Mesh& mesh, int32_t a, int32_t b, uint8_t dir);
  // The survivor's vertex fields from the input at its place; the carried vertices into the
  // tets admits() found for them.
  void apply(Mesh& mesh, int32_t survivor);
  // After SeqMesh::compact: tmap[t] is the new index of tet slot t (-1: removed).
  void compact(const std::vector<int32_t>& tmap);

  double bound() const { return share_; }
  // The largest error over the carried vertices now, as a share of the range (over components).
  double max_error(const SeqMesh& sm, const Mesh& mesh) const;

 private:
  double value_error(double value, int32_t point, int c) const;
  // Component c of the input's field f at the survivor's place (admits() located it).
  double at_survivor(const Field& f, size_t c) const;

  Mesh input_;  // points, tets and vertex fields of the input
  // The points where the bound is measured and their values of the bounded field: input_'s
  // vertices, or CollapseOptions::field_points (owned_points_, owned_values_).
  std::vector<double> owned_points_, owned_values_;
  const double* points_at_ = nullptr;
  const double* values_at_ = nullptr;
  TetLocator locator_;
  size_t in_field_ = 0, mesh_field_ = 0;  // the bounded field's index in input_ and in the mesh
  int nc_ = 1;
  double share_ = 0;
  std::vector<double> range_, tol_;  // per component
  std::vector<int32_t> head_;  // per tet slot: its first carried point (-1: none)
  std::vector<int32_t> next_;  // per point: the next one its tet carries
  // scratch of the last admits()
  std::vector<int32_t> region_, after_, points_, assign_;
  std::vector<double> survivor_values_;  // the bounded field at the survivor's place
  int32_t survivor_ = -1;
  int64_t survivor_tet_ = -1;  // the input tet holding the survivor's place, its coordinates
  double survivor_bary_[4] = {0, 0, 0, 0};
};

}  // namespace tc::sequential_detail
