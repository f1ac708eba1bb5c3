// The matching selection and its undo (cl/collapse_matching.cl).
#include "collapse/select_matching.hpp"

#include <memory>

#include "collapse/selection.hpp"

#include <algorithm>
#include <numeric>

#include "collapse/guard_surface.hpp"
#include "collapse/select_lazy.hpp"
#include "device/primitives.hpp"

namespace tc::collapse_detail {

uint32_t matching_selection(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                            uint32_t& passed_q, uint32_t& tested) {
  const std::string A = "collapse_admissible.cl", M = "collapse_matching.cl";
  Kernel decide = stage_kernel(ctx, p, M, "match_decide"), apply = stage_kernel(ctx, p, M, "match_apply"),
             loop = stage_kernel(ctx, p, M, "match_loop");
  // the priority first: lazy_init claims the first slots in its order
  const DeviceBuffer<double>& prio = selection_priority(ctx, c, s, p);
  // the test's arguments (TCC_MATCH_PARAMS): the lazy filter's, then the live test's
  lazy_start(ctx, dm, c, s, p, prio, {&decide, &apply, &loop}, true);
  s.in_place = true;
  ensure(s.tdead, ctx, std::max<size_t>(dm.nt, 1));
  ensure(s.tkill, ctx, std::max<size_t>(dm.nt, 1));
  ensure(s.dround, ctx, c.ne);
  s.tdead.fill(0);
  for (Kernel* k : {&decide, &apply, &loop})
    k->set(arg("eps_r", p.eps_r), arg("eps_f", p.eps_f), arg("tdead", s.tdead));
  selection_buffers(ctx, dm, c, s);
  ensure(s.spec, ctx, c.ne);
  s.spec.fill(p.match_early_tests ? 0 : 1);  // 1: the early test counts as done
  ensure(s.slotp, ctx, dm.nv);
  run(ctx, A, "slot_priority", dm.nv, arg("nv", dm.nv), arg("slot", s.slot[0]), arg("prio", prio), arg("slotp", s.slotp));
  const cl_int W = p.waiting_lists ? 1 : 0;
  Kernel recompute = kernel(ctx, A, "lazy_p1_recompute"), turns = kernel(ctx, A, "lazy_p1_turns");
  auto one_round = [&](uint32_t nt, int cur, cl_uint round) {
    decide.set(arg("n", nt), arg("cur", cl_uint(cur)), arg("tlist", s.work[cur]), arg("tnext", s.work[1 - cur]), arg("cnt", s.work_n), arg("edges", c.edges), arg("prio", prio), arg("slot", s.slot[0]), arg("slotp", s.slotp), arg("blocker", s.blocker), arg("spec", s.spec), arg("dround", s.dround), arg("queued", s.queued), arg("round", round), arg("inlist", s.inlist), arg("vstamp", s.vstamp), arg("dlist", s.dlist), arg("state", s.state), arg("vaff", s.vaff), arg("waiting", W), arg("whead", s.whead), arg("wnext", s.wnext));
    decide.launch(ctx, nt);
    apply.set(arg("inlist", s.inlist), arg("cnt", s.work_n), arg("edges", c.edges), arg("slot", s.slot[0]), arg("vstamp", s.vstamp), arg("round", round), arg("dlist", s.dlist), arg("state", s.state), arg("vaff", s.vaff), arg("tkill", s.tkill));
    apply.launch(ctx, nt);  // over the round's taken edges (cnt[4] <= nt)
    vertex_part(ctx, s, c, recompute, turns, prio, cur, round, &s.slotp, p.waiting_lists);
  };
  auto in_one_group = [&](uint32_t nt, int cur, cl_uint round) {
    loop.set(arg("n", nt), arg("cur", cl_int(cur)), arg("round", round), arg("t0", s.work[0]), arg("t1", s.work[1]), arg("cnt", s.work_n), arg("edges", c.edges), arg("prio", prio), arg("slot", s.slot[0]), arg("slotp", s.slotp), arg("blocker", s.blocker), arg("spec", s.spec), arg("dround", s.dround), arg("queued", s.queued), arg("inlist", s.inlist), arg("vstamp", s.vstamp), arg("dlist", s.dlist), arg("state", s.state), arg("vaff", s.vaff), arg("tkill", s.tkill), arg("max_n", p.greedy_loop_exit), arg("resume", s.resume), arg("waiting", W), arg("whead", s.whead), arg("wnext", s.wnext));
    loop.launch_one_group(ctx);
  };
  return selection_rounds(ctx, c, s, p, "match_round", one_round, in_one_group, passed_q, tested);
}

void matching_backup(Context& ctx, DeviceMesh& dm, EdgeState& s) {
  if (!s.points0.buffer()()) {
    s.points0 = DeviceBuffer<double>(ctx, 1);
    s.vfields0 = DeviceBuffer<double>(ctx, 1);
  }
  s.points0.copy_from(dm.points, size_t(dm.nv) * 3);
  s.vfields0.copy_from(dm.vfields, size_t(dm.nv) * dm.vfield_comps);
}

uint32_t matching_undo(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, SurfaceGuard& guard) {
  ensure(s.refused, ctx, c.ne);
  ensure(s.work_n, ctx, 5);
  s.refused.fill(0);
  s.work_n.fill(0);
  guard.refused_edges(ctx, s.refused, s.work[0], s.work_n);
  uint32_t n = 0;
  s.work_n.download(&n, 1);
  std::vector<uint32_t> undone;
  const uint32_t count = matching_undo(ctx, dm, c, s, s.work[0].download_range(0, n), &undone);
  guard.restrict_to_undone(ctx, dm, c, s, undone);  // the next guard run: only where the undo changed S
  return count;
}

uint32_t matching_undo(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s,
                       const std::vector<uint32_t>& refused, std::vector<uint32_t>* undone) {
  const std::string M = "collapse_matching.cl";
  ensure(s.refused, ctx, c.ne);
  ensure(s.undo, ctx, c.ne);
  ensure(s.reachmin, ctx, dm.nv);
  ensure(s.work_n, ctx, 5);
  s.reachmin.fill(0xffffffffu);
  // the refused flagged, and listed in s.work[0] (the undone: the refused first, then each growth)
  std::vector<uint8_t> flags(c.ne, 0);
  for (uint32_t e : refused) flags[e] = 1;
  s.refused.upload(flags);
  s.undo.upload(flags);
  uint32_t n = uint32_t(refused.size());
  s.work[0].upload(refused.data(), n);
  s.work_n.upload(&n, 1);
  // the taken edges
  ensure(s.cand_edges, ctx, c.ne);
  const uint32_t taken = dev::compact_indices(ctx, s.fin, s.cand_edges, c.ne);
  uint32_t done = 0;  // entries of work[0] whose reach is marked
  while (done < n) {
    // (the list's new part starts at done: marked through an offset sub-range of work[0])
    std::vector<uint32_t> fresh = s.work[0].download_range(done, n - done);
    s.work[1].upload(fresh.data(), fresh.size());
    run(ctx, M, "match_undo_reach", fresh.size(), arg("n", fresh.size()), arg("list", s.work[1]), arg("edges", c.edges), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("dround", s.dround), arg("reachmin", s.reachmin));
    done = n;
    run(ctx, M, "match_undo_grow", taken, arg("n", taken), arg("taken", s.cand_edges), arg("edges", c.edges), arg("dround", s.dround), arg("reachmin", s.reachmin), arg("undo", s.undo), arg("list", s.work[0]), arg("count", s.work_n));
    s.work_n.download(&n, 1);
  }
  // undone in the reverse order of their rounds (then of their index: any order within a round)
  std::vector<uint32_t> order = s.work[0].download_range(0, n), rounds(n);
  if (n > 0) {  // one read of the span of dround they cover (a read each cost ~35 us on PoCL)
    const auto [lo, hi] = std::minmax_element(order.begin(), order.end());
    const std::vector<uint32_t> span = s.dround.download_range(*lo, size_t(*hi - *lo) + 1);
    for (uint32_t i = 0; i < n; ++i) rounds[i] = span[order[i] - *lo];
  }
  std::vector<uint32_t> idx(n);
  std::iota(idx.begin(), idx.end(), 0u);
  std::sort(idx.begin(), idx.end(), [&](uint32_t a, uint32_t b) {
    return rounds[a] != rounds[b] ? rounds[a] > rounds[b] : order[a] > order[b];
  });
  std::vector<uint32_t> sorted(n);
  for (uint32_t i = 0; i < n; ++i) sorted[i] = order[idx[i]];
  s.work[1].upload(sorted.data(), n);
  if (undone) *undone = sorted;
  run(ctx, M, "match_undo", 1, arg("n", n), arg("order", s.work[1]), arg("refused", s.refused), arg("edges", c.edges), arg("edge_dir", s.dir), arg("tets", dm.tets), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tet_nbr", c.tet_nbr), arg("tdead", s.tdead), arg("tkill", s.tkill), arg("pts", dm.points), arg("vfield", dm.vfields), arg("vfield_stride", dm.vfield_comps), arg("pts0", s.points0), arg("vfield0", s.vfields0), arg("vaff", s.vaff), arg("state", s.state), arg("fin", s.fin), arg("reason", s.reason));
  return n;
}


namespace {

// The matching selection applies its collapses as it takes them: the mesh is kept as it was
// (begin), and the collapses the surface guard refuses are undone with those that saw them,
// then the result is tested again; the selection does not run again.
class MatchingSelection final : public Selection {
  void begin(Context& ctx, DeviceMesh& dm, EdgeState& s) override { matching_backup(ctx, dm, s); }
  Chosen choose(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                const IterationStats&) override {
    Chosen r;
    r.selected = matching_selection(ctx, dm, c, s, p, r.candidates, r.tested);
    return r;
  }
  uint32_t guard(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                 uint32_t& chosen) override {
    uint32_t refused = 0, n = 0;
    while ((n = guard_.run_applied(ctx, dm, c, s, p, chosen)) > 0) {
      refused += n;
      chosen -= matching_undo(ctx, dm, c, s, guard_);
    }
    return refused;
  }
  bool guard_leaves_final() const override { return true; }
};

}  // namespace

std::unique_ptr<Selection> make_matching_selection() { return std::make_unique<MatchingSelection>(); }

}  // namespace tc::collapse_detail
