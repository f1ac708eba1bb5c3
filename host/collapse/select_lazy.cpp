// What the lazy filter, the greedy and the matching selections share (cl/collapse_admissible.cl,
// lazy_*): the start of a selection and the vertex part of its rounds.
#include "collapse/select_lazy.hpp"

#include <algorithm>

#include "collapse/admissible.hpp"

namespace tc::collapse_detail {

// The vertex part of a per-round step of the lazy filter and of the greedy selection, after its
// decisions (cl/collapse_admissible.cl): the slots of the cnt[2] listed vertices (s.dlist) anew
// in the order `order`, then the edges now first at both end points to turn list 1 - cur
// (counted in s.work_n[1 - cur]; s.work_n[3]: those without a verdict). `recompute` and `turns`
// are the kernels lazy_p1_recompute and lazy_p1_turns, made once by the caller. With slotp (the
// matching selection) the slots' priorities are kept there too.
void vertex_part(Context& ctx, EdgeState& s, const Connectivity& c, Kernel& recompute, Kernel& turns,
                 const DeviceBuffer<double>& order, int cur, cl_uint round, DeviceBuffer<double>* slotp,
                 bool waiting) {
  uint32_t nd = 0;
  s.work_n.download(&nd, 1, 2);
  recompute.set(arg("n", nd), arg("dlist", s.dlist), arg("nb_off", c.nb_off), arg("nb_edge", c.nb_edge), arg("state", s.state), arg("cost", order), arg("slot", s.slot[0]), arg("slotp", slotp ? slotp->buffer() : order.buffer()), arg("with_slotp", cl_int(slotp ? 1 : 0)));
  recompute.launch(ctx, nd);
  turns.set(arg("n", nd), arg("dlist", s.dlist), arg("edges", c.edges), arg("slot", s.slot[0]), arg("tlist", s.work[1 - cur]), arg("cnt", s.work_n), arg("which", cl_uint(1 - cur)), arg("queued", s.queued), arg("round", round + 1), arg("verdict", s.verdict), arg("waiting", cl_int(waiting ? 1 : 0)), arg("whead", waiting ? s.whead.buffer() : s.slot[0].buffer()), arg("wnext", waiting ? s.wnext.buffer() : s.slot[0].buffer()));
  turns.launch(ctx, nd);
}

// The start shared by the lazy filter and the greedy selection: buffers, the verdicts, lazy_init
// (candidates, Q, carried refusals, the first claims in s.slot[0] in the order of `order`), and
// the test's arguments of each kernel of `tests` (from the given argument index on).
void lazy_start(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                const DeviceBuffer<double>& order, std::initializer_list<Kernel*> tests,
                bool keep_refused) {
  const std::string A = "collapse_admissible.cl";
  s.in_place = false;
  ensure(s.dir, ctx, c.ne);
  ensure(s.reason, ctx, c.ne);
  ensure(s.cand, ctx, c.ne);
  ensure(s.p1, ctx, c.ne);
  ensure(s.state, ctx, c.ne);
  ensure(s.vaff, ctx, dm.nv);
  s.vaff.fill(-1);
  const cl_int use_labels = dm.has_labels && p.use_labels ? 1 : 0;
  const cl_int mode = p.mode, paper_rule = p.paper_rule ? 1 : 0;
  ensure(s.verdict, ctx, c.ne);
  if (!s.verdict_ready) s.verdict.fill(0xff);  // TCC_VERDICT_UNKNOWN
  s.verdict_ready = false;
  const bool restrict_clean = s.restrict_clean;
  s.restrict_clean = false;
  ensure(s.slot[0], ctx, dm.nv);
  s.slot[0].fill(-1);
  run_stage(ctx, p, A, "lazy_init", c.ne, arg("ne", c.ne), arg("edges", c.edges), arg("marked", s.marked), arg("vflags", c.vflags), arg("vclass", c.vclass), arg("eflags", c.eflags), arg("mode", mode), arg("paper_rule", paper_rule), arg("pts", dm.points), arg("vfield", dm.vfields), arg("vfield_stride", dm.vfield_comps), arg("state", s.state), arg("edge_dir", s.dir), arg("reason", s.reason), arg("cand", s.cand), arg("counters", s.counters), arg("restrict_clean", cl_int(restrict_clean ? 1 : 0)), arg("vdirty", restrict_clean ? s.vdirty.buffer() : c.vflags.buffer()), arg("verdict", s.verdict), arg("cost", order), arg("slot", s.slot[0]), arg("keep_refused", cl_int(keep_refused ? 1 : 0)));
  const cl::Buffer& quality = tet_qualities(ctx, dm, c, s, p);
  for (Kernel* k : tests)
    k->set(arg("tets", dm.tets), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("tet_nbr", c.tet_nbr),
           arg("nb_off", c.nb_off), arg("nb", c.nb), arg("nb_edge", c.nb_edge), arg("labels", dm.primary_labels()),
           arg("use_labels", use_labels), arg("pts", dm.points), arg("vfield", dm.vfields),
           arg("vfield_stride", dm.vfield_comps), arg("vflags", c.vflags), arg("vclass", c.vclass),
           arg("eflags", c.eflags), arg("mode", mode), arg("paper_rule", paper_rule), arg("eps_v", p.eps_v),
           arg("q_min", p.min_quality), arg("tet_quality", quality), arg("edge_dir", s.dir), arg("reason", s.reason),
           arg("counters", s.counters), arg("verdict", s.verdict));
}

// The priority of the greedy and matching selections: greedy_priority with levels > 0, else the
// cost.
const DeviceBuffer<double>& selection_priority(Context& ctx, Connectivity& c, EdgeState& s, const StageParams& p) {
  if (!(p.priority_levels > 0)) return s.cost;
  ensure(s.prio, ctx, c.ne);
  run(ctx, "collapse_admissible.cl", "greedy_priority", c.ne, arg("ne", c.ne), arg("cost", s.cost), arg("marked", s.marked), arg("target", p.target), arg("levels", p.priority_levels), arg("prio", s.prio));
  return s.prio;
}

// The buffers of the greedy and matching selections' rounds, set for the first round.
void selection_buffers(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s) {
  ensure(s.fin, ctx, c.ne);
  ensure(s.blocker, ctx, c.ne);
  ensure(s.queued, ctx, c.ne);
  ensure(s.vstamp, ctx, dm.nv);
  ensure(s.inlist, ctx, c.ne);
  ensure(s.dlist, ctx, std::max<size_t>(dm.nv, 1));  // a vertex is listed at most once per round
  ensure(s.work[0], ctx, c.ne);
  ensure(s.work[1], ctx, c.ne);
  ensure(s.work_n, ctx, 5);
  ensure(s.resume, ctx, 3);
  ensure(s.whead, ctx, std::max<size_t>(dm.nv, 1));  // the waiting lists (tcc_wait_on, collapse_select.h)
  ensure(s.wnext, ctx, c.ne);
  s.whead.fill(-1);
  s.blocker.fill(-1);
  s.queued.fill(0xffffffffu);
  s.vstamp.fill(0xffffffffu);
  s.work_n.fill(0);
}

}  // namespace tc::collapse_detail
