// Point-in-tet geometry shared by the point location (fields.cpp) and the field error bound of
// the sequential method (collapse/field_bound.cpp), which locates points in tets that exist
// only as a collapse's candidate result.
#pragma once

#include "geometry.h"

namespace tc::fields_detail {

// Barycentric coordinates of p in the tet with corners c (signed volumes; a flat tet gives
// non-finite ones).
void barycentric(const geo::tc_d3 c[4], geo::tc_d3 p, double b[4]);
// The distance from p to the tet (0 inside) and the barycentric coordinates of the tet's point
// nearest to p.
double distance_to_tet(const geo::tc_d3 c[4], geo::tc_d3 p, double b[4]);

}  // namespace tc::fields_detail
