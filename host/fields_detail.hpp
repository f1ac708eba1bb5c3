// Point-in-tet geometry shared by the point location (fields.cpp) and the field error bound of
// the sequential method (collapse/field_bound.cpp), which locates points in tets that exist
// only as a collapse's candidate result.
#pragma once

#include <vector>

#include "geometry.h"
#include "tetcollapse/mesh.hpp"

namespace tc::fields_detail {

// Barycentric coordinates of p in the tet with corners c (signed volumes; a flat tet gives
// non-finite ones).
void barycentric(const geo::tc_d3 c[4], geo::tc_d3 p, double b[4]);
// The distance from p to the tet (0 inside) and the barycentric coordinates of the tet's point
// nearest to p.
double distance_to_tet(const geo::tc_d3 c[4], geo::tc_d3 p, double b[4]);

// The vertex fields `mesh` shares with `original` (name and component count), and the value of
// one at mesh vertex v from tet t of the original with coordinates b (resample_vertex_fields, on
// the host and on the device).
struct FieldPair {
  const Field* from;
  Field* to;
};
std::vector<FieldPair> shared_fields(const Mesh& original, Mesh& mesh);
void interpolate_at(const Mesh& original, const FieldPair& p, int64_t t, const double b[4], int64_t v);

}  // namespace tc::fields_detail
