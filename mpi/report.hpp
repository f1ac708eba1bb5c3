// What tetcollapse-mpi measures per round and per rank, its progress lines and its --stats JSON.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace tc::mpi {

// Peak resident memory of this process so far (VmHWM of /proc/self/status), in kB; 0 when
// the file is not there.
int64_t peak_rss_kb();

// One rank's figures in a round, gathered on rank 0 as plain doubles.
struct RankStats {
  double tets_in = 0, tets_out = 0, frozen = 0;
  double seconds = 0, seconds_collapse = 0, seconds_improve = 0;
  double peak_rss_kb = 0;
  double boundary_error = 0;  // the largest bound a vertex of the rank's part reached
  static constexpr int kCount = 8;
  void to(double* d) const;
  static RankStats from(const double* d);
};

struct RoundStats {
  int round = 0;
  std::string phase;  // "collapse" or "improve"
  int64_t tets_before = 0, tets_after = 0, vertices_after = 0;
  int64_t interface_vertices = 0;  // frozen in this round
  int64_t refrozen_vertices = 0;   // of them, in the band the round was to coarsen
  double seconds_partition = 0, seconds_scatter = 0, seconds_coarsen = 0, seconds_gather = 0;
  double boundary_bound = 0;  // the phase's boundary error bound (mesh units; 0: none)
  std::vector<RankStats> ranks;
};

struct RunStats {
  std::string input, output, device, boundary;
  int ranks = 1;
  int64_t vertices_in = 0, tets_in = 0, vertices_out = 0, tets_out = 0;
  double median_edge_length = 0, target_length = 0;
  double boundary_error_bound = 0;  // mesh units; 0: none
  double boundary_error = 0;        // the largest bound a vertex of the output reached
  // --max-field-error (a share of the range; 0: none), and the largest difference, as a share of
  // the range, between an input vertex's value and the output's field there
  double field_error_bound = 0, field_error = 0;
  double seconds_total = 0, seconds_read = 0, seconds_write = 0;
  std::string check;  // "valid" / "invalid" with --check
  std::vector<RoundStats> rounds;
  std::vector<int64_t> peak_rss_kb;  // per rank, over the whole run
};

std::string round_line(const RoundStats& r);
std::string rank_line(int rank, const RankStats& s);
std::string stats_json(const RunStats& s);

}  // namespace tc::mpi
