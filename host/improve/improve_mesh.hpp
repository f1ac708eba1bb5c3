// The mesh the improvement edits: tets with a dead flag and free slots, each vertex's tets,
// each tet's quality, and what may change (which vertices move and how, which faces and edges
// the input tags).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "geometry.h"
#include "improve_flip.h"
#include "tetcollapse/device.hpp"
#include "tetcollapse/improve.hpp"
#include "tetcollapse/mesh.hpp"

namespace tc::improve_detail {

using geo::tc_d3;
using Tet = std::array<int32_t, 4>;

inline bool contains(const Tet& q, int32_t x) { return q[0] == x || q[1] == x || q[2] == x || q[3] == x; }

enum Motion : uint8_t { kFixed = 0, kFree = 1, kInPlane = 2, kAlongLine = 3 };

// The paper's bad tets, below 13 degrees: by the smallest dihedral angle's cosine (the counts the
// goals state) and by the min-sine (the passes' measure, angles above 167 degrees too).
inline const double kCos13 = std::cos(13 * 3.14159265358979323846 / 180);
inline const double kSin13 = std::sin(13 * 3.14159265358979323846 / 180);

class ImpMesh {
 public:
  // Reads `mesh`; positions are edited in mesh.points directly.
  ImpMesh(Mesh& mesh, const ImproveOptions& options);
  // Writes the live tets (and their labels and tet fields) back to the mesh.
  void write_back();

  tc_d3 point(int32_t v) const { return geo::tc_point(points_.data(), v); }
  const double* point_data() const { return points_.data(); }
  // The tets as 4 ints each (dead ones included: see alive).
  const int32_t* tet_data() const { return tets_.empty() ? nullptr : tets_[0].data(); }
  // Moves v to p, a point inside its star, with its vertex field values interpolated there.
  void move(int32_t v, tc_d3 p);
  // Appends a vertex at p, a point inside the tets `around`, free to move, its vertex field
  // values interpolated there; it is in no tet yet (replace adds them). Returns its index.
  int32_t add_vertex(tc_d3 p, const std::vector<int32_t>& around);
  bool selected(int32_t v) const { return mask_.empty() || mask_[size_t(v)] != 0; }
  const Tet& tet(int32_t t) const { return tets_[size_t(t)]; }
  bool alive(int32_t t) const { return !dead_[size_t(t)]; }
  int32_t num_tet_slots() const { return int32_t(tets_.size()); }
  int64_t live_tets() const { return int64_t(tets_.size()) - int64_t(free_.size()); }
  int32_t num_vertices() const { return int32_t(vtets_.size()); }
  const std::vector<int32_t>& tets_of(int32_t v) const { return vtets_[size_t(v)]; }
  double quality(int32_t t) const { return quality_[size_t(t)]; }
  int32_t label(int32_t t) const { return label_[size_t(t)]; }
  Motion motion(int32_t v) const { return Motion(motion_[size_t(v)]); }
  // kInPlane: the plane's normal; kAlongLine: the line's direction.
  tc_d3 motion_direction(int32_t v) const { return normal_[size_t(v)]; }
  // How far v may get from where it started (infinite but on curved surfaces and lines).
  tc_d3 start(int32_t v) const { return start_[size_t(v)]; }
  double max_offset(int32_t v) const { return max_offset_[size_t(v)]; }
  // Whether moving v to p keeps the feature surface free of self-intersections (only needed
  // where the move changes the surface's shape: off flat patches and straight lines).
  bool bends_surface(int32_t v) const { return max_offset_[size_t(v)] < std::numeric_limits<double>::infinity(); }
  bool surface_stays_clear(int32_t v, tc_d3 p);
  // After v moved: its surface triangles go into the grid cells of their new places.
  void surface_moved(int32_t v);

  // Quality of tet t with vertex v at p (v need not be in t).
  double quality_with(int32_t t, int32_t v, tc_d3 p) const;
  double quality_of(const Tet& q) const {
    return geo::tc_tet_min_sine(point(q[0]), point(q[1]), point(q[2]), point(q[3]));
  }

  bool has_edge(int32_t a, int32_t b) const;
  bool has_face(int32_t a, int32_t b, int32_t c) const { return across(-1, a, b, c) >= 0; }
  bool tagged_edge(int32_t a, int32_t b) const { return tagged_edges_.count(key2(a, b)) != 0; }
  // The tagged edges as sorted keys (smaller vertex << 32 | larger), the tagged triangles as
  // sorted records of 4 ints (the vertices in increasing order, 0): what the device searches.
  std::vector<uint64_t> tagged_edge_keys() const;
  std::vector<int32_t> tagged_face_records() const;
  bool tagged_face(int32_t a, int32_t b, int32_t c) const { return tris_.count(face_key(a, b, c)) != 0; }
  // The tet other than t with the face (a, b, c), or -1 (a boundary face).
  int32_t across(int32_t t, int32_t a, int32_t b, int32_t c) const;
  bool may_change_boundary() const { return max_boundary_move_ > 0; }
  // Under a boundary error bound (ImproveOptions::max_boundary_error_abs): only relocations,
  // flips of flat quads and removals of thin tets within it change the boundary.
  bool bounded() const { return bounded_; }
  double max_boundary_move() const { return max_boundary_move_; }
  // Under the bound, each vertex carries a bound on how far the surface triangles at it are
  // from the surface the bound measures from (ImproveOptions::max_boundary_error_abs). The
  // bound v would get at p; a move is admissible while it is at most max_boundary_move().
  double boundary_error_at(int32_t v, tc_d3 p) const;
  void set_boundary_error(int32_t v, double e) { err_[size_t(v)] = e; }
  const std::vector<double>& boundary_errors() const { return err_; }
  // Replaces the tets `old` by `added` where that changes the boundary: its faces `gone` (two)
  // give way to `exposed` (two), which take over the input's tags of `gone`. False (nothing
  // done) if the tags do not allow it, if an exposed face would touch the rest of the surface,
  // or (a removal: `added` empty) if a tet across an exposed face would become a fin.
  // `flat`: the four vertices of the two pairs of faces lie in one plane (to rounding), so the
  // surface keeps its shape and its vertices may go on moving as they did. Under a boundary
  // error bound, `change` bounds the two-sided distance between the gone and the exposed pair
  // (0 when flat), and it fails when the bound would not hold.
  bool replace_on_boundary(const std::vector<int32_t>& old, const std::vector<Tet>& added,
                           const std::array<std::array<int32_t, 3>, 2>& gone,
                           const std::array<std::array<int32_t, 3>, 2>& exposed, bool flat, double change = 0);

  // Replaces the tets `old` by `added` (label and tet fields of `like`).
  void replace(const std::vector<int32_t>& old, const std::vector<Tet>& added, int32_t like);

  // Change tracking, so that a pass retries an operation that found nothing only where the
  // mesh changed since: every change stamps the vertices whose stars it altered.
  // A vertex is `settled` for an operation when the operation found nothing there and nothing
  // changed around it since.
  uint32_t stamp() const { return stamp_; }
  bool settled(const std::vector<uint32_t>& failed_at, int32_t v) const {
    return failed_at[size_t(v)] >= changed_[size_t(v)];
  }
  void failed(std::vector<uint32_t>& failed_at, int32_t v) const { failed_at[size_t(v)] = stamp_; }
  std::vector<uint32_t> smooth_failed_at, flip_failed_at;  // per vertex

  // Whether replacing tets of qualities (sine, cos) by (new_sine, new_cos) improves: the worst
  // min-sine rises and the smallest dihedral angle does not fall below min(before, threshold).
  bool improves(double sine, double cos, double new_sine, double new_cos) const {
    return new_sine > sine && new_cos <= std::max(cos, cos_threshold_);
  }
  // The quality measure's second half: the smallest dihedral angle must not fall below
  // min(its value before, the threshold) (as a cosine: not rise above max(before, cos threshold)).
  double max_cos(int32_t t) const { return max_cos_[size_t(t)]; }
  double max_cos_of(const Tet& q) const {
    return geo::tc_tet_max_dihedral_cos(point(q[0]), point(q[1]), point(q[2]), point(q[3]));
  }
  double max_cos_with(int32_t t, int32_t v, tc_d3 p) const;
  double cos_threshold() const { return cos_threshold_; }

 private:
  static uint64_t key2(int32_t a, int32_t b);
  using FaceKey = std::array<int32_t, 3>;
  static FaceKey face_key(int32_t a, int32_t b, int32_t c);
  struct FaceHash {
    size_t operator()(const FaceKey& k) const {
      return (size_t(uint32_t(k[0])) * 0x9E3779B97F4A7C15ull) ^ (size_t(uint32_t(k[1])) * 0xC2B2AE3D27D4EB4Full) ^
             size_t(uint32_t(k[2]));
    }
  };
  void mark_motion(const ImproveOptions& options);
  void touch_star(int32_t v);
  // v's vertex field values: the input fields interpolated at p in the tet of `around` holding it.
  void interpolate_fields(const std::vector<int32_t>& around, tc_d3 p, int32_t v);

  Mesh& mesh_;
  std::vector<double>& points_;
  std::vector<Tet> tets_;
  std::vector<int32_t> label_;   // per tet: which tuple of the input's label values it carries
  std::vector<int32_t> origin_;  // per tet: the input tet whose labels and tet fields it takes
  std::vector<uint8_t> dead_;
  std::vector<int32_t> free_;
  std::vector<double> quality_, max_cos_;
  std::vector<uint32_t> changed_;
  uint32_t stamp_ = 1;
  double cos_threshold_ = 1;
  std::vector<std::vector<int32_t>> vtets_;
  std::vector<uint8_t> motion_, mask_;
  std::vector<tc_d3> normal_, start_;
  std::vector<double> max_offset_;

  // The feature surface's triangles (outer boundary and interfaces) in a uniform grid of cells
  // of about their size, for the intersection test of surface moves: each triangle is listed
  // in the cells its box overlaps.
  std::vector<FaceKey> sfaces_;
  std::vector<uint32_t> sface_seen_;
  std::vector<uint8_t> sface_alive_;
  uint32_t sface_query_ = 0;
  std::unordered_map<FaceKey, int32_t, FaceHash> sface_index_;
  std::unordered_map<int64_t, std::vector<int32_t>> grid_;
  double cell_ = 0;
  tc_d3 grid_origin_{0, 0, 0};
  void build_surface_grid();
  // Per tet slot and face (4 t + f): whether the face is on the surface (on_surface), all at once.
  std::vector<uint8_t> surface_slots() const;
  void grid_insert(int32_t f);
  using CellBox = std::array<int64_t, 6>;  // lowest and highest cell indices
  std::vector<CellBox> sface_cells_;       // per surface triangle: the cells it is listed in
  CellBox cells_of(tc_d3 lo, tc_d3 hi) const;
  template <class Fn>
  void each_cell(const CellBox& b, Fn&& fn);
  template <class Fn>
  void each_cell(tc_d3 lo, tc_d3 hi, Fn&& fn);
  // The surface triangles at v (as sorted vertex triples).
  void surface_faces_at(int32_t v, std::vector<FaceKey>& out) const;
  bool on_surface(int32_t t, int32_t a, int32_t b, int32_t c) const;
  // Does triangle a (at pa; vertex v taken at p) keep clear of the surface's other triangles
  // but `ignore`?
  bool triangle_clear(const FaceKey& a, const tc_d3 (&pa)[3], int32_t v, tc_d3 p, const FaceKey* ignore,
                      int n_ignore);
  std::unordered_set<uint64_t> tagged_edges_;
  std::unordered_map<FaceKey, int64_t, FaceHash> tris_;  // the input's tagged triangles -> index
  double max_boundary_move_ = 0;
  bool bounded_ = false;
  std::vector<double> err_, err_start_;  // per vertex, under the bound: now, and at start_
};

// One topological pass over the bad tets (worst first); returns the counts in `stats`.
void flip_pass(ImpMesh& m, const std::vector<int32_t>& bad, ImprovePassStats& stats);
// The same on `ctx`: the interior flips found on the device and applied in rounds of flips
// that share no vertex; the boundary's flips and removals then on the host.
void flip_pass(ImpMesh& m, Context& ctx, const std::vector<int32_t>& bad, ImprovePassStats& stats);
// The boundary operations of a bad tet alone (after the device's flips): the removal of an edge
// of the boundary (a flat quad's diagonal), else of the tet itself. Counts in `stats`.
bool try_boundary_flips(ImpMesh& m, int32_t t, ImprovePassStats& stats);
// The vertices a smoothing pass tries: those of the bad tets that may move, in index order
// (each is skipped while `settled`).
std::vector<int32_t> smoothing_candidates(const ImpMesh& m, const std::vector<int32_t>& bad);
// One smoothing pass over the vertices of the bad tets, one after the other.
void smooth_pass(ImpMesh& m, const std::vector<int32_t>& bad, ImprovePassStats& stats);
// The same on `ctx`: the vertices off curved surfaces move on the device, in rounds of
// vertices no two of which share a tet; the others then move on the host.
void smooth_pass(ImpMesh& m, Context& ctx, const std::vector<int32_t>& bad, ImprovePassStats& stats);

// The tets around the edge (a, b) and the polygon of their other vertices (geo::tci_chain):
// r[0..mm) with (a, b, r[i], r[i+1]) the tets; closed, or open from the face (a, b, r[0]) to
// (a, b, r[mm-1]) on the boundary. Filled by edge_ring (flips.cpp), which is false for an edge
// of fewer than 2 or more than kMaxRing tets, of tets of two labels, or of no chain.
struct EdgeRing {
  static constexpr int kMaxRing = TCI_MAX_RING;
  std::vector<int32_t> tets;
  int32_t from[kMaxRing] = {}, to[kMaxRing] = {}, r[kMaxRing + 1] = {};
  int mm = 0, closed = 0, start = 0;
};
bool edge_ring(const ImpMesh& m, int32_t a, int32_t b, EdgeRing& ring);

// The operations alone (tests): each returns whether it changed the mesh.
// open_rings_only: only the edges of the boundary (the device takes the others).
bool try_edge_removal(ImpMesh& m, int32_t a, int32_t b, bool open_rings_only = false);
bool try_flip23(ImpMesh& m, int32_t t, int face);
bool try_smooth(ImpMesh& m, int32_t v);
bool try_remove_boundary_sliver(ImpMesh& m, int32_t t);
// Splits the longest interior edge of bad tet t, whose four vertices are on the surface (where
// relocation cannot reach it), at a free new vertex placed by the relocation's ascent, when that
// raises the worst quality of the edge's ring (split.cpp).
bool try_split(ImpMesh& m, int32_t t, int64_t max_tets = 0);
// try_split on each bad tet in turn (worst first); counts in stats.splits.
// (a split of an edge of n tets adds n: none that would take the mesh past max_tets, if > 0)
void split_pass(ImpMesh& m, const std::vector<int32_t>& bad, int64_t max_tets, ImprovePassStats& stats);
double boundary_quad_height(const ImpMesh& m, int32_t a, int32_t b, int32_t x1, int32_t x2);
bool flat_quad(const ImpMesh& m, int32_t a, int32_t b, int32_t x1, int32_t x2);

}  // namespace tc::improve_detail
