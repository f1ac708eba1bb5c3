// What the lazy filter, the greedy and the matching selections share (select_lazy.cpp).
#pragma once

#include <cstdint>
#include <initializer_list>

#include "collapse/connectivity.hpp"
#include "collapse/edge_state.hpp"
#include "collapse/params.hpp"
#include "collapse/upload.hpp"
#include "stopwatch.hpp"

namespace tc::collapse_detail {

void vertex_part(Context& ctx, EdgeState& s, const Connectivity& c, Kernel& recompute, Kernel& turns,
                 const DeviceBuffer<double>& order, int cur, cl_uint round, DeviceBuffer<double>* slotp = nullptr,
                 bool waiting = false);
void lazy_start(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                const DeviceBuffer<double>& order, std::initializer_list<Kernel*> tests, bool keep_refused = false);
const DeviceBuffer<double>& selection_priority(Context& ctx, Connectivity& c, EdgeState& s, const StageParams& p);
void selection_buffers(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s);

// The rounds of the greedy and matching selections (after lazy_start, selection_buffers and the
// first claims): the first turn list, then round after round until none is left, each either
// the per-round kernels (`round(nt, cur, round)`, which leave the next turn list's length in
// s.list_counts[1 - cur]) or, once a turn list holds at most p.greedy_loop_size edges, the loop in
// one work-group (`loop(nt, cur, round)`, which stops before a turn list longer than
// p.greedy_loop_exit and leaves where in s.loop_resume); then greedy_finish and the counts (passed_q
// and tested as lazy_admissible_pass1; returns the number taken).
template <class Round, class Loop>
uint32_t selection_rounds(Context& ctx, Connectivity& c, EdgeState& s, const StageParams& p, const char* name,
                          const Round& one_round, const Loop& loop, uint32_t& passed_q, uint32_t& tested) {
  const std::string A = "collapse_admissible.cl";
  run(ctx, A, "lazy_p1_first_turns", c.ne, arg("ne", c.ne), arg("cand", s.edges_are_candidates), arg("edges", c.edges), arg("slot", s.verts2slot[0]), arg("tlist", s.turn_lists[0]), arg("cnt", s.list_counts), arg("verdict", s.edges2verdict));
  uint32_t nt = 0;
  s.list_counts.download(&nt, 1);
  int cur = 0;  // the turn list of this round
  for (cl_uint round = 0; nt > 0; ++round) {
    const double t0 = Stopwatch::now();
    s.list_counts.fill(0);
    const bool one_group = nt <= p.greedy_loop_size;
    if (one_group) {
      s.loop_resume.fill(0);
      loop(nt, cur, round);
      uint32_t r[3];
      s.loop_resume.download(r, 3);
      nt = r[0];  // 0: every round done; else the loop stopped before a long turn list
      cur = int(r[1]);
      round = r[2] - 1;
    } else {
      one_round(nt, cur, round);
      s.list_counts.download(&nt, 1, size_t(1 - cur));
      cur = 1 - cur;
    }
    profile_line(ctx, name, nt, t0, one_group ? " (one work-group)" : "");
  }
  run(ctx, A, "greedy_finish", c.ne, arg("ne", c.ne), arg("state", s.edges2state), arg("p1", s.edges_pass1), arg("fin", s.edges_are_final), arg("counters", s.counters));
  uint32_t cnt[6];
  s.counters.download(cnt, 6);
  passed_q = cnt[5];
  tested = cnt[4];
  return cnt[3];
}

}  // namespace tc::collapse_detail
