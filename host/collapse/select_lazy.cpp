// What the lazy filter, the greedy and the matching selections share (cl/collapse_admissible.cl,
// lazy_*): the start of a selection and the vertex part of its rounds.
#include "collapse/select_lazy.hpp"

#include <algorithm>

#include "collapse/edge_state.hpp"
#include "stopwatch.hpp"

namespace tc::collapse_detail {

// The vertex part of a per-round step of the lazy filter and of the greedy selection, after its
// decisions (cl/collapse_admissible.cl): the slots of the cnt[2] listed vertices
// (s.lazy.vertex_list) anew in the order `order`, then the edges now first at both end points to
// turn list 1 - cur (counted in s.lazy.list_counts[1 - cur]; s.lazy.list_counts[3]: those without
// a verdict). `recompute` and `turns` are the kernels lazy_p1_recompute and lazy_p1_turns, made
// once by the caller. With slotp (the matching selection) the slots' priorities are kept there too.
void vertex_part(Context& ctx, EdgeState& s, const Connectivity& c, Kernel& recompute, Kernel& turns,
                 const DeviceBuffer<double>& order, int cur, cl_uint round, DeviceBuffer<double>* slotp,
                 bool waiting) {
  uint32_t nd = 0;
  s.lazy.list_counts.download(&nd, 1, 2);
  recompute.set(arg("n", nd), arg("dlist", s.lazy.vertex_list), arg("nb_off", c.nb_off), arg("nb_edge", c.nb_edge), arg("edges2state", s.result.edges2state), arg("edges2order", order), arg("verts2slot", s.lazy.verts2slot[0]), arg("verts2slot_priority", slotp ? slotp->buffer() : order.buffer()), arg("with_slotp", cl_int(slotp ? 1 : 0)));
  recompute.launch(ctx, nd);
  turns.set(arg("n", nd), arg("dlist", s.lazy.vertex_list), arg("edges", c.edges), arg("verts2slot", s.lazy.verts2slot[0]), arg("tlist", s.lazy.turn_lists[1 - cur]), arg("cnt", s.lazy.list_counts), arg("which", cl_uint(1 - cur)), arg("edges2queued", s.lazy.edges2queued), arg("round", round + 1), arg("edges2verdict", s.carry.edges2verdict), arg("waiting", cl_int(waiting ? 1 : 0)), arg("verts2waiting", waiting ? s.lazy.verts2waiting.buffer() : s.lazy.verts2slot[0].buffer()), arg("edges2next_waiting", waiting ? s.lazy.edges2next_waiting.buffer() : s.lazy.verts2slot[0].buffer()));
  turns.launch(ctx, nd);
}

// The start shared by the lazy filter and the greedy selection: buffers, the verdicts, lazy_init
// (candidates, Q, carried refusals, the first claims in s.lazy.verts2slot[0] in the order of
// `order`), and the test's arguments of each kernel of `tests`, by name. restrict_clean: only
// edges with clean end points are candidates (s.carry.prev_verts_are_dirty; next_selection_round).
void lazy_start(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                const DeviceBuffer<double>& order, std::initializer_list<Kernel*> tests,
                bool keep_refused, bool restrict_clean) {
  const std::string A = "collapse_admissible.cl";
  s.result.in_place = false;
  ensure(s.result.edges2dir, ctx, c.ne);
  ensure(s.result.edges2reason, ctx, c.ne);
  ensure(s.lazy.edges_are_candidates, ctx, c.ne);
  ensure(s.result.edges_pass1, ctx, c.ne);
  ensure(s.result.edges2state, ctx, c.ne);
  ensure(s.result.verts2collapse, ctx, dm.nv);
  s.result.verts2collapse.fill(-1);
  const cl_int use_labels = dm.has_labels && p.use_labels ? 1 : 0;
  const cl_int mode = p.mode, paper_rule = p.paper_rule ? 1 : 0;
  ensure(s.carry.edges2verdict, ctx, c.ne);
  if (!s.carry.verdict_ready) s.carry.edges2verdict.fill(0xff);  // TCC_VERDICT_UNKNOWN
  s.carry.verdict_ready = false;
  ensure(s.lazy.verts2slot[0], ctx, dm.nv);
  s.lazy.verts2slot[0].fill(-1);
  run_stage(ctx, p, A, "lazy_init", c.ne, arg("ne", c.ne), arg("edges", c.edges), arg("edges_are_marked", s.cost.edges_are_marked), arg("vflags", c.vflags), arg("vclass", c.vclass), arg("eflags", c.eflags), arg("mode", mode), arg("paper_rule", paper_rule), arg("pts", dm.points), arg("vfield", dm.vfields), arg("vfield_stride", dm.vfield_comps), arg("edges2state", s.result.edges2state), arg("edges2dir", s.result.edges2dir), arg("edges2reason", s.result.edges2reason), arg("edges_are_candidates", s.lazy.edges_are_candidates), arg("counters", s.cost.counters), arg("restrict_clean", cl_int(restrict_clean ? 1 : 0)), arg("prev_verts_are_dirty", restrict_clean ? s.carry.prev_verts_are_dirty.buffer() : c.vflags.buffer()), arg("edges2verdict", s.carry.edges2verdict), arg("edges2order", order), arg("verts2slot", s.lazy.verts2slot[0]), arg("keep_refused", cl_int(keep_refused ? 1 : 0)));
  const cl::Buffer& quality = tet_qualities(ctx, dm, c, s.quality, p);
  ensure(s.result.edges2eps, ctx, p.bound > 0 ? c.ne : 1);  // (read only under the bound: TCC_BOUND)
  for (Kernel* k : tests)
    k->set(arg("tets", dm.tets), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tet_nbr", c.tet_nbr),
           arg("nb_off", c.nb_off), arg("nb", c.nb), arg("nb_edge", c.nb_edge), arg("labels", dm.primary_labels()),
           arg("use_labels", use_labels), arg("pts", dm.points), arg("vfield", dm.vfields),
           arg("vfield_stride", dm.vfield_comps), arg("vflags", c.vflags), arg("vclass", c.vclass),
           arg("eflags", c.eflags), arg("mode", mode), arg("paper_rule", paper_rule), arg("eps_v", p.eps_v),
           arg("q_min", p.min_quality), arg("field_eps", p.field_eps), arg("tets2quality", quality), arg("edges2dir", s.result.edges2dir), arg("edges2reason", s.result.edges2reason),
           arg("counters", s.cost.counters), arg("edges2verdict", s.carry.edges2verdict), arg("bound", p.bound),
           arg("eps_col", p.eps_col), arg("edges2eps", s.result.edges2eps));
}

// The priority of the greedy and matching selections: greedy_priority with levels > 0, else the
// cost.
const DeviceBuffer<double>& selection_priority(Context& ctx, Connectivity& c, EdgeState& s, const StageParams& p) {
  if (!(p.priority_levels > 0)) return s.cost.edges2cost;
  ensure(s.lazy.edges2priority, ctx, c.ne);
  run(ctx, "collapse_admissible.cl", "greedy_priority", c.ne, arg("ne", c.ne), arg("edges2cost", s.cost.edges2cost), arg("edges_are_marked", s.cost.edges_are_marked), arg("target", p.target), arg("levels", p.priority_levels), arg("edges2priority", s.lazy.edges2priority));
  return s.lazy.edges2priority;
}

// The buffers of the greedy and matching selections' rounds, set for the first round.
void selection_buffers(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s) {
  ensure(s.result.edges_are_final, ctx, c.ne);
  ensure(s.lazy.edges2blocker, ctx, c.ne);
  ensure(s.lazy.edges2queued, ctx, c.ne);
  ensure(s.lazy.verts2listed, ctx, dm.nv);
  ensure(s.lazy.round_taken, ctx, c.ne);
  ensure(s.lazy.vertex_list, ctx, std::max<size_t>(dm.nv, 1));  // a vertex is listed at most once per round
  ensure(s.lazy.turn_lists[0], ctx, c.ne);
  ensure(s.lazy.turn_lists[1], ctx, c.ne);
  ensure(s.lazy.list_counts, ctx, 5);
  ensure(s.lazy.loop_resume, ctx, 3);
  ensure(s.lazy.verts2waiting, ctx, std::max<size_t>(dm.nv, 1));  // the waiting lists (tcc_wait_on, collapse_select.h)
  ensure(s.lazy.edges2next_waiting, ctx, c.ne);
  s.lazy.verts2waiting.fill(-1);
  s.lazy.edges2blocker.fill(-1);
  s.lazy.edges2queued.fill(0xffffffffu);
  s.lazy.verts2listed.fill(0xffffffffu);
  s.lazy.list_counts.fill(0);
}

uint32_t selection_rounds(Context& ctx, Connectivity& c, EdgeState& s, const StageParams& p, const char* name,
                          const RoundFn& one_round, const RoundFn& loop, uint32_t& passed_q, uint32_t& tested) {
  const std::string A = "collapse_admissible.cl";
  run(ctx, A, "lazy_p1_first_turns", c.ne, arg("ne", c.ne), arg("edges_are_candidates", s.lazy.edges_are_candidates), arg("edges", c.edges), arg("verts2slot", s.lazy.verts2slot[0]), arg("tlist", s.lazy.turn_lists[0]), arg("cnt", s.lazy.list_counts), arg("edges2verdict", s.carry.edges2verdict));
  uint32_t nt = 0;
  s.lazy.list_counts.download(&nt, 1);
  int cur = 0;  // the turn list of this round
  for (cl_uint round = 0; nt > 0; ++round) {
    const double t0 = Stopwatch::now();
    s.lazy.list_counts.fill(0);
    const bool one_group = nt <= p.greedy_loop_size;
    if (one_group) {
      s.lazy.loop_resume.fill(0);
      loop(nt, cur, round);
      uint32_t r[3];
      s.lazy.loop_resume.download(r, 3);
      nt = r[0];  // 0: every round done; else the loop stopped before a long turn list
      cur = int(r[1]);
      round = r[2] - 1;
    } else {
      one_round(nt, cur, round);
      s.lazy.list_counts.download(&nt, 1, size_t(1 - cur));
      cur = 1 - cur;
    }
    profile_line(ctx, name, nt, t0, one_group ? " (one work-group)" : "");
  }
  run(ctx, A, "greedy_finish", c.ne, arg("ne", c.ne), arg("edges2state", s.result.edges2state), arg("edges_pass1", s.result.edges_pass1), arg("edges_are_final", s.result.edges_are_final), arg("counters", s.cost.counters));
  uint32_t cnt[6];
  s.cost.counters.download(cnt, 6);
  passed_q = cnt[5];
  tested = cnt[4];
  return cnt[3];
}

}  // namespace tc::collapse_detail
