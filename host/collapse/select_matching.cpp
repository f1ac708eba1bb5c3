// The matching selection and its undo (cl/collapse_matching.cl).
#include "collapse/select_matching.hpp"

#include <algorithm>
#include <memory>
#include <numeric>

#include "collapse/edge_state.hpp"
#include "collapse/guard_surface.hpp"
#include "collapse/select_lazy.hpp"
#include "collapse/selection.hpp"
#include "device/primitives.hpp"

namespace tc::collapse_detail {

uint32_t matching_selection(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, MatchingState& m,
                            const StageParams& p, uint32_t& passed_q, uint32_t& tested) {
  const std::string A = "collapse_admissible.cl", M = "collapse_matching.cl";
  Kernel decide = stage_kernel(ctx, p, M, "match_decide"), apply = stage_kernel(ctx, p, M, "match_apply"),
             loop = stage_kernel(ctx, p, M, "match_loop");
  // the priority first: lazy_init claims the first slots in its order
  const DeviceBuffer<double>& prio = selection_priority(ctx, c, s, p);
  // the test's arguments (TCC_MATCH_PARAMS): the lazy filter's, then the live test's
  lazy_start(ctx, dm, c, s, p, prio, {&decide, &apply, &loop}, true);
  s.result.in_place = true;
  ensure(s.result.tets_are_dead, ctx, std::max<size_t>(dm.nt, 1));
  ensure(m.tets2killer, ctx, std::max<size_t>(dm.nt, 1));
  ensure(m.edges2round, ctx, c.ne);
  s.result.tets_are_dead.fill(0);
  for (Kernel* k : {&decide, &apply, &loop})
    k->set(arg("eps_r", p.eps_r), arg("eps_f", p.eps_f), arg("tets_are_dead", s.result.tets_are_dead));
  selection_buffers(ctx, dm, c, s);
  ensure(m.edges_early_tested, ctx, c.ne);
  m.edges_early_tested.fill(p.match_early_tests ? 0 : 1);  // 1: the early test counts as done
  ensure(m.verts2slot_priority, ctx, dm.nv);
  run(ctx, A, "slot_priority", dm.nv, arg("nv", dm.nv), arg("verts2slot", s.lazy.verts2slot[0]), arg("edges2priority", prio), arg("verts2slot_priority", m.verts2slot_priority));
  const cl_int W = p.waiting_lists ? 1 : 0;
  Kernel recompute = kernel(ctx, A, "lazy_p1_recompute"), turns = kernel(ctx, A, "lazy_p1_turns");
  auto one_round = [&](uint32_t nt, int cur, cl_uint round) {
    decide.set(arg("n", nt), arg("cur", cl_uint(cur)), arg("tlist", s.lazy.turn_lists[cur]), arg("tnext", s.lazy.turn_lists[1 - cur]), arg("cnt", s.lazy.list_counts), arg("edges", c.edges), arg("edges2priority", prio), arg("verts2slot", s.lazy.verts2slot[0]), arg("verts2slot_priority", m.verts2slot_priority), arg("edges2blocker", s.lazy.edges2blocker), arg("edges_early_tested", m.edges_early_tested), arg("edges2round", m.edges2round), arg("edges2queued", s.lazy.edges2queued), arg("round", round), arg("inlist", s.lazy.round_taken), arg("verts2listed", s.lazy.verts2listed), arg("dlist", s.lazy.vertex_list), arg("edges2state", s.result.edges2state), arg("verts2collapse", s.result.verts2collapse), arg("waiting", W), arg("verts2waiting", s.lazy.verts2waiting), arg("edges2next_waiting", s.lazy.edges2next_waiting));
    decide.launch(ctx, nt);
    apply.set(arg("inlist", s.lazy.round_taken), arg("cnt", s.lazy.list_counts), arg("edges", c.edges), arg("verts2slot", s.lazy.verts2slot[0]), arg("verts2listed", s.lazy.verts2listed), arg("round", round), arg("dlist", s.lazy.vertex_list), arg("edges2state", s.result.edges2state), arg("verts2collapse", s.result.verts2collapse), arg("tets2killer", m.tets2killer));
    apply.launch(ctx, nt);  // over the round's taken edges (cnt[4] <= nt)
    vertex_part(ctx, s, c, recompute, turns, prio, cur, round, &m.verts2slot_priority, p.waiting_lists);
  };
  auto in_one_group = [&](uint32_t nt, int cur, cl_uint round) {
    loop.set(arg("n", nt), arg("cur", cl_int(cur)), arg("round", round), arg("t0", s.lazy.turn_lists[0]), arg("t1", s.lazy.turn_lists[1]), arg("cnt", s.lazy.list_counts), arg("edges", c.edges), arg("edges2priority", prio), arg("verts2slot", s.lazy.verts2slot[0]), arg("verts2slot_priority", m.verts2slot_priority), arg("edges2blocker", s.lazy.edges2blocker), arg("edges_early_tested", m.edges_early_tested), arg("edges2round", m.edges2round), arg("edges2queued", s.lazy.edges2queued), arg("inlist", s.lazy.round_taken), arg("verts2listed", s.lazy.verts2listed), arg("dlist", s.lazy.vertex_list), arg("edges2state", s.result.edges2state), arg("verts2collapse", s.result.verts2collapse), arg("tets2killer", m.tets2killer), arg("max_n", p.greedy_loop_exit), arg("resume", s.lazy.loop_resume), arg("waiting", W), arg("verts2waiting", s.lazy.verts2waiting), arg("edges2next_waiting", s.lazy.edges2next_waiting));
    loop.launch_one_group(ctx);
  };
  return selection_rounds(ctx, c, s, p, "match_round", one_round, in_one_group, passed_q, tested);
}

void matching_backup(Context& ctx, DeviceMesh& dm, MatchingState& m) {
  if (!m.points_before.buffer()()) {
    m.points_before = DeviceBuffer<double>(ctx, 1);
    m.vfields_before = DeviceBuffer<double>(ctx, 1);
  }
  m.points_before.copy_from(dm.points, size_t(dm.nv) * 3);
  m.vfields_before.copy_from(dm.vfields, size_t(dm.nv) * dm.vfield_comps);
}

uint32_t matching_undo(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, MatchingState& m,
                       SurfaceGuard& guard) {
  ensure(m.edges_are_refused, ctx, c.ne);
  ensure(s.lazy.list_counts, ctx, 5);
  m.edges_are_refused.fill(0);
  s.lazy.list_counts.fill(0);
  guard.refused_edges(ctx, m.edges_are_refused, s.lazy.turn_lists[0], s.lazy.list_counts);
  uint32_t n = 0;
  s.lazy.list_counts.download(&n, 1);
  std::vector<uint32_t> undone;
  const uint32_t count = matching_undo(ctx, dm, c, s, m, s.lazy.turn_lists[0].download_range(0, n), &undone);
  guard.restrict_to_undone(ctx, dm, c, s, undone);  // the next guard run: only where the undo changed S
  return count;
}

uint32_t matching_undo(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, MatchingState& m,
                       const std::vector<uint32_t>& refused, std::vector<uint32_t>* undone) {
  const std::string M = "collapse_matching.cl";
  ensure(m.edges_are_refused, ctx, c.ne);
  ensure(m.edges_to_undo, ctx, c.ne);
  ensure(m.verts2first_round, ctx, dm.nv);
  ensure(s.lazy.list_counts, ctx, 5);
  m.verts2first_round.fill(0xffffffffu);
  // the refused flagged, and listed in s.lazy.turn_lists[0] (the undone: the refused first, then
  // each growth)
  std::vector<uint8_t> flags(c.ne, 0);
  for (uint32_t e : refused) flags[e] = 1;
  m.edges_are_refused.upload(flags);
  m.edges_to_undo.upload(flags);
  uint32_t n = uint32_t(refused.size());
  s.lazy.turn_lists[0].upload(refused.data(), n);
  s.lazy.list_counts.upload(&n, 1);
  // the taken edges
  ensure(s.lazy.candidate_list, ctx, c.ne);
  const uint32_t taken = dev::compact_indices(ctx, s.result.edges_are_final, s.lazy.candidate_list, c.ne);
  uint32_t done = 0;  // entries of work[0] whose reach is marked
  while (done < n) {
    // (the list's new part starts at done: marked through an offset sub-range of work[0])
    std::vector<uint32_t> fresh = s.lazy.turn_lists[0].download_range(done, n - done);
    s.lazy.turn_lists[1].upload(fresh.data(), fresh.size());
    run(ctx, M, "match_undo_reach", fresh.size(), arg("n", fresh.size()), arg("list", s.lazy.turn_lists[1]), arg("edges", c.edges), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("edges2round", m.edges2round), arg("verts2first_round", m.verts2first_round));
    done = n;
    run(ctx, M, "match_undo_grow", taken, arg("n", taken), arg("taken", s.lazy.candidate_list), arg("edges", c.edges), arg("edges2round", m.edges2round), arg("verts2first_round", m.verts2first_round), arg("edges_to_undo", m.edges_to_undo), arg("list", s.lazy.turn_lists[0]), arg("count", s.lazy.list_counts));
    s.lazy.list_counts.download(&n, 1);
  }
  // undone in the reverse order of their rounds (then of their index: any order within a round)
  std::vector<uint32_t> order = s.lazy.turn_lists[0].download_range(0, n), rounds(n);
  if (n > 0) {  // one read of the span of dround they cover (a read per entry costs a round trip each)
    const auto [lo, hi] = std::minmax_element(order.begin(), order.end());
    const std::vector<uint32_t> span = m.edges2round.download_range(*lo, size_t(*hi - *lo) + 1);
    for (uint32_t i = 0; i < n; ++i) rounds[i] = span[order[i] - *lo];
  }
  std::vector<uint32_t> idx(n);
  std::iota(idx.begin(), idx.end(), 0u);
  std::sort(idx.begin(), idx.end(), [&](uint32_t a, uint32_t b) {
    return rounds[a] != rounds[b] ? rounds[a] > rounds[b] : order[a] > order[b];
  });
  std::vector<uint32_t> sorted(n);
  for (uint32_t i = 0; i < n; ++i) sorted[i] = order[idx[i]];
  s.lazy.turn_lists[1].upload(sorted.data(), n);
  if (undone) *undone = sorted;
  run(ctx, M, "match_undo", 1, arg("n", n), arg("order", s.lazy.turn_lists[1]), arg("edges_are_refused", m.edges_are_refused), arg("edges", c.edges), arg("edges2dir", s.result.edges2dir), arg("tets", dm.tets), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tet_nbr", c.tet_nbr), arg("tets_are_dead", s.result.tets_are_dead), arg("tets2killer", m.tets2killer), arg("pts", dm.points), arg("vfield", dm.vfields), arg("vfield_stride", dm.vfield_comps), arg("pts0", m.points_before), arg("vfield0", m.vfields_before), arg("verts2collapse", s.result.verts2collapse), arg("edges2state", s.result.edges2state), arg("edges_are_final", s.result.edges_are_final), arg("edges2reason", s.result.edges2reason));
  return n;
}


namespace {

// The matching selection applies its collapses as it takes them: the mesh is kept as it was
// (begin), and the collapses the surface guard refuses are undone with those that saw them,
// then the result is tested again; the selection does not run again.
class MatchingSelection final : public Selection {
  void begin(Context& ctx, DeviceMesh& dm, EdgeState&) override { matching_backup(ctx, dm, state_); }
  Chosen choose(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                const IterationStats&) override {
    Chosen r;
    r.selected = matching_selection(ctx, dm, c, s, state_, p, r.candidates, r.tested);
    return r;
  }
  uint32_t guard(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                 uint32_t& chosen) override {
    uint32_t refused = 0, n = 0;
    while ((n = guard_.run_applied(ctx, dm, c, s, p, chosen)) > 0) {
      refused += n;
      chosen -= matching_undo(ctx, dm, c, s, state_, guard_);
    }
    return refused;
  }
  bool guard_leaves_final() const override { return true; }
  void release(EdgeState& s) override {
    Selection::release(s);
    state_ = MatchingState{};
  }

  MatchingState state_;
};

}  // namespace

std::unique_ptr<Selection> make_matching_selection() { return std::make_unique<MatchingSelection>(); }

}  // namespace tc::collapse_detail
