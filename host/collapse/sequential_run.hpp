// The iterations of the sequential CPU method (tc::collapse_sequential), one step at a time so
// that the tests can look at the mesh between two iterations.
//
// One iteration (the paper's "CPU sequential" baseline, Sec. 4):
//   1. every edge of the current mesh with its cost (the edge length) and marking (cost below
//      the target, vertex mask); Q and then the link condition, the volume test and the quality
//      guard on each marked edge; every admissible edge goes into a priority queue ordered by
//      (cost, edge index) -- the edge index order is that of the lexicographic (a, b), a < b;
//   2. pop the queue until empty. An edge whose star an earlier collapse of this iteration
//      changed (an end point in touched()) is checked again on the current mesh: still an edge,
//      still marked, and every check passes with the current classes; an edge whose cost changed
//      (an end point moved) goes back into the queue with its new cost. The others keep the
//      verdict of step 1, which still holds since nothing they depend on changed. Last, the
//      surface guard of the parallel pipeline (SeqMesh::guard_ok, cl/collapse_guard.cl), which
//      looks beyond the star: a collapse whose new S triangles would cross S is refused (its end
//      points then count as touched, so the edge is tested again next iteration);
//   3. the dead vertices and tets are dropped from the arrays (order kept).
// Iterations repeat until one collapses fewer than max(eps_c, 1) edges, or max_iterations.
// Edges created by a collapse (the removed vertex's edges, now at the survivor) wait for the
// next iteration, as in the paper. Greedy mode (set_greedy; the parallel method's host tail):
// after each collapse the marked edges of every touched vertex go into the queue at once (each
// edge once), and the run stops after an iteration in which the surface guard refused nothing.
// Then every marked edge was tested after the last change of its star and refused, except those
// the guard refused, so a later greedy iteration lists only those edges (its edges, marked,
// candidates and tested count them alone).
// The options of the parallel method's conflict detection (conflicts, selection_rounds) do not
// apply; a user cost (cost_cl_source) is refused.
//
// IterationStats of an iteration: edges (all edges of the mesh; with a vertex mask that needs
// both end points, the edges between selected vertices, the only ones listed), marked (all
// marked edges; in a greedy iteration after the first, of the listed edges only, as edges), candidates (of those, passing Q at the start),
// tested (link and volume tests at the start), selected (pushed into the queue),
// refused_by_guard (popped edges the surface guard refused); seconds_connectivity: the edge
// list, seconds_select: marking, checks and queue, seconds_collapse: popping, checking
// again, the surface guard, collapsing and the compaction (seconds_cost and seconds_guard are
// 0).
//
// Reuse (CollapseTuning::reuse_across_iterations, default on; the result is the same either
// way and a test compares both): an edge neither of whose end points was touched in the
// previous iteration has the star, cost and verdict it had then; it was not admissible then
// (an admissible edge either collapsed or was overtaken by a collapse that touched it), so step
// 1 skips its link and volume tests. Off: every marked edge passing Q is tested, and every
// popped edge checked again.
#pragma once

#include <chrono>
#include <cmath>
#include <cstdint>
#include <vector>

#include <memory>

#include "collapse/edge_key_set.hpp"
#include "collapse/field_bound.hpp"
#include "collapse/sequential_mesh.hpp"
#include "collapse/surface_distance.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/mesh.hpp"

namespace tc::sequential_detail {

SeqParams seq_params_from(const CollapseOptions& o);

// What the parallel method hands its host tail (collapse.cpp) besides the mesh: the tet
// neighbours and, per vertex of the current mesh, the flags and classes (the device's, made by
// the same rules: SeqMesh does not compute them again), and whether the star changed in the device's last iteration
// (touched; also the end points of an edge the surface guard refused). An edge whose end points
// are both untouched was not admissible then (the greedy selection takes or blocks, within
// reach, every admissible candidate) and its star, cost, flags and classes are the same now,
// so with reuse_across_iterations the first iteration skips its tests, as it skips those of
// its own earlier iterations' untouched edges.
struct TailSeed {
  std::vector<uint8_t> vflags, vclass, touched;
  std::vector<int32_t> tet_nbr;  // 4 per tet (collapse_common.h), the device's
  // The edges of the mesh (a, b), a < b, 2 per edge, the device's (Connectivity::edges): the
  // first iteration's edge list, instead of gathering N(v) of every vertex again (a visible share
  // of a short tail). Empty: gathered. Any order: the queue orders by (cost, a, b).
  std::vector<int32_t> edges;
};

class SequentialRun {
 public:
  // Validates the options (std::invalid_argument) and the mesh (tc::InputError).
  SequentialRun(Mesh& mesh, const CollapseOptions& options, const TailSeed* seed = nullptr);

  // Runs one iteration; false when there is nothing more to do (the stop rule was met, or
  // max_iterations reached, or no tets), without running one.
  bool step();
  // Remaps mesh.tris and mesh.edges and completes the report. Call once, after the last step.
  CollapseReport finish();

  SeqMesh& seq() { return sm_; }
  // Greedy: after each collapse the marked edges around it go into the queue at once, so that
  // one iteration collapses until nothing is admissible; the run then stops, unless the surface
  // guard refused an edge (it looks beyond the star), which another iteration tests again.
  void set_greedy(bool on) { greedy_ = on; }
  const CollapseReport& report() const { return report_; }
  // Greedy: the edges (2 per edge, current numbering) the surface guard refused in the last
  // iteration, which the next one lists (alone).
  const std::vector<int32_t>& guard_refused() const { return refused_; }
  double target() const { return target_; }
  // origin(): where each vertex of the mesh the run was given is now, its index or its
  // survivor's when a collapse removed it (mesh.tris and mesh.edges are remapped through it);
  // source(): which vertex of that mesh each vertex now is. keep_origin(), before the first
  // step, keeps both (origin is kept anyway for a mesh with triangles or edges).
  void keep_origin();
  const std::vector<int32_t>& origin() const { return origin_; }
  const std::vector<int32_t>& source() const { return source_; }
  // Under a boundary error bound: per vertex, the bound on how far the S triangles at it are
  // from the input's S (each S triangle is within the largest of its corners'). Zero at the
  // start unless seeded (before the first step: what earlier changes of S left, per vertex of
  // the mesh given); after finish(), per vertex of the result.
  void seed_boundary_error(std::vector<double> eps);
  const std::vector<double>& boundary_errors() const { return eps_; }

 private:
  // The edge's cost: its length, or CollapseOptions::field_difference_cost's |f0 - f1| (the
  // device's, params.cpp: the first component of the first vertex field), or harmonic_cost's.
  double cost(int32_t a, int32_t b) {
    if (o_.harmonic_cost) return harmonic_cost(a, b);
    if (!o_.field_difference_cost) return sm_.length(a, b);
    const Field& f = mesh_.vertex_fields[0];
    return std::fabs(f.values[size_t(a) * size_t(f.components)] - f.values[size_t(b) * size_t(f.components)]);
  }

  // The vertex mask's verdict on the edge (a, b): both end points selected, or either with
  // mask_either; every edge without a mask.
  bool selected(int32_t a, int32_t b) const {
    if (mask_.empty()) return true;
    return o_.mask_either ? (mask_[a] || mask_[b]) : (mask_[a] && mask_[b]);
  }
  // Minus the drop of the harmonic sum (+infinity outside the mask, where Q refuses, or where
  // it does not drop), with the survivor where the rules or the line search put it.
  double harmonic_cost(int32_t a, int32_t b);
  // The line search: the place on the edge (a, b) with the smallest harmonic sum after the
  // collapse, and that sum.
  double harmonic_place(int32_t a, int32_t b, geo::tc_d3* place);
  // The last line search's edge, result and the collapse count it saw: the cost, the checks and
  // the collapse ask for the same edge's place several times between two collapses.
  struct HarmonicPlace {
    int32_t a = -1, b = -1;
    int64_t collapses = -1;
    geo::tc_d3 place{0, 0, 0};
    double sum = 0;
  };
  HarmonicPlace last_place_;
  std::vector<SeqMesh::HarmonicTerm> terms_;
  int64_t collapses_ = 0;  // collapses so far (the line search's cache key)

  struct QueueEntry {
    double cost;
    int32_t a, b;  // a < b
    uint8_t dir;
  };

  Mesh& mesh_;
  const CollapseOptions o_;  // a copy: the run may outlive the caller's options
  CollapseReport report_;
  std::chrono::steady_clock::time_point t_start_;
  SeqParams params_;  // before sm_, which is built from it
  SeqMesh sm_;
  double target_ = 0;
  int it_ = 0;
  bool done_ = false;
  std::vector<uint8_t> mask_;      // per current vertex (empty: no mask)
  // The boundary error bound (mesh units, 0: none) and, per current vertex, the bound on how far
  // S near it has moved from the input's (SeqMesh::surface_change).
  double bound_ = 0;
  std::vector<double> eps_;
  std::unique_ptr<FieldBound> field_;  // the field error bound (null: none)
  // The boundary error bound measured where the carried one refuses (CollapseOptions::
  // boundary_reference; null: not measured), and how far every point of the reference may be
  // from S now (the bound, or more where the vertex bounds given say so).
  std::shared_ptr<const std::vector<double>> reference_triangles_;
  std::unique_ptr<surface_distance::ReferenceSurface> reference_;
  double reach_ = 0;
  std::vector<std::array<geo::tc_d3, 3>> olds_, news_, around_;
  std::vector<int32_t> corners_;
  // Whether the collapse of (a, b) in direction dir keeps S within the bound of the reference,
  // measured; its corners (collapse_fans) in corners_.
  bool measured_ok(int32_t a, int32_t b, uint8_t dir);
  // The predicate (SeqMesh::predicate), and under the measured bound the merge of a detail
  // smaller than it (CollapseTuning::merge_features_within_bound): whether (a, b) is such a merge
  // (refused_fe: the S flags of an edge the predicate refused, which it then need not ask again).
  int predicate(int32_t a, int32_t b, uint8_t& fe);
  bool merges_feature(int32_t a, int32_t b, const uint8_t* refused_fe = nullptr);
  std::vector<int32_t> tmap_;
  std::vector<int32_t> origin_;    // input vertex -> current vertex (only with tris or edges)
  std::vector<int32_t> source_;    // current vertex -> input vertex (keep_origin)
  std::vector<uint32_t> touched_;  // per vertex: 1 + the last iteration that touched its star (0: none)
  std::vector<QueueEntry> edges_, heap_;
  std::vector<int32_t> seed_edges_;  // TailSeed::edges, for the first iteration (then cleared)
  std::vector<int32_t> nb_, vmap_, kept_;
  bool greedy_ = false;
  EdgeKeySet queued_;  // greedy: the edges (a << 32 | b) in the queue
  // greedy: the edges the surface guard refused in the last iteration (2 per edge; the
  // candidates of the next one)
  std::vector<int32_t> refused_;
  std::vector<uint32_t> greedy_mark_;
  uint32_t greedy_stamp_ = 0;
};

}  // namespace tc::sequential_detail
