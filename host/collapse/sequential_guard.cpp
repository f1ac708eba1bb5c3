// The surface guard of the sequential method's dynamic mesh (SeqMesh::build_guard, guard_ok and
// the grid of S faces they keep): see sequential_mesh.hpp.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "collapse/sequential_mesh.hpp"
#include "collapse_guard_geometry.h"  // tc::geo::tc_sg_tri_tri, the device guard's own test
#include "collapse_predicate.h"
#include "tetcollapse/error.hpp"

namespace tc::sequential_detail {

using geo::tc_d3;

namespace {

// Bounding box of a triangle, and whether two are apart (the guard kernels' box test,
// tcc_sg_tri_box_apart, on the boxes sguard_tris stores).
// (std::min / max rather than fmin / fmax: they differ only for NaN coordinates)
void box_of(const tc_d3* p, tc_d3& lo, tc_d3& hi) {
  lo = hi = p[0];
  for (int k = 1; k < 3; ++k) {
    lo = {std::min(lo.x, p[k].x), std::min(lo.y, p[k].y), std::min(lo.z, p[k].z)};
    hi = {std::max(hi.x, p[k].x), std::max(hi.y, p[k].y), std::max(hi.z, p[k].z)};
  }
}
bool boxes_apart(const tc_d3& alo, const tc_d3& ahi, const tc_d3& blo, const tc_d3& bhi) {
  return alo.x > bhi.x || alo.y > bhi.y || alo.z > bhi.z || blo.x > ahi.x || blo.y > ahi.y || blo.z > ahi.z;
}
bool boxes_apart(const tc_d3* a, const tc_d3* b) {
  tc_d3 alo, ahi, blo, bhi;
  box_of(a, alo, ahi);
  box_of(b, blo, bhi);
  return boxes_apart(alo, ahi, blo, bhi);
}

}  // namespace

int64_t SeqMesh::verify_guard() {
  if (!guard_on_) return 0;
  int64_t missing = 0;
  for (int32_t t = 0; t < nt_; ++t) {
    if (!talive_[t]) continue;
    for (int f = 0; f < 4; ++f) {
      if (!owned_sface(t, f)) continue;
      tc_d3 p[3];
      face_points(t, f, p);
      tc_d3 lo, hi;
      box_of(p, lo, hi);
      each_guard_cell(p, [&](size_t cell) {
        // an entry of the face whose box holds the face's box now
        auto holds = [&](int32_t e, const GuardBox& b) {
          return e == 4 * t + f && b.lo[0] <= lo.x && b.lo[1] <= lo.y && b.lo[2] <= lo.z && hi.x <= b.hi[0] &&
                 hi.y <= b.hi[1] && hi.z <= b.hi[2];
        };
        missing += any_live_guard_face(cell, lo, hi, holds, false) ? 0 : 1;
      });
    }
  }
  // no face twice in a cell among the live entries (a registration makes the earlier ones stale)
  const tc_d3 all_lo{-INFINITY, -INFINITY, -INFINITY}, all_hi{INFINITY, INFINITY, INFINITY};
  std::vector<int32_t> ids;
  for (size_t cell = 0; cell + 1 < gcell_off_.size(); ++cell) {
    ids.clear();
    any_live_guard_face(
        cell, all_lo, all_hi,
        [&](int32_t e, const GuardBox&) {
          ids.push_back(e);
          return false;
        },
        false);
    std::sort(ids.begin(), ids.end());
    missing += int64_t(ids.size()) - (std::unique(ids.begin(), ids.end()) - ids.begin());
  }
  return missing;
}

void SeqMesh::guard_cells(const tc_d3* p, int (&lo)[3], int (&hi)[3]) const {
  tc_d3 blo, bhi;
  box_of(p, blo, bhi);
  const double l[3] = {blo.x, blo.y, blo.z}, h[3] = {bhi.x, bhi.y, bhi.z}, o[3] = {guard_org_.x, guard_org_.y, guard_org_.z};
  for (int c = 0; c < 3; ++c) {
    auto cell = [&](double v) {
      const double x = std::floor((v - o[c]) / guard_h_);
      return !(x > 0.0) ? 0 : x >= double(guard_dim_[c]) ? guard_dim_[c] - 1 : int(x);
    };
    lo[c] = cell(l[c]);
    hi[c] = cell(h[c]);
  }
}

SeqMesh::GuardBox SeqMesh::guard_box(const tc_d3* p) {
  tc_d3 lo, hi;
  box_of(p, lo, hi);
  const double l[3] = {lo.x, lo.y, lo.z}, h[3] = {hi.x, hi.y, hi.z};
  GuardBox b;
  constexpr double kMax = std::numeric_limits<float>::max();
  for (int c = 0; c < 3; ++c) {
    // rounded outward; beyond the float range to infinity (a double-to-float conversion of a
    // value out of range is undefined); a NaN stays NaN: never apart, as with the doubles
    b.lo[c] = l[c] > kMax ? float(kMax) : l[c] < -kMax ? -INFINITY : float(l[c]);
    if (double(b.lo[c]) > l[c]) b.lo[c] = std::nextafter(b.lo[c], -INFINITY);
    b.hi[c] = h[c] < -kMax ? -float(kMax) : h[c] > kMax ? INFINITY : float(h[c]);
    if (double(b.hi[c]) < h[c]) b.hi[c] = std::nextafter(b.hi[c], INFINITY);
  }
  return b;
}

void SeqMesh::guard_insert(int32_t t, int f) {
  const uint32_t ver = ++gver_[4 * size_t(t) + size_t(f)];  // its earlier entries are stale now
  tc_d3 p[3];
  face_points(t, f, p);
  const GuardBox box = guard_box(p);
  each_guard_cell(p, [&](size_t cell) {
    // (unreachable at any size the method can hold in memory; were it thrown within collapse(),
    // the SeqMesh would be left half changed, and the run is abandoned)
    if (gnodes_.size() + 1 >= size_t(std::numeric_limits<int32_t>::max()))
      throw InputError("<mesh>", "the sequential method's surface guard needs more than 2^31 grid entries");
    gnodes_.push_back({4 * t + f, ghead_[cell], ver, box});
    ghead_[cell] = int32_t(gnodes_.size() - 1);
  });
}

void SeqMesh::build_guard(double h) {
  guard_on_ = true;
  guard_h_req_ = h;
  gnodes_.clear();
  gver_.assign(4 * size_t(nt_), 0);
  gseen_.assign(4 * size_t(nt_), 0);
  gstamp_ = 0;
  // the S faces (all three vertices on S, owned), their mean extent and the bounding box
  std::vector<int32_t> faces;
  double extent = 0;
  tc_d3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (int32_t v = 0; v < nv_; ++v) {
    if (!valive_[v]) continue;
    const tc_d3 p = point(v);
    lo = {std::fmin(lo.x, p.x), std::fmin(lo.y, p.y), std::fmin(lo.z, p.z)};
    hi = {std::fmax(hi.x, p.x), std::fmax(hi.y, p.y), std::fmax(hi.z, p.z)};
  }
  for (int32_t t = 0; t < nt_; ++t) {
    if (!talive_[t]) continue;
    const int32_t* q = tet(t);
    for (int f = 0; f < 4; ++f) {
      bool all_s = true;
      for (int j = 0; j < 4 && all_s; ++j) all_s = j == f || vflags_[q[j]] != 0;
      if (!all_s || !owned_sface(t, f)) continue;
      faces.push_back(4 * t + f);
      tc_d3 p[3];
      face_points(t, f, p);
      tc_d3 flo, fhi;
      box_of(p, flo, fhi);
      extent += std::fmax(fhi.x - flo.x, std::fmax(fhi.y - flo.y, fhi.z - flo.z));
    }
  }
  guard_h_ = faces.empty() ? h : extent / double(faces.size());  // a few S faces per cell
  const double span = std::fmax(hi.x - lo.x, std::fmax(hi.y - lo.y, hi.z - lo.z));
  if (!(guard_h_ > 0) || !std::isfinite(guard_h_)) guard_h_ = std::isfinite(span) && span > 0 ? span : 1.0;
  guard_h_ = std::fmax(guard_h_, span / double(1 << 20));  // at most 2^20 cells per axis
  guard_org_ = std::isfinite(lo.x) ? lo : tc_d3{0, 0, 0};
  const double d[3] = {hi.x - lo.x, hi.y - lo.y, hi.z - lo.z};
  const double max_cells = std::fmax(65536.0, 8.0 * double(faces.size()));
  for (;;) {
    for (int c = 0; c < 3; ++c)
      guard_dim_[c] = std::isfinite(d[c]) ? std::max(1, std::min(1 << 20, int(std::floor(d[c] / guard_h_)) + 1)) : 1;
    const double cells = double(guard_dim_[0]) * double(guard_dim_[1]) * double(guard_dim_[2]);
    if (cells <= max_cells) break;
    guard_h_ *= std::fmax(1.01, std::cbrt(cells / max_cells));  // larger cells, fewer of them
  }
  // the faces by cell (counted, then placed), each in every cell its box meets
  const size_t ncells = size_t(guard_dim_[0]) * size_t(guard_dim_[1]) * size_t(guard_dim_[2]);
  ghead_.assign(ncells, -1);
  gcell_off_.assign(ncells + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    for (int32_t e : faces) {
      tc_d3 p[3];
      face_points(e >> 2, e & 3, p);
      const GuardBox box = pass == 1 ? guard_box(p) : GuardBox{};
      each_guard_cell(p, [&](size_t c) {
        if (pass == 0) {
          ++gcell_off_[c + 1];
        } else {  // the offsets moved one cell on (restored below)
          gbuilt_box_[gcell_off_[c]] = box;
          gbuilt_[gcell_off_[c]++] = e;
        }
      });
    }
    if (pass == 0) {
      for (size_t c = 0; c < ncells; ++c) {
        if (double(gcell_off_[c]) + double(gcell_off_[c + 1]) >= double(std::numeric_limits<int32_t>::max()))
          throw InputError("<mesh>", "the sequential method's surface guard needs more than 2^31 grid entries");
        gcell_off_[c + 1] += gcell_off_[c];
      }
      gbuilt_.assign(gcell_off_[ncells], -1);
      gbuilt_box_.resize(gcell_off_[ncells]);
    }
  }
  for (size_t c = ncells; c > 0; --c) gcell_off_[c] = gcell_off_[c - 1];
  gcell_off_[0] = 0;
}

bool SeqMesh::guard_ok(int32_t a, int32_t b, uint8_t dir, bool scan_all) {
  if (!guard_on_) return true;
  if (a > b) std::swap(a, b);
  const bool remove_b = (dir & TCC_DIR_REMOVE_V1) != 0;
  const int32_t x = remove_b ? b : a, y = remove_b ? a : b;
  const tc_d3 p = placement(a, b, dir), py = point(y);
  const bool moves_y = !(py.x == p.x && py.y == p.y && py.z == p.z);
  if (!vflags_[x] && !(moves_y && vflags_[y])) return true;  // S is not touched
  // the new S triangles (tcc_sg_new_tri)
  newtris_.clear();
  each_new_sface(x, y, moves_y, [&](int32_t t, const int32_t* q, int f, int32_t other) {
    if (!(other < 0 || (labels_ && label(t) != label(other)))) return;
    NewTri nt;
    for (int k = 0; k < 3; ++k) {
      int32_t v = q[geo::TC_TET_FACES[f][k]];
      if (v == x) v = y;
      nt.id[k] = v;
      nt.pos[k] = v == y ? p : point(v);
    }
    newtris_.push_back(nt);
  });
  // among themselves (S folded over itself around y)
  for (size_t i = 0; i < newtris_.size(); ++i)
    for (size_t j = i + 1; j < newtris_.size(); ++j)
      if (!boxes_apart(newtris_[i].pos, newtris_[j].pos) &&
          geo::tc_sg_tri_tri(newtris_[i].id, newtris_[i].pos, newtris_[j].id, newtris_[j].pos))
        return false;
  // against the current S faces near them, but those the collapse moves or removes
  for (const NewTri& nt : newtris_) {
    if (++gstamp_ == 0) {
      std::fill(gseen_.begin(), gseen_.end(), 0u);
      gstamp_ = 1;
    }
    tc_d3 nlo, nhi;
    box_of(nt.pos, nlo, nhi);
    // does the new triangle cross face e (4 t + f) of a live tet, once per face
    auto crosses = [&](int32_t e) {
      if (gseen_[e] == gstamp_) return false;
      gseen_[e] = gstamp_;
      const int32_t t = e >> 2;
      const int f = e & 3;
      const int32_t* q = tet(t);
      int32_t fid[3];
      bool replaced = false;
      for (int c = 0; c < 3; ++c) {
        fid[c] = q[geo::TC_TET_FACES[f][c]];
        replaced = replaced || fid[c] == x || (moves_y && fid[c] == y);
      }
      if (replaced) return false;  // a face the collapse moves or removes
      const tc_d3 fpos[3] = {point(fid[0]), point(fid[1]), point(fid[2])};
      tc_d3 flo, fhi;
      box_of(fpos, flo, fhi);
      if (boxes_apart(nlo, nhi, flo, fhi) || !owned_sface(t, f)) return false;
      return geo::tc_sg_tri_tri(nt.id, nt.pos, fid, fpos) != 0;
    };
    bool crossed = false;
    if (scan_all) {  // every face of every live tet (the tests' reference)
      for (int32_t t = 0; t < nt_ && !crossed; ++t)
        for (int f = 0; f < 4 && !crossed && talive_[t]; ++f) crossed = crosses(4 * t + f);
    } else {  // those of the grid's live entries in the triangle's cells (alive)
      each_guard_cell(nt.pos, [&](size_t cell) {
        crossed = crossed || any_live_guard_face(cell, nlo, nhi, [&](int32_t e, const GuardBox&) { return crosses(e); });
      });
    }
    if (crossed) return false;
  }
  return true;
}

}  // namespace tc::sequential_detail
