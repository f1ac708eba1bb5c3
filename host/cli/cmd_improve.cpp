// tetcollapse improve IN OUT: raise the worst element quality (flips and vertex relocation).
#include <cstdio>
#include <iostream>
#include <memory>

#include "cli/common.hpp"
#include "cli/improve_cli.hpp"
#include "stopwatch.hpp"
#include "tetcollapse/fields.hpp"

namespace tc::cli {


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
