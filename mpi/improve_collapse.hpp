// The improvement's collapse step for a part. tc::improve skips it under a vertex mask (the
// collapse renumbers the vertices, which the library's mask cannot follow); tetcollapse-mpi
// follows its vertices by a field (coarsen.cpp), so it runs the step itself, as
// host/improve/improve.cpp does: the short edges between vertices of tets below 13 degrees,
// through the sequential method's checks with the quality guard at 0.3, kept only when the
// smallest dihedral angle and the counts below 10 and 13 degrees get no worse. Without it a
// part keeps about 1% more tets than `tetcollapse` leaves (W1).
#pragma once

#include <cstdint>
#include <vector>

#include "tetcollapse/improve.hpp"

namespace tc::mpi {

// Collapses within `selected` (one byte per vertex); `length`: the longest edge to collapse, in
// mesh units (the library's default is 1.5 x the median edge length of the whole mesh). Returns
// how many edges collapsed (0: the mesh is as it was).
int64_t collapse_bad_tets(Mesh& mesh, const std::vector<uint8_t>& selected, const ImproveOptions& options,
                          double length);

}  // namespace tc::mpi
