// What a looser conflict rule would give per iteration (a what-if for the speed goal; nothing
// in the pipeline uses the other rules). On a mesh's first iteration, in the greedy selection's
// priority order (cl/collapse_admissible.cl, greedy_*: 64 steps per target length, then the
// index hash), it counts the collapses each rule takes:
//   current:  an admissible edge (admissible(): verdicts on every marked edge, no surface guard)
//             is taken unless an end point is within reach of an edge taken before it (an end
//             point or a neighbour of one): the greedy selection itself, so its count equals the
//             device's first iteration when the guard refuses nothing;
//   moved:    within reach only of the vertices a collapse moves or removes (both end points for
//             a midpoint, the removed one when the survivor stays put): the changed tets are
//             then disjoint and neither changes the links the other's link condition reads;
//   checked:  edges sharing no end point, each tested (SeqMesh: Q, link condition, volume) on
//             the mesh with the earlier ones collapsed. Such a sequence is valid, so this is
//             what a selection that tests collapses sharing tets together could take; also the
//             tests it makes and the rounds a parallel version would need (a candidate decides
//             once every candidate before it within reach has, or when an edge at an end point
//             is taken);
//   matching: admissible edges sharing no end point, untested against each other (a bound for
//             the others, except that "checked" also takes edges refused on the start mesh that
//             pass once their neighbours have collapsed, as the quality guard's refusals do).
// With --whole-run, the current and checked rules also run to the end on the host (SeqMesh,
// surface guard included), printing the collapses per iteration; with --out PREFIX it writes
// each rule's final mesh to PREFIXcurrent.vtu and PREFIXchecked.vtu (for `tetcollapse check`).
//
//   bench_conflict_rule [MESH] [--target-factor F] [--min-quality Q] [--priority-levels L]
//                       [--whole-run [--out PREFIX]]
// Defaults (bench_stage_setup.hpp): W1's mesh (robot 514k), 2 x median edge length, min_quality 0.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numeric>
#include <string>
#include <vector>

#include "collapse/sequential_mesh.hpp"
#include "collapse_predicate.h"
#include "collapse/sequential_run.hpp"
#include "bench_stage_setup.hpp"

using namespace tc;
using namespace tc::collapse_detail;

int main(int argc, char** argv) {
  bench::StageBenchArgs a;
  bool whole_run = false;
  std::string out_prefix;  // with --whole-run: each rule's final mesh to PREFIX{current,checked}.vtu
  auto own = [&](int& i) {
    if (!std::strcmp(argv[i], "--whole-run")) {
      whole_run = true;
      return true;
    }
    if (std::strcmp(argv[i], "--out") || i + 1 >= argc) return false;
    out_prefix = argv[++i];
    return true;
  };
  if (int rc = bench::parse_stage_args("bench_conflict_rule", argc, argv, a, own, false); rc >= 0) return rc;
  bench::StageBench b;
  if (!bench::load_stage_bench("bench_conflict_rule", a, b)) return 1;
  auto& [mesh, ctx, p, dm, vertex_new, c] = b;
  CollapseOptions& o = a.options;
  const std::string& path = a.path;
  EdgeState s;
  const uint32_t marked = cost_and_mark(ctx, dm, c, s, p);
  const uint32_t adm = admissible(ctx, dm, c, s, p);
  const std::vector<uint8_t> reason = s.result.edges2reason.download_range(0, c.ne);
  const std::vector<uint8_t> dir = s.result.edges2dir.download_range(0, c.ne);
  const std::vector<double> cost = s.cost.edges2cost.download_range(0, c.ne);
  const std::vector<int32_t> edges = c.edges.download_range(0, size_t(c.ne) * 2);
  const std::vector<uint32_t> nb_off = c.nb_off.download_range(0, size_t(dm.nv) + 1);
  const std::vector<int32_t> nb = c.nb.download_range(0, nb_off.back());
  // greedy_priority's order: floor(cost / target * levels), then the index hash (a bijection)
  std::vector<uint32_t> order;
  for (uint32_t e = 0; e < c.ne; ++e)
    if (reason[e] == kOk) order.push_back(e);
  auto prio = [&](uint32_t e) {
    return std::floor(cost[e] / p.target * p.priority_levels) + double(e * 2654435761u) * (1.0 / 4294967296.0);
  };
  auto by_prio = [&](uint32_t a, uint32_t b) {
    const double pa = prio(a), pb = prio(b);
    return pa < pb || (pa == pb && a < b);
  };
  std::sort(order.begin(), order.end(), by_prio);
  // the vertices a collapse moves or removes (dir bits: collapse_predicate.h)
  auto moved = [&](uint32_t e, int32_t* m) {
    const int32_t v0 = edges[2 * e], v1 = edges[2 * e + 1];
    const uint8_t d = dir[e];
    if (d & (TCC_DIR_MIDPOINT | TCC_DIR_USER)) {  // both move
      m[0] = v0;
      m[1] = v1;
      return 2;
    }
    m[0] = (d & TCC_DIR_REMOVE_V1) ? v1 : v0;
    return 1;
  };
  auto close_nbhd = [&](int32_t v, auto&& fn) {
    fn(v);
    for (uint32_t j = nb_off[v]; j < nb_off[v + 1]; ++j) fn(nb[j]);
  };
  // The round of the first of two rounds given per vertex (-1: none), one of them given.
  auto first_of = [](int32_t x, int32_t y) { return x >= 0 && y >= 0 ? std::min(x, y) : std::max(x, y); };
  // The round after the last one in which a candidate within reach of (a, b) decided.
  auto after_reach = [&](const std::vector<int32_t>& last, int32_t a, int32_t b) {
    int32_t r = 0;
    for (int32_t x : {a, b}) close_nbhd(x, [&](int32_t z) { r = std::max(r, last[z]); });
    return r + 1;
  };
  // current rule: mark N[a] and N[b] of each taken edge; an edge with a marked end point waits.
  //
  // Its rounds as the checked rule's below: an edge decides once every admissible edge before it
  // within reach has decided, or in the round an edge within reach is taken (reach_at: the first
  // such round per vertex). Only the admissible edges here (the device also waits for the refused
  // ones, whose speculative volume test decides them early).
  std::vector<uint8_t> reach(dm.nv, 0);
  std::vector<int32_t> last_cur(dm.nv, 0), reach_at(dm.nv, -1);
  size_t taken_current = 0, kept_current = 0;
  int32_t rounds_current = 0;
  for (uint32_t e : order) {
    const int32_t a = edges[2 * e], b = edges[2 * e + 1];
    const int32_t r = reach[a] || reach[b] ? first_of(reach_at[a], reach_at[b]) : after_reach(last_cur, a, b);
    last_cur[a] = std::max(last_cur[a], r);
    last_cur[b] = std::max(last_cur[b], r);
    rounds_current = std::max(rounds_current, r);
    if (reach[a] || reach[b]) continue;
    ++taken_current;
    int32_t m[2];
    kept_current += moved(e, m) == 1;
    close_nbhd(a, [&](int32_t z) {
      reach[z] = 1;
      if (reach_at[z] < 0) reach_at[z] = r;
    });
    close_nbhd(b, [&](int32_t z) {
      reach[z] = 1;
      if (reach_at[z] < 0) reach_at[z] = r;
    });
  }
  // moved rule: near_moved = N[M(t)], near_ends = N[E(t)] of the taken edges t; e waits when an end
  // point of e is near a moved vertex or a vertex e moves is near an end point
  std::vector<uint8_t> near_moved(dm.nv, 0), near_ends(dm.nv, 0);
  size_t taken_moved = 0, kept_moved = 0;
  for (uint32_t e : order) {
    const int32_t a = edges[2 * e], b = edges[2 * e + 1];
    int32_t m[2];
    const int nm = moved(e, m);
    bool wait = near_moved[a] || near_moved[b];
    for (int k = 0; k < nm && !wait; ++k) wait = near_ends[m[k]];
    if (wait) continue;
    ++taken_moved;
    kept_moved += nm == 1;
    for (int k = 0; k < nm; ++k) close_nbhd(m[k], [&](int32_t z) { near_moved[z] = 1; });
    close_nbhd(a, [&](int32_t z) { near_ends[z] = 1; });
    close_nbhd(b, [&](int32_t z) { near_ends[z] = 1; });
  }
  // nearly a bound: vertex-disjoint admissible edges (a matching; collapses sharing tets would
  // need their combined result tested)
  std::vector<uint8_t> used(dm.nv, 0);
  size_t taken_matching = 0;
  for (uint32_t e : order) {
    const int32_t a = edges[2 * e], b = edges[2 * e + 1];
    if (used[a] || used[b]) continue;
    ++taken_matching;
    used[a] = used[b] = 1;
  }
  // What checking the combined result could keep: vertex-disjoint edges taken one after another in
  // the same order, each checked (Q, link condition, volume; no surface guard) on the mesh with the
  // earlier ones collapsed (SeqMesh), over the marked edges that pass Q at the start. Such a
  // sequence is valid, so this bounds what a selection of collapses that share tets, tested
  // together, could take in one iteration.
  size_t taken_checked = 0, checks_checked = 0;
  std::vector<size_t> checks_per_round;
  int32_t rounds_checked = 0;
  {
    std::vector<int32_t> input_of(dm.nv, -1);  // device vertex -> input vertex
    for (size_t v = 0; v < vertex_new.size(); ++v) input_of[vertex_new[v]] = int32_t(v);
    if (vertex_new.empty()) std::iota(input_of.begin(), input_of.end(), 0);
    Mesh work = mesh;
    sequential_detail::SeqMesh sm(work, sequential_detail::seq_params_from(o));
    std::vector<uint32_t> cands;
    for (uint32_t e = 0; e < c.ne; ++e)
      if (reason[e] != kNotMarked && reason[e] != kRefusedQ) cands.push_back(e);
    std::sort(cands.begin(), cands.end(), by_prio);
    // The rounds a parallel version would need, from the decisions: a candidate decides once every
    // candidate before it within reach (an end point in N[a] or N[b], on the start mesh) has
    // decided, or at once in the round where an edge sharing an end point is taken. Per vertex: the
    // last round in which a candidate at it decided (last_at), and the round in which an edge at it
    // was taken (taken_at).
    std::vector<int32_t> last_at(dm.nv, 0), taken_at(dm.nv, -1);
    std::vector<uint8_t> end_point(mesh.num_vertices(), 0);  // of a collapse taken (input numbering)
    for (uint32_t e : cands) {
      const int32_t da = edges[2 * e], db = edges[2 * e + 1];  // device numbering (N on the start mesh)
      const int32_t r = taken_at[da] >= 0 || taken_at[db] >= 0 ? first_of(taken_at[da], taken_at[db])
                                                               : after_reach(last_at, da, db);
      int32_t a = input_of[da], b = input_of[db];
      bool in = false;
      if (!end_point[a] && !end_point[b] && sm.alive(a) && sm.alive(b) && sm.is_edge(a, b)) {
        if (a > b) std::swap(a, b);
        ++checks_checked;
        if (size_t(r) >= checks_per_round.size()) checks_per_round.resize(size_t(r) + 1, 0);
        ++checks_per_round[size_t(r)];
        const sequential_detail::Verdict v = sm.check(a, b);
        if (v.reason == kOk) {
          sm.collapse(a, b, v.dir);
          end_point[a] = end_point[b] = 1;
          ++taken_checked;
          in = true;
        }
      }
      last_at[da] = std::max(last_at[da], r);
      last_at[db] = std::max(last_at[db], r);
      if (in) taken_at[da] = taken_at[db] = r;
      rounds_checked = std::max(rounds_checked, r);
    }
  }
  std::printf("mesh %s\n%u vertices, %u edges, %u marked, %u admissible (target %g, min_quality %g)\n", path.c_str(),
              dm.nv, c.ne, marked, adm, p.target, p.min_quality);
  std::printf("current rule: %zu collapses (%zu keep an end point in place), %d rounds\n", taken_current, kept_current,
              rounds_current);
  std::printf("moved rule:   %zu collapses (%zu keep an end point in place): %.2fx\n", taken_moved, kept_moved,
              double(taken_moved) / double(std::max<size_t>(1, taken_current)));
  std::printf("checked:      %zu collapses (vertex-disjoint, each checked after the earlier ones): %.2fx; %zu checks, "
              "%d rounds\n",
              taken_checked, double(taken_checked) / double(std::max<size_t>(1, taken_current)), checks_checked,
              rounds_checked);
  {
    std::printf("  checks by round:");
    size_t cum = 0;
    for (size_t r = 0; r < checks_per_round.size(); ++r) {
      cum += checks_per_round[r];
      if (r == 5 || r == 10 || r == 20 || r == 30 || r == 50 || r == 100 || r == 150 || r + 1 == checks_per_round.size())
        std::printf(" <=%zu: %.1f%%", r, 100.0 * double(cum) / double(std::max<size_t>(1, checks_checked)));
    }
    std::printf("\n");
  }
  std::printf("matching:     %zu collapses (vertex-disjoint edges admissible at the start): %.2fx\n", taken_matching,
              double(taken_matching) / double(std::max<size_t>(1, taken_current)));
  if (whole_run) {
    // Both rules to the end, iteration by iteration, on the host (SeqMesh, surface guard included):
    // each iteration lists the marked edges (shorter than the target) that pass Q, in priority
    // order (the 64 steps, then a hash of the end points), and takes them one after another:
    // "current" when no end point is within reach of an edge taken before it in this iteration
    // (checked on the mesh as it is: the same as on the iteration's start mesh, since such edges do
    // not interact), "checked" when no end point is an end point of one (checked on the mesh with
    // the earlier ones collapsed).
    for (int rule = 0; rule < 2; ++rule) {
      Mesh work = mesh;
      sequential_detail::SeqMesh sm(work, sequential_detail::seq_params_from(o));
      sm.build_guard(p.target);
      std::vector<int32_t> nbv;
      size_t total = 0;
      std::printf("%s rule, collapses per iteration:", rule == 0 ? "current" : "checked");
      int it = 0;
      for (;; ++it) {
        struct Cand {
          double prio;
          int32_t a, b;
        };
        std::vector<Cand> cands;
        for (int32_t v = 0; v < sm.num_vertices(); ++v) {
          if (!sm.alive(v)) continue;
          sm.neighbours(v, nbv, true);
          for (int32_t u : nbv) {
            const double len = sm.length(v, u);
            if (!(len < p.target)) continue;
            const uint32_t h = uint32_t(v) * 2654435761u ^ uint32_t(u) * 40503u;
            cands.push_back({std::floor(len / p.target * p.priority_levels) + double(h) / 4294967296.0, v, u});
          }
        }
        std::sort(cands.begin(), cands.end(), [](const Cand& x, const Cand& y) {
          return x.prio < y.prio || (x.prio == y.prio && (x.a < y.a || (x.a == y.a && x.b < y.b)));
        });
        std::vector<uint8_t> blocked(sm.num_vertices(), 0);
        size_t n = 0;
        for (const Cand& cd : cands) {
          const int32_t a = cd.a, b = cd.b;
          if (blocked[a] || blocked[b] || !sm.alive(a) || !sm.alive(b) || !sm.is_edge(a, b)) continue;
          const sequential_detail::Verdict v = sm.check(a, b);
          if (v.reason != kOk || !sm.guard_ok(a, b, v.dir)) continue;
          if (rule == 0) {  // N[a] and N[b] on the mesh before this collapse
            for (int32_t x : {a, b}) {
              blocked[x] = 1;
              sm.neighbours(x, nbv);
              for (int32_t z : nbv) blocked[z] = 1;
            }
          }
          const int32_t m = sm.collapse(a, b, v.dir);
          blocked[a] = blocked[b] = blocked[m] = 1;
          ++n;
        }
        std::printf(" %zu", n);
        std::fflush(stdout);
        total += n;
        if (n == 0) break;
      }
      std::printf("\n  %d iterations (the last takes nothing), %zu collapses, %d vertices and %d tets left\n", it + 1,
                  total, sm.alive_vertices(), sm.alive_tets());
      if (!out_prefix.empty()) {
        std::vector<int32_t> vmap, kept;
        sm.compact(vmap, kept);
        const std::string out = out_prefix + (rule == 0 ? "current.vtu" : "checked.vtu");
        write_mesh(out, work);
        std::printf("  written to %s\n", out.c_str());
      }
    }
  }
  return 0;
}
