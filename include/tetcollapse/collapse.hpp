// Parallel edge collapse on an OpenCL device (paper, Algorithm 1).
//
//   tc::Context ctx;                        // device selection: see device.hpp
//   tc::CollapseOptions opt;                // defaults: target = 1 x median edge length
//   opt.target_factor = 2;
//   tc::CollapseReport r = tc::collapse(mesh, opt, ctx);   // mesh is replaced by the result
//
// The algorithm (the paper's Algorithm 1, with the choices beyond it named):
//
//   upload the mesh, renumbered along a Morton curve (tuning.spatial_order)
//   build the connectivity: rings, neighbours N(v), edges, tet neighbours, the feature surface S
//     and the class of every vertex (interior, face, ridge, corner)
//   target = target_length, or target_factor x the median edge length
//   repeat
//     cost and marking: an edge is marked when its cost (its length) is below the target
//     selection: among the marked edges, those that pass the admissible filter (the predicate
//       Q of the boundary mode, the link condition, the volume test eps_v, the quality guard)
//       and do not conflict with each other (Conflicts: Matching, Greedy, TwoPass, AtomicMin)
//     surface guard: a collapse whose new S triangles would cross S is refused; the selection
//       runs again without it (Matching: the collapse is undone)
//     collapse: survivors placed, removed vertices and degenerate tets dropped, mesh compacted
//     stop when fewer than max(eps_c, 1) edges collapsed, or after max_iterations
//     build the connectivity again, carried for the vertices no collapse touched
//     host tail: once the collapses per iteration are few and shrink slowly, the rest runs on
//       the host, greedily (tuning.host_tail)
//   download the mesh
//
// Boundary and material interfaces. The feature surface S is the outer boundary plus, when the
// mesh has labels, every face between tets of different primary labels (tet_labels[0]).
// Vertices are classified interior / face / ridge / corner with the rules of tc::build_topology
// (topology.hpp), recomputed every iteration. Modes:
//   Strict    a vertex of S is never removed or moved; only interior vertices are removed, onto
//             an interior neighbour (midpoint) or onto a vertex of S (which stays put).
//   Features  the paper's rule: rank interior 0 < face 1 < ridge 2 < corner 3; the removed
//             vertex has the lower rank (equal ranks: the higher index is removed and the
//             survivor goes to the midpoint; different ranks: the survivor keeps its position);
//             corners never move; a face vertex is removed only along an S-edge, a ridge vertex
//             only along a ridge edge; an edge joining two S vertices that is not an S-edge is
//             refused. By default an interior vertex may collapse onto a vertex of S (placement =
//             that vertex, so S stays exact); paper_boundary_rule refuses that, as the paper does.
//   Free      anything the link condition and the volume test allow, midpoint placement.
//
// Attributes: every label array and tet field is carried with its tet; vertex fields stay with
// the survivor (averaged with the removed vertex for midpoint placement); input triangles and
// edges (mesh.tris, mesh.edges) are remapped through the vertex map and dropped when degenerate.
//
// Determinism: the same input and options give the same output bit for bit, whatever the run and
// the work-group size (atomics only count; every list is sorted).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "tetcollapse/device.hpp"
#include "tetcollapse/mesh.hpp"

namespace tc {

// What one iteration did; the same meaning under every conflict detection and on the host.
struct IterationStats {
  int iteration = 0;              // 0-based
  bool on_host = false;           // an iteration of the host tail (CollapseTuning::host_tail)
  // Of the mesh the iteration started from. A host-tail iteration after its first lists only
  // the edges the surface guard refused in the iteration before (every other edge was refused
  // after its star last changed): edges, marked, candidates and tested count those alone.
  int64_t vertices = 0, tets = 0, edges = 0;
  int64_t marked = 0;             // cost below the target (and in the vertex mask)
  int64_t candidates = 0;         // marked and passing the predicate Q (and the user predicate)
  // Tests run of the link condition and the volume test (and the quality guard). The selections
  // test lazily, an edge only when no cheaper rival can still take it, and only edges no earlier
  // selection of the iteration tested; the matching selection may test an edge twice (early
  // while it waits, and on the mesh as it is when its turn comes); the atomic-min conflicts test
  // every marked edge.
  int64_t tested = 0;
  int64_t selected = 0;           // chosen by the first selection, before the surface guard
  // Chosen collapses the surface guard refused, over all its runs (the selection then runs
  // again, or with the matching selection the collapse and those that saw it are undone).
  int64_t refused_by_guard = 0;
  // Collapses refused because they would take S beyond the boundary error bound (or a field
  // beyond the field error bound).
  int64_t refused_by_bound = 0;
  int64_t collapsed = 0;
  int64_t tets_after = 0, vertices_after = 0;
  // Seconds per stage (wall time, the queue finished after each stage): the connectivity, the
  // cost and marking, the selections (filter and conflicts), the surface guard (with the
  // undo), the collapse and compaction.
  double seconds_connectivity = 0, seconds_cost = 0, seconds_select = 0, seconds_guard = 0, seconds_collapse = 0,
         seconds_total = 0;
};

struct CollapseReport {
  int64_t vertices_in = 0, vertices_out = 0, tets_in = 0, tets_out = 0;
  std::vector<IterationStats> iterations;
  double seconds_total = 0;  // collapse() without the host<->device transfers of the mesh
  double seconds_upload = 0, seconds_download = 0;
  std::string device;
  double target_length = 0;   // the threshold actually used
  double median_edge_length = 0;  // of the input (computed when target_length <= 0)
  double eps_v = 0;           // the volume threshold actually used
  // With a boundary error bound: the bound in mesh units, and the largest bound the run's
  // changes of S reached (the result's S is within it of the input's, both ways).
  double boundary_error_bound = 0, boundary_error = 0;
  // With a boundary error bound, per vertex of the result: a bound on how far the S triangles
  // at it are from the input's S (each S triangle is within the largest of its corners'); the
  // improvement phase goes on from it (ImproveOptions::vertex_boundary_error).
  std::vector<double> vertex_boundary_error;
  // With a boundary error bound: the surface it measured from (CollapseOptions::
  // boundary_reference), for a run that goes on from this one.
  std::shared_ptr<const std::vector<double>> boundary_reference;
  // With a field error bound: the bound (a share of the field's range), and the largest
  // difference, as a share of the range, between an input vertex's value and the result's
  // piecewise linear field at it (over the bounded field's components).
  double field_error_bound = 0, field_error = 0;
};

// How the parallel method goes about its work: choices of speed and memory that a user rarely
// sets. reuse_across_iterations never changes the result; the others change which of the
// equally valid collapses are taken, or the output's numbering.
struct CollapseTuning {
  // Matching and Greedy: the order is the cost in steps of target_length / priority_levels and,
  // within a step, a fixed pseudo-random order of the edges (a bijective hash of the edge
  // index). The exact cost order (0) makes the parallel rounds follow chains of slowly growing
  // cost: many more rounds per iteration for few more collapses.
  double priority_levels = 64;
  // Reuse work across iterations: verdicts of the link and volume tests of edges whose rings
  // did not change, and the connectivity of the vertices no collapse touched. Same result either
  // way (a test compares both); false recomputes everything.
  bool reuse_across_iterations = true;
  // Renumber vertices along a Morton curve and tets by their smallest new vertex before the run,
  // for the memory locality of the stages. The output's vertices and tets follow that order
  // instead of the input's.
  bool spatial_order = true;
  // Host tail. Parallel method (any conflict detection but AtomicMin), run until nothing
  // collapses (eps_c <= 1), without user functions (has_user_functions): once an iteration
  // collapses fewer than host_tail x (its tets) edges and the counts shrink slowly enough to
  // promise many more iterations (at the ratio of the last two, at least
  // host_tail_min_iterations until none), the rest runs on the host with the sequential
  // method's checks, greedily (after each collapse the marked edges around it are queued at
  // once, so one iteration leaves nothing admissible; another runs only when the surface guard
  // refused an edge, since it looks beyond the star). The last iterations of the parallel
  // method collapse a few edges each (a cascade: a collapse makes a neighbour admissible) at
  // the price of passes over the whole mesh, which on a CPU device cost more than collapsing
  // them one by one; on a GPU those passes are cheap. Negative (default): with
  // Context::cpu_tuning (default: a CPU device) kHostTailCpu (kHostTailCpuMatching with the
  // matching selection, whose tail iterations are each a pass over the mesh for fewer
  // collapses), else 0; 0: every iteration on the device. Decided by counts only: the output
  // stays deterministic.
  static constexpr double kHostTailCpu = 0.002, kHostTailCpuMatching = 0.005;
  double host_tail = -1;
  // The host's fixed cost (its dynamic mesh, the edge list, the first tests of the marked edges
  // the last device iteration touched, the final compaction) is worth about this many device
  // iterations of the same mesh on a CPU device: a tail that dies out faster stays on the
  // device. Negative (default): kHostTailIterations, or kHostTailIterationsMatching with the
  // matching selection (its tail iterations cost more, and its tail shrinks faster).
  static constexpr double kHostTailIterations = 24, kHostTailIterationsMatching = 6;
  double host_tail_min_iterations = -1;
  // Under a boundary error bound: measure a change of S the carried bound refuses against the
  // reference surface (CollapseOptions::boundary_reference) on the host. The parallel method
  // then always ends with its host tail, which measures the collapses of S the device refused
  // (not with host_tail 0: all on the device, the carried bound alone).
  bool remeasure_boundary_error = true;
  // Under a measured boundary error bound: a detail of the boundary smaller than the bound may
  // go, as MMG's -hausd removes it. An edge of the boundary (not of an interface) no longer than
  // the bound, which the predicate refuses for its end points' classes (two corners; ridge
  // vertices across, or off, their ridges), collapses onto its end of the higher class when the
  // measured distance stays within the bound. False: features stay whatever their size.
  bool merge_features_within_bound = true;
};

struct CollapseOptions {
  // Method. Parallel: the pipeline above on the OpenCL device. Sequential: the CPU baseline of
  // the paper's evaluation (every admissible edge in a priority queue by cost; pop, re-check,
  // collapse), the same checks and predicate, no device needed (collapse_sequential).
  enum Method { Parallel, Sequential };
  Method method = Parallel;
  // Sequential method: an edge whose star an earlier collapse of the same iteration changed is
  // re-checked on the current mesh and collapsed when it still passes (false, default: the
  // best sequential baseline), or skipped until the next iteration (true: the paper's "skip
  // if the collapse has been invalidated by a prior collapse", fewer collapses per iteration).
  bool sequential_skip_invalidated = false;
  // Conflict detection of the parallel method.
  // Matching (default): the edges that taking the marked edges one after another in priority
  //   order would take, each tested on the mesh with the collapses taken before it applied,
  //   skipping only those that share an end point with an edge taken before: its collapses may
  //   share tets (each is tested on the result of the earlier ones), so an iteration takes about
  //   four times as many as Greedy's and a run needs about a third of the iterations
  //   (cl/collapse_matching.cl). A waiting edge gets one early volume test, and a refusal there is
  //   final for the iteration. The surface guard tests the result; the collapses it refuses are
  //   undone with those taken after them within reach. Fewer iterations and a faster run than
  //   Greedy, for slightly more tets at the end (bench/README.md).
  // Greedy: one selection under the conflicts of both of the paper's passes: the
  //   edges that taking the marked edges one after another in cost order would take, skipping
  //   each that fails the tests or touches a tet of an edge taken before. Like the two passes it
  //   never takes two edges that share a vertex or touch a common tet, but it chooses among all
  //   candidates where pass 2 chooses among pass 1's winners only, and it tests only the edges
  //   whose turn comes: fewer iterations than TwoPass, and faster (bench/README.md).
  // TwoPass: the paper's two passes (pass 1 over edges, pass 2 over tets), each the greedy
  //   independent set of its candidates in (cost, index) order.
  // AtomicMin: Gautron and Kenzel 2023, every admissible edge propagates a 64-bit descriptor
  //   (cost bits high, edge index low) with atomic_min to the tets of both one-rings and
  //   collapses when it holds the minimum in all of them; needs cl_khr_int64_extended_atomics.
  enum Conflicts { TwoPass, AtomicMin, Greedy, Matching };
  Conflicts conflicts = Matching;

  // Edges with a cost below target_length are marked. <= 0: target_factor x the input's median
  // edge length.
  double target_length = 0;
  double target_factor = 1;
  // Stop when an iteration collapses fewer than max(eps_c, 1) edges.
  int64_t eps_c = 0;
  int max_iterations = 1000;

  enum Boundary { Strict, Features, Free };
  Boundary boundary = Features;
  bool paper_boundary_rule = false;  // Features/Strict: refuse every non-S edge touching S
  bool use_labels = true;            // material interfaces from tet_labels[0]

  double eps_f = 0.01;   // face threshold on 1 - dot(n_i, n_j)  (see topology.hpp)
  double eps_r = 0.1;    // ridge threshold on 1 - dot(n_1, n_2)
  // Boundary error bound (features mode): a collapse that changes
  // S (the boundary and the material interfaces) is made only while a bound on the two-sided
  // Hausdorff distance between the input's S and the result's stays within max_boundary_error
  // x the bounding-box diagonal of the input (or max_boundary_error_abs in mesh units, when
  // > 0). The bound is carried per vertex and grows by each change of S near it
  // (cl/collapse_surface_error.h); it is conservative, so the measured distance is smaller. With
  // a bound, eps_f is not used: a vertex of a smoothly curved face is a face vertex (ridges and
  // corners as eps_r says), so curved faces coarsen within the bound. The parallel method tests
  // it on the device as its selection tests an edge (cl/collapse_bound.h), with the greedy
  // selection whatever `conflicts` says (the matching one would spend the bound faster:
  // bench/README.md); its host tail goes on from the device's bounds. 0 (both): no bound.
  double max_boundary_error = 0;
  double max_boundary_error_abs = 0;
  // With a bound: per vertex of the mesh given, what earlier changes of S already spent of it,
  // in mesh units (as CollapseReport::vertex_boundary_error reports it: a run goes on from
  // where one before it ended, as the MPI tool's rounds do); empty: none.
  std::vector<double> vertex_boundary_error;
  // With a bound: the input's S as triangles (9 coordinates each) for the re-measurement: a
  // collapse the carried bound refuses is made when the distance between its new S triangles
  // and this surface, and between this surface near the S triangles it replaces and the S
  // around after it, both measured (collapse/surface_distance.hpp), stay within the bound. The
  // S triangles it makes and those around them then count as having spent the whole bound in
  // vertex_boundary_error, so that the carried bound never builds on them. Null: the mesh's own S
  // when vertex_boundary_error is empty (a first run), else no re-measurement. A run reports the
  // one it used (CollapseReport::boundary_reference) for a run that goes on from it.
  std::shared_ptr<const std::vector<double>> boundary_reference;
  bool bounds_boundary_error() const { return max_boundary_error > 0 || max_boundary_error_abs > 0; }
  // Field error bound (beyond the paper, after Cignoni et al. 2000): a collapse is made only
  // while every input vertex keeps, in the result's piecewise linear vertex field
  // `bounded_field` (empty: the first vertex field), its input value within max_field_error x
  // the field's range over the input (per component). Each current tet carries the input
  // vertices inside it; a collapse locates those of the tets it changes in the tets it makes and
  // evaluates the field there, so the bound is checked, not estimated. A collapse that would
  // leave an input vertex outside the result is refused too (its value would depend on which
  // tet is nearest), so no input vertex falls outside, in any boundary mode. The survivor's
  // vertex fields are the input's fields at its place.
  // Every edge up to target_length is a candidate (+infinity when target_length <= 0: the
  // bound alone decides). The check needs the input vertices of the region a collapse changes,
  // which the device does not hold: both methods run the sequential method's collapses. Not
  // with user functions (std::invalid_argument). 0: no bound.
  double max_field_error = 0;
  std::string bounded_field;
  // With max_field_error, a run that goes on from an earlier coarsening of the same input (as
  // the MPI tool's rounds do): the points where the bound is measured, instead of the vertices
  // of the mesh given: 3 coordinates per point (the input's vertices), their input values of
  // the bounded field (its components per point), and the tet of the mesh given that holds each
  // (one on a shared face: either); field_range: the field's range over the input per
  // component (empty: over the points' values). Empty points: the mesh's own vertices.
  std::vector<double> field_points, field_point_values, field_range;
  std::vector<int32_t> field_point_tets;
  // Tets of the collapsed neighbourhood must keep a volume >= the volume threshold
  // (volume_threshold): by default eps_v x the input's mean tet volume, so that a mesh gives the
  // same result in any unit (the paper's absolute 2e-12 refuses every collapse of a mesh whose
  // tets are all smaller, a part of a few millimetres in metres, and freezes the neighbourhood
  // of every smaller tet of a larger one); 2e-10 is the paper's 2e-12 on its W1 robot (mean tet
  // volume 0.0101). Absolute: eps_v in mesh units, as the paper; DiagonalCubed: eps_v x the cube
  // of the input's bounding-box diagonal.
  enum VolumeScale { MeanTetVolume, Absolute, DiagonalCubed };
  double eps_v = 2e-10;
  VolumeScale eps_v_scale = MeanTetVolume;
  // Quality guard: a collapse is refused when the worst mean-ratio quality (tc_tet_quality:
  // 1 regular, -> 0 sliver) of the tets it reshapes would fall below min(their worst quality
  // before, min_quality). 0 turns it off (the paper's behaviour: only eps_v is checked).
  double min_quality = 0.1;
  // Selection rounds per iteration (two-pass conflicts only; the greedy selection leaves no such
  // edge): after the conflict passes, edges whose stars are disjoint from those of the
  // collapses chosen so far are selected again in the same connectivity (same rules). 1 is the
  // paper's algorithm and the default: a second round collapses more per early iteration but
  // needs more iterations in all (bench/README.md).
  int selection_rounds = 1;

  // Adaptive marking: with a non-empty mask (one byte per input vertex, non-zero = selected),
  // only edges whose both end points are selected are marked, or either end point with
  // mask_either. The mask travels with the survivors.
  std::vector<uint8_t> vertex_mask;
  bool mask_either = false;

  // The paper's cost for volume rendering (Section 4.5): |f0 - f1|, the first component of the
  // first vertex field at the two ends, instead of the length; edges below target_length (> 0,
  // required) are marked. Unlike the same cost as a cost_cl_source, the host tail and the
  // sequential method evaluate it too. Not with cost_cl_source.
  bool field_difference_cost = false;
  // With field_difference_cost (beyond the paper): a collapse is also refused when an end point
  // that moves would find, at its old place, the new piecewise linear field (the survivor's
  // value interpolated along the edge) off its value by more than field_check x target_length.
  // The edge-end difference is blind where the field bends (at a peak both ends are alike): this
  // step's error is what flattens it. 0: the paper's cost alone.
  double field_check = 0;
  // The paper's collapse for mesh improvement (Section 4.6), sequential method only: the cost of
  // an edge is minus the drop of the sum of the harmonic indices eta = (sum of the squared face
  // areas) / volume (Alexa 2019) over the tets the collapse reshapes, an edge whose collapse
  // leaves that sum no lower is not marked (target_length is not used), and a survivor that
  // may go anywhere on the edge goes where a line search along it puts the smallest sum.
  bool harmonic_cost = false;

  // Optional user cost, OpenCL C source defining
  //     double tc_user_cost(double3 p0, double3 p1, double f0, double f1);
  // p0, p1: end points; f0, f1: first component of the first vertex field at them (0 without
  // vertex fields). Edges with tc_user_cost < target_length are marked (target_length must then
  // be > 0, there is no median of a user cost). Compiled into the cost kernel at run time.
  std::string cost_cl_source;

  // Optional user placement, OpenCL C source defining
  //     double3 tc_user_placement(double3 p0, double3 p1, double f0, double f1);
  // (p0, p1, f0, f1 as for the cost; which end point is p0 is the pipeline's choice, from its
  // internal numbering, so write it symmetric in (p0, f0) and (p1, f1)): where the survivor
  // goes, in place of the midpoint, when both end points are off S (every edge in free
  // mode). The boundary modes keep their rules for the vertices of S (a face vertex moves along
  // its face, etc.). The survivor's vertex fields are interpolated at the placement's parameter
  // along the edge (clamped to the edge). The volume test, the quality guard and the surface
  // guard see the placement, so an unwise one is refused, never applied.
  std::string placement_cl_source;

  // Optional user predicate, OpenCL C source defining
  //     int tc_user_predicate(double3 p0, double3 p1, double f0, double f1);
  // (arguments as for the cost): 0 refuses the collapse of the edge, as the predicate Q does;
  // evaluated with Q on every marked edge of every iteration.
  // The three sources are compiled as one file each: an #include of a file of your own is not
  // found (the kernels' own headers are), so keep each function self-contained.
  std::string predicate_cl_source;

  bool has_user_functions() const {
    return !cost_cl_source.empty() || !placement_cl_source.empty() || !predicate_cl_source.empty();
  }

  // How the parallel method goes about it (not what it computes).
  CollapseTuning tuning;

  // Called after every iteration (e.g. for a progress line).
  std::function<void(const IterationStats&)> progress;
};

// Coarsens `mesh` in place. Throws tc::InputError for a mesh the pipeline cannot take (index out
// of range, repeated vertex in a tet, more than 2^31 entities), std::invalid_argument for bad
// options, tc::DeviceError for device failures (including a user cost that does not compile).
// With options.method == Sequential it runs collapse_sequential (ctx is not used).
CollapseReport collapse(Mesh& mesh, const CollapseOptions& options, Context& ctx);

// The sequential CPU method (options.method is ignored); no OpenCL device needed.
CollapseReport collapse_sequential(Mesh& mesh, const CollapseOptions& options);

// Median edge length of a mesh (unique edges), on the host. 0 for a mesh without tets.
double median_edge_length(const Mesh& mesh);

// The volume threshold a run uses: options.eps_v times what options.eps_v_scale names (the mean
// tet volume or the cube of the bounding-box diagonal of `mesh`, or 1).
double volume_threshold(const Mesh& mesh, const CollapseOptions& options);
// The feature surface S of `mesh` (its boundary faces and, with labels, the faces between
// different primary labels) as triangles, 9 coordinates each: a reference surface for
// CollapseOptions::boundary_reference.
std::vector<double> feature_surface_triangles(const Mesh& mesh, bool use_labels = true);

// The boundary error bound in mesh units: max_boundary_error_abs when > 0, else
// max_boundary_error x the bounding-box diagonal of `mesh` (0: no bound).
double boundary_error_bound(const Mesh& mesh, const CollapseOptions& options);

}  // namespace tc
