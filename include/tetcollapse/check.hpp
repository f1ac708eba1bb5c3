// Validity and quality checker for tetrahedral meshes.
//
//   tc::CheckReport r = tc::check_mesh(mesh, options, &reference);   // reference optional
//   if (!r.valid) ...               // r.errors: one line each, naming the first offenders
//   std::string json = tc::check_report_json(r);   // one JSON object, snake_case keys
//   std::string text = tc::check_report_text(r);   // human summary
//
// Validity (any failure makes `valid` false and adds an error finding):
//   * vertex indices in range, finite coordinates, no tet repeating a vertex, no two tets on
//     the same four vertices;
//   * every tet strictly positively oriented, decided exactly (CGAL exact predicates).
//     Positive means geo::tc_orient3d(p0,p1,p2,p3) > 0 (right-hand rule of Gmsh/Medit/VTK);
//     CGAL::orientation(p0,p1,p2,p3) == CGAL::POSITIVE is the same test (both are the sign
//     of det[p1-p0, p2-p0, p3-p0]; checked on the unit corner tet by test_check);
//   * every triangular face in one or two tets, in opposite orientations when in two;
//   * the boundary surface (faces in one tet, oriented out of their tet) is edge-manifold,
//     closed and consistently oriented;
//   * no self-intersection of the boundary surface (CGAL Polygon Mesh Processing);
//   * no two vertices closer than `duplicate_tol` on every axis.
// Warnings (do not affect `valid`): unreferenced vertices, positive tets with volume below
// `eps_volume`, non-manifold (pinched) boundary vertices, an invalid reference mesh.
// With a reference: the boundary's number of connected components and Euler characteristic
// must not change (error otherwise); volume change, Hausdorff distance and reductions are
// reported, and gated only when an option asks.
//
// The checker never throws on bad mesh data: everything becomes a finding. It throws
// std::bad_alloc only when memory runs out.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "tetcollapse/fields.hpp"
#include "tetcollapse/mesh.hpp"

namespace tc {

struct CheckOptions {
  // Tets with 0 < volume < eps_volume x the mesh's mean tet volume (eps_volume itself when
  // eps_volume_absolute) are counted (warning): the collapse's default volume threshold.
  double eps_volume = 2e-10;
  bool eps_volume_absolute = false;
  bool small_volume_is_error = false;
  double duplicate_tol = 1e-13;   // vertices differing by less than this on every axis
  bool self_intersection = true;  // CGAL PMP self-intersection test of the boundary
  bool quality = true;            // dihedral angles, radius ratio, AMIPS, edge lengths
  bool hausdorff = true;          // with a reference: two-sided Hausdorff distance
  double hausdorff_rel_error = 1e-4;  // error bound of the Hausdorff distance, x bbox diagonal
  int64_t field_samples = 100000;    // with a reference: random points for the field errors
  int max_offenders = 5;          // offenders named per finding
  int histogram_bins = 18;

  // Gates (off when negative): each one that fails adds an error finding.
  double min_dihedral_gate_deg = -1;     // smallest dihedral angle must be >= this
  double max_hausdorff_rel_gate = -1;    // Hausdorff / reference bbox diagonal must be <= this
  double max_volume_change_rel_gate = -1;  // |total volume change| / reference volume <= this
};

enum class Severity { Error, Warning };

// One kind of problem, with how often it occurs and the first offenders.
// `code` and the meaning of each offender tuple:
//   non_finite_coordinate      {vertex}
//   index_out_of_range         {tet, corner, value}
//   repeated_vertex            {tet}
//   duplicate_tet              {tet_a, tet_b}            (same four vertices)
//   inverted_tet               {tet}                     (exact orientation negative)
//   flat_tet                   {tet}                     (exact orientation zero)
//   small_volume               {tet}                     (warning, or error by option)
//   face_in_many_tets          {v0, v1, v2, tet, tet, tet, ...}   (sorted face vertices, then its tets)
//   face_same_orientation      {v0, v1, v2, tet_a, tet_b}
//   boundary_open_edge         {u, v}                    (boundary edge in one boundary triangle)
//   boundary_nonmanifold_edge  {u, v, triangles}         (boundary edge in > 2 boundary triangles)
//   boundary_orientation       {u, v}                    (two boundary triangles run u->v the same way)
//   boundary_nonmanifold_vertex {vertex, umbrellas}      (warning: pinched boundary vertex)
//   boundary_self_intersection {tet_a, face_a, tet_b, face_b}  (boundary faces, face i opposite vertex i)
//   duplicate_vertices         {v_a, v_b}
//   unreferenced_vertex        {vertex}                  (warning)
//   min_dihedral_gate          {tet}                     (tets below the gate)
//   topology_changed, hausdorff_gate, volume_change_gate, reference_invalid,
//   self_intersection_skipped, hausdorff_skipped       {} (no offender tuples)
struct CheckFinding {
  Severity severity = Severity::Error;
  std::string code;
  int64_t count = 0;                            // offenders in total
  std::vector<std::vector<int64_t>> offenders;  // the first max_offenders tuples
  std::string message;                          // one line, names the first offenders
};

// min / max / mean / median of a set of values (count 0: all NaN).
struct Stats {
  int64_t count = 0;
  double min = std::numeric_limits<double>::quiet_NaN();
  double max = std::numeric_limits<double>::quiet_NaN();
  double mean = std::numeric_limits<double>::quiet_NaN();
  double median = std::numeric_limits<double>::quiet_NaN();
};

// Equal-width bins over [lo, hi]; values outside are clamped into the end bins.
struct Histogram {
  std::string name;
  double lo = 0, hi = 1;
  std::vector<int64_t> counts;
};

// The boundary surface: faces in exactly one tet. Components are connected through
// edges; euler = vertices - edges + faces (2 per sphere-like closed component).
struct SurfaceTopology {
  int64_t vertices = 0, edges = 0, faces = 0;
  int64_t components = 0;
  int64_t euler = 0;
  int64_t nonmanifold_vertices = 0;  // pinched boundary vertices
};

struct LabelVolume {
  int32_t label = 0;
  double volume = 0, reference_volume = 0;
  double change = 0;      // volume - reference_volume
  double change_rel = 0;  // change / reference_volume (NaN when the reference has none)
};

struct ReferenceComparison {
  int64_t reference_vertices = 0, reference_tets = 0;
  double tet_reduction = 0, vertex_reduction = 0;  // 1 - mesh / reference
  double volume = 0, reference_volume = 0;
  double volume_change = 0, volume_change_rel = 0;
  std::string label_name;                          // primary labels compared ("" = none)
  std::vector<LabelVolume> labels;
  SurfaceTopology reference_boundary;
  bool topology_changed = false;
  bool reference_valid = true;
  bool hausdorff_computed = false;
  double hausdorff = std::numeric_limits<double>::quiet_NaN();          // max of both directions
  double hausdorff_to_reference = std::numeric_limits<double>::quiet_NaN();    // mesh -> reference
  double hausdorff_from_reference = std::numeric_limits<double>::quiet_NaN();  // reference -> mesh
  double hausdorff_rel = std::numeric_limits<double>::quiet_NaN();      // / reference bbox diagonal
  double hausdorff_error_bound = 0;
  // Per vertex field both meshes have: how far the mesh's field is from the reference's
  // (tc::field_errors, CheckOptions::field_samples random points and every reference vertex).
  std::vector<FieldError> fields;
};

struct QualityReport {
  bool computed = false;
  int64_t tets = 0;                 // tets measured (indices valid, no repeated vertex)
  Stats min_dihedral_deg;           // per-tet smallest dihedral angle
  Stats max_dihedral_deg;           // per-tet largest dihedral angle
  double median_dihedral_deg = std::numeric_limits<double>::quiet_NaN();  // over all 6 angles
  int64_t below_5_deg = 0, below_10_deg = 0, below_13_deg = 0;  // tets with min dihedral below
  Stats radius_ratio;               // 3 * inradius / circumradius, 1 for a regular tet
  Stats amips;                      // conformal AMIPS energy, 1 for regular; positive tets only
  Stats mean_ratio;                 // geo::tc_tet_quality
  Stats edge_length;                // over unique edges
  std::vector<Histogram> histograms;
};

struct CheckReport {
  bool valid = true;
  std::vector<CheckFinding> findings;
  std::vector<std::string> errors;    // messages of the error findings, in order
  std::vector<std::string> warnings;  // messages of the warning findings

  int64_t vertices = 0, tets = 0;
  int64_t referenced_vertices = 0;
  int64_t interior_faces = 0, boundary_faces = 0;
  int64_t inverted_tets = 0, flat_tets = 0, small_volume_tets = 0;
  double volume = 0;                  // sum of signed tet volumes
  double boundary_volume = 0;         // volume enclosed by the boundary (divergence theorem)
  double min_volume = std::numeric_limits<double>::quiet_NaN();
  double bbox_min[3] = {0, 0, 0}, bbox_max[3] = {0, 0, 0};
  double bbox_diagonal = 0;
  SurfaceTopology boundary;
  bool self_intersection_checked = false;
  int64_t self_intersections = 0;     // intersecting boundary triangle pairs

  QualityReport quality;
  bool has_reference = false;
  ReferenceComparison reference;

  std::vector<std::pair<std::string, double>> timings;  // seconds per phase, in order

  const CheckFinding* find(const std::string& code) const;  // nullptr when absent
};

// Runs every check on `mesh` (and the comparison with `reference` when given).
CheckReport check_mesh(const Mesh& mesh, const CheckOptions& options = {}, const Mesh* reference = nullptr);

// One JSON object with every number of the report (non-finite numbers as null).
std::string check_report_json(const CheckReport& report);

// A short human summary: verdict, counts, errors and warnings, quality, reference.
std::string check_report_text(const CheckReport& report);

}  // namespace tc
