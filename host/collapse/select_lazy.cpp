// What the lazy filter, the greedy and the matching selections share (cl/collapse_admissible.cl,
// lazy_*): the start of a selection and the vertex part of its rounds.
#include "collapse/select_lazy.hpp"

#include <algorithm>

#include "collapse/admissible.hpp"

namespace tc::collapse_detail {

// The vertex part of a per-round step of the lazy filter and of the greedy selection, after its
// decisions (cl/collapse_admissible.cl): the slots of the cnt[2] listed vertices (s.vertex_list) anew
// in the order `order`, then the edges now first at both end points to turn list 1 - cur
// (counted in s.list_counts[1 - cur]; s.list_counts[3]: those without a verdict). `recompute` and `turns`
// are the kernels lazy_p1_recompute and lazy_p1_turns, made once by the caller. With slotp (the
// matching selection) the slots' priorities are kept there too.
void vertex_part(Context& ctx, EdgeState& s, const Connectivity& c, Kernel& recompute, Kernel& turns,
                 const DeviceBuffer<double>& order, int cur, cl_uint round, DeviceBuffer<double>* slotp,
                 bool waiting) {
  uint32_t nd = 0;
  s.list_counts.download(&nd, 1, 2);
  recompute.set(arg("n", nd), arg("dlist", s.vertex_list), arg("nb_off", c.nb_off), arg("nb_edge", c.nb_edge), arg("state", s.edges2state), arg("cost", order), arg("slot", s.verts2slot[0]), arg("slotp", slotp ? slotp->buffer() : order.buffer()), arg("with_slotp", cl_int(slotp ? 1 : 0)));
  recompute.launch(ctx, nd);
  turns.set(arg("n", nd), arg("dlist", s.vertex_list), arg("edges", c.edges), arg("slot", s.verts2slot[0]), arg("tlist", s.turn_lists[1 - cur]), arg("cnt", s.list_counts), arg("which", cl_uint(1 - cur)), arg("queued", s.edges2queued), arg("round", round + 1), arg("verdict", s.edges2verdict), arg("waiting", cl_int(waiting ? 1 : 0)), arg("whead", waiting ? s.verts2waiting.buffer() : s.verts2slot[0].buffer()), arg("wnext", waiting ? s.edges2next_waiting.buffer() : s.verts2slot[0].buffer()));
  turns.launch(ctx, nd);
}

// The start shared by the lazy filter and the greedy selection: buffers, the verdicts, lazy_init
// (candidates, Q, carried refusals, the first claims in s.verts2slot[0] in the order of `order`), and
// the test's arguments of each kernel of `tests`, by name.
void lazy_start(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                const DeviceBuffer<double>& order, std::initializer_list<Kernel*> tests,
                bool keep_refused) {
  const std::string A = "collapse_admissible.cl";
  s.in_place = false;
  ensure(s.edges2dir, ctx, c.ne);
  ensure(s.edges2reason, ctx, c.ne);
  ensure(s.edges_are_candidates, ctx, c.ne);
  ensure(s.edges_pass1, ctx, c.ne);
  ensure(s.edges2state, ctx, c.ne);
  ensure(s.verts2collapse, ctx, dm.nv);
  s.verts2collapse.fill(-1);
  const cl_int use_labels = dm.has_labels && p.use_labels ? 1 : 0;
  const cl_int mode = p.mode, paper_rule = p.paper_rule ? 1 : 0;
  ensure(s.edges2verdict, ctx, c.ne);
  if (!s.verdict_ready) s.edges2verdict.fill(0xff);  // TCC_VERDICT_UNKNOWN
  s.verdict_ready = false;
  const bool restrict_clean = s.restrict_clean;
  s.restrict_clean = false;
  ensure(s.verts2slot[0], ctx, dm.nv);
  s.verts2slot[0].fill(-1);
  run_stage(ctx, p, A, "lazy_init", c.ne, arg("ne", c.ne), arg("edges", c.edges), arg("marked", s.edges_are_marked), arg("vflags", c.vflags), arg("vclass", c.vclass), arg("eflags", c.eflags), arg("mode", mode), arg("paper_rule", paper_rule), arg("pts", dm.points), arg("vfield", dm.vfields), arg("vfield_stride", dm.vfield_comps), arg("state", s.edges2state), arg("edge_dir", s.edges2dir), arg("reason", s.edges2reason), arg("cand", s.edges_are_candidates), arg("counters", s.counters), arg("restrict_clean", cl_int(restrict_clean ? 1 : 0)), arg("vdirty", restrict_clean ? s.prev_verts_are_dirty.buffer() : c.vflags.buffer()), arg("verdict", s.edges2verdict), arg("cost", order), arg("slot", s.verts2slot[0]), arg("keep_refused", cl_int(keep_refused ? 1 : 0)));
  const cl::Buffer& quality = tet_qualities(ctx, dm, c, s, p);
  for (Kernel* k : tests)
    k->set(arg("tets", dm.tets), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tet_nbr", c.tet_nbr),
           arg("nb_off", c.nb_off), arg("nb", c.nb), arg("nb_edge", c.nb_edge), arg("labels", dm.primary_labels()),
           arg("use_labels", use_labels), arg("pts", dm.points), arg("vfield", dm.vfields),
           arg("vfield_stride", dm.vfield_comps), arg("vflags", c.vflags), arg("vclass", c.vclass),
           arg("eflags", c.eflags), arg("mode", mode), arg("paper_rule", paper_rule), arg("eps_v", p.eps_v),
           arg("q_min", p.min_quality), arg("tet_quality", quality), arg("edge_dir", s.edges2dir), arg("reason", s.edges2reason),
           arg("counters", s.counters), arg("verdict", s.edges2verdict));
}

// The priority of the greedy and matching selections: greedy_priority with levels > 0, else the
// cost.
const DeviceBuffer<double>& selection_priority(Context& ctx, Connectivity& c, EdgeState& s, const StageParams& p) {
  if (!(p.priority_levels > 0)) return s.edges2cost;
  ensure(s.edges2priority, ctx, c.ne);
  run(ctx, "collapse_admissible.cl", "greedy_priority", c.ne, arg("ne", c.ne), arg("cost", s.edges2cost), arg("marked", s.edges_are_marked), arg("target", p.target), arg("levels", p.priority_levels), arg("prio", s.edges2priority));
  return s.edges2priority;
}

// The buffers of the greedy and matching selections' rounds, set for the first round.
void selection_buffers(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s) {
  ensure(s.edges_are_final, ctx, c.ne);
  ensure(s.edges2blocker, ctx, c.ne);
  ensure(s.edges2queued, ctx, c.ne);
  ensure(s.verts2listed, ctx, dm.nv);
  ensure(s.round_taken, ctx, c.ne);
  ensure(s.vertex_list, ctx, std::max<size_t>(dm.nv, 1));  // a vertex is listed at most once per round
  ensure(s.turn_lists[0], ctx, c.ne);
  ensure(s.turn_lists[1], ctx, c.ne);
  ensure(s.list_counts, ctx, 5);
  ensure(s.loop_resume, ctx, 3);
  ensure(s.verts2waiting, ctx, std::max<size_t>(dm.nv, 1));  // the waiting lists (tcc_wait_on, collapse_select.h)
  ensure(s.edges2next_waiting, ctx, c.ne);
  s.verts2waiting.fill(-1);
  s.edges2blocker.fill(-1);
  s.edges2queued.fill(0xffffffffu);
  s.verts2listed.fill(0xffffffffu);
  s.list_counts.fill(0);
}

}  // namespace tc::collapse_detail
