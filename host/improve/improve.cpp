// The improvement's driver: the algorithm of tetcollapse/improve.hpp.
#include "tetcollapse/improve.hpp"

#include <algorithm>
#include <cmath>

#include "collapse/params.hpp"
#include "collapse/programs.hpp"
#include "collapse/sequential_run.hpp"
#include "improve/improve_mesh.hpp"
#include "improve/star_mesh.hpp"
#include "stopwatch.hpp"

namespace tc {

using namespace improve_detail;

namespace {

constexpr double kDeg = 180.0 / 3.14159265358979323846;
constexpr double kMinAngleGain = 0.05;  // degrees
constexpr double kMinCountGain = 0.05;  // share of the tets below 10 or 13 degrees
// The collapse step's rounds (ImproveOptions::collapse_rounds): each only after one that raised
// the smallest angle by kMinAngleGain or removed this share of the tets below 10 or 13 degrees.
constexpr double kMinRoundGain = 0.1;
// A tet is below 10 (13) degrees when the cosine of its smallest angle is above these.
const double kCos10 = std::cos(10 / kDeg);  // (kCos13: improve_mesh.hpp)
// The vertex mask through the collapse step (collapse_bad).
const char* const kMaskField = "tetcollapse:improve-mask";

// The live tets below the threshold, worst first (ties by index: deterministic).
std::vector<int32_t> bad_tets(const ImpMesh& m, double threshold) {
  std::vector<int32_t> bad;
  for (int32_t t = 0; t < m.num_tet_slots(); ++t)
    if (m.alive(t) && m.quality(t) < threshold) bad.push_back(t);
  std::sort(bad.begin(), bad.end(), [&](int32_t a, int32_t b) {
    return m.quality(a) < m.quality(b) || (m.quality(a) == m.quality(b) && a < b);
  });
  return bad;
}

// The smallest dihedral angle and the tets below 10 and 13 degrees, from the kept cosines.
void measure(const ImpMesh& m, ImprovePassStats& s) {
  double c = -1;
  for (int32_t t = 0; t < m.num_tet_slots(); ++t)
    if (m.alive(t)) {
      c = std::max(c, m.max_cos(t));
      s.below_10_deg += m.max_cos(t) > kCos10;
      s.below_13_deg += m.max_cos(t) > kCos13;
    }
  s.min_dihedral_deg = std::acos(std::min(1.0, c)) * kDeg;
}

int64_t pinned_below_13(const ImpMesh& m) {
  int64_t n = 0;
  for (int32_t t = 0; t < m.num_tet_slots(); ++t) {
    if (!m.alive(t) || m.max_cos(t) <= kCos13) continue;
    const Tet& q = m.tet(t);
    n += m.motion(q[0]) == kFixed && m.motion(q[1]) == kFixed && m.motion(q[2]) == kFixed && m.motion(q[3]) == kFixed;
  }
  return n;
}

}  // namespace

QualitySummary quality_summary(const Mesh& mesh) {
  QualitySummary s;
  s.tets = mesh.num_tets();
  if (s.tets == 0) return s;
  // By the cosine of each tet's smallest angle: one arc cosine per figure, not six per tet.
  std::vector<double> cosines(size_t(s.tets));
  for (int64_t t = 0; t < s.tets; ++t) {
    geo::tc_d3 p[4];
    for (int k = 0; k < 4; ++k) p[k] = geo::tc_point(mesh.points.data(), mesh.tets[size_t(4 * t + k)]);
    const double c = geo::tc_tet_max_dihedral_cos(p[0], p[1], p[2], p[3]);
    cosines[size_t(t)] = c;
    s.below_10_deg += c > kCos10;
    s.below_13_deg += c > kCos13;
  }
  const auto deg = [](double c) { return std::acos(std::max(-1.0, std::min(1.0, c))) * kDeg; };
  s.min_dihedral_deg = deg(*std::max_element(cosines.begin(), cosines.end()));
  std::nth_element(cosines.begin(), cosines.begin() + ptrdiff_t(cosines.size() / 2), cosines.end());
  s.median_dihedral_deg = deg(cosines[cosines.size() / 2]);
  return s;
}

namespace {

// Passes of flips and relocation on `mesh` until they stall; appends them to the report.
// With a context, the vertices are relocated on its device, and on a GPU the flips found there.
// Under a boundary error bound, options.vertex_boundary_error goes on from what the passes spent.
void passes(Mesh& mesh, ImproveOptions& options, Context* ctx, int max_passes, ImproveReport& report, bool first) {
  const Stopwatch setup;
  ImpMesh m(mesh, options);
  report.seconds_setup += setup.peek();
  if (first) report.pinned_below_13_before = pinned_below_13(m);
  const double threshold = std::sin(options.threshold_deg / kDeg);
  for (int it = 0; it < max_passes; ++it) {
    const Stopwatch pass_clock;
    ImprovePassStats stats;
    stats.iteration = int(report.passes.size());
    const std::vector<int32_t> bad = bad_tets(m, threshold);
    stats.bad_tets = int64_t(bad.size());
    if (options.flips) {
      // A CPU device finds flips no faster than the host, which needs no rounds (bench/README.md)
      if (ctx && !ctx->cpu_tuning()) flip_pass(m, *ctx, bad, stats);
      else flip_pass(m, bad, stats);
    }
    if (options.splits) split_pass(m, bad_tets(m, threshold), options.max_tets, stats);
    const double flipped = pass_clock.peek();
    stats.seconds_flips = flipped;
    if (options.smoothing) {
      if (ctx) smooth_pass(m, *ctx, bad_tets(m, threshold), stats);
      else smooth_pass(m, bad_tets(m, threshold), stats);
    }
    stats.seconds_relocation = pass_clock.peek() - flipped;
    measure(m, stats);
    stats.seconds = pass_clock.peek();
    report.passes.push_back(stats);
    if (options.progress) options.progress(stats);
    if (stats.edge_removals + stats.flips23 + stats.boundary_removals + stats.splits + stats.relocated == 0) break;
    // Later passes make ever smaller gains on the same vertices: stop once a pass leaves the
    // worst angle and the counts below 10 and 13 degrees (nearly) as they were (counts at zero
    // included, which no pass can lower).
    if (it > 0) {
      const ImprovePassStats& prev = report.passes[report.passes.size() - 2];
      const auto kept = [](int64_t now, int64_t before) {
        return !(double(now) < double(before) * (1 - kMinCountGain));
      };
      if (stats.min_dihedral_deg < prev.min_dihedral_deg + kMinAngleGain &&
          kept(stats.below_10_deg, prev.below_10_deg) && kept(stats.below_13_deg, prev.below_13_deg))
        break;
    }
  }
  report.pinned_below_13_after = pinned_below_13(m);
  const Stopwatch write;
  m.write_back();
  // (a vertex a split added lies inside what the mask selected)
  if (!options.vertex_mask.empty()) options.vertex_mask.resize(size_t(mesh.num_vertices()), 1);
  if (m.bounded()) options.vertex_boundary_error = m.boundary_errors();
  report.seconds_setup += write.peek();
}

// The collapse step: edges between vertices of tets below 13 degrees, by the harmonic index's
// drop (CollapseOptions::harmonic_cost) or the shortest first. On the CPU even with a
// device: a few hundred edges, where the parallel method takes as long (it uploads and connects
// the whole mesh) and its order of collapses left more bad tets on W1. On the star mesh of
// those vertices (star_mesh), spliced back: the same collapses as on the whole mesh.
int64_t collapse_bad(Mesh& mesh, ImproveOptions& options, bool harmonic) {
  const std::vector<uint8_t>& selected = options.vertex_mask;  // (empty: all)
  std::vector<uint8_t> mask(size_t(mesh.num_vertices()), 0);
  bool any = false;
  for (int64_t t = 0; t < mesh.num_tets(); ++t) {
    geo::tc_d3 p[4];
    for (int k = 0; k < 4; ++k) p[k] = geo::tc_point(mesh.points.data(), mesh.tets[size_t(4 * t + k)]);
    if (geo::tc_tet_max_dihedral_cos(p[0], p[1], p[2], p[3]) <= kCos13) continue;
    for (int k = 0; k < 4; ++k) {
      const size_t v = size_t(mesh.tets[size_t(4 * t + k)]);
      mask[v] = selected.empty() || selected[v];
      any = any || mask[v];
    }
  }

  if (!any) return 0;
  CollapseOptions o;
  o.method = CollapseOptions::Sequential;
  o.boundary = options.boundary;
  o.eps_f = options.eps_f;
  o.eps_r = options.eps_r;
  o.use_labels = options.use_labels;
  // What the collapse reshapes may fall to this mean ratio (or stay as bad as it was): a
  // collapse whose removed tets are the slivers must be allowed to lower the others a little
  // (with 1, the guard at its strictest, a short edge's slivers were never collapsed); the
  // dihedral figures are checked after the step.
  o.min_quality = 0.3;
  // (the harmonic cost marks by the sum's drop, not by a length: no median needed)
  o.target_length = options.collapse_length > 0 ? options.collapse_length
                    : harmonic                  ? 1.0
                                                : 1.5 * median_edge_length(mesh);
  o.harmonic_cost = harmonic;
  // the volume threshold of the whole mesh, not of the star mesh the step runs on
  o.eps_v = volume_threshold(mesh, o);
  o.eps_v_scale = CollapseOptions::Absolute;
  // A vertex mask follows the renumbering as a vertex field (a survivor of two selected vertices
  // is selected: the mean of two ones); under a bound the step goes on from what was spent at
  // each vertex, which reaches the star mesh and comes back through the splice as the last field.
  const bool masked = !selected.empty();
  const bool bounded = options.boundary == CollapseOptions::Features && options.max_boundary_error_abs > 0;
  if (bounded) o.max_boundary_error_abs = options.max_boundary_error_abs;
  const size_t fields = mesh.vertex_fields.size();
  int64_t collapsed = 0;
  try {
    if (masked) {
      std::vector<double> ones(selected.size());
      for (size_t v = 0; v < selected.size(); ++v) ones[v] = selected[v] ? 1.0 : 0.0;
      mesh.vertex_fields.push_back({kMaskField, 1, std::move(ones)});
    }
    if (bounded) {
      std::vector<double> spent = options.vertex_boundary_error;
      spent.resize(size_t(mesh.num_vertices()), 0.0);
      mesh.vertex_fields.push_back({collapse_detail::kBoundField, 1, std::move(spent)});
    }
    StarMesh star = star_mesh(mesh, mask);
    o.vertex_mask.resize(star.verts.size());
    for (size_t i = 0; i < star.verts.size(); ++i) o.vertex_mask[i] = mask[size_t(star.verts[i])];
    sequential_detail::SequentialRun run(star.mesh, o);
    run.keep_origin();
    if (bounded) run.seed_boundary_error(star.mesh.vertex_fields.back().values);
    while (run.step()) {
    }
    for (const IterationStats& it : run.finish().iterations) collapsed += it.collapsed;
    if (bounded) star.mesh.vertex_fields.back().values = run.boundary_errors();
    if (collapsed > 0) splice(mesh, star, run);
  } catch (...) {
    mesh.vertex_fields.resize(fields);  // (the mask's and the bound's, last)
    throw;
  }
  if (bounded) {
    options.vertex_boundary_error = std::move(mesh.vertex_fields.back().values);
    mesh.vertex_fields.pop_back();
  }
  if (masked) {
    const std::vector<double>& m = mesh.vertex_fields.back().values;
    options.vertex_mask.assign(m.size(), 0);
    for (size_t v = 0; v < m.size(); ++v) options.vertex_mask[v] = m[v] > 0.5;
    mesh.vertex_fields.pop_back();
  }
  return collapsed;
}

ImproveReport improve_on(Mesh& mesh, const ImproveOptions& given, Context* ctx) {
  const Stopwatch clock;
  if (ctx) prefetch_programs(*ctx);
  ImproveReport report;
  report.before = quality_summary(mesh);
  // Under a boundary error bound, options.vertex_boundary_error follows each stage's changes.
  collapse_detail::check_bound_mode(given.max_boundary_error_abs > 0, given.boundary, "max_boundary_error_abs");
  ImproveOptions options = given;
  passes(mesh, options, ctx, options.max_iterations, report, true);
  // Rounds of the collapse step and the passes after it, while a round raises the smallest angle
  // or removes a tenth of the tets below 10 or 13 degrees left (a collapse frees its neighbours
  // for the next passes, which free edges for the next step).
  const int rounds = options.collapse_rounds;
  for (int round = 0; round < rounds; ++round) {
    if (!options.collapse || int(report.passes.size()) >= options.max_iterations) break;
    const ImprovePassStats before = report.passes.back();
    const Stopwatch step;
    ImprovePassStats stats;
    stats.iteration = int(report.passes.size());
    // The collapse's guard measures the mean ratio, not the dihedral angles: each part of the
    // step is kept only if it left the smallest angle and the counts below 10 and 13 degrees no
    // worse than the last pass (or part) measured them.
    ImprovePassStats q0 = report.passes.back();
    QualitySummary q;
    // The paper's step (the harmonic index's drop, a line search; no tet of a region made worse)
    // first, then the shortest edges with the mean-ratio guard on what is left; each kept only
    // if the figures are no worse.
    for (bool harmonic : {true, false}) {
      if (harmonic && !options.harmonic_collapse) continue;
      Mesh kept = mesh;
      std::vector<double> spent = options.vertex_boundary_error;
      std::vector<uint8_t> selected = options.vertex_mask;
      const int64_t n = collapse_bad(mesh, options, harmonic);
      const QualitySummary qa = quality_summary(mesh);
      if (n == 0 || qa.min_dihedral_deg < q0.min_dihedral_deg || qa.below_10_deg > q0.below_10_deg ||
          qa.below_13_deg > q0.below_13_deg) {
        mesh = std::move(kept);
        options.vertex_boundary_error = std::move(spent);
        options.vertex_mask = std::move(selected);
        continue;
      }
      stats.collapsed += n;
      q = qa;
      q0.min_dihedral_deg = qa.min_dihedral_deg;
      q0.below_10_deg = qa.below_10_deg;
      q0.below_13_deg = qa.below_13_deg;
    }
    if (stats.collapsed > 0) {
      stats.min_dihedral_deg = q.min_dihedral_deg;
      stats.below_10_deg = q.below_10_deg;
      stats.below_13_deg = q.below_13_deg;
      stats.seconds = step.peek();
      report.passes.push_back(stats);
      if (options.progress) options.progress(stats);
      passes(mesh, options, ctx, options.max_iterations - int(report.passes.size()), report, false);
    }
    const ImprovePassStats& after = report.passes.back();
    if (!(after.min_dihedral_deg >= before.min_dihedral_deg + kMinAngleGain ||
          double(after.below_10_deg) < double(before.below_10_deg) * (1 - kMinRoundGain) ||
          double(after.below_13_deg) < double(before.below_13_deg) * (1 - kMinRoundGain)))
      break;
  }
  report.after = quality_summary(mesh);
  if (options.max_boundary_error_abs > 0) report.vertex_boundary_error = std::move(options.vertex_boundary_error);
  report.seconds_total = clock.peek();
  return report;
}

}  // namespace

void improve_detail::prefetch_programs(Context& ctx) {
  ctx.prefetch("improve_relocate.cl");                      // smooth_pass (relocate_device.cpp)
  if (!ctx.cpu_tuning()) ctx.prefetch("improve_flip.cl");  // flip_pass (flips_device.cpp) off a CPU
}

ImproveReport improve(Mesh& mesh, const ImproveOptions& options) { return improve_on(mesh, options, nullptr); }
ImproveReport improve(Mesh& mesh, const ImproveOptions& options, Context& ctx) {
  return improve_on(mesh, options, &ctx);
}

}  // namespace tc
