// tetcollapse improve IN OUT: raise the worst element quality (flips and vertex relocation).
#include <cstdio>
#include <iostream>
#include <memory>

#include "cli/common.hpp"
#include "cli/improve_cli.hpp"
#include "stopwatch.hpp"
#include "tetcollapse/fields.hpp"

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
  c.opt.collapse = !c.no_collapse;
  c.opt.harmonic_collapse = !c.no_harmonic;
  if (!quiet)
    c.opt.progress = [](const ImprovePassStats& s) {
      std::fprintf(stderr,
                   "improve %3d: bad tets %8lld  edge removals %6lld  2-3 flips %6lld  boundary %5lld  moved %7lld  "
                   "collapsed %6lld  min dihedral %6.2f  below 10: %6lld  below 13: %6lld  %.3f s\n",
                   s.iteration + 1, (long long)s.bad_tets, (long long)s.edge_removals, (long long)s.flips23,
                   (long long)s.boundary_removals,
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

void register_improve(CLI::App& app, int& exit_code) {
  struct Opts {
    std::string in, out, boundary = "features", stats, method = "parallel", device;
    InputOptions input;
    OutputOptions output;
    ImproveCli improve;
    bool no_labels = false, check = false, quiet = false;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "improve",
      "Raise the worst element quality of a mesh: edge removal (3-2, 4-4, n -> 2n-4 flips), 2-3\n"
      "flips, flips of flat boundary quads, vertex relocation, removal of thin boundary tets and a\n"
      "collapse of short edges of the tets still below 13 degrees, each accepted only when the worst\n"
      "quality of what it changes rises; the worst dihedral angle never falls. Interfaces are kept;\n"
      "the boundary as --boundary says");
  cmd->add_option("IN", o->in, "Input mesh")->required();
  cmd->add_option("OUT", o->out, "Output mesh (written to a temporary file and renamed)")->required();
  cmd->add_option("--boundary", o->boundary,
                  "strict: no boundary vertex moves and no boundary face changes (bit for bit); features\n"
                  "(default) and free: surface vertices move within their surface (freely on flat patches\n"
                  "and straight feature lines, elsewhere within --max-boundary-move), flat boundary quads\n"
                  "flip their diagonal, thin boundary tets may go")
      ->check(CLI::IsMember({"strict", "features", "free"}));
  cmd->add_flag("--no-labels", o->no_labels, "Do not treat material interfaces as boundary (flips still keep labels)");
  cmd->add_option("--eps-f", o->improve.opt.eps_f, "Face-vertex threshold on 1 - dot of normals")->capture_default_str();
  cmd->add_option("--eps-r", o->improve.opt.eps_r, "Ridge-edge threshold on 1 - dot of normals")->capture_default_str();
  add_improve_options(*cmd, o->improve);
  cmd->add_option("--method", o->method,
                  "parallel (default): vertex relocation on the OpenCL device, in rounds of vertices that\n"
                  "share no tet; sequential: everything on the CPU, one operation after the other (no\n"
                  "OpenCL device needed). Flips and the collapse step run on the CPU either way")
      ->check(CLI::IsMember({"parallel", "sequential"}));
  cmd->add_option("--device", o->device,
                  "OpenCL device: index or name substring (see 'tetcollapse devices');\n"
                  "default: $TETCOLLAPSE_DEVICE, else the first GPU, else the first CPU");
  cmd->add_option("--stats", o->stats, "Write the run's statistics as JSON to this file ('-' for stdout)");
  cmd->add_flag("--check", o->check, "Check the result (validity, unchanged boundary topology) and fail if invalid");
  cmd->add_flag("-q,--quiet", o->quiet, "No progress lines, only errors");
  add_input_options(*cmd, o->input);
  add_output_options(*cmd, o->output);
  cmd->callback([o, &exit_code] {
    check_output_path(o->out, &o->output);
    check_output_path(o->stats, nullptr);
    const Stopwatch total;
    Mesh mesh = read_input(o->in, o->input, o->quiet);
    Mesh input;  // for --check, and the vertex fields' values at the moved vertices
    if (o->check || !mesh.vertex_fields.empty()) input = mesh;
    ImproveOptions& opt = o->improve.opt;
    opt.boundary = boundary_mode(o->boundary);
    opt.use_labels = !o->no_labels;
    if (o->method == "sequential" && !o->device.empty())
      throw CLI::ValidationError("--device", "the sequential method runs on the CPU without a device");
    std::unique_ptr<Context> ctx;
    if (o->method == "parallel") {
      ctx = open_device(o->device, o->quiet);
    }
    ImproveReport r = run_improve(mesh, o->improve, o->quiet, ctx.get());
    // (a relocation interpolates in the star as it was then; the input's field is the truth)
    if (!mesh.vertex_fields.empty()) resample_vertex_fields(input, mesh);
    exit_code = kOk;
    const std::string verdict =
        o->check ? check_result(mesh, input, opt.boundary == CollapseOptions::Strict, o->quiet, exit_code) : "";
    if (exit_code != kCheckFailed) write_mesh(o->out, mesh, write_options(o->output));
    if (!o->quiet)
      std::fprintf(stderr,
                   "%s -> %s\n  before: %s\n  after:  %s\n  tets below 13 degrees whose vertices may not move: "
                   "%lld -> %lld\n  improve %.3f s, total %.3f s\n",
                   o->in.c_str(), o->out.c_str(), quality_line(r.before).c_str(), quality_line(r.after).c_str(),
                   (long long)r.pinned_below_13_before, (long long)r.pinned_below_13_after, r.seconds_total,
                   total.peek());
    if (!o->stats.empty()) {
      JsonWriter w;
      w.begin_object().field("input", o->in).field("output", o->out).field("tets", r.after.tets);
      if (!verdict.empty()) w.field("check", verdict);
      write_improve(w, r);
      w.field("seconds_total", total.peek()).end_object();
      write_report(o->stats, w.str());
    }
  });
}

}  // namespace tc::cli
