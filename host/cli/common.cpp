#include "cli/common.hpp"

#include <cstdio>
#include <iostream>

#include "io/io_util.hpp"
#include "stopwatch.hpp"
#ifdef TETCOLLAPSE_HAVE_CHECK
#include "tetcollapse/check.hpp"
#endif

namespace tc::cli {

void add_input_options(CLI::App& cmd, InputOptions& o) {
  cmd.add_option("--format", o.format,
                 "Input format instead of the one the extension names: msh, mesh, meshb, vtk, vtu, node");
  cmd.add_flag("--fix-orientation", o.fix_orientation,
               "When tets are mixed positive and negative, flip the negative ones instead of refusing the mesh");
  cmd.add_flag("--no-sol", o.no_sol, "Medit: do not read the .sol file beside the .mesh");
}

// An OpenCL C file of the user (--cost-cl, --placement-cl, --predicate-cl), headed by a #line
// directive so that the compiler's messages name the file and its lines.
std::string cl_file(const std::string& path) {
  std::string quoted;
  for (char ch : path) {
    if (ch == '"' || ch == '\\') quoted += '\\';
    quoted += ch;
  }
  return "#line 1 \"" + quoted + "\"\n" + io::load_file(path);
}

std::unique_ptr<Context> open_device(const std::string& spec, bool quiet) {
  auto ctx = std::make_unique<Context>(spec);
  if (quiet) return ctx;
  std::cerr << "device: " << ctx->info().name << " (" << ctx->info().platform_name << ")\n";
  const std::string name = ctx->info().name;
  // One line when the first compile begins, then one as each program is done (other lines of
  // the run come in between, so not updated in place).
  ctx->set_compile_notice([name, said = false, last = 0, clock = Stopwatch()](const std::string& file, int done,
                                                                             int total) mutable {
    if (!said) {
      said = true;
      clock = Stopwatch();
      std::cerr << "compiling kernels for " << name
                << " (a first run on this device, driver or cache; later runs read them from "
                << Context::cache_dir() << ")...\n";
    }
    if (done <= last) return;  // queued, not done
    last = done;
    char line[256];
    std::snprintf(line, sizeof line, "  compiled %d of %d programs (%s), %.1f s\n", done, total, file.c_str(),
                  clock.peek());
    std::cerr << line;
  });
  return ctx;
}

Mesh read_input(const std::string& path, const InputOptions& o, bool quiet) {
  ReadOptions ro;
  if (!o.format.empty()) ro.format = parse_format(o.format);
  ro.orientation = o.fix_orientation ? OrientationPolicy::Fix : OrientationPolicy::Refuse;
  ro.read_sol = !o.no_sol;
  ro.as_is = o.as_is;
  ReadNotes notes;
  Mesh m = read_mesh(path, ro, &notes);
  if (!quiet)
    for (const auto& n : notes.notes) std::cerr << path << ": note: " << n << "\n";
  return m;
}

void add_output_options(CLI::App& cmd, OutputOptions& o) {
  cmd.add_option("--out-format", o.format,
                 "Output format instead of the one the extension names: msh, mesh, meshb, vtk, vtu, node");
  cmd.add_flag("--ascii", o.ascii, "Write text instead of binary where the format has both");
  cmd.add_option("--gmsh-version", o.gmsh_version, "Gmsh output version: 41 (default) or 22")
      ->check(CLI::IsMember({22, 41}));
  cmd.add_option("--vtu-encoding", o.vtu_encoding, "VTU data: appended (raw, default), base64 or ascii")
      ->check(CLI::IsMember({"appended", "base64", "ascii"}));
}

WriteOptions write_options(const OutputOptions& o) {
  WriteOptions w;
  if (!o.format.empty()) w.format = parse_format(o.format);
  w.binary = !o.ascii;
  w.gmsh_version = o.gmsh_version;
  if (o.ascii || o.vtu_encoding == "ascii") w.vtu_encoding = WriteOptions::VtuEncoding::Ascii;
  else if (o.vtu_encoding == "base64") w.vtu_encoding = WriteOptions::VtuEncoding::Base64;
  else w.vtu_encoding = WriteOptions::VtuEncoding::Appended;
  return w;
}

void check_output_path(const std::string& path, const OutputOptions* o) {
  if (path.empty() || (!o && path == "-")) return;  // a report may go to stdout, a mesh may not
  // the checks write_mesh and io::AtomicFile make (an unknown --out-format: InputError naming it)
  if (o) io::output_format(path, write_options(*o).format);
  io::require_output_folder(path);
}

CollapseOptions::Boundary boundary_mode(const std::string& name) {
  return name == "strict" ? CollapseOptions::Strict : name == "free" ? CollapseOptions::Free : CollapseOptions::Features;
}

CollapseOptions::Conflicts conflicts_mode(const std::string& name) {
  return name == "atomic-min" ? CollapseOptions::AtomicMin
         : name == "two-pass" ? CollapseOptions::TwoPass
         : name == "matching" ? CollapseOptions::Matching
                              : CollapseOptions::Greedy;
}

void add_volume_options(CLI::App& app, double& eps_v, std::string& scale) {
  app.add_option("--eps-v", eps_v,
                 "Refuse collapses leaving a tet with volume below V times the input's mean tet volume\n"
                 "(--eps-v-scale; the default is the paper's absolute 2e-12 on its W1 robot mesh)")
      ->capture_default_str();
  app.add_option("--eps-v-scale", scale,
                 "What --eps-v multiplies: mean-tet (default: a mesh gives the same result in any unit),\n"
                 "absolute (1: mesh units, as the paper, e.g. --eps-v 2e-12 --eps-v-scale absolute) or\n"
                 "diagonal (the cube of the input's bounding-box diagonal)")
      ->capture_default_str()
      ->check(CLI::IsMember({"mean-tet", "absolute", "diagonal"}));
}

CollapseOptions::VolumeScale volume_scale(const std::string& name) {
  return name == "absolute" ? CollapseOptions::Absolute
         : name == "diagonal" ? CollapseOptions::DiagonalCubed
                              : CollapseOptions::MeanTetVolume;
}

CollapseOptions::Method method_mode(const std::string& name) {
  return name == "sequential" ? CollapseOptions::Sequential : CollapseOptions::Parallel;
}

void check_method(const std::string& method, const std::string& device,
                  const std::vector<std::pair<const char*, const std::string*>>& needs_parallel) {
  if (method_mode(method) != CollapseOptions::Sequential) return;
  if (!device.empty()) throw CLI::ValidationError("--device", "the sequential method runs on the CPU without a device");
  for (const auto& [name, value] : needs_parallel)
    if (!value->empty())
      throw CLI::ValidationError(name, "needs the parallel method (it is compiled as OpenCL C); not with --method sequential");
}

std::string check_result(const Mesh& result, const Mesh& input, bool hausdorff, bool quiet, int& exit_code) {
#ifdef TETCOLLAPSE_HAVE_CHECK
  CheckOptions co;
  co.hausdorff = hausdorff;
  const CheckReport cr = check_mesh(result, co, &input);
  if (!cr.valid) {
    std::cerr << "check: the result is INVALID\n" << check_report_text(cr);
    exit_code = kCheckFailed;
  } else if (!quiet) {
    std::cerr << "check: valid, boundary topology unchanged\n";
  }
  return cr.valid ? "valid" : "invalid";
#else
  (void)result, (void)input, (void)hausdorff, (void)quiet, (void)exit_code;
  throw CLI::ValidationError("--check", "this build has no checker (CGAL)");
#endif
}

// Writes `text` to `path` atomically, or to stdout when path is "-".
void write_report(const std::string& path, const std::string& text) {
  if (path == "-") {
    std::cout << text << "\n";
    return;
  }
  io::AtomicFile f(path, false);
  f.stream() << text << "\n";
  f.commit();
}

}  // namespace tc::cli
