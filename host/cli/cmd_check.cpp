#include <iostream>

#include "cli/common.hpp"
#include "io/io_util.hpp"
#include "tetcollapse/check.hpp"

namespace tc::cli {

void register_check(CLI::App& app, int& exit_code) {
  struct Opts {
    std::string path, reference, json, eps_v_scale = "mean-tet";
    InputOptions input;
    CheckOptions check;
    bool quiet = false;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "check",
      "Check a mesh for validity (exact orientation, face pairing, closed manifold boundary without\n"
      "self-intersection, duplicate vertices) and report its quality; exit code 1 when invalid.\n"
      "With --reference: volume change, boundary Hausdorff distance, reduction, and the boundary\n"
      "topology (components, Euler characteristic) must be unchanged.");
  cmd->add_option("MESH", o->path, "Mesh to check")->required();
  cmd->add_option("--reference", o->reference, "The input the mesh was made from, to compare with");
  cmd->add_option("--json", o->json, "Write the full report as one JSON object to this file ('-' for stdout)");
  cmd->add_option("--eps-v", o->check.eps_volume,
                  "Count tets with volume below this times the mesh's mean tet volume (the collapse's --eps-v)")
      ->capture_default_str();
  cmd->add_option("--eps-v-scale", o->eps_v_scale,
                  "What --eps-v multiplies: mean-tet (default) or absolute (1: mesh units, e.g. the paper's\n"
                  "--eps-v 2e-12 --eps-v-scale absolute)")
      ->capture_default_str()
      ->check(CLI::IsMember({"mean-tet", "absolute"}));
  cmd->add_flag("--small-volume-error", o->check.small_volume_is_error, "Tets below --eps-v make the mesh invalid");
  cmd->add_option("--duplicate-tol", o->check.duplicate_tol,
                  "Vertices closer than this on every axis are duplicates")
      ->capture_default_str();
  cmd->add_flag("!--no-self-intersection", o->check.self_intersection, "Skip the boundary self-intersection test");
  cmd->add_flag("!--no-hausdorff", o->check.hausdorff, "Skip the Hausdorff distance to the reference");
  cmd->add_flag("!--no-quality", o->check.quality, "Skip the quality statistics");
  cmd->add_option("--min-dihedral", o->check.min_dihedral_gate_deg,
                  "Fail when the smallest dihedral angle (degrees) is below this");
  cmd->add_option("--max-hausdorff-rel", o->check.max_hausdorff_rel_gate,
                  "Fail when the Hausdorff distance / reference bounding-box diagonal exceeds this");
  cmd->add_option("--max-volume-change-rel", o->check.max_volume_change_rel_gate,
                  "Fail when |volume change| / reference volume exceeds this");
  cmd->add_flag("-q,--quiet", o->quiet, "Print only the verdict line");
  add_input_options(*cmd, o->input);
  cmd->callback([o, &exit_code] {
    o->check.eps_volume_absolute = o->eps_v_scale == "absolute";
    check_output_path(o->json, nullptr);
    // Defects are findings (exit 1), not read errors: only an unparsable file is exit 2.
    o->input.as_is = true;
    Mesh m = read_input(o->path, o->input, o->quiet);
    Mesh ref;
    if (!o->reference.empty()) ref = read_input(o->reference, o->input, o->quiet);
    CheckReport r = check_mesh(m, o->check, o->reference.empty() ? nullptr : &ref);
    if (!o->json.empty()) write_report(o->json, check_report_json(r));
    if (o->json != "-") {
      if (o->quiet)
        std::cout << o->path << ": " << (r.valid ? "valid" : "INVALID") << "\n";
      else
        std::cout << o->path << "\n" << check_report_text(r);
    }
    exit_code = r.valid ? kOk : kCheckFailed;
  });
}

}  // namespace tc::cli
