// The sequential CPU method (CollapseOptions::Sequential, the paper's "CPU sequential" baseline)
// over a dynamic mesh: vertex -> tets lists updated in place by every collapse, so nothing is
// rebuilt between two collapses. Used by tc::collapse_sequential (sequential.cpp) and by the
// tests, which step it one iteration at a time and compare its checks with the device's.
// Defined in sequential_mesh.cpp (rings, flags and classes, collapses, compaction),
// sequential_checks.cpp (the admissible checks) and sequential_guard.cpp (the surface guard).
//
// Same semantics as the parallel pipeline (cl/collapse_*.cl):
//   * the feature surface S (boundary faces and, with labels, interfaces between different
//     primary labels), vertex flags and classes and edge flags with the rules of
//     cl/collapse_connectivity.cl (= tc::build_topology), derived here from the tets around a
//     vertex: every face through v lies in a tet of ring(v), so the star of v alone decides
//     which of its faces are on S, who owns them, and so the class of v;
//   * Q is cl/collapse_predicate.h itself (compiled as C++); the link condition with the
//     virtual vertex, the volume test and the quality guard are cl/collapse_checks.h itself,
//     list limits (TCC_MAX_LINK) included, read over this mesh's rings (SeqStar); only the
//     gathering of an edge's common neighbours is the host's own;
//   * geometry from cl/geometry.h (tc::geo);
//   * the surface guard of cl/collapse_guard.cl (guard_ok), with its triangle test
//     (cl/collapse_guard_geometry.h) and its choice of the new S triangles.
//
// Keeping the classes current. A collapse r -> s changes only faces through s (renamed from r,
// glued where a tet of the edge disappears, or moved with s), so the flags and classes that can
// change are those of s and of its neighbours, all vertices of the tets of ring(r) U ring(s)
// before the collapse (touched()). When neither r nor s is on S no S-face changes at all (a
// glued face is on S only if one of its two sides was), and nothing needs recomputing;
// otherwise s and every touched vertex on S are reclassified (a vertex off S stays off S: its
// faces keep their two tets, or are glued from two faces off S). verify_classes() recomputes
// everything from scratch for the tests.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <vector>

#include "collapse/params.hpp"
#include "geometry.h"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/mesh.hpp"

namespace tc::sequential_detail {

using SeqParams = collapse_detail::CheckParams;  // the same checks as the parallel method's

// Result of the admissible checks of one edge: reason as collapse_detail::Reason (kOk, kRefusedQ,
// kRefusedLink, kRefusedVolume, kRefusedQuality) and, when kOk, the edge_dir bits.
struct Verdict {
  uint8_t reason = 0;
  uint8_t dir = 0;
};

// The mesh as the link and volume tests of cl/collapse_checks.h read it (sequential_mesh.cpp
// defines their access to it): ring(v) = pool[roff[v] .. roff[v] + rlen[v]), the tets (4 vertices
// each), their neighbours (SeqMesh::across), the primary labels (null: no interfaces), the vertex
// flags and the points.
struct SeqStar {
  const int32_t* pool;
  const uint32_t* roff;
  const uint32_t* rlen;
  const int32_t* tets;
  const int32_t* nbr;
  const int32_t* labels;
  const uint8_t* vflags;
  const double* pts;
  const double* field;  // the first vertex field (with field_eps > 0)
  size_t field_stride;
  double field_eps;
};

class SeqMesh {
 public:
  // Works on `mesh` in place (points, tets, labels, fields). Throws tc::InputError for a mesh
  // the method cannot take (as the device pipeline's upload does). With vflags and vclass (one
  // per vertex, both or neither), the flags and classes are taken from them instead of being
  // computed: the parallel method's host tail hands over the device's, made by the same rules
  // (verify_classes() recomputes them).
  SeqMesh(Mesh& mesh, const SeqParams& params, const std::vector<uint8_t>* vflags = nullptr,
          const std::vector<uint8_t>* vclass = nullptr, const std::vector<int32_t>* tet_nbr = nullptr);

  int32_t num_vertices() const { return nv_; }  // slots, dead ones included until compact()
  int32_t num_tets() const { return nt_; }
  int32_t alive_vertices() const { return alive_v_; }
  int32_t alive_tets() const { return alive_t_; }
  bool alive(int32_t v) const { return valive_[v] != 0; }

  // N(v) into out (unordered), or only its vertices above v.
  void neighbours(int32_t v, std::vector<int32_t>& out, bool above_only = false);
  bool is_edge(int32_t a, int32_t b) const;
  double length(int32_t a, int32_t b) const;

  uint8_t vflags(int32_t v) const { return vflags_[v]; }
  uint8_t vclass(int32_t v) const { return vclass_[v]; }
  // The eflags of cl/collapse_connectivity.cl (TCC_BOUNDARY | TCC_INTERFACE | TCC_RIDGE).
  uint8_t edge_flags(int32_t a, int32_t b, bool with_ridge = true);

  // The checks of an edge a < b, as the admissible filter runs them: Q (the edge_dir bits, or
  // -1; fe receives the edge's flags), then the link condition, the volume test and the
  // quality guard (a collapse_detail::Reason); check() runs both.
  int predicate(int32_t a, int32_t b, uint8_t& fe);
  uint8_t link_and_volume(int32_t a, int32_t b, uint8_t fe, int dir);
  Verdict check(int32_t a, int32_t b);
  // link_and_volume(...) == kOk, the cheaper test first (for when the reason does not matter).
  bool admissible(int32_t a, int32_t b, uint8_t fe, int dir);
  // The volume test with the quality guard at max(its own, q) (the link condition aside).
  bool keeps_shape(int32_t a, int32_t b, int dir, double q) const;

  // Collapses the edge (a, b) in the direction `dir` (bits for the ordered pair (min, max), as
  // check() returns them). Returns the survivor. touched() then lists every vertex whose star
  // changed (survivor included, the removed vertex too).
  int32_t collapse(int32_t a, int32_t b, uint8_t dir);
  const std::vector<int32_t>& touched() const { return touched_; }

  // Drops the dead vertices and tets from the mesh arrays (order kept) and rebuilds the
  // vertex -> tets lists. vmap receives, for every vertex slot before, its new index (for a
  // removed vertex: the new index of the vertex it finally went into), and kept, for every new
  // index, the vertex slot it comes from.
  void compact(std::vector<int32_t>& vmap, std::vector<int32_t>& kept);

  // Recomputes every flag and class from scratch; returns the number of vertices whose cached
  // flags or class differ (0 when the incremental updates are right).
  int64_t verify_classes();
  // The same for the tet neighbours: the faces of live tets whose kept neighbour differs from a
  // ring scan's.
  int64_t verify_nbr() const;
  // The same for the surface guard's grid (after build_guard): the (S face, cell) pairs without
  // a live entry whose box holds the face's box now (any_live_guard_face, without dropping the
  // stale entries), over every S face of the live tets and every cell its box meets, and the
  // live entries that repeat a face in a cell.
  int64_t verify_guard();

  // The boundary error bound (CollapseOptions::max_boundary_error): a bound on the two-sided
  // Hausdorff distance between S before and after the collapse of (a, b) in direction dir
  // (cl/collapse_surface_error.h; 0 when S does not change, infinity when it cannot be bounded),
  // and in *base the largest of eps over the vertices of the S faces it replaces (infinity too
  // once *base + the bound would pass `limit`). The run carries eps per vertex: the survivor's
  // becomes *base + the bound.
  double surface_change(int32_t a, int32_t b, uint8_t dir, const std::vector<double>& eps, double* base,
                        double limit = INFINITY);
  // Beyond the paper, under the bound: for a collapse of S to the edge's midpoint (dir), the
  // direction among the midpoint and either end point kept that gives the smallest bound, an
  // end point only where the reshaped tets keep TCC_END_POINT_MIN_QUALITY (or what they had);
  // any other dir as it is. Its surface_change in *change and *base.
  uint8_t closest_placement(int32_t a, int32_t b, uint8_t dir, const std::vector<double>& eps, double* base,
                            double* change);
  // The boundary error bound measured (collapse/surface_distance.hpp): the S triangles now, one
  // per face (9 coordinates each, appended to out); and for the collapse of (a, b) in direction
  // dir the S triangles it replaces (olds), those it makes (news) and the S triangles that stay
  // at the new ones' other corners (around), with in `corners` those corners and the corners of
  // the triangles around (the survivor aside).
  void s_triangles(std::vector<double>& out) const;
  void collapse_fans(int32_t a, int32_t b, uint8_t dir, std::vector<std::array<geo::tc_d3, 3>>& olds,
                     std::vector<std::array<geo::tc_d3, 3>>& news, std::vector<std::array<geo::tc_d3, 3>>& around,
                     std::vector<int32_t>& corners) const;

  // The tets the collapse of (a, b) in direction dir removes or reshapes (those of ring(a) U
  // ring(b), each once), in `tets`; in `after` four vertices per tet as the collapse leaves it
  // (the removed vertex renamed to the survivor; -1s for a removed tet); the survivor and its
  // place. A reshaped tet keeps its index through collapse().
  void collapse_region(int32_t a, int32_t b, uint8_t dir, std::vector<int32_t>& tets, std::vector<int32_t>& after,
                       int32_t* survivor, geo::tc_d3* place);
  bool tet_alive(int32_t t) const { return talive_[t] != 0; }
  // The sum of the harmonic indices of the tets of ring(a) U ring(b) (place null), or of those
  // the collapse of (a, b) leaves with the survivor at *place (infinity if one is flat or
  // inverted); worst_sine: the smallest tc_tet_min_sine of the same tets.
  double harmonic_sum(int32_t a, int32_t b, const geo::tc_d3* place);
  double worst_sine(int32_t a, int32_t b, const geo::tc_d3* place);
  // The same sum for the survivor at a + t (b - a), as a function of t: per tet the collapse
  // leaves, eta(t) = (q0 + q1 t + q2 t^2) / (v0 + v1 t) (squared areas are quadratic in t, the
  // volume is linear), so that a line search evaluates each tet in a few operations.
  struct HarmonicTerm {
    double q0, q1, q2, v0, v1;
  };
  void harmonic_terms(int32_t a, int32_t b, std::vector<HarmonicTerm>& terms);
  static double harmonic_at(const std::vector<HarmonicTerm>& terms, double t);
  // Where the survivor goes when both ends may move (TCC_DIR_MIDPOINT): fn(a, b, &p) sets p,
  // or returns false for the midpoint. The checks and the collapse all see it.
  void set_free_placement(std::function<bool(int32_t, int32_t, geo::tc_d3*)> fn) { free_placement_ = std::move(fn); }
  const int32_t* tet_vertices(int32_t t) const { return tet(t); }
  // A tet through v (-1: none).
  int32_t some_tet(int32_t v) const { return rlen_[v] > 0 ? ring(v)[0] : -1; }

  // Surface guard (the device's: cl/collapse_guard.cl). build_guard() indexes the current
  // S faces in a grid of cells of the mean extent of an S face (h when there is none);
  // collapses keep it current and compact() renumbers it (rebuilds it once the collapses
  // have added more than half as many entries again, plus 1024). guard_ok() tells whether the collapse
  // of (a, b) in direction dir keeps S free of self-intersections: its new S triangles (those
  // of tcc_sg_new_tri) against every current S face it does not replace, and among themselves,
  // with the device's triangle test (cl/collapse_guard_geometry.h).
  // Before build_guard() every collapse passes.
  void build_guard(double h);
  bool guard_ok(int32_t a, int32_t b, uint8_t dir) { return guard_ok(a, b, dir, false); }
  // The same verdict from a scan of every face of every live tet instead of the grid (the tests'
  // reference for the grid's entries).
  bool guard_ok_scanning(int32_t a, int32_t b, uint8_t dir) { return guard_ok(a, b, dir, true); }

 private:
  struct FaceAt {  // a face through v: tet t, local face f (opposite vertex f), key y << 32 | z of
    uint64_t key;   // its other vertices y < z
    int32_t t;
    int8_t f;
  };

  const int32_t* tet(int32_t t) const { return tets_->data() + 4 * size_t(t); }
  static bool has(const int32_t* q, int32_t x) { return q[0] == x || q[1] == x || q[2] == x || q[3] == x; }
  static int local(const int32_t* q, int32_t x) {
    return q[0] == x ? 0 : q[1] == x ? 1 : q[2] == x ? 2 : q[3] == x ? 3 : -1;
  }
  geo::tc_d3 point(int32_t v) const { return geo::tc_point(points_->data(), v); }
  // fn(t, q, f, lv) for every face f of every tet t = q of ring(v) that holds v (f != lv, the
  // local index of v)
  template <class Fn>
  void each_face_through(int32_t v, Fn&& fn) const {
    const int32_t* r = ring(v);
    for (uint32_t i = 0; i < rlen_[v]; ++i) {
      const int32_t t = r[i];
      const int32_t* q = tet(t);
      const int lv = local(q, v);
      for (int f = 0; f < 4; ++f)
        if (f != lv) fn(t, q, f, lv);
    }
  }
  int32_t label(int32_t t) const { return labels_ ? (*labels_)[t] : 0; }
  // The collapse of (a, b) in direction dir: x goes, y survives at p (moves_y: p is not y's place).
  struct CollapseEnds {
    int32_t x, y;
    geo::tc_d3 p;
    bool moves_y;
  };
  CollapseEnds collapse_ends(int32_t a, int32_t b, uint8_t dir) const;
  // fn(t, q, f) for every S face a tet t = q owns that the collapse of x onto y replaces: those
  // through x, those of the tets it removes, and through y when it moves (each once: a tet
  // through x is seen from ring(x)).
  template <class Fn>
  void each_old_sface(int32_t x, int32_t y, bool moves_y, Fn&& fn) const {
    for (int side = 0; side < (moves_y ? 2 : 1); ++side) {
      const int32_t z = side == 0 ? x : y;
      const int32_t* rz = ring(z);
      for (uint32_t i = 0; i < rlen_[z]; ++i) {
        const int32_t t = rz[i];
        const int32_t* q = tet(t);
        if (side == 1 && has(q, x)) continue;
        const bool removed = side == 0 && has(q, y);
        for (int f = 0; f < 4; ++f)
          if (!(q[f] == z && !removed) && owned_sface(t, f)) fn(t, q, f);
      }
    }
  }
  // fn(t, q, f, other) for every face f of a tet t = q that the collapse of x onto y keeps
  // (through x, and through y when it moves) and that is on S after it, or may be:
  // tcc_sg_new_tri's choice before its label test. other: the tet across the face after the
  // collapse (-1: the boundary); the face is on S when other < 0 or the labels differ.
  template <class Fn>
  void each_new_sface(int32_t x, int32_t y, bool moves_y, Fn&& fn) const {
    for (int side = 0; side < 2; ++side) {
      const int32_t z = side == 0 ? x : y, w = side == 0 ? y : x;
      const int32_t* rz = ring(z);
      for (uint32_t i = 0; i < rlen_[z]; ++i) {
        const int32_t t = rz[i];
        const int32_t* q = tet(t);
        if (has(q, w)) continue;  // removed by the collapse, or seen from ring(x)
        for (int f = 0; f < 4; ++f) {
          if (q[f] == z) continue;  // the face opposite z does not contain it
          // a face on S after is on S now, or glued to one through a removed tet: either way its
          // two vertices other than z are on S now (cheap, and it spares most ring scans)
          bool others_on_s = true;
          for (int j = 0; j < 4 && others_on_s; ++j) others_on_s = j == f || q[j] == z || vflags_[q[j]] != 0;
          if (!others_on_s) continue;
          const int32_t o = across(t, f);
          if (o >= 0 && has(tet(o), x) && has(tet(o), y)) {  // glued through the removed tet o
            fn(t, q, f, across(o, local(tet(o), z)));
          } else if (side == 0 || moves_y) {  // (through y and y stays: unchanged)
            fn(t, q, f, o);
          }
        }
      }
    }
  }

  const int32_t* ring(int32_t v) const { return pool_.data() + roff_[v]; }
  // fn(t, q, removed) for every tet t = q of ring(first) U ring(second), each once, those of
  // ring(first) first; removed: it holds both (the collapse of the edge removes it).
  template <class Fn>
  void each_edge_star_tet(int32_t first, int32_t second, Fn&& fn) const {
    for (int side = 0; side < 2; ++side) {
      const int32_t z = side == 0 ? first : second, w = side == 0 ? second : first;
      const int32_t* rz = ring(z);
      for (uint32_t i = 0; i < rlen_[z]; ++i) {
        const int32_t* q = tet(rz[i]);
        const bool both = has(q, w);
        if (side == 1 && both) continue;  // seen from ring(first)
        fn(rz[i], q, both);
      }
    }
  }
  // fn(c) for the corners c of each tet of ring(a) U ring(b) (place null), or of each one the
  // collapse of (a, b) leaves, with the survivor at *place
  template <class Fn>
  void each_edge_star_shape(int32_t a, int32_t b, const geo::tc_d3* place, Fn&& fn) const {
    each_edge_star_tet(a, b, [&](int32_t, const int32_t* q, bool removed) {
      if (removed && place) return;
      geo::tc_d3 c[4];
      for (int k = 0; k < 4; ++k) c[k] = place && (q[k] == a || q[k] == b) ? *place : point(q[k]);
      fn(c);
    });
  }
  uint32_t ring_size(int32_t v) const { return rlen_[v]; }
  void ring_append(int32_t v, int32_t t);
  void ring_remove(int32_t v, int32_t t);
  void rebuild_rings();

  uint32_t next_stamp();
  void classify(int32_t v, uint8_t& flags, uint8_t& cls);
  // tet_nbr (collapse_common.h): -1 none, -2 several, else the tet; kept current by collapse()
  // and compact() (nbr_), built once from the rings (build_nbr) unless given
  int32_t across(int32_t t, int f) const { return nbr_[4 * size_t(t) + size_t(f)]; }
  int32_t scan_across(int32_t t, int f) const;  // the same from a ring scan
  void build_nbr();
  // tcc_owned_sface: the kind of the face if t owns it on S, else 0; *on_s (when given) its kind
  // on S whoever owns it
  uint8_t owned_sface(int32_t t, int f, uint8_t* on_s = nullptr) const;
  bool guard_ok(int32_t a, int32_t b, uint8_t dir, bool scan_all);
  void guard_insert(int32_t t, int f);
  void guard_cells(const geo::tc_d3* p, int (&lo)[3], int (&hi)[3]) const;
  // fn(cell) for every cell of the guard's grid that the box of triangle p meets
  template <class Fn>
  void each_guard_cell(const geo::tc_d3* p, Fn&& fn) const {
    int lo[3], hi[3];
    guard_cells(p, lo, hi);
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i) fn(guard_cell(i, j, k));
  }
  // The positions of the vertices of face f of tet t, in the face's order.
  void face_points(int32_t t, int f, geo::tc_d3 (&p)[3]) const {
    const int32_t* q = tet(t);
    for (int k = 0; k < 3; ++k) p[k] = point(q[geo::TC_TET_FACES[f][k]]);
  }
  // fn(e, box) for the face ids e (4 t + f) of the cell's live entries (build_guard's, then
  // those inserted since) whose box (GuardBox: the face's at its registration) meets the box
  // [lo, hi], stopping at the first for which fn holds. An entry is live when its tet is alive
  // and it is of the face's latest registration (gver_); with prune, the others met are dropped
  // from the cell. A live entry's face may no longer be owned on S: guard_ok checks that.
  // Dropping the others changes no guard verdict, for finite coordinates and exact vflags_: a
  // face's box and owner change only in a collapse() that leaves it holding the survivor, which
  // registers it again when it is owned on S then (and build_guard registers every S face), so
  // an owned S face has live entries, with its current box, in every cell that box meets;
  // guard_ok tests a face only when its current box meets the new triangle's, and two boxes
  // that meet share a cell (the cell of a finite coordinate is monotone in it). A NaN
  // coordinate falls in cell 0 (guard_cells): such a triangle could meet a face there only
  // through an entry of another cell (the volume test refuses a NaN placement first).
  template <class Fn>
  bool any_live_guard_face(size_t cell, const geo::tc_d3& lo, const geo::tc_d3& hi, Fn&& fn, bool prune = true) {
    auto apart = [&](const GuardBox& b) {
      return lo.x > b.hi[0] || lo.y > b.hi[1] || lo.z > b.hi[2] || b.lo[0] > hi.x || b.lo[1] > hi.y || b.lo[2] > hi.z;
    };
    for (uint32_t r = gcell_off_[cell]; r < gcell_off_[cell + 1]; ++r) {
      const int32_t e = gbuilt_[r];
      if (e < 0 || apart(gbuilt_box_[r])) continue;
      if (gver_[size_t(e)] != 0 || !talive_[size_t(e >> 2)]) {
        if (prune) gbuilt_[r] = -1;
        continue;
      }
      if (fn(e, gbuilt_box_[r])) return true;
    }
    for (int32_t* link = &ghead_[cell]; *link >= 0;) {
      GuardNode& node = gnodes_[size_t(*link)];
      if (node.face >= 0 && apart(node.box)) {
        link = &node.next;
        continue;
      }
      if (node.face < 0 || gver_[size_t(node.face)] != node.ver || !talive_[size_t(node.face >> 2)]) {
        if (prune) *link = node.next;  // unlinked
        else link = &node.next;
        continue;
      }
      if (fn(node.face, node.box)) return true;
      link = &node.next;
    }
    return false;
  }
  size_t guard_cell(int i, int j, int k) const {
    return size_t(i) + size_t(guard_dim_[0]) * (size_t(j) + size_t(guard_dim_[1]) * size_t(k));
  }
  // the link and volume tests of cl/collapse_checks.h over star()
  SeqStar star() const;
  bool link_ok(int32_t a, int32_t b, uint8_t fe);
  // (with the quality guard at q_min)
  uint8_t volume_and_quality(int32_t a, int32_t b, int dir, double q_min) const;
  geo::tc_d3 placement(int32_t a, int32_t b, unsigned dir) const;

  std::function<bool(int32_t, int32_t, geo::tc_d3*)> free_placement_;

  Mesh& mesh_;
  std::vector<double>* points_;
  std::vector<int32_t>* tets_;
  const std::vector<int32_t>* labels_ = nullptr;  // primary labels when they drive interfaces
  SeqParams p_;
  int32_t nv_ = 0, nt_ = 0, alive_v_ = 0, alive_t_ = 0;
  int vfield_comps_ = 0;

  std::vector<uint8_t> valive_, talive_;
  std::vector<int32_t> nbr_;  // 4 per tet slot: across(t, f)
  // vertex -> tets: ring(v) = pool_[roff_[v] .. roff_[v] + rlen_[v]), capacity rcap_[v]; a list
  // that outgrows its slot moves to the end of the pool (rebuilt compactly by compact()).
  std::vector<int32_t> pool_;
  std::vector<uint32_t> roff_, rlen_, rcap_;
  std::vector<uint8_t> vflags_, vclass_;
  std::vector<int32_t> fwd_;  // removed vertex -> the vertex it went into

  // scratch, reused: no allocation per check or collapse once warm
  std::vector<uint32_t> mark_;
  uint32_t stamp_ = 0;
  std::vector<int32_t> cn_, rr_, touched_, gone_, reclass_;
  std::vector<FaceAt> faces_;
  // surface guard: cells of the grid -> S faces (4 t + f) registered there, possibly stale
  // (a dead tet, a face no longer on S, or one registered again after it moved): checked on use
  struct NewTri {
    int32_t id[3];
    geo::tc_d3 pos[3];
  };
  bool guard_on_ = false;
  double guard_h_req_ = 0, guard_h_ = 1;
  geo::tc_d3 guard_org_{0, 0, 0};
  int guard_dim_[3] = {1, 1, 1};
  // The box of a face at its registration, in floats rounded outward: a live entry's face has not
  // moved since, so an entry whose box is apart from the new triangle's is passed over by its own
  // data, before its liveness, tet and points are read.
  struct GuardBox {
    float lo[3], hi[3];
  };
  static GuardBox guard_box(const geo::tc_d3* p);
  // A face registered after the build, in its cell's list.
  struct GuardNode {
    int32_t face;  // 4 t + f, -1 when dropped by compact()
    int32_t next;  // the next node of the cell's list, -1 ends
    uint32_t ver;  // the face's registration (gver_) this node holds
    GuardBox box;
  };
  // A dense grid of at most max(2^16, 8 x the S faces) cells (build_guard makes the cells larger
  // when the mean extent would need more): the faces build_guard placed, by cell (gbuilt_ and
  // gbuilt_box_ from gcell_off_[c] to gcell_off_[c + 1]), and per cell a list of the faces
  // registered since (ghead_, then gnodes_). No allocation per cell, and a build is two passes
  // over the faces (a hash map of per-cell vectors took ~20 ms per build on W1's host tail). A
  // face id is 4 t + f, -1 when dropped by compact().
  std::vector<uint32_t> gcell_off_;
  std::vector<int32_t> gbuilt_;
  std::vector<GuardBox> gbuilt_box_;
  std::vector<int32_t> ghead_;
  std::vector<GuardNode> gnodes_;
  // per face id: how many times guard_insert registered it (build_guard's entries are of
  // registration 0; any_live_guard_face)
  std::vector<uint32_t> gver_;
  std::vector<uint32_t> gseen_;
  uint32_t gstamp_ = 0;
  std::vector<NewTri> newtris_;
  // the S-faces of the vertex classify() looked at last (cl/collapse_classify.h's arrays)
  std::vector<int32_t> sf_after_, sf_before_;
  std::vector<geo::tc_d3> sf_normal_;
};

}  // namespace tc::sequential_detail
