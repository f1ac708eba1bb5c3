// Mesh improvement: raise the worst element quality of a tetrahedral mesh without changing
// its boundary beyond what the boundary mode allows (the paper's Section 4.6, after Klingner
// and Shewchuk's Stellar).
//
//   improve(mesh):
//     q(t) = smallest sine of t's six dihedral angles (tc_tet_min_sine; < 0 when inverted)
//     repeat up to max_iterations times:
//       bad = tets with q < sin(threshold_deg), worst first
//       for t in bad:                     -- topological pass
//         edge removal on t's edges       (n tets around an interior edge -> 2n - 4, n <= 7:
//                                          the 3-2 flip and Shewchuk's generalisation, the
//                                          best triangulation of the edge's ring by Klincsek's
//                                          dynamic programme)
//         else a 2-3 flip on t's faces
//         else, if t has two faces on the outer boundary and is thin, its removal (features
//                                          and free modes; the boundary moves by at most
//                                          max_boundary_move)
//         accepted only if the worst q of the changed tets rises
//       for t in bad with q < sin(13 degrees) and its four vertices on the surface:
//         split its longest interior edge at a new free vertex (placed by the smoothing's
//         ascent over the edge's tets), each tet around the edge in two, when the worst q of
//         those tets rises and the mesh stays within max_tets   -- split pass
//       for v in vertices of bad tets:    -- smoothing pass (with a device: in rounds of
//                                          vertices no two of which share a tet, lowest star
//                                          quality first; curved surfaces' vertices after, on
//                                          the host)
//         move v to raise the worst q of its star (ascent along the worst tets' gradients
//         with a line search; a Face vertex of a flat boundary patch moves within its plane,
//         a ridge vertex along its line, on curved ones within max_boundary_move; corners
//         do not move)
//       stop when nothing changed, or when a pass left the smallest dihedral angle and the
//       counts of tets below 10 and 13 degrees as they were
//     collapse edges between vertices of the tets still below 13 degrees: first the paper's
//     (those whose collapse lowers the sum of the harmonic indices of what it reshapes, the
//     largest drop first, the survivor where a line search along the edge puts the smallest
//     sum), then the shortest; each only when it does not lower the worst quality of what it
//     reshapes; then the passes above again; up to 4 such rounds, each only after one that
//     raised the smallest angle or removed a tenth of the tets below 10 or 13 degrees
//
// The worst quality of the mesh never falls: each operation is accepted only when the worst
// quality of what it changes rises. Flips and splits change interior faces of one label only, so
// the material interfaces are kept (and the vertex numbering, but by the collapse step, and for
// the vertices a split appends); the outer
// boundary changes only by the
// removal of thin boundary tets (within max_boundary_move, tagged triangles following), and in
// strict mode not at all: no boundary vertex moves, so the boundary stays bit for bit.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "tetcollapse/collapse.hpp"
#include "tetcollapse/device.hpp"
#include "tetcollapse/mesh.hpp"

namespace tc {

// What a user reads of a mesh's quality (dihedral angles in degrees).
struct QualitySummary {
  int64_t tets = 0;
  double min_dihedral_deg = 0;     // smallest dihedral angle of the mesh
  double median_dihedral_deg = 0;  // median of the tets' smallest dihedral angles
  int64_t below_10_deg = 0, below_13_deg = 0;  // tets with a dihedral angle below
};
QualitySummary quality_summary(const Mesh& mesh);

struct ImprovePassStats {
  int iteration = 0;
  int64_t edge_removals = 0;  // n -> 2n - 4 (n = 3: the 3-2 flip)
  int64_t flips23 = 0;
  int64_t boundary_removals = 0;  // thin tets with two boundary faces removed
  int64_t splits = 0;         // interior edges of bad tets split at a new vertex
  int64_t relocated = 0;      // vertices moved
  int64_t collapsed = 0;      // edges collapsed (the collapse step, between two series of passes)
  int64_t bad_tets = 0;       // tets below the threshold at the start of the pass
  double min_dihedral_deg = 0;  // after the pass
  int64_t below_10_deg = 0, below_13_deg = 0;
  double seconds = 0;
  double seconds_flips = 0, seconds_relocation = 0;  // parts of `seconds`
};

struct ImproveReport {
  QualitySummary before, after;
  // Tets below 13 degrees whose four vertices may not move (boundary mode, corners, ridges,
  // curved faces): only a flip of an interior edge or face can remove them.
  int64_t pinned_below_13_before = 0, pinned_below_13_after = 0;
  std::vector<ImprovePassStats> passes;
  double seconds_total = 0;
  // Building the improvement's mesh (the vertex classes, the surface grid) and writing it back.
  double seconds_setup = 0;
  // Under a boundary error bound (ImproveOptions::max_boundary_error_abs): per vertex of the
  // output, the bound it reached (ImproveOptions::vertex_boundary_error for a run after it).
  std::vector<double> vertex_boundary_error;
};

struct ImproveOptions {
  CollapseOptions::Boundary boundary = CollapseOptions::Features;
  double eps_f = 0.01;     // as CollapseOptions: which boundary vertices are Face vertices
  double eps_r = 0.1;
  bool use_labels = true;  // material interfaces from tet_labels[0] are kept
  int max_iterations = 30;  // passes in all, the collapse steps counted
  // Tets with a dihedral angle below this (or above 180 minus it) are worked on.
  double threshold_deg = 20;
  bool flips = true, smoothing = true;
  // A bad tet whose four vertices lie on the surface (relocation cannot reach it) may have its
  // longest interior edge split at a new free vertex, when that raises the worst quality of the
  // edge's ring (the only operation that adds a vertex).
  bool splits = true;
  // Splits stop where the mesh would have more tets than this (0: no limit); the coarsening
  // command passes its input's count, so that its splits never take the mesh past it (a mesh
  // that hardly coarsens, all of it thin parts, would otherwise grow).
  int64_t max_tets = 0;
  // features and free modes: a bad tet with two faces on the outer boundary may be removed
  // (its two other faces become boundary: the boundary quad's diagonal flips) when the
  // boundary moves by at most this share of the bounding-box diagonal; 0: never.
  double max_boundary_move = 0.001;
  // With > 0 (mesh units): the boundary changes stay within this two-sided distance of the
  // surface as it was (or of the surface that vertex_boundary_error measures from). Each vertex
  // carries a bound on how far the S triangles at it are from there, the collapse step's as
  // the sequential method's (CollapseOptions::max_boundary_error_abs), a relocation's the
  // smaller of two: the largest bound of its fan plus the distance between the fan before and
  // after (cl/collapse_surface_error.h; along a line, how far the vertex moved), or the fan's
  // largest bound at the start of its series of passes plus how far a vertex of the fan got
  // from where that series started. A thin boundary tet is removed while the largest bound of
  // its four corners plus how far the removal moves the boundary stays within it (the corners
  // then take that; max_boundary_move is not used).
  double max_boundary_error_abs = 0;
  // With max_boundary_error_abs: per vertex, what earlier changes of S already spent of it
  // (CollapseReport::vertex_boundary_error, which the coarsening command passes); empty: none.
  std::vector<double> vertex_boundary_error;
  // Collapse of the short edges of the tets below 13 degrees that flips and relocation left
  // (the paper's improvement by collapse), through the sequential method's checks, with the
  // quality guard at 0.3 (no collapse lowers the worst mean ratio of what it reshapes below
  // min(0.3, its value before)); the step is kept only if it leaves the smallest dihedral
  // angle and the counts below 10 and 13 degrees no worse. Edges up to collapse_length; 0:
  // 1.5 x the mesh's median edge length. After it, flips and relocation run again.
  bool collapse = true;
  double collapse_length = 0;
  // The collapse step begins as the paper's: edges of the bad tets whose collapse lowers the sum
  // of the harmonic indices of what it reshapes, the largest drop first, the survivor placed by
  // a line search along the edge, and no tet of the region made worse by its smallest dihedral
  // angle (CollapseOptions::harmonic_cost); then the shortest edges as above on what is left.
  bool harmonic_collapse = true;
  // At most this many rounds of the collapse step and the passes after it, each only after one
  // that raised the smallest angle or removed a tenth of the tets below 10 or 13 degrees.
  int collapse_rounds = 4;
  // With a non-empty mask (one byte per vertex, non-zero = selected), only selected vertices
  // move, only tets whose vertices are all selected are flipped, and the collapse step collapses
  // only edges between two selected vertices (the mask follows its renumbering).
  std::vector<uint8_t> vertex_mask;
  std::function<void(const ImprovePassStats&)> progress;
};

// Improves `mesh` in place: tets, labels and tet fields (a new tet takes those of a tet it
// replaces), vertex positions (a moved vertex takes the values of the vertex fields at its new
// place, interpolated linearly in the tets around it). Throws InputError for an inverted tet.
// On the CPU, one operation after the other (the sequential baseline).
ImproveReport improve(Mesh& mesh, const ImproveOptions& options = {});
// The same on ctx's device. Each smoothing pass moves the vertices off curved surfaces in
// rounds of vertices no two of which share a tet (the one of lowest star quality, then index,
// first), then the others on the host, where the surface guard runs. Unless the context tunes
// for a CPU (Context::cpu_tuning; a CPU finds them as fast on the host), each flip pass finds
// the interior flips of the bad tets on the device and applies rounds of flips sharing no
// vertex (worst tet first), the last quarter and the boundary's operations on the host. The
// result does not depend on the work-group size; the operations are those of the CPU version,
// in another order, so the meshes differ slightly.
ImproveReport improve(Mesh& mesh, const ImproveOptions& options, Context& ctx);

}  // namespace tc
