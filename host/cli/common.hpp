// Pieces shared by the subcommands of the tetcollapse command line.
#pragma once

#include <CLI/CLI.hpp>

#include <memory>
#include <string>
#include <utility>

#include "tetcollapse/collapse.hpp"
#include "tetcollapse/io.hpp"

namespace tc::cli {

// An OpenCL C file of the user (--cost-cl, --placement-cl, --predicate-cl), headed by a #line
// directive so that the compiler's messages name the file and its lines.
std::string cl_file(const std::string& path);

// Exit codes, documented in README.md.
enum ExitCode : int {
  kOk = 0,
  kCheckFailed = 1,   // the mesh (or the result) failed a validity check
  kBadInput = 2,      // unreadable input, bad usage
  kDeviceError = 3,   // OpenCL / device failure
  kOutputError = 4,   // the result could not be written (nothing half-written is left)
};

// The first argument by which the tool starts itself as a kernel compile helper (main.cpp).
inline constexpr const char* kCompileHelperArg = "__compile-helper";

// Options every subcommand that reads a mesh shares.
struct InputOptions {
  std::string format;            // "" = from the extension
  bool fix_orientation = false;  // flip negatively oriented tets of a mixed mesh
  bool no_sol = false;
  bool as_is = false;            // the checker's reading (ReadOptions::as_is); not an option
};
void add_input_options(CLI::App& cmd, InputOptions& o);
Mesh read_input(const std::string& path, const InputOptions& o, bool quiet);
// The OpenCL context of --device SPEC; unless quiet, says which device, and says once when a
// run compiles kernels (a first run on this device: seconds).
std::unique_ptr<Context> open_device(const std::string& spec, bool quiet);

struct OutputOptions {
  std::string format;
  bool ascii = false;
  int gmsh_version = 41;
  std::string vtu_encoding = "appended";
};
void add_output_options(CLI::App& cmd, OutputOptions& o);
WriteOptions write_options(const OutputOptions& o);
// Before any work: the errors that writing `path` at the end would give (an unknown output
// format or extension, a folder that does not exist), so that a long run does not end in
// them. `o` null: a report file (JSON), whose format is not a mesh format, and "-" is stdout.
void check_output_path(const std::string& path, const OutputOptions* o);
// Writes `text` to `path` atomically, or to stdout when path is "-" (--stats, --json).
void write_report(const std::string& path, const std::string& text);

// --boundary strict|features|free (the option checks the name) as the options' enum.
CollapseOptions::Boundary boundary_mode(const std::string& name);
// --conflicts matching|greedy|two-pass|atomic-min (the option checks the name) as the options' enum.
CollapseOptions::Conflicts conflicts_mode(const std::string& name);
// --method parallel|sequential: its help, the name (the option checks it) as the options' enum,
// and, with the sequential method, a --device or an option that needs the parallel method
// refused (CLI::ValidationError naming the first given; an empty value is not given).
inline constexpr const char* kMethodHelp =
    "parallel (default): the OpenCL pipeline; sequential: the CPU priority-queue baseline\n"
    "with the same checks (no OpenCL device needed)";
CollapseOptions::Method method_mode(const std::string& name);
// --eps-v V and --eps-v-scale mean-tet|absolute|diagonal (CollapseOptions::eps_v and
// eps_v_scale; the option checks the name), and the name as the options' enum.
void add_volume_options(CLI::App& app, double& eps_v, std::string& scale);
CollapseOptions::VolumeScale volume_scale(const std::string& name);
// --no-merge-features (CollapseTuning::merge_features_within_bound off): its help.
inline constexpr const char* kNoMergeFeaturesHelp =
    "Under --max-boundary-error, keep every ridge and corner whatever its size (default: a detail of\n"
    "the boundary smaller than the bound, an edge no longer than it that the ridge and corner rules\n"
    "refuse, may collapse where the measured distance stays within the bound, as MMG's -hausd)";
void check_method(const std::string& method, const std::string& device,
                  const std::vector<std::pair<const char*, const std::string*>>& needs_parallel);

// --check of the commands that change a mesh: checks `result` against `input` (validity, the
// boundary's topology; with `hausdorff` also the boundary distance, 0 expected in strict mode),
// prints the verdict, sets exit_code to kCheckFailed when invalid; returns "valid"/"invalid".
std::string check_result(const Mesh& result, const Mesh& input, bool hausdorff, bool quiet, int& exit_code);

// Registration of each subcommand: adds it to `app` and returns a flag set when it ran.
void register_collapse(CLI::App& app, int& exit_code);
void register_info(CLI::App& app, int& exit_code);
void register_convert(CLI::App& app, int& exit_code);
void register_devices(CLI::App& app, int& exit_code);
void register_check(CLI::App& app, int& exit_code);
void register_features(CLI::App& app, int& exit_code);
void register_improve(CLI::App& app, int& exit_code);

}  // namespace tc::cli
