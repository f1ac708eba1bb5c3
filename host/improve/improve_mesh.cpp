#include "improve/improve_mesh.hpp"

#include <algorithm>
#include <limits>
#include <map>
#include <stdexcept>

#include "collapse_guard_geometry.h"
#include "collapse_surface_error.h"
#include "tetcollapse/error.hpp"
#include "tetcollapse/topology.hpp"

namespace tc::improve_detail {

uint64_t ImpMesh::key2(int32_t a, int32_t b) {
  if (a > b) std::swap(a, b);
  return uint64_t(uint32_t(a)) << 32 | uint32_t(b);
}

std::vector<uint64_t> ImpMesh::tagged_edge_keys() const {
  std::vector<uint64_t> keys(tagged_edges_.begin(), tagged_edges_.end());
  std::sort(keys.begin(), keys.end());
  return keys;
}

std::vector<int32_t> ImpMesh::tagged_face_records() const {
  std::vector<FaceKey> faces;
  faces.reserve(tris_.size());
  for (const auto& [k, index] : tris_) faces.push_back(k);
  std::sort(faces.begin(), faces.end());
  std::vector<int32_t> out;
  out.reserve(4 * faces.size());
  for (const FaceKey& f : faces) out.insert(out.end(), {f[0], f[1], f[2], 0});
  return out;
}

ImpMesh::FaceKey ImpMesh::face_key(int32_t a, int32_t b, int32_t c) {
  FaceKey k{a, b, c};
  std::sort(k.begin(), k.end());
  return k;
}

ImpMesh::ImpMesh(Mesh& mesh, const ImproveOptions& options) : mesh_(mesh), points_(mesh.points) {
  const int64_t nt = mesh.num_tets(), nv = mesh.num_vertices();
  tets_.resize(size_t(nt));
  origin_.resize(size_t(nt));
  dead_.assign(size_t(nt), 0);
  quality_.resize(size_t(nt));
  max_cos_.resize(size_t(nt));
  vtets_.resize(size_t(nv));
  changed_.assign(size_t(nv), stamp_);
  smooth_failed_at.assign(size_t(nv), 0);
  flip_failed_at.assign(size_t(nv), 0);
  cos_threshold_ = std::cos(options.threshold_deg * 3.14159265358979323846 / 180.0);
  for (int64_t t = 0; t < nt; ++t) {
    for (int k = 0; k < 4; ++k) tets_[size_t(t)][k] = mesh.tets[size_t(4 * t + k)];
    origin_[size_t(t)] = int32_t(t);
    quality_[size_t(t)] = quality_of(tets_[size_t(t)]);
    max_cos_[size_t(t)] = max_cos_of(tets_[size_t(t)]);
    if (geo::tc_tet_volume(point(tets_[t][0]), point(tets_[t][1]), point(tets_[t][2]), point(tets_[t][3])) < 0)
      throw InputError("<mesh>", "tet " + std::to_string(t) + " is inverted; the improvement needs positive tets");
    for (int k = 0; k < 4; ++k) vtets_[size_t(tets_[size_t(t)][k])].push_back(int32_t(t));
  }
  // A flip keeps the labels: tets with different tuples of label values never share one.
  label_.assign(size_t(nt), 0);
  if (!mesh.tet_labels.empty()) {
    std::map<std::vector<int32_t>, int32_t> ids;
    std::vector<int32_t> tuple(mesh.tet_labels.size());
    for (int64_t t = 0; t < nt; ++t) {
      for (size_t k = 0; k < tuple.size(); ++k) tuple[k] = mesh.tet_labels[k].values[size_t(t)];
      label_[size_t(t)] = ids.emplace(tuple, int32_t(ids.size())).first->second;
    }
  }
  for (int64_t i = 0; i < mesh.num_tris(); ++i)
    tris_.emplace(face_key(mesh.tris[3 * i], mesh.tris[3 * i + 1], mesh.tris[3 * i + 2]), i);
  for (size_t i = 0; i + 1 < mesh.edges.size(); i += 2) tagged_edges_.insert(key2(mesh.edges[i], mesh.edges[i + 1]));
  if (!options.vertex_mask.empty() && options.vertex_mask.size() != size_t(nv))
    throw std::invalid_argument("vertex_mask has " + std::to_string(options.vertex_mask.size()) + " entries for " +
                                std::to_string(nv) + " vertices");
  mask_ = options.vertex_mask;
  if (options.max_boundary_error_abs > 0 && options.boundary != CollapseOptions::Strict) {
    // A boundary error bound, carried per vertex (boundary_error_at), from what earlier changes
    // of S spent.
    bounded_ = true;
    max_boundary_move_ = options.max_boundary_error_abs;
    err_ = options.vertex_boundary_error;
    if (err_.empty()) err_.assign(size_t(nv), 0.0);
    if (err_.size() != size_t(nv))
      throw std::invalid_argument("vertex_boundary_error has " + std::to_string(err_.size()) + " entries for " +
                                  std::to_string(nv) + " vertices");
    err_start_ = err_;
  } else if (options.boundary != CollapseOptions::Strict && options.max_boundary_move > 0 && nv > 0) {
    max_boundary_move_ = options.max_boundary_move * bbox_diagonal(mesh);
  }
  mark_motion(options);
  if (max_boundary_move_ > 0) build_surface_grid();
}

bool ImpMesh::on_surface(int32_t t, int32_t a, int32_t b, int32_t c) const {
  const int32_t o = across(t, a, b, c);
  return o < 0 || label_[size_t(o)] != label_[size_t(t)];
}

void ImpMesh::surface_faces_at(int32_t v, std::vector<FaceKey>& out) const {
  out.clear();
  for (int32_t t : vtets_[size_t(v)]) {
    const Tet& q = tets_[size_t(t)];
    for (const auto& F : geo::TC_TET_FACES) {
      const int32_t a = q[size_t(F[0])], b = q[size_t(F[1])], c = q[size_t(F[2])];
      if ((a == v || b == v || c == v) && on_surface(t, a, b, c)) {
        const FaceKey k = face_key(a, b, c);
        if (std::find(out.begin(), out.end(), k) == out.end()) out.push_back(k);
      }
    }
  }
}

ImpMesh::CellBox ImpMesh::cells_of(tc_d3 lo, tc_d3 hi) const {
  const auto cell = [&](double x, double o) { return int64_t(std::floor((x - o) / cell_)); };
  return {cell(lo.x, grid_origin_.x), cell(lo.y, grid_origin_.y), cell(lo.z, grid_origin_.z),
          cell(hi.x, grid_origin_.x), cell(hi.y, grid_origin_.y), cell(hi.z, grid_origin_.z)};
}

template <class Fn>
void ImpMesh::each_cell(const CellBox& b, Fn&& fn) {
  for (int64_t i = b[0]; i <= b[3]; ++i)
    for (int64_t j = b[1]; j <= b[4]; ++j)
      for (int64_t k = b[2]; k <= b[5]; ++k) fn((i * 2097152 + j) * 2097152 + k);
}

template <class Fn>
void ImpMesh::each_cell(tc_d3 lo, tc_d3 hi, Fn&& fn) {
  each_cell(cells_of(lo, hi), fn);
}

// Lists face f in the cells of its box, and only there (a moved face leaves its old cells).
void ImpMesh::grid_insert(int32_t f) {
  const FaceKey& k = sfaces_[size_t(f)];
  tc_d3 lo = point(k[0]), hi = lo;
  for (int i = 1; i < 3; ++i) {
    const tc_d3 p = point(k[size_t(i)]);
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  const CellBox box = cells_of(lo, hi);
  if (size_t(f) < sface_cells_.size()) {
    if (sface_cells_[size_t(f)] == box) return;
    each_cell(sface_cells_[size_t(f)], [&](int64_t c) {
      auto& list = grid_[c];
      list.erase(std::remove(list.begin(), list.end(), f), list.end());
    });
  } else {
    sface_cells_.resize(size_t(f) + 1);
  }
  sface_cells_[size_t(f)] = box;
  each_cell(box, [&](int64_t c) { grid_[c].push_back(f); });
}

std::vector<uint8_t> ImpMesh::surface_slots() const {
  // Each face met once, at its smallest vertex: the faces of that vertex's tets that it is the
  // smallest of, sorted by their other two vertices, pair up (one pass over the tets instead of
  // a search of a vertex's tets per face, as on_surface makes).
  std::vector<uint8_t> surface(4 * size_t(num_tet_slots()), 0);
  std::vector<std::pair<uint64_t, int32_t>> faces;  // (b << 32 | c, 4 t + f)
  for (int32_t v = 0; v < num_vertices(); ++v) {
    faces.clear();
    for (int32_t t : vtets_[size_t(v)]) {
      const Tet& q = tets_[size_t(t)];
      for (int f = 0; f < 4; ++f) {
        if (q[size_t(f)] == v) continue;  // (the face opposite v)
        const auto& F = geo::TC_TET_FACES[f];
        int32_t b = -1, c = -1;  // the face's other two vertices, both above v
        for (int k = 0; k < 3; ++k) {
          const int32_t w = q[size_t(F[k])];
          if (w == v) continue;
          if (w < v) b = c = -2;
          else if (b == -1) b = w;
          else if (c == -1) c = w;
        }
        if (b < 0 || c < 0) continue;
        if (b > c) std::swap(b, c);
        faces.push_back({uint64_t(uint32_t(b)) << 32 | uint32_t(c), 4 * t + f});
      }
    }
    std::sort(faces.begin(), faces.end());
    for (size_t i = 0; i < faces.size();) {
      size_t j = i + 1;
      while (j < faces.size() && faces[j].first == faces[i].first) ++j;
      const int32_t s0 = faces[i].second, s1 = faces[i + 1 < j ? i + 1 : i].second;
      if (j - i == 1) {
        surface[size_t(s0)] = 1;
      } else if (j - i == 2) {
        surface[size_t(s0)] = surface[size_t(s1)] = label_[size_t(s0 / 4)] != label_[size_t(s1 / 4)];
      } else {  // (not a manifold: as on_surface decides it)
        for (size_t k = i; k < j; ++k) {
          const int32_t t = faces[k].second / 4;
          const auto& F = geo::TC_TET_FACES[faces[k].second % 4];
          const Tet& q = tets_[size_t(t)];
          surface[size_t(faces[k].second)] = on_surface(t, q[size_t(F[0])], q[size_t(F[1])], q[size_t(F[2])]);
        }
      }
      i = j;
    }
  }
  return surface;
}

void ImpMesh::build_surface_grid() {
  double total = 0;
  const std::vector<uint8_t> surface = surface_slots();
  for (int32_t t = 0; t < num_tet_slots(); ++t) {
    const Tet& q = tets_[size_t(t)];
    for (int f = 0; f < 4; ++f) {
      const auto& F = geo::TC_TET_FACES[f];
      const int32_t a = q[size_t(F[0])], b = q[size_t(F[1])], c = q[size_t(F[2])];
      if (!surface[4 * size_t(t) + size_t(f)]) continue;
      const FaceKey k = face_key(a, b, c);
      if (sface_index_.emplace(k, int32_t(sfaces_.size())).second) {
        sfaces_.push_back(k);
        total += geo::length(point(b) - point(a));
      }
    }
  }
  if (sfaces_.empty()) return;
  cell_ = 2 * total / double(sfaces_.size());
  grid_origin_ = start_.empty() ? tc_d3{0, 0, 0} : start_[0];
  sface_seen_.assign(sfaces_.size(), 0);
  sface_alive_.assign(sfaces_.size(), 1);
  for (int32_t f = 0; f < int32_t(sfaces_.size()); ++f) grid_insert(f);
}

bool ImpMesh::triangle_clear(const FaceKey& a, const tc_d3 (&pa)[3], int32_t v, tc_d3 p,
                             const FaceKey* ignore, int n_ignore) {
  auto at = [&](int32_t x) { return x == v ? p : point(x); };
  const tc_d3 lo{std::min({pa[0].x, pa[1].x, pa[2].x}), std::min({pa[0].y, pa[1].y, pa[2].y}),
                 std::min({pa[0].z, pa[1].z, pa[2].z})};
  const tc_d3 hi{std::max({pa[0].x, pa[1].x, pa[2].x}), std::max({pa[0].y, pa[1].y, pa[2].y}),
                 std::max({pa[0].z, pa[1].z, pa[2].z})};
  ++sface_query_;
  bool clear = true;
  each_cell(lo, hi, [&](int64_t c) {
    const auto it = grid_.find(c);
    if (!clear || it == grid_.end()) return;
    for (int32_t g : it->second) {
      if (sface_seen_[size_t(g)] == sface_query_) continue;
      sface_seen_[size_t(g)] = sface_query_;
      if (!sface_alive_[size_t(g)]) continue;  // gone from the surface
      const FaceKey& b = sfaces_[size_t(g)];
      const tc_d3 pb[3] = {at(b[0]), at(b[1]), at(b[2])};
      // boxes apart, by more than the tri-tri test's tolerance (1e-9 of the size): no contact
      const double bxl = std::min({pb[0].x, pb[1].x, pb[2].x}), bxh = std::max({pb[0].x, pb[1].x, pb[2].x});
      const double byl = std::min({pb[0].y, pb[1].y, pb[2].y}), byh = std::max({pb[0].y, pb[1].y, pb[2].y});
      const double bzl = std::min({pb[0].z, pb[1].z, pb[2].z}), bzh = std::max({pb[0].z, pb[1].z, pb[2].z});
      const double tol = 1e-6 * std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z, bxh - bxl, byh - byl, bzh - bzl});
      if (bxl > hi.x + tol || bxh < lo.x - tol || byl > hi.y + tol || byh < lo.y - tol || bzl > hi.z + tol ||
          bzh < lo.z - tol)
        continue;
      if (b == a || std::find(ignore, ignore + n_ignore, b) != ignore + n_ignore) continue;
      if (geo::tc_sg_tri_tri(a.data(), pa, b.data(), pb)) {
        clear = false;
        return;
      }
    }
  });
  return clear;
}

bool ImpMesh::surface_stays_clear(int32_t v, tc_d3 p) {
  if (sfaces_.empty()) return true;
  std::vector<FaceKey> fan;
  surface_faces_at(v, fan);
  for (const FaceKey& a : fan) {
    const tc_d3 pa[3] = {a[0] == v ? p : point(a[0]), a[1] == v ? p : point(a[1]), a[2] == v ? p : point(a[2])};
    if (!triangle_clear(a, pa, v, p, nullptr, 0)) return false;
  }
  return true;
}

namespace {

// The fan test's fallback for fans it cannot bound because of a triangle with no area (common
// on coarsened flat patches): when neither fan folds seen along the vertex's normal n (no
// triangle turned over, the same area covered), every point of one lies straight above or
// below a point of the other, within the slab of both fans' points along n.
double slab_distance(const tc_d3* olds, const tc_d3* news, int n, tc_d3 o, tc_d3 nz) {
  double sum_old = 0, sum_new = 0, lo = 0, hi = 0, scale = 0;
  for (int i = 0; i < 3 * n; ++i) scale = std::max({scale, geo::length(olds[i] - o), geo::length(news[i] - o)});
  const double tiny = 1e-12 * scale * scale;
  double sign = 0;
  for (int i = 0; i < n; ++i) sign += geo::dot(geo::cross(olds[3 * i + 1] - olds[3 * i], olds[3 * i + 2] - olds[3 * i]), nz);
  sign = sign < 0 ? -1 : 1;
  for (int side = 0; side < 2; ++side)
    for (int i = 0; i < n; ++i) {
      const tc_d3* t = (side == 0 ? olds : news) + 3 * i;
      const double a = sign * geo::dot(geo::cross(t[1] - t[0], t[2] - t[0]), nz);
      if (!(a >= -tiny)) return std::numeric_limits<double>::infinity();
      (side == 0 ? sum_old : sum_new) += a;
      for (int k = 0; k < 3; ++k) {
        const double h = geo::dot(t[k] - o, nz);
        lo = std::min(lo, h);
        hi = std::max(hi, h);
      }
    }
  if (!(std::fabs(sum_old - sum_new) <= 1e-9 * (sum_old + sum_new))) return std::numeric_limits<double>::infinity();
  return hi - lo + 1e-12 * scale;
}

// A move by `moved` along a line of direction `dir` (its fan two sheets meeting there): when
// every triangle's plane holds the direction, two triangles of a sheet sharing an edge off the
// line lie in one plane (their planes meet in that edge, which would otherwise be parallel to
// the line), so each sheet is planar and the move re-triangulates it in place; the triangles'
// tilt against the direction bounds what is left.
double line_distance(const tc_d3* olds, int n, double moved, tc_d3 dir) {
  double tilt = 0;
  for (int i = 0; i < n; ++i) {
    const tc_d3* t = olds + 3 * i;
    const tc_d3 c = geo::cross(t[1] - t[0], t[2] - t[0]);
    const double l = geo::length(c);
    if (!(l > 0)) return std::numeric_limits<double>::infinity();
    tilt = std::max(tilt, std::fabs(geo::dot(c, dir)) / l);
  }
  return tilt <= 1e-9 ? moved * tilt : std::numeric_limits<double>::infinity();
}

}  // namespace

double ImpMesh::boundary_error_at(int32_t v, tc_d3 p) const {
  const tc_d3 here = point(v);
  // two bounds: the fan's largest plus the distance between the fan before and after; the fan's
  // largest at the start plus how far a vertex of it got since (every point of a triangle moves
  // by at most what its corners do)
  double base = err_[size_t(v)], base_start = err_start_[size_t(v)], shift = geo::length(p - start_[size_t(v)]);
  tc_d3 olds[3 * TCC_MAX_FAN], news[3 * TCC_MAX_FAN];
  int oid[3 * TCC_MAX_FAN], nid[3 * TCC_MAX_FAN];
  int n = 0;
  bool fits = true;
  // v's surface triangles, each once: from the tet on the owner's side (outside, or the smaller
  // label), in that tet's orientation, so that the fan is oriented one way
  for (int32_t t : vtets_[size_t(v)]) {
    const Tet& q = tets_[size_t(t)];
    for (int f = 0; f < 4; ++f) {
      if (q[size_t(f)] == v) continue;  // the face opposite v
      const auto& F = geo::TC_TET_FACES[f];
      const int32_t c[3] = {q[size_t(F[0])], q[size_t(F[1])], q[size_t(F[2])]};
      const int32_t o = across(t, c[0], c[1], c[2]);
      if (!(o < 0 || label_[size_t(t)] < label_[size_t(o)])) continue;
      for (int k = 0; k < 3; ++k) {
        base = std::max(base, err_[size_t(c[k])]);
        base_start = std::max(base_start, err_start_[size_t(c[k])]);
        if (c[k] != v) shift = std::max(shift, geo::length(point(c[k]) - start_[size_t(c[k])]));
      }
      if (n == TCC_MAX_FAN) {
        fits = false;
        continue;
      }
      for (int k = 0; k < 3; ++k) {
        olds[3 * n + k] = point(c[k]);
        news[3 * n + k] = c[k] == v ? p : point(c[k]);
        oid[3 * n + k] = c[k];
        nid[3 * n + k] = c[k] == v ? -1 : c[k];  // (v moved)
      }
      ++n;
    }
  }
  // A fan the test cannot bound: every point of the fan moves by at most what v does.
  const double moved = geo::length(p - here);
  double fan = moved;
  if (fits && motion(v) == kInPlane) {
    fan = geo::tcc_fan_distance(olds, oid, n, news, nid, n);
    if (!(fan < moved)) fan = std::min(fan, slab_distance(olds, news, n, here, normal_[size_t(v)]));
  } else if (fits && motion(v) == kAlongLine) {
    fan = std::min(moved, line_distance(olds, n, moved, normal_[size_t(v)]));
  }
  return std::min(base + std::min(fan, moved), base_start + shift);
}

void ImpMesh::surface_moved(int32_t v) {
  if (sfaces_.empty()) return;
  std::vector<FaceKey> fan;
  surface_faces_at(v, fan);
  for (const FaceKey& k : fan) {
    const auto it = sface_index_.find(k);
    if (it != sface_index_.end()) grid_insert(it->second);
  }
}

int32_t ImpMesh::across(int32_t t, int32_t a, int32_t b, int32_t c) const {
  // (through the shortest of the three vertices' lists: a tet with the face is in each)
  if (vtets_[size_t(b)].size() < vtets_[size_t(a)].size()) std::swap(a, b);
  if (vtets_[size_t(c)].size() < vtets_[size_t(a)].size()) std::swap(a, c);
  for (int32_t s : vtets_[size_t(a)]) {
    if (s == t) continue;
    if (contains(tets_[size_t(s)], b) && contains(tets_[size_t(s)], c)) return s;
  }
  return -1;
}

bool ImpMesh::replace_on_boundary(const std::vector<int32_t>& old, const std::vector<Tet>& added,
                                  const std::array<std::array<int32_t, 3>, 2>& gone,
                                  const std::array<std::array<int32_t, 3>, 2>& exposed, bool flat,
                                  double change) {
  // Under the bound: the new triangles lie within `change` of the old ones, which lay within
  // their corners' largest bound (spent); their own corners are three of the quad's four.
  // And the bound by displacement: the old triangles were within max A + max D (A their
  // corners' start bounds, D their displacements), and a corner's move since is at most its
  // displacement now plus max D, so the corners' start bounds become max A + 2 max D (+ change).
  double spent = 0, a = 0, d = 0;
  if (bounded_) {
    for (const auto& g : gone)
      for (int32_t v : g) {
        spent = std::max(spent, err_[size_t(v)]);
        a = std::max(a, err_start_[size_t(v)]);
        d = std::max(d, geo::length(point(v) - start_[size_t(v)]));
      }
    if (!(spent + change <= max_boundary_move_)) return false;
  }
  // A removal: the tets across the exposed faces must not become fins (three or four faces on
  // the surface). Either way the exposed faces must not touch the rest of the surface (on thin
  // parts of a model, or where near-degenerate tets fold it).
  for (const auto& e : exposed) {
    if (added.empty()) {
      const int32_t n = across(old[0], e[0], e[1], e[2]);
      if (n < 0) return false;
      int on = 0;
      const Tet& q = tets_[size_t(n)];
      for (const auto& F : geo::TC_TET_FACES)
        on += on_surface(n, q[size_t(F[0])], q[size_t(F[1])], q[size_t(F[2])]);
      if (on >= 2) return false;
    }
    if (!sfaces_.empty()) {
      const FaceKey k = face_key(e[0], e[1], e[2]);
      const tc_d3 pe[3] = {point(k[0]), point(k[1]), point(k[2])};
      const FaceKey ignore[2] = {face_key(gone[0][0], gone[0][1], gone[0][2]), face_key(gone[1][0], gone[1][1], gone[1][2])};
      if (!triangle_clear(k, pe, -1, pe[0], ignore, 2)) return false;
    }
  }
  if (!tris_.empty()) {
    const auto g0 = tris_.find(face_key(gone[0][0], gone[0][1], gone[0][2]));
    const auto g1 = tris_.find(face_key(gone[1][0], gone[1][1], gone[1][2]));
    if ((g0 == tris_.end()) != (g1 == tris_.end())) return false;  // one tagged, one not
    if (g0 != tris_.end()) {
      if (mesh_.tri_tags[size_t(g0->second)] != mesh_.tri_tags[size_t(g1->second)]) return false;
      const int64_t i0 = g0->second, i1 = g1->second;
      tris_.erase(g0);
      tris_.erase(tris_.find(face_key(gone[1][0], gone[1][1], gone[1][2])));
      for (int k = 0; k < 3; ++k) {
        mesh_.tris[size_t(3 * i0 + k)] = exposed[0][size_t(k)];
        mesh_.tris[size_t(3 * i1 + k)] = exposed[1][size_t(k)];
      }
      tris_.emplace(face_key(exposed[0][0], exposed[0][1], exposed[0][2]), i0);
      tris_.emplace(face_key(exposed[1][0], exposed[1][1], exposed[1][2]), i1);
    }
  }
  // The vertices' surface fans changed: unless in one plane, what was flat around them may be
  // no longer.
  if (!flat)
    for (int32_t t : old)
      for (int32_t v : tets_[size_t(t)]) motion_[size_t(v)] = kFixed;
  if (bounded_)
    for (const auto& g : gone)
      for (int32_t v : g) {
        err_[size_t(v)] = std::max(err_[size_t(v)], spent + change);
        err_start_[size_t(v)] = std::max(err_start_[size_t(v)], a + 2 * d + change);
      }
  replace(old, added, old[0]);
  if (!sfaces_.empty()) {
    for (const auto& g : gone) {
      const auto it = sface_index_.find(face_key(g[0], g[1], g[2]));
      if (it == sface_index_.end()) continue;
      sface_alive_[size_t(it->second)] = 0;
      sface_index_.erase(it);
    }
    for (const auto& e : exposed) {
      const FaceKey k = face_key(e[0], e[1], e[2]);
      sface_index_[k] = int32_t(sfaces_.size());
      sfaces_.push_back(k);
      sface_seen_.push_back(0);
      sface_alive_.push_back(1);
      grid_insert(int32_t(sfaces_.size()) - 1);
    }
  }
  return true;
}

// Interior vertices move freely. A vertex of the feature surface (boundary and interfaces)
// moves only within the surface: a vertex inside a patch (no ridge or tagged edge at it, one
// fan of surface triangles) within its tangent plane, a vertex on a feature line (exactly two
// ridge or tagged edges) along the line's chord. Where the patch is flat, or the line straight,
// to rounding, the surface keeps its shape and the move is not bounded; elsewhere (features and
// free modes) the vertex stays within max_offset of where it started, so that the surface moves
// by at most max_boundary_move: a move by d within a plane at angle theta to the surface's
// triangles (a line at angle theta to its edges) leaves the vertex d sin(theta) off them.
// Corners, pinched vertices and (strict mode) every surface vertex stay.
void ImpMesh::mark_motion(const ImproveOptions& options) {
  constexpr double kStraight = 1e-9;  // sin of the angle counted as flat or straight
  const int32_t nv = num_vertices();
  motion_.assign(size_t(nv), kFree);
  normal_.assign(size_t(nv), tc_d3{0, 0, 0});
  max_offset_.assign(size_t(nv), std::numeric_limits<double>::infinity());
  start_.resize(size_t(nv));
  for (int32_t v = 0; v < nv; ++v) start_[size_t(v)] = point(v);
  Topology topo = build_topology(mesh_, TopologyOptions{options.eps_f, options.eps_r, options.use_labels});
  const bool may_bend = options.boundary != CollapseOptions::Strict && max_boundary_move_ > 0;
  for (int32_t v = 0; v < nv; ++v) {
    if (topo.vertex_class[size_t(v)] == uint8_t(VertexClass::Interior)) continue;
    motion_[size_t(v)] = kFixed;
    if (options.boundary == CollapseOptions::Strict) continue;
    int32_t line_ends[2], lines = 0, surface_edges = 0;
    for (int32_t i = topo.vertex_edges_offsets[size_t(v)]; i < topo.vertex_edges_offsets[size_t(v) + 1]; ++i) {
      const int32_t e = topo.vertex_edges[size_t(i)];
      const int32_t w = topo.edges[2 * size_t(e)] == v ? topo.edges[2 * size_t(e) + 1] : topo.edges[2 * size_t(e)];
      surface_edges += topo.edge_boundary[size_t(e)] != 0;
      if (topo.edge_ridge[size_t(e)] || tagged_edge(v, w)) {
        if (lines < 2) line_ends[lines] = w;
        ++lines;
      }
    }
    const int32_t fb = topo.vertex_sfaces_offsets[size_t(v)], fe = topo.vertex_sfaces_offsets[size_t(v) + 1];
    double bend = 0;  // sin of the largest angle between the allowed motion and the surface
    tc_d3 dir{0, 0, 0};
    if (lines == 0) {
      if (surface_edges != fe - fb) continue;  // not one fan (pinched, or a boundary of S)
      for (int32_t i = fb; i < fe; ++i) dir = dir + geo::tc_point(topo.sface_normals.data(), topo.vertex_sfaces[size_t(i)]);
      dir = geo::normalize(dir);
      if (!(geo::dot(dir, dir) > 0.5)) continue;
      for (int32_t i = fb; i < fe; ++i)
        bend = std::max(bend, geo::length(geo::cross(dir, geo::tc_point(topo.sface_normals.data(), topo.vertex_sfaces[size_t(i)]))));
    } else if (lines == 2) {
      const tc_d3 p = point(v), a = point(line_ends[0]), b = point(line_ends[1]);
      dir = geo::normalize(b - a);
      if (!(geo::dot(dir, dir) > 0.5)) continue;
      bend = std::max(geo::length(geo::cross(dir, geo::normalize(p - a))), geo::length(geo::cross(dir, geo::normalize(b - p))));
    } else {
      continue;  // a corner
    }
    if (bend > kStraight) {
      if (!may_bend) continue;
      max_offset_[size_t(v)] = bounded_ && lines != 0 ? max_boundary_move_ : max_boundary_move_ / bend;
    } else if (bounded_) {
      // Under the bound a flat patch's or a straight line's vertex is accounted as a curved
      // one's: once a neighbour has moved, its fan is no longer flat.
      max_offset_[size_t(v)] = max_boundary_move_ / kStraight;
    }
    motion_[size_t(v)] = lines == 0 ? kInPlane : kAlongLine;
    normal_[size_t(v)] = dir;
  }
  // Vertices of tagged triangles off the feature surface, and of tagged edges off it, stay.
  for (int64_t i = 0; i < 3 * mesh_.num_tris(); ++i)
    if (topo.vertex_class[size_t(mesh_.tris[size_t(i)])] == uint8_t(VertexClass::Interior))
      motion_[size_t(mesh_.tris[size_t(i)])] = kFixed;
  for (int32_t v : mesh_.edges)
    if (topo.vertex_class[size_t(v)] == uint8_t(VertexClass::Interior)) motion_[size_t(v)] = kFixed;
  for (int32_t v = 0; v < nv; ++v)
    if (!selected(v)) motion_[size_t(v)] = kFixed;
}

void ImpMesh::interpolate_fields(const std::vector<int32_t>& around, tc_d3 p, int32_t v) {
  if (!mesh_.vertex_fields.empty()) {
    // The tet of `around` (as it is) holding p, by its barycentric coordinates: the one whose
    // smallest coordinate is largest (p is inside their union, so that one holds it).
    int32_t best = -1;
    double best_min = -std::numeric_limits<double>::infinity(), bary[4] = {0, 0, 0, 0};
    for (int32_t t : around) {
      const Tet& q = tets_[size_t(t)];
      const tc_d3 c[4] = {point(q[0]), point(q[1]), point(q[2]), point(q[3])};
      const double vol = geo::tc_orient3d(c[0], c[1], c[2], c[3]);
      if (!(vol > 0)) continue;
      double b[4];
      for (int k = 0; k < 4; ++k) {
        tc_d3 d[4] = {c[0], c[1], c[2], c[3]};
        d[k] = p;
        b[k] = geo::tc_orient3d(d[0], d[1], d[2], d[3]) / vol;
      }
      const double lo = std::min(std::min(b[0], b[1]), std::min(b[2], b[3]));
      if (lo > best_min) {
        best_min = lo;
        best = t;
        std::copy(b, b + 4, bary);
      }
    }
    if (best >= 0)
      for (Field& f : mesh_.vertex_fields) {
        const size_t nc = size_t(f.components);
        std::vector<double> value(nc, 0.0);
        for (int k = 0; k < 4; ++k)
          for (size_t c = 0; c < nc; ++c) value[c] += bary[k] * f.values[size_t(tets_[size_t(best)][k]) * nc + c];
        std::copy(value.begin(), value.end(), f.values.begin() + ptrdiff_t(size_t(v) * nc));
      }
  }
}

void ImpMesh::move(int32_t v, tc_d3 p) {
  interpolate_fields(vtets_[size_t(v)], p, v);
  points_[3 * size_t(v)] = p.x;
  points_[3 * size_t(v) + 1] = p.y;
  points_[3 * size_t(v) + 2] = p.z;
  for (int32_t t : vtets_[size_t(v)]) {
    quality_[size_t(t)] = quality_of(tets_[size_t(t)]);
    max_cos_[size_t(t)] = max_cos_of(tets_[size_t(t)]);
  }
  ++stamp_;
  touch_star(v);
}

int32_t ImpMesh::add_vertex(tc_d3 p, const std::vector<int32_t>& around) {
  const int32_t v = num_vertices();
  points_.insert(points_.end(), {p.x, p.y, p.z});
  for (Field& f : mesh_.vertex_fields) f.values.resize(f.values.size() + size_t(f.components), 0.0);
  interpolate_fields(around, p, v);
  vtets_.emplace_back();
  changed_.push_back(stamp_);
  smooth_failed_at.push_back(0);
  flip_failed_at.push_back(0);
  if (!mask_.empty()) mask_.push_back(1);
  motion_.push_back(kFree);
  normal_.push_back({0, 0, 0});
  max_offset_.push_back(std::numeric_limits<double>::infinity());
  start_.push_back(p);
  if (bounded_) {  // (inside: no surface at it)
    err_.push_back(0);
    err_start_.push_back(0);
  }
  return v;
}

void ImpMesh::touch_star(int32_t v) {
  for (int32_t t : vtets_[size_t(v)])
    for (int32_t x : tets_[size_t(t)]) changed_[size_t(x)] = stamp_;
}

double ImpMesh::max_cos_with(int32_t t, int32_t v, tc_d3 p) const {
  const Tet& q = tets_[size_t(t)];
  tc_d3 c[4];
  for (int k = 0; k < 4; ++k) c[k] = q[k] == v ? p : point(q[k]);
  return geo::tc_tet_max_dihedral_cos(c[0], c[1], c[2], c[3]);
}

double ImpMesh::quality_with(int32_t t, int32_t v, tc_d3 p) const {
  const Tet& q = tets_[size_t(t)];
  tc_d3 c[4];
  for (int k = 0; k < 4; ++k) c[k] = q[k] == v ? p : point(q[k]);
  return geo::tc_tet_min_sine(c[0], c[1], c[2], c[3]);
}

bool ImpMesh::has_edge(int32_t a, int32_t b) const {
  const auto& la = vtets_[size_t(a)];
  const auto& lb = vtets_[size_t(b)];
  const auto& l = la.size() <= lb.size() ? la : lb;
  const int32_t other = la.size() <= lb.size() ? b : a;
  for (int32_t t : l)
    if (contains(tets_[size_t(t)], other)) return true;
  return false;
}

void ImpMesh::replace(const std::vector<int32_t>& old, const std::vector<Tet>& added, int32_t like) {
  const int32_t lab = label_[size_t(like)], org = origin_[size_t(like)];
  ++stamp_;
  for (int32_t t : old)
    for (int32_t v : tets_[size_t(t)]) touch_star(v);
  for (int32_t t : old) {
    dead_[size_t(t)] = 1;
    for (int32_t v : tets_[size_t(t)]) {
      auto& l = vtets_[size_t(v)];
      l.erase(std::find(l.begin(), l.end(), t));
    }
    free_.push_back(t);
  }
  for (const Tet& q : added) {
    int32_t t;
    if (!free_.empty()) {
      t = free_.back();
      free_.pop_back();
    } else {
      t = int32_t(tets_.size());
      tets_.emplace_back();
      label_.push_back(0);
      origin_.push_back(0);
      dead_.push_back(0);
      quality_.push_back(0);
      max_cos_.push_back(0);
    }
    tets_[size_t(t)] = q;
    label_[size_t(t)] = lab;
    origin_[size_t(t)] = org;
    dead_[size_t(t)] = 0;
    quality_[size_t(t)] = quality_of(q);
    max_cos_[size_t(t)] = max_cos_of(q);
    for (int32_t v : q) vtets_[size_t(v)].push_back(t);
  }
}

void ImpMesh::write_back() {
  std::vector<int32_t> tets;
  std::vector<int32_t> origin;
  for (size_t t = 0; t < tets_.size(); ++t) {
    if (dead_[t]) continue;
    tets.insert(tets.end(), tets_[t].begin(), tets_[t].end());
    origin.push_back(origin_[t]);
  }
  mesh_.tets = std::move(tets);
  for (auto& labels : mesh_.tet_labels) {
    std::vector<int32_t> v(origin.size());
    for (size_t i = 0; i < origin.size(); ++i) v[i] = labels.values[size_t(origin[i])];
    labels.values = std::move(v);
  }
  for (auto& field : mesh_.tet_fields) {
    const size_t nc = size_t(field.components);
    std::vector<double> v(origin.size() * nc);
    for (size_t i = 0; i < origin.size(); ++i)
      std::copy_n(field.values.begin() + ptrdiff_t(size_t(origin[i]) * nc), nc, v.begin() + ptrdiff_t(i * nc));
    field.values = std::move(v);
  }
}

}  // namespace tc::improve_detail
