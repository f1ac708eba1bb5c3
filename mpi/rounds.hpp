// A phase of tetcollapse-mpi in rounds (see driver.hpp): partition, scatter, coarsen or improve
// with the interface frozen, gather, until nothing is left to do.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "coarsen.hpp"
#include "options.hpp"
#include "report.hpp"

namespace tc::mpi {

// Rank 0's state between rounds.
struct Round {
  Mesh& whole;  // the mesh of the round (moved out while the parts are away)
  // Per vertex: where the round is to work, which its cut avoids (empty: everywhere). After a
  // phase's first round, the vertices within o.rings tets of one the round before froze in its
  // band.
  std::vector<uint8_t> band;
  int number;  // rounds so far, over both phases
  // Under --max-field-error: the input and its bounded field, whose vertices every round
  // measures at (field_points.hpp); null otherwise.
  const Mesh* field_input = nullptr;
  std::string field_name;
};

// The rank's device context, opened when first needed: on rank 0 after the first cut, whose
// METIS work then does not add to the OpenCL runtime's memory in rank 0's peak (the other ranks
// open theirs while rank 0 cuts).
class LazyDevice {
 public:
  LazyDevice(std::string spec, bool talk) : spec_(std::move(spec)), talk_(talk) {}
  Context& get();

 private:
  std::string spec_;
  bool talk_;
  std::unique_ptr<Context> ctx_;
};

// Runs on every rank; returns the agreed exit code. Rank 0 appends each round to stats.rounds.
// Under settings.boundary_bound, state.whole carries the bound each vertex spent (kSpentField).
int run_phase(Phase phase, Round& state, const Settings& settings, const Options& options, LazyDevice& device,
              RunStats& stats, MPI_Comm comm);

}  // namespace tc::mpi
