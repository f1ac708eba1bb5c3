#include "rounds.hpp"

#include <algorithm>
#include <cstdio>
#include <malloc.h>
#include <optional>

#include "agree.hpp"
#include "exchange.hpp"
#include "field_points.hpp"
#include "partition.hpp"
#include "stopwatch.hpp"

namespace tc::mpi {

Context& LazyDevice::get() {
  if (!ctx_) ctx_ = cli::open_device(spec_, !talk_);
  return *ctx_;
}

namespace {

// One round: partition (the cut avoiding the band), scatter, coarsen or improve, gather. Returns
// the agreed exit code; on rank 0 fills `rs` and the next round's band.
int run_round(Phase phase, Round& st, const Settings& s, const Options& o, LazyDevice& device, RoundStats& rs,
              MPI_Comm comm) {
  int rank = 0, nranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &nranks);
  Stopwatch clock;
  std::vector<int32_t> tet_part;
  int code = guarded(rank, [&] {
    if (rank != 0) return;
    PartitionOptions po;
    po.nparts = nranks, po.seed = o.seed + st.number - 1, po.avoid_weight = o.avoid_weight;
    po.max_graph_nodes = o.partition_nodes;
    tet_part = partition_tets(st.whole, po, st.band);
  });
  if ((code = agree(code, comm))) return code;
  rs.seconds_partition = clock.lap();

  // Scatter: rank 0 cuts out and sends one part at a time, then drops the whole mesh.
  Part mine;
  int64_t whole_vertices = 0;
  if (rank == 0) {
    rs.tets_before = st.whole.num_tets();
    whole_vertices = st.whole.num_vertices();
    Splitter split(st.whole, tet_part, nranks);
    std::optional<FieldPointCut> points;
    if (st.field_input) points.emplace(*st.field_input, st.field_name, st.whole, tet_part, nranks);
    auto extract = [&](int p) {
      Part part = split.extract(p, st.band);
      if (points) points->fill(p, part);
      return part;
    };
    rs.interface_vertices = split.interface_vertices();
    for (size_t v = 0; v < st.band.size(); ++v) rs.refrozen_vertices += st.band[v] && split.shared()[v];
    if (!o.quiet && st.number == 1 && (split.dropped_tris() || split.dropped_edges()))
      std::fprintf(stderr, "note: %lld tagged triangles and %lld edges are not faces or edges of a tet: dropped\n",
                   (long long)split.dropped_tris(), (long long)split.dropped_edges());
    for (int p = 1; p < nranks; ++p) send_part(extract(p), p, comm);
    mine = extract(0);
    st.whole = Mesh();
  } else {
    mine = recv_part(0, comm);
  }
  tet_part = {};
  // The whole mesh, the cut and METIS's work are gone: give their pages back before the part
  // is coarsened (glibc keeps freed heap memory, and raises its mmap threshold after the reader's
  // large buffers are freed, so they would count in rank 0's peak twice).
  malloc_trim(0);
  rs.seconds_scatter = clock.lap();

  // Every rank works on its part.
  RankReport rr;
  Stopwatch own;
  code = guarded(rank, [&] {
    rr = coarsen_part(mine, phase, s, s.collapse.method == CollapseOptions::Sequential ? nullptr : &device.get());
  });
  const RankStats mine_stats{double(rr.tets_in),   double(rr.tets_out),     double(rr.frozen),
                             own.lap(),             rr.seconds_collapse,     rr.seconds_improve,
                             double(peak_rss_kb()), rr.boundary_error};
  if ((code = agree(code, comm))) return code;
  rs.seconds_coarsen = clock.lap();

  // Gather: rank 0 merges the parts in rank order; the next band is around what stayed frozen.
  std::vector<double> all(static_cast<size_t>(RankStats::kCount * nranks));
  double one[RankStats::kCount];
  mine_stats.to(one);
  MPI_Gather(one, RankStats::kCount, MPI_DOUBLE, all.data(), RankStats::kCount, MPI_DOUBLE, 0, comm);
  if (rank == 0) {
    code = guarded(rank, [&] {
      Merger merge(whole_vertices, st.band);
      merge.add(std::move(mine));
      for (int p = 1; p < nranks; ++p) merge.add(recv_part(p, comm));
      st.whole = merge.finish();
      st.band = grow(st.whole, merge.was_frozen(), o.rings);
    });
    rs.tets_after = st.whole.num_tets(), rs.vertices_after = st.whole.num_vertices();
    for (int p = 0; p < nranks; ++p) rs.ranks.push_back(RankStats::from(&all[size_t(RankStats::kCount * p)]));
  } else {
    send_part(mine, 0, comm);
  }
  if ((code = agree(code, comm))) return code;
  rs.seconds_gather = clock.lap();
  return cli::kOk;
}

}  // namespace

// The rounds of one phase: the first works everywhere but on the interface, each after it on the
// band around what the one before left frozen, until a round has nothing of its band frozen (or,
// collapsing, removed fewer than o.round_threshold of its tets), or after o.max_rounds (two
// when improving).
int run_phase(Phase phase, Round& st, const Settings& s, const Options& o, LazyDevice& device, RunStats& stats,
              MPI_Comm comm) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  st.band.clear();
  for (int round = 1;; ++round) {
    RoundStats rs;
    rs.round = ++st.number;
    rs.phase = phase == Phase::Collapse ? "collapse" : "improve";
    rs.boundary_bound = s.boundary_bound;
    if (int code = run_round(phase, st, s, o, device, rs, comm)) return code;
    double go = 0;
    if (rank == 0) {
      const double removed = rs.tets_before ? double(rs.tets_before - rs.tets_after) / double(rs.tets_before) : 0;
      const bool pending = round == 1 ? rs.interface_vertices > 0 : rs.refrozen_vertices > 0;
      // (Improving the band again rarely changes more than a few tets: two improvement rounds.)
      const int max_rounds = phase == Phase::Improve ? std::min(2, o.max_rounds) : o.max_rounds;
      go = pending && round < max_rounds && (phase == Phase::Improve || removed >= o.round_threshold);
      if (!o.quiet) {
        std::fprintf(stderr, "%s\n", round_line(rs).c_str());
        for (size_t p = 0; p < rs.ranks.size(); ++p) std::fprintf(stderr, "%s\n", rank_line(int(p), rs.ranks[p]).c_str());
      }
      stats.rounds.push_back(std::move(rs));
    }
    MPI_Bcast(&go, 1, MPI_DOUBLE, 0, comm);
    if (go == 0) return cli::kOk;
  }
}

}  // namespace tc::mpi
