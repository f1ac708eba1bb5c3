// The rounds of tetcollapse-mpi (ParMmg / PaMPA style):
//
//   rank 0 reads IN; target length, volume threshold and boundary move from the whole mesh
//   collapse phase, in rounds:
//     rank 0 cuts the mesh with METIS (faces near the band still to do weigh more) and scatters
//     every rank coarsens its part, the vertices in tets of other parts frozen (vertex mask)
//     rank 0 gathers (frozen vertices merged by global id), the band = within --rings tets of
//       the vertices the round froze where it was to work
//     until nothing of the band was frozen, a round removed < --round-threshold, or --rounds
//   improvement phase, the same rounds with tc::improve (at most two: everywhere, the band)
//   rank 0 resamples the vertex fields from the input, checks (--check) and writes OUT
//
// The phases follow `tetcollapse`, which collapses everything before it improves: a mesh
// improved and then collapsed again coarsens further than one run does.
#pragma once

#include <mpi.h>

#include "options.hpp"

namespace tc::mpi {

// Runs on every rank; returns the exit code (the same on every rank: errors are agreed on).
int run(Options& options, MPI_Comm comm);

}  // namespace tc::mpi
