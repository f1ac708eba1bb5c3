// The improvement phase's options and reports, shared by `tetcollapse improve`, the coarsening
// command and tetcollapse-mpi (cli/improve_cli.hpp).
#include "cli/improve_cli.hpp"

#include <cstdio>

namespace tc::cli {

void add_improve_options(CLI::App& cmd, ImproveCli& c) {
  cmd.add_option("--improve-iterations", c.opt.max_iterations,
                 "Improvement: at most N passes of flips and vertex relocation (each stops early when\n"
                 "nothing changes)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd.add_option("--improve-threshold", c.opt.threshold_deg,
                 "Improvement: work on the tets with a dihedral angle below DEG (or above 180 - DEG)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 60.0));
  cmd.add_flag("--no-flips", c.no_flips, "Improvement: no edge removal or 2-3 flips");
  cmd.add_option("--max-boundary-move", c.opt.max_boundary_move,
                 "Improvement, features and free modes: how far the boundary may move, as a share of the\n"
                 "bounding-box diagonal: relocations off flat patches and straight lines, and the removal of\n"
                 "thin tets with two boundary faces, stay within it (0: neither)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd.add_flag("--no-smoothing", c.no_smoothing, "Improvement: no vertex relocation");
  cmd.add_flag("--no-splits", c.no_splits,
               "Improvement: no edge splits (a bad tet whose four vertices lie on the surface has its longest\n"
               "interior edge split at a new vertex when that raises the worst quality of the edge's tets)");
  cmd.add_flag("--no-harmonic-collapse", c.no_harmonic,
               "Improvement: the collapse step without the paper's part (edges of the bad tets by the drop\n"
               "of the harmonic index, the survivor placed by a line search): the shortest edges only");
  cmd.add_option("--improve-collapse-rounds", c.opt.collapse_rounds,
                 "Improvement: at most N rounds of the collapse step and the passes after it, each only\n"
                 "after one that raised the smallest angle or removed a tenth of the tets below 10 or 13\n"
                 "degrees (fewer: faster, more slivers left)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd.add_flag("--no-improve-collapse", c.no_collapse,
               "Improvement: no collapse of the short edges of the tets still below 13 degrees after\n"
               "the flips and relocation (that step removes a few vertices)");
}

std::string quality_line(const QualitySummary& q) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "min dihedral %.2f, median %.2f degrees, %lld below 10, %lld below 13",
                q.min_dihedral_deg, q.median_dihedral_deg, (long long)q.below_10_deg, (long long)q.below_13_deg);
  return buf;
}

const ImproveOptions& improve_options(ImproveCli& c, bool quiet) {
  c.opt.flips = !c.no_flips;
  c.opt.smoothing = !c.no_smoothing;
  c.opt.splits = !c.no_splits;
  c.opt.collapse = !c.no_collapse;
  c.opt.harmonic_collapse = !c.no_harmonic;
  if (!quiet)
    c.opt.progress = [](const ImprovePassStats& s) {
      std::fprintf(stderr,
                   "improve %3d: bad tets %8lld  edge removals %6lld  2-3 flips %6lld  boundary %5lld  splits %5lld  moved %7lld  "
                   "collapsed %6lld  min dihedral %6.2f  below 10: %6lld  below 13: %6lld  %.3f s\n",
                   s.iteration + 1, (long long)s.bad_tets, (long long)s.edge_removals, (long long)s.flips23,
                   (long long)s.boundary_removals, (long long)s.splits,
                   (long long)s.relocated, (long long)s.collapsed, s.min_dihedral_deg, (long long)s.below_10_deg,
                   (long long)s.below_13_deg, s.seconds);
    };
  return c.opt;
}

ImproveReport run_improve(Mesh& mesh, ImproveCli& c, bool quiet, Context* ctx) {
  const ImproveOptions& o = improve_options(c, quiet);
  return ctx ? improve(mesh, o, *ctx) : improve(mesh, o);
}

void write_quality(JsonWriter& w, std::string_view key, const QualitySummary& q) {
  w.key(key)
      .begin_object()
      .field("tets", q.tets)
      .field("min_dihedral_deg", q.min_dihedral_deg)
      .field("median_dihedral_deg", q.median_dihedral_deg)
      .field("below_10_deg", q.below_10_deg)
      .field("below_13_deg", q.below_13_deg)
      .end_object();
}

void write_improve(JsonWriter& w, const ImproveReport& r) {
  w.key("improve").begin_object().field("seconds", r.seconds_total).field("seconds_setup", r.seconds_setup);
  write_quality(w, "quality_before", r.before);
  write_quality(w, "quality_after", r.after);
  w.field("pinned_below_13_before", r.pinned_below_13_before).field("pinned_below_13_after", r.pinned_below_13_after);
  w.key("passes").begin_array();
  for (const auto& p : r.passes)
    w.begin_object()
        .field("iteration", p.iteration)
        .field("bad_tets", p.bad_tets)
        .field("edge_removals", p.edge_removals)
        .field("flips23", p.flips23)
        .field("boundary_removals", p.boundary_removals)
        .field("splits", p.splits)
        .field("relocated", p.relocated)
        .field("collapsed", p.collapsed)
        .field("min_dihedral_deg", p.min_dihedral_deg)
        .field("below_10_deg", p.below_10_deg)
        .field("below_13_deg", p.below_13_deg)
        .field("seconds", p.seconds)
        .field("seconds_flips", p.seconds_flips)
        .field("seconds_relocation", p.seconds_relocation)
        .end_object();
  w.end_array().end_object();
}

}  // namespace tc::cli
