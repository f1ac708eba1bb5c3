// The paper's two-pass selection: the lazy admissible filter with conflict pass 1, conflict
// pass 2, further selection rounds (cl/collapse_conflict.cl, cl/collapse_admissible.cl lazy_p1_*).
#include "collapse/select_two_pass.hpp"

#include <memory>

#include "collapse/edge_state.hpp"
#include "collapse/select_lazy.hpp"
#include "collapse/selection.hpp"
#include "collapse/verdict_carry.hpp"
#include "device/primitives.hpp"
#include "stopwatch.hpp"

namespace tc::collapse_detail {

namespace {
// Compacts the candidate edges (flags[e] != 0) into s.lazy.candidate_list and prepares the per-slot
// rival storage; returns their number.
uint32_t prepare_candidates(Context& ctx, EdgeState& s, TwoPassState& t, const DeviceBuffer<uint32_t>& flags,
                            uint32_t ne) {
  ensure(s.lazy.candidate_list, ctx, ne);
  const uint32_t n = dev::compact_indices(ctx, flags, s.lazy.candidate_list, ne);
  ensure(t.slots2rival_count, ctx, n);
  ensure(t.slots2rivals, ctx, size_t(n) * 16);  // TCC_RIVALS
  t.slots2rival_count.fill(0xffffffffu);        // TCC_UNSCANNED
  return n;
}

// The worklist loop of the conflict rounds: round(n, first, cur) enqueues one round over the n
// entries of s.lazy.turn_lists[cur] (all candidates when first), which appends those still
// undecided to s.lazy.turn_lists[1 - cur] via s.lazy.list_counts; repeats until none is left. Every
// round decides at least the undecided candidate of smallest (cost, index), so this terminates.
// When `tail` is given, the rounds left once at most tail_size entries remain go to tail(n, first,
// cur), which runs them all in one launch.
template <class Round, class Tail = void (*)(uint32_t, cl_int, int)>
void rounds(Context& ctx, EdgeState& s, uint32_t n, const char* what, const Round& round, const Tail* tail = nullptr,
            uint32_t tail_size = 0) {
  ensure(s.lazy.list_counts, ctx, 1);
  ensure(s.lazy.turn_lists[0], ctx, n);
  ensure(s.lazy.turn_lists[1], ctx, n);
  int cur = 0;
  for (cl_int first = 1; n > 0; first = 0) {
    s.lazy.list_counts.fill(0);
    const double t0 = Stopwatch::now();
    if (tail && n <= tail_size) {
      (*tail)(n, first, cur);
      profile_line(ctx, what, n, t0, " (all remaining rounds)");
      return;
    }
    round(n, first, cur);
    uint32_t next = 0;
    s.lazy.list_counts.download(&next, 1);
    profile_line(ctx, what, n, t0);
    n = next;
    cur = 1 - cur;
  }
}

// Pass-1 rounds (collapse_conflict.cl: pass1_claim, then `decide`, whose arguments other than the
// round's are already set) over the n candidates of s.lazy.candidate_list until none is left
// undecided. s.result.verts2collapse must be -1 everywhere; it ends with the IN edge at each
// vertex.
void pass1_rounds(Context& ctx, Kernel& decide, EdgeState& s, const Connectivity& c, uint32_t nv, uint32_t n,
                  const char* what) {
  ensure(s.lazy.verts2slot[0], ctx, nv);
  ensure(s.lazy.verts2slot[1], ctx, nv);
  s.lazy.verts2slot[0].fill(-1);
  s.lazy.verts2slot[1].fill(-1);
  Kernel claim = kernel(ctx, "collapse_conflict.cl", "pass1_claim");
  auto round = [&](uint32_t m, cl_int first, int cur) {
    claim.set(arg("n", m), arg("first", first), arg("list", s.lazy.turn_lists[cur]), arg("cand", s.lazy.candidate_list), arg("edges", c.edges), arg("edges2cost", s.cost.edges2cost), arg("verts2collapse", s.result.verts2collapse), arg("verts2slot", s.lazy.verts2slot[cur]), arg("edges2state", s.result.edges2state));
    claim.launch(ctx, m);
    decide.set(arg("n", m), arg("first", first), arg("list", s.lazy.turn_lists[cur]), arg("next", s.lazy.turn_lists[1 - cur]), arg("next_n", s.lazy.list_counts), arg("cand", s.lazy.candidate_list), arg("edges", c.edges), arg("verts2slot", s.lazy.verts2slot[cur]), arg("verts2slot_next", s.lazy.verts2slot[1 - cur]), arg("edges2state", s.result.edges2state), arg("verts2collapse", s.result.verts2collapse));
    decide.launch(ctx, m);
  };
  rounds(ctx, s, n, what, round);
}
}  // namespace

namespace {
// Pass 1 of the lazy filter over the candidates (s.lazy.edges_are_candidates[e] != 0 for e < ne;
// lazy_init made them and their first claims in s.lazy.verts2slot[0]; cl/collapse_admissible.cl,
// lazy_p1_*): rounds over the turn list until it is empty. `decide` and `loop` have the test's
// arguments set. s.result.verts2collapse must be -1 everywhere. The rounds run in one work-group
// (lazy_p1_loop) while the turn list holds at most p.loop_tests edges to test (the others take the
// verdict carried from the previous iteration, cheap) and at most p.loop_turns in all; the loop
// hands back to the per-round kernels when a list has more than p.loop_exit_tests to test.
void lazy_p1_rounds(Context& ctx, EdgeState& s, const Connectivity& c, Kernel& decide, Kernel& loop,
                    const StageParams& p) {
  const std::string A = "collapse_admissible.cl";
  const uint32_t n = c.ne;  // bounds the candidates
  ensure(s.lazy.edges2queued, ctx, c.ne);
  ensure(s.lazy.turn_lists[0], ctx, n);
  ensure(s.lazy.turn_lists[1], ctx, n);
  ensure(s.lazy.vertex_list, ctx, 2 * size_t(n) + 1);  // an edge is listed at most twice per pass
  ensure(s.lazy.list_counts, ctx, 4);
  ensure(s.lazy.loop_resume, ctx, 3);
  s.lazy.edges2queued.fill(0xffffffffu);
  s.lazy.list_counts.fill(0);
  if (n == 0) return;
  run(ctx, A, "lazy_p1_first_turns", n, arg("ne", n), arg("edges_are_candidates", s.lazy.edges_are_candidates), arg("edges", c.edges), arg("verts2slot", s.lazy.verts2slot[0]), arg("tlist", s.lazy.turn_lists[0]), arg("cnt", s.lazy.list_counts), arg("edges2verdict", s.carry.edges2verdict));
  uint32_t cnt[4];
  s.lazy.list_counts.download(cnt, 4);
  uint32_t nt = cnt[0], nu = cnt[3];
  Kernel recompute = kernel(ctx, A, "lazy_p1_recompute"), turns = kernel(ctx, A, "lazy_p1_turns");
  int cur = 0;  // the list of this round
  cl_uint round = 0;
  while (nt > 0) {
    const double t0 = Stopwatch::now();
    s.lazy.list_counts.fill(0);
    const bool one_group = nu <= p.loop_tests && nt <= p.loop_turns;
    if (one_group) {
      s.lazy.loop_resume.fill(0);
      loop.set(arg("n", nt), arg("cur", cl_int(cur)), arg("round", round), arg("t0", s.lazy.turn_lists[0]), arg("t1", s.lazy.turn_lists[1]), arg("cnt", s.lazy.list_counts), arg("dlist", s.lazy.vertex_list), arg("edges2queued", s.lazy.edges2queued), arg("edges", c.edges), arg("edges2cost", s.cost.edges2cost), arg("verts2slot", s.lazy.verts2slot[0]), arg("edges2state", s.result.edges2state), arg("verts2collapse", s.result.verts2collapse), arg("max_tests", cl_uint(p.loop_exit_tests)), arg("resume", s.lazy.loop_resume));
      loop.launch_one_group(ctx);
      uint32_t r[3];
      s.lazy.loop_resume.download(r, 3);
      nt = r[0];  // 0: every round done; else the loop stopped before a list with many to test
      nu = UINT32_MAX;
      cur = int(r[1]);
      round = r[2];
    } else {
      decide.set(arg("n", nt), arg("tlist", s.lazy.turn_lists[cur]), arg("edges", c.edges), arg("edges2state", s.result.edges2state), arg("verts2collapse", s.result.verts2collapse), arg("verts2slot", s.lazy.verts2slot[0]), arg("dlist", s.lazy.vertex_list), arg("cnt", s.lazy.list_counts));
      decide.launch(ctx, nt);
      vertex_part(ctx, s, c, recompute, turns, s.cost.edges2cost, cur, round);
      s.lazy.list_counts.download(cnt, 4);
      nt = cnt[1 - cur];
      nu = cnt[3];
      cur = 1 - cur;
      ++round;
    }
    profile_line(ctx, "lazy_p1_round", nt, t0, one_group ? " (one work-group)" : "");
  }
}
}  // namespace

uint32_t conflict_pass1(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s) {
  const std::string F = "collapse_conflict.cl";
  ensure(s.result.edges_pass1, ctx, c.ne);
  ensure(s.result.edges2state, ctx, c.ne);
  ensure(s.result.verts2collapse, ctx, dm.nv);
  s.result.verts2collapse.fill(-1);
  run(ctx, F, "conflict_init", c.ne, arg("ne", c.ne), arg("edges_are_admissible", s.result.edges_are_admissible), arg("edges2state", s.result.edges2state));
  ensure(s.lazy.candidate_list, ctx, c.ne);
  const uint32_t n = dev::compact_indices(ctx, s.result.edges_are_admissible, s.lazy.candidate_list, c.ne);
  Kernel decide = kernel(ctx, F, "conflict_pass1_decide");
  pass1_rounds(ctx, decide, s, c, dm.nv, n, "conflict_pass1_decide");
  run(ctx, F, "conflict_pass1_finish", c.ne, arg("ne", c.ne), arg("edges", c.edges), arg("edges2state", s.result.edges2state), arg("edges_pass1", s.result.edges_pass1), arg("verts2collapse", s.result.verts2collapse), arg("counters", s.cost.counters));
  return read_counter(s.cost, 2);
}

uint32_t lazy_admissible_pass1(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                               uint32_t& passed_q, uint32_t& tested, bool restrict_clean) {
  const std::string T = "collapse_select_two_pass.cl";
  // the test's arguments, the same for the per-round kernel and the one-work-group loop
  Kernel decide = stage_kernel(ctx, p, T, "lazy_p1_decide"), loop = stage_kernel(ctx, p, T, "lazy_p1_loop");
  lazy_start(ctx, dm, c, s, p, s.cost.edges2cost, {&decide, &loop}, false, restrict_clean);
  lazy_p1_rounds(ctx, s, c, decide, loop, p);
  run(ctx, "collapse_conflict.cl", "conflict_pass1_finish", c.ne, arg("ne", c.ne), arg("edges", c.edges), arg("edges2state", s.result.edges2state), arg("edges_pass1", s.result.edges_pass1), arg("verts2collapse", s.result.verts2collapse), arg("counters", s.cost.counters));
  uint32_t cnt[6];
  s.cost.counters.download(cnt, 6);
  passed_q = cnt[5];
  tested = cnt[4];
  return cnt[2];
}

uint32_t conflict_pass2(Context& ctx, DeviceMesh&, Connectivity& c, EdgeState& s, TwoPassState& t, uint32_t loop_size) {
  const std::string F = "collapse_conflict.cl";
  ensure(s.result.edges_are_final, ctx, c.ne);
  run(ctx, F, "conflict_pass2_init", c.ne, arg("ne", c.ne), arg("edges_pass1", s.result.edges_pass1), arg("edges2state", s.result.edges2state));
  const uint32_t n = prepare_candidates(ctx, s, t, s.result.edges_pass1, c.ne);
  Kernel round = kernel(ctx, F, "conflict_pass2_round"), loop = kernel(ctx, F, "conflict_pass2_loop");
  round.set(arg("edges", c.edges), arg("edges2cost", s.cost.edges2cost), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("verts2collapse", s.result.verts2collapse), arg("edges2state", s.result.edges2state));
  loop.set(arg("edges", c.edges), arg("edges2cost", s.cost.edges2cost), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("verts2collapse", s.result.verts2collapse), arg("edges2state", s.result.edges2state));
  // the last rounds (at most loop_size candidates left) in one work-group
  auto tail = [&](uint32_t m, cl_int first, int cur) {
    loop.set(arg("n", m), arg("first", first), arg("cur", cl_int(cur)), arg("l0", s.lazy.turn_lists[0]), arg("l1", s.lazy.turn_lists[1]), arg("next_n", s.lazy.list_counts), arg("cand", s.lazy.candidate_list), arg("slots2rivals", t.slots2rivals), arg("slots2rival_count", t.slots2rival_count));
    loop.launch_one_group(ctx);
  };
  rounds(
      ctx, s, n, "conflict_pass2_round",
      [&](uint32_t m, cl_int first, int cur) {
        round.set(arg("n", m), arg("first", first), arg("list", s.lazy.turn_lists[cur]), arg("next", s.lazy.turn_lists[1 - cur]), arg("next_n", s.lazy.list_counts), arg("cand", s.lazy.candidate_list), arg("slots2rivals", t.slots2rivals), arg("slots2rival_count", t.slots2rival_count));
        round.launch(ctx, m);
      },
      &tail, loop_size);
  run(ctx, F, "conflict_finalize", c.ne, arg("ne", c.ne), arg("edges", c.edges), arg("edges_pass1", s.result.edges_pass1), arg("edges2state", s.result.edges2state), arg("edges_are_final", s.result.edges_are_final), arg("verts2collapse", s.result.verts2collapse), arg("counters", s.cost.counters));
  return read_counter(s.cost, 3);
}

uint32_t next_selection_round(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, TwoPassState& t,
                              const StageParams& p, uint32_t& tested) {
  remember_for_carry(ctx, dm, c, s);  // s.carry.prev_verts_are_dirty: the stars of the collapses chosen so far
  std::swap(s.result.edges_are_final, t.rounds_final);
  std::swap(s.result.edges2dir, t.rounds_dir);
  std::swap(s.result.verts2collapse, t.rounds_verts2collapse);
  s.carry.verdict_ready = true;  // this iteration's verdicts still hold (same connectivity)
  uint32_t passed_q = 0;
  lazy_admissible_pass1(ctx, dm, c, s, p, passed_q, tested, true);  // edges with clean end points only
  const uint32_t total = conflict_pass2(ctx, dm, c, s, t);  // counters[3] counts both rounds
  run(ctx, "collapse_verdicts.cl", "merge_rounds_edges", c.ne, arg("ne", c.ne), arg("rounds_final", t.rounds_final), arg("rounds_dir", t.rounds_dir), arg("edges_are_final", s.result.edges_are_final), arg("edges2dir", s.result.edges2dir));
  run(ctx, "collapse_verdicts.cl", "merge_rounds_vertices", dm.nv, arg("nv", dm.nv), arg("rounds_verts2collapse", t.rounds_verts2collapse), arg("verts2collapse", s.result.verts2collapse));
  return total;
}


namespace {

// The paper's selection, with `rounds` selection rounds per iteration (next_selection_round).
class TwoPassSelection final : public Selection {
 public:
  explicit TwoPassSelection(int rounds) : rounds_(rounds) {}

 private:
  Chosen choose(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                const IterationStats&) override {
    Chosen r;
    lazy_admissible_pass1(ctx, dm, c, s, p, r.candidates, r.tested);
    r.selected = conflict_pass2(ctx, dm, c, s, state_);
    for (int round = 1; round < rounds_ && r.selected > 0; ++round) {
      uint32_t tested = 0;
      const uint32_t total = next_selection_round(ctx, dm, c, s, state_, p, tested);
      r.tested += tested;
      if (total == r.selected) break;  // nothing more
      r.selected = total;
    }
    return r;
  }
  void release(EdgeState& s) override {
    Selection::release(s);
    state_ = TwoPassState{};
  }
  int rounds_;
  TwoPassState state_;
};

}  // namespace

std::unique_ptr<Selection> make_two_pass_selection(int rounds) { return std::make_unique<TwoPassSelection>(rounds); }

}  // namespace tc::collapse_detail
