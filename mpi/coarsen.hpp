// One rank's work in a round: coarsen or improve its part with the interface vertices frozen,
// and find the frozen vertices again in the library's output.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "part.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/improve.hpp"

namespace tc::mpi {

// What every rank runs with, in absolute units computed on rank 0 from the whole mesh.
struct Settings {
  CollapseOptions collapse;   // target_length and eps_v absolute (eps_v_relative false)
  ImproveOptions improve;     // max_boundary_move relative to the whole mesh's diagonal
  double whole_diagonal = 0;  // bounding-box diagonal of the whole input
  double collapse_length = 0;  // the improvement's collapse step: 1.5 x the coarse mesh's median
  // The phase's boundary error bound, in mesh units (0: no bound), as tc::coarsen shares it
  // (kCollapseShareOfBound of it for the collapse). Each vertex carries what it spent of it
  // (kSpentField) from round to round, so that every round goes on from there, as one run of
  // the library would (the frozen interface vertices keep theirs: nothing at them changes).
  double boundary_bound = 0;
  // The whole input's S as triangles, the reference every round's collapse measures the bound
  // against (CollapseOptions::boundary_reference); null: not measured.
  std::shared_ptr<const std::vector<double>> boundary_reference;
  // --region and --labels: only their vertices change (tetcollapse's masks, found on each part:
  // a vertex that is not frozen has its whole star in the part)
  std::string region, labels;
  // Under --max-field-error (collapse.max_field_error): the bounded field's range over the whole
  // input, per component; each part's round measures the bound at the input's vertices its tets
  // hold (Part::field_points).
  std::vector<double> field_range;
};

// Under a boundary error bound, the whole mesh's and each part's last vertex field between the
// rounds: per vertex, the bound it reached (CollapseReport::vertex_boundary_error); the driver
// adds it before the first round and drops it after the last.
constexpr const char* kSpentField = "tetcollapse-mpi:boundary-error";

struct RankReport {
  int64_t tets_in = 0, tets_out = 0, vertices_in = 0, vertices_out = 0, frozen = 0;
  double seconds_collapse = 0, seconds_improve = 0;
  double boundary_error = 0;  // the largest bound a vertex of the part reached
};

// What a round does to each part: the rounds of the collapse phase coarsen, then those of the
// improvement phase improve, as `tetcollapse` collapses everything before it improves (an
// improved mesh coarsens further when collapsed again, so interleaving them would coarsen more).
enum class Phase { Collapse, Improve };

// Coarsens (or improves) part.mesh in place. The frozen vertices keep their positions bit for bit and are
// found again by a vertex field carrying their global id; on return part.gid holds that id for
// them and -1 for every other vertex, part.frozen says which are which. Throws what the
// library throws, and std::runtime_error when a frozen vertex was lost (a library fault).
// ctx null: on the CPU (the sequential method, CollapseOptions::method).
RankReport coarsen_part(Part& part, Phase phase, const Settings& settings, Context* ctx);

}  // namespace tc::mpi
