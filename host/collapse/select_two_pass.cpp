// The paper's two-pass selection: the lazy admissible filter with conflict pass 1, conflict
// pass 2, further selection rounds (cl/collapse_conflict.cl, cl/collapse_admissible.cl lazy_p1_*).
#include "collapse/select_two_pass.hpp"

#include <memory>

#include "collapse/select_lazy.hpp"
#include "collapse/selection.hpp"
#include "collapse/verdict_carry.hpp"
#include "device/primitives.hpp"
#include "stopwatch.hpp"

namespace tc::collapse_detail {

namespace {
// Compacts the candidate edges (flags[e] != 0) into s.candidate_list and prepares the per-slot
// rival storage; returns their number.
uint32_t prepare_candidates(Context& ctx, EdgeState& s, const DeviceBuffer<uint32_t>& flags, uint32_t ne) {
  ensure(s.candidate_list, ctx, ne);
  const uint32_t n = dev::compact_indices(ctx, flags, s.candidate_list, ne);
  ensure(s.slots2rival_count, ctx, n);
  ensure(s.slots2rivals, ctx, size_t(n) * 16);  // TCC_RIVALS
  s.slots2rival_count.fill(0xffffffffu);             // TCC_UNSCANNED
  return n;
}

// The worklist loop of the conflict rounds: round(n, first, cur) enqueues one round over the n
// entries of s.turn_lists[cur] (all candidates when first), which appends those still undecided to
// s.turn_lists[1 - cur] via s.list_counts; repeats until none is left. Every round decides at least the
// undecided candidate of smallest (cost, index), so this terminates. When `tail` is given,
// the rounds left once at most tail_size entries remain go to tail(n, first, cur), which runs
// them all in one launch.
template <class Round, class Tail = void (*)(uint32_t, cl_int, int)>
void rounds(Context& ctx, EdgeState& s, uint32_t n, const char* what, const Round& round, const Tail* tail = nullptr,
            uint32_t tail_size = 0) {
  ensure(s.list_counts, ctx, 1);
  ensure(s.turn_lists[0], ctx, n);
  ensure(s.turn_lists[1], ctx, n);
  int cur = 0;
  for (cl_int first = 1; n > 0; first = 0) {
    s.list_counts.fill(0);
    const double t0 = Stopwatch::now();
    if (tail && n <= tail_size) {
      (*tail)(n, first, cur);
      profile_line(ctx, what, n, t0, " (all remaining rounds)");
      return;
    }
    round(n, first, cur);
    uint32_t next = 0;
    s.list_counts.download(&next, 1);
    profile_line(ctx, what, n, t0);
    n = next;
    cur = 1 - cur;
  }
}

// Pass-1 rounds (collapse_conflict.cl: pass1_claim, then `decide`, whose arguments other than
// the round's are already set) over the n candidates of s.candidate_list until none is left
// undecided. s.verts2collapse must be -1 everywhere; it ends with the IN edge at each vertex.
void pass1_rounds(Context& ctx, Kernel& decide, EdgeState& s, const Connectivity& c, uint32_t nv, uint32_t n,
                  const char* what) {
  ensure(s.verts2slot[0], ctx, nv);
  ensure(s.verts2slot[1], ctx, nv);
  s.verts2slot[0].fill(-1);
  s.verts2slot[1].fill(-1);
  Kernel claim = kernel(ctx, "collapse_conflict.cl", "pass1_claim");
  auto round = [&](uint32_t m, cl_int first, int cur) {
    claim.set(arg("n", m), arg("first", first), arg("list", s.turn_lists[cur]), arg("cand", s.candidate_list), arg("edges", c.edges), arg("cost", s.edges2cost), arg("vaff", s.verts2collapse), arg("slot", s.verts2slot[cur]), arg("state", s.edges2state));
    claim.launch(ctx, m);
    decide.set(arg("n", m), arg("first", first), arg("list", s.turn_lists[cur]), arg("next", s.turn_lists[1 - cur]), arg("next_n", s.list_counts), arg("cand", s.candidate_list), arg("edges", c.edges), arg("slot", s.verts2slot[cur]), arg("slot_next", s.verts2slot[1 - cur]), arg("state", s.edges2state), arg("vaff", s.verts2collapse));
    decide.launch(ctx, m);
  };
  rounds(ctx, s, n, what, round);
}
}  // namespace

namespace {
// Pass 1 of the lazy filter over the candidates (s.edges_are_candidates[e] != 0 for e < ne; lazy_init made them
// and their first claims in s.verts2slot[0]; cl/collapse_admissible.cl, lazy_p1_*): rounds over the
// turn list until it is empty. `decide` and `loop` have the test's arguments set. s.verts2collapse must
// be -1 everywhere. The rounds run in one work-group (lazy_p1_loop) while the turn list holds
// at most p.loop_tests edges to test (the others take the verdict carried from the previous
// iteration, cheap) and at most p.loop_turns in all; the loop hands back to the per-round
// kernels when a list has more than p.loop_exit_tests to test.
void lazy_p1_rounds(Context& ctx, EdgeState& s, const Connectivity& c, Kernel& decide, Kernel& loop,
                    const StageParams& p) {
  const std::string A = "collapse_admissible.cl";
  const uint32_t n = c.ne;  // bounds the candidates
  ensure(s.edges2queued, ctx, c.ne);
  ensure(s.turn_lists[0], ctx, n);
  ensure(s.turn_lists[1], ctx, n);
  ensure(s.vertex_list, ctx, 2 * size_t(n) + 1);  // an edge is listed at most twice per pass
  ensure(s.list_counts, ctx, 4);
  ensure(s.loop_resume, ctx, 3);
  s.edges2queued.fill(0xffffffffu);
  s.list_counts.fill(0);
  if (n == 0) return;
  run(ctx, A, "lazy_p1_first_turns", n, arg("ne", n), arg("cand", s.edges_are_candidates), arg("edges", c.edges), arg("slot", s.verts2slot[0]), arg("tlist", s.turn_lists[0]), arg("cnt", s.list_counts), arg("verdict", s.edges2verdict));
  uint32_t cnt[4];
  s.list_counts.download(cnt, 4);
  uint32_t nt = cnt[0], nu = cnt[3];
  Kernel recompute = kernel(ctx, A, "lazy_p1_recompute"), turns = kernel(ctx, A, "lazy_p1_turns");
  int cur = 0;  // the list of this round
  cl_uint round = 0;
  while (nt > 0) {
    const double t0 = Stopwatch::now();
    s.list_counts.fill(0);
    const bool one_group = nu <= p.loop_tests && nt <= p.loop_turns;
    if (one_group) {
      s.loop_resume.fill(0);
      loop.set(arg("n", nt), arg("cur", cl_int(cur)), arg("round", round), arg("t0", s.turn_lists[0]), arg("t1", s.turn_lists[1]), arg("cnt", s.list_counts), arg("dlist", s.vertex_list), arg("queued", s.edges2queued), arg("edges", c.edges), arg("cost", s.edges2cost), arg("slot", s.verts2slot[0]), arg("state", s.edges2state), arg("vaff", s.verts2collapse), arg("max_tests", cl_uint(p.loop_exit_tests)), arg("resume", s.loop_resume));
      loop.launch_one_group(ctx);
      uint32_t r[3];
      s.loop_resume.download(r, 3);
      nt = r[0];  // 0: every round done; else the loop stopped before a list with many to test
      nu = UINT32_MAX;
      cur = int(r[1]);
      round = r[2];
    } else {
      decide.set(arg("n", nt), arg("tlist", s.turn_lists[cur]), arg("edges", c.edges), arg("state", s.edges2state), arg("vaff", s.verts2collapse), arg("slot", s.verts2slot[0]), arg("dlist", s.vertex_list), arg("cnt", s.list_counts));
      decide.launch(ctx, nt);
      vertex_part(ctx, s, c, recompute, turns, s.edges2cost, cur, round);
      s.list_counts.download(cnt, 4);
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
  ensure(s.edges_pass1, ctx, c.ne);
  ensure(s.edges2state, ctx, c.ne);
  ensure(s.verts2collapse, ctx, dm.nv);
  s.verts2collapse.fill(-1);
  run(ctx, F, "conflict_init", c.ne, arg("ne", c.ne), arg("adm", s.edges_are_admissible), arg("state", s.edges2state));
  ensure(s.candidate_list, ctx, c.ne);
  const uint32_t n = dev::compact_indices(ctx, s.edges_are_admissible, s.candidate_list, c.ne);
  Kernel decide = kernel(ctx, F, "conflict_pass1_decide");
  pass1_rounds(ctx, decide, s, c, dm.nv, n, "conflict_pass1_decide");
  run(ctx, F, "conflict_pass1_finish", c.ne, arg("ne", c.ne), arg("edges", c.edges), arg("state", s.edges2state), arg("p1", s.edges_pass1), arg("vaff", s.verts2collapse), arg("counters", s.counters));
  return read_counter(s, 2);
}

uint32_t lazy_admissible_pass1(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                               uint32_t& passed_q, uint32_t& tested) {
  const std::string A = "collapse_admissible.cl";
  // the test's arguments, the same for the per-round kernel and the one-work-group loop
  Kernel decide = stage_kernel(ctx, p, A, "lazy_p1_decide"), loop = stage_kernel(ctx, p, A, "lazy_p1_loop");
  lazy_start(ctx, dm, c, s, p, s.edges2cost, {&decide, &loop});
  lazy_p1_rounds(ctx, s, c, decide, loop, p);
  run(ctx, "collapse_conflict.cl", "conflict_pass1_finish", c.ne, arg("ne", c.ne), arg("edges", c.edges), arg("state", s.edges2state), arg("p1", s.edges_pass1), arg("vaff", s.verts2collapse), arg("counters", s.counters));
  uint32_t cnt[6];
  s.counters.download(cnt, 6);
  passed_q = cnt[5];
  tested = cnt[4];
  return cnt[2];
}

uint32_t conflict_pass2(Context& ctx, DeviceMesh&, Connectivity& c, EdgeState& s, uint32_t loop_size) {
  const std::string F = "collapse_conflict.cl";
  ensure(s.edges_are_final, ctx, c.ne);
  run(ctx, F, "conflict_pass2_init", c.ne, arg("ne", c.ne), arg("p1", s.edges_pass1), arg("state", s.edges2state));
  const uint32_t n = prepare_candidates(ctx, s, s.edges_pass1, c.ne);
  Kernel round = kernel(ctx, F, "conflict_pass2_round"), loop = kernel(ctx, F, "conflict_pass2_loop");
  round.set(arg("edges", c.edges), arg("cost", s.edges2cost), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("vaff", s.verts2collapse), arg("state", s.edges2state));
  loop.set(arg("edges", c.edges), arg("cost", s.edges2cost), arg("nb_off", c.nb_off), arg("nb", c.nb), arg("vaff", s.verts2collapse), arg("state", s.edges2state));
  // the last rounds (at most loop_size candidates left) in one work-group
  auto tail = [&](uint32_t m, cl_int first, int cur) {
    loop.set(arg("n", m), arg("first", first), arg("cur", cl_int(cur)), arg("l0", s.turn_lists[0]), arg("l1", s.turn_lists[1]), arg("next_n", s.list_counts), arg("cand", s.candidate_list), arg("rivals", s.slots2rivals), arg("rcount", s.slots2rival_count));
    loop.launch_one_group(ctx);
  };
  rounds(
      ctx, s, n, "conflict_pass2_round",
      [&](uint32_t m, cl_int first, int cur) {
        round.set(arg("n", m), arg("first", first), arg("list", s.turn_lists[cur]), arg("next", s.turn_lists[1 - cur]), arg("next_n", s.list_counts), arg("cand", s.candidate_list), arg("rivals", s.slots2rivals), arg("rcount", s.slots2rival_count));
        round.launch(ctx, m);
      },
      &tail, loop_size);
  run(ctx, F, "conflict_finalize", c.ne, arg("ne", c.ne), arg("edges", c.edges), arg("p1", s.edges_pass1), arg("state", s.edges2state), arg("fin", s.edges_are_final), arg("vaff", s.verts2collapse), arg("counters", s.counters));
  return read_counter(s, 3);
}

uint32_t next_selection_round(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                              uint32_t& tested) {
  remember_for_carry(ctx, dm, c, s);  // s.prev_verts_are_dirty: the stars of the collapses chosen so far
  std::swap(s.edges_are_final, s.rounds_final);
  std::swap(s.edges2dir, s.rounds_dir);
  std::swap(s.verts2collapse, s.rounds_verts2collapse);
  s.restrict_clean = true;
  s.verdict_ready = true;  // this iteration's verdicts still hold (same connectivity)
  uint32_t passed_q = 0;
  lazy_admissible_pass1(ctx, dm, c, s, p, passed_q, tested);
  const uint32_t total = conflict_pass2(ctx, dm, c, s);  // counters[3] counts both rounds
  run(ctx, "collapse_verdicts.cl", "merge_rounds_edges", c.ne, arg("ne", c.ne), arg("fin1", s.rounds_final), arg("dir1", s.rounds_dir), arg("fin", s.edges_are_final), arg("dir", s.edges2dir));
  run(ctx, "collapse_verdicts.cl", "merge_rounds_vertices", dm.nv, arg("nv", dm.nv), arg("vaff1", s.rounds_verts2collapse), arg("vaff", s.verts2collapse));
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
    r.selected = conflict_pass2(ctx, dm, c, s);
    for (int round = 1; round < rounds_ && r.selected > 0; ++round) {
      uint32_t tested = 0;
      const uint32_t total = next_selection_round(ctx, dm, c, s, p, tested);
      r.tested += tested;
      if (total == r.selected) break;  // nothing more
      r.selected = total;
    }
    return r;
  }
  int rounds_;
};

}  // namespace

std::unique_ptr<Selection> make_two_pass_selection(int rounds) { return std::make_unique<TwoPassSelection>(rounds); }

}  // namespace tc::collapse_detail
