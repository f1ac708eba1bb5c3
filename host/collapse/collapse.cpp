// The collapse loop (paper, Algorithm 1) over the stages of host/collapse/stages.cpp.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <numeric>
#include <stdexcept>
#include <string>

#include "collapse/guard_surface.hpp"
#include "collapse/sequential_run.hpp"
#include "collapse/stages.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/error.hpp"
#include "geometry.h"

namespace tc {

using namespace collapse_detail;

namespace {

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Median of the first-iteration edge lengths (the cost buffer holds them when there is no user
// cost). nth_element: the lower median for an even count, as in tc::summarize.
double median_of(std::vector<double> v) {
  if (v.empty()) return 0;
  size_t m = (v.size() - 1) / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  return v[m];
}

void remap_elements(std::vector<int32_t>& elems, std::vector<int32_t>& tags, int arity,
                    const std::vector<int32_t>& origin) {
  const size_t n = elems.size() / arity;
  std::vector<int32_t> out, out_tags;
  out.reserve(elems.size());
  for (size_t i = 0; i < n; ++i) {
    int32_t v[3];
    bool ok = true;
    for (int k = 0; k < arity; ++k) {
      int32_t x = elems[i * arity + k];
      if (x < 0 || size_t(x) >= origin.size()) {
        ok = false;
        break;
      }
      v[k] = origin[x];
      for (int j = 0; j < k; ++j) ok = ok && v[j] != v[k];
    }
    if (!ok) continue;
    out.insert(out.end(), v, v + arity);
    if (i < tags.size()) out_tags.push_back(tags[i]);
  }
  elems.swap(out);
  if (!tags.empty()) tags.swap(out_tags);
}

}  // namespace

double median_edge_length(const Mesh& mesh) {
  std::vector<uint64_t> keys;
  keys.reserve(mesh.tets.size() / 4 * 6);
  for (size_t t = 0; t + 3 < mesh.tets.size(); t += 4)
    for (int e = 0; e < 6; ++e) {
      uint32_t a = uint32_t(mesh.tets[t + geo::TC_TET_EDGES[e][0]]), b = uint32_t(mesh.tets[t + geo::TC_TET_EDGES[e][1]]);
      if (a > b) std::swap(a, b);
      keys.push_back(uint64_t(a) << 32 | b);
    }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  std::vector<double> len;
  len.reserve(keys.size());
  const int64_t nv = mesh.num_vertices();
  for (uint64_t k : keys) {
    int64_t a = int64_t(k >> 32), b = int64_t(k & 0xffffffffu);
    if (a >= nv || b >= nv) continue;
    double d = 0;
    for (int c = 0; c < 3; ++c) d += (mesh.points[3 * b + c] - mesh.points[3 * a + c]) * (mesh.points[3 * b + c] - mesh.points[3 * a + c]);
    len.push_back(std::sqrt(d));
  }
  return median_of(std::move(len));
}

double volume_threshold(const Mesh& mesh, const CollapseOptions& options) {
  if (!options.eps_v_relative) return options.eps_v;
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i + 2 < mesh.points.size(); i += 3)
    for (int c = 0; c < 3; ++c) {
      lo[c] = std::min(lo[c], mesh.points[i + c]);
      hi[c] = std::max(hi[c], mesh.points[i + c]);
    }
  double d2 = 0;
  for (int c = 0; c < 3; ++c) d2 += hi[c] > lo[c] ? (hi[c] - lo[c]) * (hi[c] - lo[c]) : 0;
  return options.eps_v * d2 * std::sqrt(d2);
}

namespace {

// CollapseOptions::host_tail on this device (negative: automatic).
double host_tail_fraction(const CollapseOptions& o, const Context& ctx) {
  if (o.host_tail >= 0) return o.host_tail;
  if (!ctx.cpu_tuning()) return 0.0;
  return o.conflicts == CollapseOptions::Matching ? CollapseOptions::kHostTailCpuMatching : CollapseOptions::kHostTailCpu;
}

// CollapseOptions::host_tail_min_iterations (negative: automatic).
double host_tail_iterations(const CollapseOptions& o) {
  if (o.host_tail_min_iterations >= 0) return o.host_tail_min_iterations;
  return o.conflicts == CollapseOptions::Matching ? CollapseOptions::kHostTailIterationsMatching
                                                  : CollapseOptions::kHostTailIterations;
}

// After the last iteration of `its`, does the rest run on the host? When it collapsed fewer
// than fraction x its tets, and the collapses shrink slowly: at the ratio r of the last two
// iterations' counts (at most 0.95), c r^n < 1 takes n = ln c / ln(1 / r) >=
// host_tail_min_iterations more iterations (a tail that dies out fast, r ~0.6, is cheaper on
// the device than the host's fixed cost). Counts only: the choice is deterministic.
bool host_tail_due(const CollapseOptions& o, double fraction, const std::vector<IterationStats>& its) {
  if (!(fraction > 0) || o.conflicts == CollapseOptions::AtomicMin || o.eps_c > 1 || o.has_user_functions() ||
      its.size() < 2)
    return false;
  const IterationStats& s = its.back();
  if (s.iteration + 1 >= o.max_iterations || !(double(s.collapsed) < fraction * double(s.tets))) return false;
  const double c = double(s.collapsed);
  const double r = std::min(0.95, c / double(std::max<int64_t>(its[its.size() - 2].collapsed, 1)));
  return std::log(c) >= host_tail_iterations(o) * std::log(1 / r);
}

// The host tail: the sequential method, greedy, on the downloaded mesh (current numbering; its
// triangles and edges already remapped), with the run's target and volume threshold and the
// current mask. Its iterations continue the report's.
void finish_on_host(Mesh& mesh, const CollapseOptions& options, const collapse_detail::StageParams& p,
                    std::vector<uint8_t> mask, const sequential_detail::TailSeed* seed, CollapseReport& report) {
  const int done = int(report.iterations.size());
  CollapseOptions o = options;
  o.method = CollapseOptions::Sequential;
  o.sequential_skip_invalidated = false;  // greedy: every queued edge has a touched end point
  o.target_length = p.target;
  o.eps_v = p.eps_v;
  o.eps_v_relative = false;
  o.vertex_mask = std::move(mask);
  o.max_iterations = options.max_iterations - done;
  auto continued = [done](IterationStats t) {  // numbered on from the device's iterations
    t.iteration += done;
    t.on_host = true;
    return t;
  };
  o.progress = [&](const IterationStats& s) {
    if (options.progress) options.progress(continued(s));
  };
  sequential_detail::SequentialRun run(mesh, o, seed);
  run.set_greedy(true);
  while (run.step()) {
  }
  const CollapseReport r = run.finish();
  for (const IterationStats& t : r.iterations) report.iterations.push_back(continued(t));
  report.seconds_total += r.seconds_total;
}

// TETCOLLAPSE_HOST_TAIL_SEED=0 hands the host tail the mesh alone (a switch for the tests, which
// compare both ways: the same output).
bool tail_seed_enabled() {
  const char* e = std::getenv("TETCOLLAPSE_HOST_TAIL_SEED");
  return !(e && std::string(e) == "0");
}

// The host tail's seed (sequential_run.hpp) for the current mesh: its connectivity (carried
// through the last compaction, as the next iteration would build it), the tet neighbours, the
// flags and classes, and the touched flags (tail_touched) where the last iteration's selection
// was greedy and the verdicts are carried; else every vertex counts as touched.
void tail_seed(Context& ctx, DeviceMesh& dm, Connectivity& conn, EdgeState& st, const StageParams& p,
               const CollapseOptions& options, sequential_detail::TailSeed& seed) {
  const bool reuse = options.reuse_across_iterations;
  build_connectivity(ctx, dm, conn, p, reuse ? &st : nullptr);
  seed.vflags = conn.vflags.download_range(0, dm.nv);
  seed.vclass = conn.vclass.download_range(0, dm.nv);
  seed.tet_nbr = conn.tet_nbr.download_range(0, 4 * size_t(dm.nt));
  seed.edges = conn.edges.download_range(0, 2 * size_t(conn.ne));
  if (reuse && (options.conflicts == CollapseOptions::Greedy || options.conflicts == CollapseOptions::Matching)) {
    carry_verdicts(ctx, dm, conn, st);
    seed.touched = tail_touched(ctx, dm, conn, st);
  } else {
    seed.touched.assign(dm.nv, 1);
  }
}

}  // namespace

CollapseReport collapse(Mesh& mesh, const CollapseOptions& options, Context& ctx) {
  if (options.method == CollapseOptions::Sequential) return collapse_sequential(mesh, options);
  if (options.max_iterations < 0) throw std::invalid_argument("max_iterations must be >= 0");
  if (options.selection_rounds < 1) throw std::invalid_argument("selection_rounds must be >= 1");
  if (options.selection_rounds > 1 && options.conflicts != CollapseOptions::TwoPass)
    throw std::invalid_argument("selection_rounds > 1 needs the two-pass conflict detection");
  if (!(options.priority_levels >= 0) || !std::isfinite(options.priority_levels))
    throw std::invalid_argument("priority_levels must be finite and >= 0");
  if (!options.cost_cl_source.empty() && !(options.target_length > 0))
    throw std::invalid_argument("a user cost (cost_cl_source) needs an explicit target_length > 0");
  if (!(options.target_length > 0) && !(options.target_factor > 0))
    throw std::invalid_argument("target_factor must be > 0 when target_length is not given");

  if (options.conflicts == CollapseOptions::AtomicMin && !ctx.info().int64_atomics_extended)
    throw DeviceError("device '" + ctx.info().name +
                      "' lacks cl_khr_int64_extended_atomics (64-bit atomic min), which --conflicts atomic-min needs; "
                      "use --conflicts two-pass");
  CollapseReport report;
  report.device = ctx.info().name;
  report.vertices_in = mesh.num_vertices();
  report.tets_in = mesh.num_tets();

  StageParams p = params_from(options);
  p.eps_v = volume_threshold(mesh, options);
  report.eps_v = p.eps_v;

  const double t_start = now();
  DeviceMesh dm, next;
  // origin: input vertex -> current vertex
  std::vector<int32_t> origin0;
  upload_mesh(ctx, mesh, options, dm, options.spatial_order ? &origin0 : nullptr);
  if (!options.spatial_order) {
    origin0.resize(dm.nv);
    std::iota(origin0.begin(), origin0.end(), 0);
  }
  const uint32_t n_origin = dm.nv;
  DeviceBuffer<int32_t> origin(ctx, origin0);
  ctx.finish();
  report.seconds_upload = now() - t_start;

  Connectivity conn;
  EdgeState st;
  SurfaceGuard guard;
  bool host_tail = false;
  sequential_detail::TailSeed seed;
  const double tail_fraction = host_tail_fraction(options, ctx);
  p.target = options.target_length;
  const double t_loop = now();
  for (int it = 0; it < options.max_iterations && dm.nt > 0; ++it) {
    IterationStats s;
    s.iteration = it;
    s.vertices = dm.nv;
    s.tets = dm.nt;
    double t0 = now();
    build_connectivity(ctx, dm, conn, p, options.reuse_across_iterations ? &st : nullptr);
    ctx.finish();
    double t1 = now();
    s.seconds_connectivity = t1 - t0;
    s.edges = conn.ne;
    if (options.reuse_across_iterations) carry_verdicts(ctx, dm, conn, st);
    if (it == 0 && !(p.target > 0)) {
      // the target from the input's median edge length, on the device's edge list
      StageParams q = p;
      q.cost_source.clear();
      q.target = 0;
      cost_and_mark(ctx, dm, conn, st, q);
      report.median_edge_length = median_of(st.cost.download_range(0, conn.ne));
      p.target = options.target_factor * report.median_edge_length;
    }
    s.marked = cost_and_mark(ctx, dm, conn, st, p);
    double t2 = now();
    s.seconds_cost = t2 - t1;
    // Selection; again when the surface guard refuses some of it. marked and passed_q are
    // counted before the first selection, tested and the seconds add up over the selections
    // (a selection tests only edges no earlier one tested), the other counts are the last's.
    double t_sel = t2;
    // the matching selection applies its collapses as it takes them: the mesh as it is now, for
    // a selection again when the surface guard refuses some
    const bool matching = options.conflicts == CollapseOptions::Matching;
    if (matching) matching_backup(ctx, dm, st);
    for (bool first = true;; first = false) {
      // the admissible filter: every marked edge tested (atomic-min), or lazily within the greedy
      // selection or within pass 1
      if (options.conflicts == CollapseOptions::AtomicMin) {
        s.admissible = admissible(ctx, dm, conn, st, p);
        s.tested = s.marked;
      } else {
        uint32_t passed_q = 0, tested = 0;
        s.admissible = options.conflicts == CollapseOptions::Greedy ? greedy_selection(ctx, dm, conn, st, p, passed_q, tested)
                       : matching ? matching_selection(ctx, dm, conn, st, p, passed_q, tested)
                                  : lazy_admissible_pass1(ctx, dm, conn, st, p, passed_q, tested);
        if (first) s.passed_q = passed_q;
        s.tested += tested;
      }
      const double t4 = now();
      s.seconds_admissible += t4 - t_sel;
      t_sel = t4;
      // the conflict detection (the greedy selection's is done)
      if (options.conflicts == CollapseOptions::AtomicMin) {
        s.after_pass2 = s.after_pass1 = conflicts_atomic_min(ctx, dm, conn, st);
      } else if (options.conflicts == CollapseOptions::Greedy || matching) {
        s.after_pass2 = s.after_pass1 = s.admissible;
      } else {
        s.after_pass1 = s.admissible;
        s.after_pass2 = conflict_pass2(ctx, dm, conn, st);
      }
      for (int r = 1; r < options.selection_rounds && s.after_pass2 > 0; ++r) {
        uint32_t tested = 0;
        const uint32_t total = next_selection_round(ctx, dm, conn, st, p, tested);
        s.tested += tested;
        if (total == s.after_pass2) break;  // nothing more
        s.after_pass2 = total;
      }
      // Surface guard (guard_surface.hpp): the refused edges are unmarked; this iteration's
      // verdicts still hold for the next selection.
      uint32_t refused = 0;
      if (matching) {
        // the collapses are applied: the refused ones are undone, with those that saw them, and
        // the result is tested again
        while ((refused = guard.run_applied(ctx, dm, conn, st, p, uint32_t(s.after_pass2))) > 0)
          s.after_pass2 -= matching_undo(ctx, dm, conn, st, guard);
        s.after_pass1 = s.admissible = s.after_pass2;
      } else {
        refused = guard.run(ctx, dm, conn, st, p, uint32_t(s.after_pass2));
      }
      const double t5 = now();
      s.seconds_pass2 += t5 - t_sel;
      t_sel = t5;
      if (refused == 0) break;
      st.verdict_ready = true;
    }
    s.collapsed = s.after_pass2;
    if (s.collapsed > 0) {
      if (options.reuse_across_iterations) remember_for_carry(ctx, dm, conn, st);
      collapse_and_compact(ctx, p, dm, next, conn, st, origin, n_origin);
      if (options.reuse_across_iterations) note_compaction(ctx, dm, conn, st);
    }
    ctx.finish();
    double t6 = now();
    s.seconds_collapse = t6 - t_sel;
    s.seconds_total = t6 - t0;
    s.vertices_after = dm.nv;
    s.tets_after = dm.nt;
    report.iterations.push_back(s);
    if (options.progress) options.progress(s);
    if (s.collapsed < std::max<int64_t>(options.eps_c, 1)) break;
    if (host_tail_due(options, tail_fraction, report.iterations)) {
      host_tail = true;
      if (tail_seed_enabled()) tail_seed(ctx, dm, conn, st, p, options, seed);
      break;
    }
  }
  report.target_length = p.target;
  const double t_down = now();
  report.seconds_total = t_down - t_loop;

  download_mesh(dm, mesh);
  if (!mesh.tris.empty() || !mesh.edges.empty()) {
    std::vector<int32_t> org = origin.download();
    remap_elements(mesh.tris, mesh.tri_tags, 3, org);
    remap_elements(mesh.edges, mesh.edge_tags, 2, org);
  }
  std::vector<uint8_t> mask;
  if (host_tail && dm.has_mask) mask = dm.vmask.download_range(0, dm.nv);
  report.seconds_download = now() - t_down;
  if (host_tail) finish_on_host(mesh, options, p, std::move(mask), seed.vflags.empty() ? nullptr : &seed, report);
  report.vertices_out = mesh.num_vertices();
  report.tets_out = mesh.num_tets();
  return report;
}

}  // namespace tc
