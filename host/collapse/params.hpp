// What the stages are told: the user's options as the kernels take them, and the reasons a
// test gives for refusing an edge.
#pragma once

#include <cstdint>
#include <string>

#include "tetcollapse/collapse.hpp"
#include "tetcollapse/device.hpp"

namespace tc::collapse_detail {

enum Reason : uint8_t {
  kOk = 0, kNotMarked = 1, kRefusedQ = 2, kRefusedLink = 3, kRefusedVolume = 4, kRefusedQuality = 6,
  kUntested = 5,  // lazy filter: passed Q, never tested because a cheaper rival won (an edge
                  // with a refusal carried from the previous iteration keeps that reason)
  kRefusedSurface = 7,  // the surface guard (guard_surface.hpp)
  kVolumeOk = 8         // in verdict[] only (TCC_VOLUME_OK): the volume test passed, the link not yet run
};

// What the admissible checks of both methods are told: the boundary mode and the thresholds.
struct CheckParams {
  int mode = 1;  // TCC_STRICT 0, TCC_FEATURES 1, TCC_FREE 2 (collapse_predicate.h)
  bool paper_rule = false;
  bool use_labels = true;
  double eps_f = 0.01, eps_r = 0.1, eps_v = 2e-12;
  double min_quality = 0;  // quality guard, 0 = off
  // the field check (CollapseOptions::field_check) in field units, 0 = off; the first vertex
  // field (TCS_FIELD, cl/collapse_checks.h)
  double field_eps = 0;
};
CheckParams check_params_from(const CollapseOptions& o);

struct StageParams : CheckParams {
  double target = 0;
  int mask_mode = 0;  // 0 none, 1 both, 2 either
  std::string cost_source;  // user cost, "" for the edge length
  // The user's placement and predicate (OpenCL C, "" for none) and the -D options that switch
  // them on (collapse_common.h): compiled into the kernels that place a survivor or evaluate Q
  // (stage_kernel).
  std::string user_source, user_defines;
  // One work-group for the conflict rounds (no launch and read-back per round): lazy pass 1
  // once at most loop_tests edges of a turn list are to be tested and loop_turns in all, back
  // to per-round launches when a list has more than loop_exit_tests to test; pass 2
  // (conflict_pass2's loop_size) once at most 2048 candidates wait. Results do not depend on
  // them (tests set them to 0 and to the maximum).
  uint32_t loop_tests = 128, loop_turns = 4096, loop_exit_tests = 512;
  // Greedy selection: the priority in steps of target / priority_levels (0: the exact cost),
  // CollapseTuning::priority_levels; its rounds run in one work-group (greedy_loop) once the
  // turn list holds at most greedy_loop_size edges, back to per-round kernels when one holds
  // more than greedy_loop_exit. Results do not depend on the last two. With the waiting lists a
  // turn list holds only edges to decide, each a test of some microseconds, so past a small
  // list one core is slower than two cores plus a round's launches (the sizes measured with
  // bench_selection; bench/README.md).
  double priority_levels = 64;
  uint32_t greedy_loop_size = 128, greedy_loop_exit = 512;
  // Greedy and matching selections: an edge waiting for its blocker waits on the blocker's
  // vertex and is woken when the blocker decides (tcc_wait_on, cl/collapse_select.h), instead of
  // going to every turn list until then. Results do not depend on it.
  bool waiting_lists = true;
  // Matching selection: a waiting edge's early volume test (cl/collapse_matching.cl; MatchingState::edges_early_tested).
  bool match_early_tests = true;
  // The boundary error bound in mesh units (0: none; bound.hpp) and the vertex field component
  // that carries the bound per vertex.
  double bound = 0;
  uint32_t eps_col = 0;
};
// The build option of the programs of a run under a boundary error bound that test it, those
// with the selection's test (kBoundHeader): set for the run (Context::ProgramOptions), so each
// program is built in one variant per run, and the others are the unbounded run's.
constexpr const char* kBoundDefines = "-DTCC_BOUND";
constexpr const char* kBoundHeader = "collapse_select.h";
// The hidden last vertex field that carries the boundary error bound per vertex through a run
// on the device or through the improvement's collapse step (popped before the caller sees it).
constexpr const char* kBoundField = "tetcollapse:boundary_error";
// The field error bound's points (CollapseOptions::field_points and the rest) come only with
// the bound (std::invalid_argument), for both methods; their sizes are FieldBound's to check.
void check_field_points_options(const CollapseOptions& o);
// The boundary error bound's options, for both methods (std::invalid_argument): finite, >= 0,
// and only in the features mode.
void check_boundary_error_options(const CollapseOptions& o);
// That a bound (`bounded`; `option` names it) comes only with the features mode
// (std::invalid_argument): the collapse's and the improvement's.
void check_bound_mode(bool bounded, CollapseOptions::Boundary mode, const char* option);
// The bound per vertex at the start of a run: CollapseOptions::vertex_boundary_error, checked
// against the mesh (std::invalid_argument), or zeros.
std::vector<double> initial_boundary_error(const Mesh& mesh, const CollapseOptions& o);
// Whether a run under a bound measures the changes of S the carried bound refuses: asked to
// (CollapseTuning::remeasure_boundary_error) and with a reference surface, the one given or, when
// no bound was spent before the run (vertex_boundary_error empty or zeros), the mesh's own S.
bool measures_boundary_error(const CollapseOptions& o);
StageParams params_from(const CollapseOptions& o);
// The options the parallel method refuses (std::invalid_argument), or this device cannot run
// (tc::DeviceError).
void check_options(const CollapseOptions& o, const Context& ctx);

}  // namespace tc::collapse_detail
