// Under --max-field-error: the points where every round measures the field error bound, the
// input's vertices. Rank 0 locates them in each round's mesh and gives each part those its tets
// hold (the library's CollapseOptions::field_points), so a round checks the field against the
// input, not against the mesh the round before left, and the rounds keep the bound as one run of
// tetcollapse does.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "part.hpp"
#include "tetcollapse/mesh.hpp"

namespace tc::mpi {

// The range of vertex field `name` of the input, per component (the bound is a share of it).
// Throws std::invalid_argument when the input has no such field.
std::vector<double> field_range(const Mesh& input, const std::string& name);

// The input's vertices cut along the round's partition: each located in `whole` (a point in no
// tet: the nearest tet), and so given to the part of that tet, with the tet's index in the part
// (Splitter::extract keeps the tets' order).
class FieldPointCut {
 public:
  FieldPointCut(const Mesh& input, const std::string& name, const Mesh& whole, const std::vector<int32_t>& tet_part,
                int nparts);
  // Part p's points, their values and their tets, into part.
  void fill(int p, Part& part) const;

 private:
  const Mesh& input_;
  const Field& field_;  // the bounded field of the input
  std::vector<int32_t> part_of_, local_tet_;  // per input vertex (-1: no part, an unused vertex)
};

// The largest difference, as a share of `range` per component, between the input's value of
// field `name` at each of its vertices and `mesh`'s piecewise linear field there (what the bound
// bounds).
double measured_field_error(const Mesh& input, const std::string& name, const Mesh& mesh,
                            const std::vector<double>& range);

}  // namespace tc::mpi
