// The dynamic mesh of the sequential method: see sequential_mesh.hpp.
#include "collapse/sequential_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "collapse/stages.hpp"  // collapse_detail::Reason
#include "collapse_classify.h"  // the classification rules, the device's own
#include "collapse_guard_geometry.h"  // tc::geo::tc_sg_tri_tri, the device guard's own test
#include "collapse_predicate.h"
#include "tetcollapse/error.hpp"

namespace tc::sequential_detail {

using namespace collapse_detail;
using geo::tc_d3;

namespace {

// The list limits of the kernels, so that the verdicts agree even where they bite:
// TCC_MAX_LINK (cl/collapse_admissible.cl) and TCC_MAX_VERTEX_SFACES (collapse_connectivity.cl).
constexpr size_t kMaxLink = 96;
constexpr size_t kMaxVertexSFaces = 64;
constexpr uint8_t kSMask = TCC_BOUNDARY | TCC_INTERFACE;

tc_d3 face_normal(const std::vector<double>& pts, const int32_t* q, int f) {
  tc_d3 p0 = geo::tc_point(pts.data(), q[geo::TC_TET_FACES[f][0]]);
  tc_d3 p1 = geo::tc_point(pts.data(), q[geo::TC_TET_FACES[f][1]]);
  tc_d3 p2 = geo::tc_point(pts.data(), q[geo::TC_TET_FACES[f][2]]);
  return geo::normalize(geo::cross(p1 - p0, p2 - p0));
}

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

// Does the face of q opposite local vertex f run from x to y (x, y consecutive in its order)?
bool runs(const int32_t* q, int f, int32_t x, int32_t y) {
  int32_t f0 = q[geo::TC_TET_FACES[f][0]], f1 = q[geo::TC_TET_FACES[f][1]], f2 = q[geo::TC_TET_FACES[f][2]];
  return (f0 == x && f1 == y) || (f1 == x && f2 == y) || (f2 == x && f0 == y);
}

}  // namespace

SeqMesh::SeqMesh(Mesh& mesh, const SeqParams& params, const std::vector<uint8_t>* vflags,
                 const std::vector<uint8_t>* vclass, const std::vector<int32_t>* tet_nbr)
    : mesh_(mesh), points_(&mesh.points), tets_(&mesh.tets), p_(params) {
  collapse_detail::check_collapse_input(mesh);  // the same refusals as the device pipeline
  const int64_t nv = mesh.num_vertices(), nt = mesh.num_tets();
  auto check_fields = [](const std::vector<Field>& fields, int64_t count, const char* kind) {
    for (const Field& f : fields)
      if (f.components <= 0 || f.values.size() != size_t(count) * size_t(f.components))
        throw InputError("<mesh>", std::string(kind) + " field '" + f.name + "' has " + std::to_string(f.values.size()) +
                                       " values, expected " + std::to_string(count) + " x " + std::to_string(f.components));
  };
  check_fields(mesh.vertex_fields, nv, "vertex");
  check_fields(mesh.tet_fields, nt, "tet");

  labels_ = p_.use_labels && !mesh.tet_labels.empty() ? &mesh.tet_labels[0].values : nullptr;
  nv_ = alive_v_ = int32_t(nv);
  nt_ = alive_t_ = int32_t(nt);
  valive_.assign(nv_, 1);
  talive_.assign(nt_, 1);
  fwd_.assign(nv_, -1);
  mark_.assign(nv_, 0);
  lmark_.assign(nv_, 0);
  rebuild_rings();
  if (tet_nbr) {
    if (tet_nbr->size() != 4 * size_t(nt_))
      throw std::invalid_argument("SeqMesh: the given tet neighbours need four entries per tet");
    nbr_ = *tet_nbr;
  } else {
    build_nbr();
  }
  if (vflags && vclass) {
    if (vflags->size() != size_t(nv_) || vclass->size() != size_t(nv_))
      throw std::invalid_argument("SeqMesh: the given vertex flags and classes need one entry per vertex");
    vflags_ = *vflags;
    vclass_ = *vclass;
    return;
  }
  vflags_.assign(nv_, 0);
  vclass_.assign(nv_, TCC_INTERIOR);
  for (int32_t v = 0; v < nv_; ++v) classify(v, vflags_[v], vclass_[v]);
}

// --- vertex -> tets lists ---

void SeqMesh::rebuild_rings() {
  rlen_.assign(nv_, 0);
  for (int32_t t = 0; t < nt_; ++t)
    for (int k = 0; k < 4; ++k) ++rlen_[tet(t)[k]];
  // every list gets room to grow by half (a survivor takes over the tets of the removed vertex)
  roff_.resize(nv_);
  rcap_.resize(nv_);
  size_t total = 0;
  for (int32_t v = 0; v < nv_; ++v) {
    roff_[v] = uint32_t(total);
    rcap_[v] = rlen_[v] + rlen_[v] / 2 + 2;
    total += rcap_[v];
  }
  if (total + total / 2 >= std::numeric_limits<uint32_t>::max())
    throw InputError("<mesh>", "mesh too large for the sequential method's 32-bit list offsets");
  pool_.clear();
  pool_.reserve(total + total / 4);  // lists that outgrow their slot move to the end
  pool_.resize(total);
  std::fill(rlen_.begin(), rlen_.end(), 0u);
  for (int32_t t = 0; t < nt_; ++t)
    for (int k = 0; k < 4; ++k) {
      int32_t v = tet(t)[k];
      pool_[roff_[v] + rlen_[v]++] = t;
    }
}

void SeqMesh::ring_append(int32_t v, int32_t t) {
  if (rlen_[v] == rcap_[v]) {
    const uint32_t cap = std::max<uint32_t>(8, 2 * rcap_[v]);
    const size_t at = pool_.size();
    if (at + cap >= std::numeric_limits<uint32_t>::max())
      throw InputError("<mesh>", "mesh too large for the sequential method's 32-bit list offsets");
    pool_.resize(at + cap);
    std::copy(pool_.begin() + roff_[v], pool_.begin() + roff_[v] + rlen_[v], pool_.begin() + at);
    roff_[v] = uint32_t(at);
    rcap_[v] = cap;
  }
  pool_[roff_[v] + rlen_[v]++] = t;
}

void SeqMesh::ring_remove(int32_t v, int32_t t) {
  int32_t* r = pool_.data() + roff_[v];
  for (uint32_t i = 0; i < rlen_[v]; ++i)
    if (r[i] == t) {
      r[i] = r[--rlen_[v]];
      return;
    }
}

uint32_t SeqMesh::next_stamp() {
  if (++stamp_ == 0) {  // wrapped: forget every old stamp
    std::fill(mark_.begin(), mark_.end(), 0u);
    std::fill(lmark_.begin(), lmark_.end(), 0u);
    stamp_ = 1;
  }
  return stamp_;
}

void SeqMesh::neighbours(int32_t v, std::vector<int32_t>& out, bool above_only) {
  out.clear();
  const uint32_t s = next_stamp();
  const int32_t* r = ring(v);
  for (uint32_t i = 0; i < rlen_[v]; ++i) {
    const int32_t* q = tet(r[i]);
    for (int k = 0; k < 4; ++k) {
      int32_t u = q[k];
      if (u == v || (above_only && u < v) || mark_[u] == s) continue;
      mark_[u] = s;
      out.push_back(u);
    }
  }
}

bool SeqMesh::is_edge(int32_t a, int32_t b) const {
  const int32_t* r = ring(a);
  for (uint32_t i = 0; i < rlen_[a]; ++i)
    if (has(tet(r[i]), b)) return true;
  return false;
}

double SeqMesh::length(int32_t a, int32_t b) const {
  tc_d3 d = point(b) - point(a);
  return geo::sqrt(geo::dot(d, d));
}

bool SeqMesh::ring_has(int32_t x, int32_t y, int32_t z, int32_t w) const {
  const int32_t* r = ring(x);
  for (uint32_t i = 0; i < rlen_[x]; ++i) {
    const int32_t* q = tet(r[i]);
    if (has(q, y) && has(q, z) && (w < 0 || has(q, w))) return true;
  }
  return false;
}

// tcc_triangle_kind: is (x, y, z) an S-face?
uint8_t SeqMesh::triangle_kind(int32_t x, int32_t y, int32_t z) const {
  int n = 0;
  int32_t t0 = -1, t1 = -1;
  const int32_t* r = ring(x);
  for (uint32_t i = 0; i < rlen_[x]; ++i) {
    const int32_t* q = tet(r[i]);
    if (has(q, y) && has(q, z)) {
      if (n == 0) t0 = r[i];
      else if (n == 1) t1 = r[i];
      ++n;
    }
  }
  if (n == 0) return 0;
  if (n != 2) return TCC_BOUNDARY;
  if (labels_ && label(t0) != label(t1)) return TCC_INTERFACE;
  return 0;
}

// --- flags and classes (conn_vertex_flags*, conn_surface_flags) ---

uint8_t SeqMesh::edge_flags(int32_t a, int32_t b, bool with_ridge) {
  if (!vflags_[a] || !vflags_[b]) return 0;  // an S-edge joins two S vertices
  // the faces through a and b, in the tets around the edge, with the tets across them
  uint8_t flags = 0;
  int ns = 0;
  int32_t ft[2] = {-1, -1};
  int ff[2] = {0, 0};
  const int32_t* r = ring(a);
  for (uint32_t i = 0; i < rlen_[a]; ++i) {
    const int32_t t = r[i];
    const int32_t* q = tet(t);
    const int lb = local(q, b);
    if (lb < 0) continue;
    const int la = local(q, a);
    for (int f = 0; f < 4; ++f) {
      if (f == la || f == lb) continue;
      uint8_t on_s = 0;
      const uint8_t own = owned_sface(t, f, &on_s);
      flags |= on_s;
      if (own) {
        if (ns < 2) {
          ft[ns] = t;
          ff[ns] = f;
        }
        ++ns;
      }
    }
  }
  if (with_ridge && ns > 0) {
    bool ridge;
    if (ns != 2) {
      ridge = true;
    } else if (runs(tet(ft[0]), ff[0], a, b) == runs(tet(ft[1]), ff[1], a, b)) {
      ridge = true;  // the two S-faces are not consistently oriented
    } else {
      tc_d3 n0 = face_normal(*points_, tet(ft[0]), ff[0]), n1 = face_normal(*points_, tet(ft[1]), ff[1]);
      ridge = 1.0 - geo::dot(n0, n1) > p_.eps_r;
    }
    if (ridge) flags |= TCC_RIDGE;
  }
  return flags;
}

void SeqMesh::classify(int32_t v, uint8_t& flags_out, uint8_t& cls_out) {
  // every face through v: on S and owned as tcc_owned_sface says (owned_sface)
  uint8_t flags = 0;
  bool overflow = false;
  sf_after_.clear();
  sf_before_.clear();
  sf_normal_.clear();
  each_face_through(v, [&](int32_t t, const int32_t* q, int f, int) {
    uint8_t on_s = 0;
    const uint8_t own = owned_sface(t, f, &on_s);
    flags |= on_s;
    if (!own) return;
    if (sf_after_.size() == kMaxVertexSFaces) {
      overflow = true;
      return;
    }
    int32_t w[3] = {q[geo::TC_TET_FACES[f][0]], q[geo::TC_TET_FACES[f][1]], q[geo::TC_TET_FACES[f][2]]};
    int p = w[0] == v ? 0 : w[1] == v ? 1 : 2;
    sf_after_.push_back(w[(p + 1) % 3]);
    sf_before_.push_back(w[(p + 2) % 3]);
    sf_normal_.push_back(face_normal(*points_, q, f));
  });
  flags_out = flags;
  if (!flags || (sf_after_.empty() && !overflow)) {
    cls_out = TCC_INTERIOR;
    return;
  }
  // the class by the connectivity stage's own rules (cl/collapse_classify.h)
  cls_out = overflow ? TCC_CORNER
                     : uint8_t(geo::tc_sf_class(sf_after_.data(), sf_before_.data(), sf_normal_.data(),
                                                int(sf_after_.size()), p_.eps_r, p_.eps_f));
}

int64_t SeqMesh::verify_classes() {
  int64_t bad = 0;
  for (int32_t v = 0; v < nv_; ++v) {
    if (!valive_[v]) continue;
    uint8_t f = 0, c = 0;
    classify(v, f, c);
    if (f != vflags_[v] || c != vclass_[v]) ++bad;
  }
  return bad;
}

// --- the admissible checks ---

int SeqMesh::predicate(int32_t a, int32_t b, uint8_t& fe) {
  fe = edge_flags(a, b);
  return rules::tcc_predicate_q(a, b, vflags_[a], vflags_[b], fe, vclass_[a], vclass_[b], p_.mode,
                                p_.paper_rule ? 1 : 0);
}

Verdict SeqMesh::check(int32_t a, int32_t b) {
  if (a > b) std::swap(a, b);
  Verdict v;
  uint8_t fe = 0;
  const int dir = predicate(a, b, fe);
  if (dir < 0) {
    v.reason = kRefusedQ;
    return v;
  }
  v.reason = link_and_volume(a, b, fe, dir);
  if (v.reason == kOk) v.dir = uint8_t(dir);
  return v;
}

tc_d3 SeqMesh::placement(int32_t a, int32_t b, unsigned dir) const {
  tc_d3 p0 = point(a), p1 = point(b);
  if (dir & TCC_DIR_MIDPOINT) return (p0 + p1) * 0.5;
  return (dir & TCC_DIR_REMOVE_V1) ? p0 : p1;
}

// tcc_link_and_volume, over the current rings (a < b): the volume and quality test first.
uint8_t SeqMesh::link_and_volume(int32_t a, int32_t b, uint8_t fe, int dir) {
  const uint8_t r = volume_and_quality(a, b, dir);
  if (r != kOk) return r;
  return link_ok(a, b, fe) ? kOk : kRefusedLink;
}

bool SeqMesh::admissible(int32_t a, int32_t b, uint8_t fe, int dir) { return link_and_volume(a, b, fe, dir) == kOk; }

// The link condition of tcc_link_and_volume (a < b): true when it holds.
bool SeqMesh::link_ok(int32_t a, int32_t b, uint8_t fe) {
  const uint8_t fa = vflags_[a], fb = vflags_[b];
  // N(a) marked sA; the common neighbours cn = N(a) n N(b) re-marked sC
  const uint32_t sA = next_stamp(), sC = next_stamp();
  const int32_t* ra = ring(a);
  const int32_t* rb = ring(b);
  for (uint32_t i = 0; i < rlen_[a]; ++i) {
    const int32_t* q = tet(ra[i]);
    for (int k = 0; k < 4; ++k)
      if (q[k] != a) mark_[q[k]] = sA;
  }
  cn_.clear();
  for (uint32_t i = 0; i < rlen_[b]; ++i) {
    const int32_t* q = tet(rb[i]);
    for (int k = 0; k < 4; ++k) {
      int32_t u = q[k];
      if (u != b && mark_[u] == sA) {
        mark_[u] = sC;
        cn_.push_back(u);
      }
    }
  }
  if (cn_.size() > kMaxLink) return false;
  // lk(ab): the pairs (c, d) of the tets around the edge, their vertices marked sL
  const uint32_t sL = next_stamp();
  pc_.clear();
  pd_.clear();
  for (uint32_t i = 0; i < rlen_[a]; ++i) {
    const int32_t* q = tet(ra[i]);
    if (!has(q, b)) continue;
    int32_t o[2];
    int no = 0;
    for (int k = 0; k < 4; ++k)
      if (q[k] != a && q[k] != b) o[no++] = q[k];
    pc_.push_back(o[0]);
    pd_.push_back(o[1]);
    lmark_[o[0]] = lmark_[o[1]] = sL;
  }
  if (pc_.size() > kMaxLink) return false;
  // (iii) with w, inside the tets (a,b,c,d) of the edge: no S-faces (a,c,d) and (b,c,d)
  if ((fa & kSMask) && (fb & kSMask))
    for (size_t m = 0; m < pc_.size(); ++m)
      if (triangle_kind(a, pc_[m], pd_[m]) && triangle_kind(b, pc_[m], pd_[m])) return false;
  // (i) every common neighbour is a vertex of lk(ab); and w: a, b both on S needs an S-edge
  for (int32_t c : cn_)
    if (lmark_[c] != sL) return false;
  if (!rules::tcc_w_join_ok(fa, fb, fe)) return false;
  // (ii) with w: S-edges (a,c) and (b,c) need the S-face (a,b,c), of the kinds they share
  for (int32_t c : cn_) {
    if (!(vflags_[c] & kSMask)) continue;
    const uint8_t fac = edge_flags(a, c, false), fbc = edge_flags(b, c, false);
    if ((fac & kSMask) && (fbc & kSMask) && !rules::tcc_w_join_ok(fac, fbc, triangle_kind(a, b, c))) return false;
  }
  // (ii) triangles and (iii) tets and S-faces, from the tets of ring(a) without b
  for (uint32_t i = 0; i < rlen_[a]; ++i) {
    const int32_t* q = tet(ra[i]);
    if (has(q, b)) continue;
    int32_t o[3];
    int no = 0;
    for (int k = 0; k < 4; ++k)
      if (q[k] != a) o[no++] = q[k];
    const bool in[3] = {mark_[o[0]] == sC, mark_[o[1]] == sC, mark_[o[2]] == sC};
    if (in[0] && in[1] && in[2] && ring_has(b, o[0], o[1], o[2])) return false;  // tets (a,c,d,e), (b,c,d,e)
    static constexpr int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
    for (const auto& pr : pairs) {
      if (!in[pr[0]] || !in[pr[1]]) continue;
      const int32_t c = o[pr[0]], d = o[pr[1]];
      // triangles (a,c,d) and (b,c,d) need the tet (a,b,c,d), i.e. (c, d) in lk(ab); when it is,
      // (b,c,d) is a triangle (of that tet), so the kernel's order of tests gives the same answer
      bool in_lk = false;
      for (size_t m = 0; m < pc_.size() && !in_lk; ++m)
        in_lk = (pc_[m] == c && pd_[m] == d) || (pc_[m] == d && pd_[m] == c);
      if (!in_lk) {
        if (ring_has(b, c, d, -1)) return false;
        continue;  // (b,c,d) is no triangle
      }
      // S-faces (a,c,d) and (b,c,d); an S-face through a needs a on S (and b likewise)
      if ((fa & kSMask) && (fb & kSMask) && triangle_kind(a, c, d) && triangle_kind(b, c, d)) return false;
    }
  }
  return true;
}

// The volumes (and the quality guard) after the tentative collapse.
uint8_t SeqMesh::volume_and_quality(int32_t a, int32_t b, int dir) const {
  const tc_d3 p = placement(a, b, unsigned(dir));
  double q_old = 1.0, q_new = 1.0;
  const double q_min = p_.min_quality;
  for (int side = 0; side < 2; ++side) {
    const int32_t x = side == 0 ? a : b, y = side == 0 ? b : a;
    const tc_d3 px = point(x);
    if (px.x == p.x && px.y == p.y && px.z == p.z) continue;  // x does not move: its tets keep their shape
    const int32_t* rx = ring(x);
    for (uint32_t i = 0; i < rlen_[x]; ++i) {
      const int32_t* q = tet(rx[i]);
      if (has(q, y)) continue;  // removed by the collapse
      tc_d3 c[4];
      for (int k = 0; k < 4; ++k) c[k] = q[k] == x ? p : point(q[k]);
      if (!(geo::tc_tet_volume(c[0], c[1], c[2], c[3]) >= p_.eps_v)) return kRefusedVolume;
      if (q_min > 0.0) {
        double qn = geo::tc_tet_quality(c[0], c[1], c[2], c[3]);
        double qo = geo::tc_tet_quality(point(q[0]), point(q[1]), point(q[2]), point(q[3]));
        q_new = qn < q_new ? qn : q_new;
        q_old = qo < q_old ? qo : q_old;
      }
    }
  }
  if (q_min > 0.0 && q_new < (q_old < q_min ? q_old : q_min)) return kRefusedQuality;
  return kOk;
}

// --- collapse and compaction ---

int32_t SeqMesh::collapse(int32_t a, int32_t b, uint8_t dir) {
  if (a > b) std::swap(a, b);
  const bool remove_b = (dir & TCC_DIR_REMOVE_V1) != 0;
  const int32_t r = remove_b ? b : a, s = remove_b ? a : b;
  const tc_d3 p = placement(a, b, dir);
  const bool on_s = vflags_[r] || vflags_[s];
  // the vertices whose star changes: those of the tets of ring(r) U ring(s)
  const uint32_t st = next_stamp();
  touched_.clear();
  for (int32_t x : {r, s}) {
    const int32_t* rx = ring(x);
    for (uint32_t i = 0; i < rlen_[x]; ++i) {
      const int32_t* q = tet(rx[i]);
      for (int k = 0; k < 4; ++k)
        if (mark_[q[k]] != st) {
          mark_[q[k]] = st;
          touched_.push_back(q[k]);
        }
    }
  }
  // the tets of the edge disappear, the other tets of ring(r) move to s
  rr_.assign(ring(r), ring(r) + rlen_[r]);
  gone_.clear();
  for (int32_t t : rr_) {
    int32_t* q = tets_->data() + 4 * size_t(t);
    if (has(q, s)) {
      gone_.insert(gone_.end(), q, q + 4);
      // the tets A across the face opposite r (s, c, d) and B across the one opposite s (r, c, d)
      // become neighbours through (s, c, d) (cl/collapse_update.cl, tet_nbr_update)
      int32_t* nt = nbr_.data() + 4 * size_t(t);
      const int32_t A = nt[local(q, r)], B = nt[local(q, s)];
      for (int side = 0; side < 2; ++side) {
        const int32_t X = side == 0 ? A : B, Y = side == 0 ? B : A;
        if (X < 0) continue;
        int32_t* nx = nbr_.data() + 4 * size_t(X);
        for (int k = 0; k < 4; ++k)
          if (nx[k] == t) nx[k] = Y;
      }
      talive_[t] = 0;
      --alive_t_;
      for (int k = 0; k < 4; ++k)
        if (q[k] != r) ring_remove(q[k], t);
    } else {
      q[local(q, r)] = s;
      ring_append(s, t);
    }
  }
  rlen_[r] = 0;
  valive_[r] = 0;
  --alive_v_;
  fwd_[r] = s;
  double* ps = points_->data() + 3 * size_t(s);
  ps[0] = p.x;
  ps[1] = p.y;
  ps[2] = p.z;
  if (dir & TCC_DIR_MIDPOINT)  // vertex fields follow the placement (collapse_compact.cl)
    for (Field& f : mesh_.vertex_fields)
      for (int c = 0; c < f.components; ++c) {
        double& x = f.values[size_t(s) * f.components + c];
        x = 0.5 * (x + f.values[size_t(r) * f.components + c]);
      }
  // Faces of S change only through s, and only when r or s is on S; a vertex off S stays off
  // S (see the header). A touched vertex u's class depends on its S-faces and their vertices'
  // positions: those faces change (are renamed to s, moved with s, glued) only where they hold s
  // now, or belonged to a removed tet. So s is classified again, then the vertices of its S-faces
  // (classify(s) lists them in sf_after_, sf_before_) and the vertices on S of the removed tets; every other
  // touched vertex keeps its class (verify_classes() checks it in the tests). When s's list
  // overflows, every touched vertex on S.
  if (on_s) {
    classify(s, vflags_[s], vclass_[s]);
    if (sf_after_.size() >= kMaxVertexSFaces) {
      for (int32_t u : touched_)
        if (valive_[u] && vflags_[u] && u != s) classify(u, vflags_[u], vclass_[u]);
    } else {
      reclass_.clear();
      reclass_.assign(sf_after_.begin(), sf_after_.end());
      reclass_.insert(reclass_.end(), sf_before_.begin(), sf_before_.end());
      reclass_.insert(reclass_.end(), gone_.begin(), gone_.end());
      const uint32_t st2 = next_stamp();
      mark_[s] = st2;
      for (int32_t u : reclass_)
        if (mark_[u] != st2) {
          mark_[u] = st2;
          if (valive_[u] && vflags_[u]) classify(u, vflags_[u], vclass_[u]);
        }
    }
  }
  // the S faces that changed (moved, renamed, or owned by another tet now) all contain s
  if (on_s && guard_on_) {
    const int32_t* rs = ring(s);
    for (uint32_t i = 0; i < rlen_[s]; ++i) {
      const int32_t* q = tet(rs[i]);
      for (int f = 0; f < 4; ++f)
        if (q[f] != s && owned_sface(rs[i], f)) guard_insert(rs[i], f);
    }
  }
  return s;
}

void SeqMesh::compact(std::vector<int32_t>& vmap, std::vector<int32_t>& kept) {
  vmap.assign(nv_, -1);
  kept.clear();
  int32_t n = 0;
  for (int32_t v = 0; v < nv_; ++v)
    if (valive_[v]) {
      vmap[v] = n++;
      kept.push_back(v);
    }
  for (int32_t v = 0; v < nv_; ++v) {
    if (valive_[v]) continue;
    int32_t x = v;
    while (!valive_[x]) x = fwd_[x];  // r -> s -> ... ends at a survivor
    vmap[v] = vmap[x];
  }
  // vertices and their data, in order (vmap[v] <= v: in place)
  std::vector<double>& pts = *points_;
  for (int32_t v = 0; v < nv_; ++v) {
    if (!valive_[v]) continue;
    const int32_t o = vmap[v];
    for (int c = 0; c < 3; ++c) pts[3 * size_t(o) + c] = pts[3 * size_t(v) + c];
    vflags_[o] = vflags_[v];
    vclass_[o] = vclass_[v];
  }
  pts.resize(3 * size_t(n));
  for (Field& f : mesh_.vertex_fields) {
    const size_t nc = size_t(f.components);
    for (int32_t v = 0; v < nv_; ++v)
      if (valive_[v])
        for (size_t c = 0; c < nc; ++c) f.values[size_t(vmap[v]) * nc + c] = f.values[size_t(v) * nc + c];
    f.values.resize(size_t(n) * nc);
  }
  // tets with their labels, fields and neighbours
  std::vector<int32_t>& tets = *tets_;
  std::vector<int32_t> tmap(nt_, -1);
  for (int32_t t = 0, m = 0; t < nt_; ++t)
    if (talive_[t]) tmap[t] = m++;
  int32_t m = 0;
  for (int32_t t = 0; t < nt_; ++t) {
    if (!talive_[t]) continue;
    for (int k = 0; k < 4; ++k) {
      tets[4 * size_t(m) + k] = vmap[tets[4 * size_t(t) + k]];
      const int32_t o = nbr_[4 * size_t(t) + k];
      nbr_[4 * size_t(m) + k] = o < 0 ? o : tmap[o];  // a live tet's neighbours are alive
    }
    for (Labels& l : mesh_.tet_labels) l.values[m] = l.values[t];
    for (Field& f : mesh_.tet_fields)
      for (int c = 0; c < f.components; ++c)
        f.values[size_t(m) * f.components + c] = f.values[size_t(t) * f.components + c];
    ++m;
  }
  tets.resize(4 * size_t(m));
  nbr_.resize(4 * size_t(m));
  // the guard's grid kept, its faces renumbered (those of removed tets dropped), unless the
  // collapses since it was built added more than half as many entries again (stale ones,
  // checked on use): then built again below
  const bool rebuild_guard = guard_on_ && 2 * gnodes_.size() > gbuilt_.size() + 1024;
  if (guard_on_ && !rebuild_guard) {
    auto renumber = [&](int32_t& e) {
      if (e >= 0) e = tmap[size_t(e >> 2)] < 0 ? -1 : 4 * tmap[size_t(e >> 2)] + (e & 3);
    };
    for (int32_t& e : gbuilt_) renumber(e);
    for (GuardNode& node : gnodes_) renumber(node.face);
    // the registrations follow their faces (a kept tet's new index is at most its old one)
    for (size_t t = 0; t < tmap.size(); ++t)
      if (tmap[t] >= 0)
        for (size_t f = 0; f < 4; ++f) gver_[4 * size_t(tmap[t]) + f] = gver_[4 * t + f];
    gver_.resize(4 * size_t(m));
    gseen_.assign(4 * size_t(m), 0);
    gstamp_ = 0;
  }
  for (Labels& l : mesh_.tet_labels) l.values.resize(m);
  for (Field& f : mesh_.tet_fields) f.values.resize(size_t(m) * f.components);

  nv_ = alive_v_ = n;
  nt_ = alive_t_ = m;
  valive_.assign(n, 1);
  talive_.assign(m, 1);
  fwd_.assign(n, -1);
  vflags_.resize(n);
  vclass_.resize(n);
  mark_.resize(n);  // stale stamps are all older than the next one
  lmark_.resize(n);
  rebuild_rings();
  if (rebuild_guard) build_guard(guard_h_req_);
}

// --- surface guard ---

int32_t SeqMesh::scan_across(int32_t t, int f) const {
  const int32_t* q = tet(t);
  int32_t p[3];
  int n = 0;
  for (int j = 0; j < 4; ++j)
    if (j != f) p[n++] = q[j];
  // every tet of the face is in the ring of each of its vertices: scan the shortest
  if (rlen_[p[1]] < rlen_[p[0]]) std::swap(p[0], p[1]);
  if (rlen_[p[2]] < rlen_[p[0]]) std::swap(p[0], p[2]);
  int count = 0;
  int32_t other = -1;
  const int32_t* r = ring(p[0]);
  for (uint32_t i = 0; i < rlen_[p[0]]; ++i) {
    const int32_t u = r[i];
    if (u != t && has(tet(u), p[1]) && has(tet(u), p[2])) {
      if (count == 0) other = u;
      ++count;
    }
  }
  return count == 0 ? -1 : count == 1 ? other : -2;
}

// nbr_ from scratch: every face matched by its smallest vertex v among the faces of ring(v) (a
// sort of their keys), as the device's conn_tet_neighbours does.
void SeqMesh::build_nbr() {
  nbr_.assign(4 * size_t(nt_), -1);
  for (int32_t v = 0; v < nv_; ++v) {
    faces_.clear();
    each_face_through(v, [&](int32_t t, const int32_t* q, int f, int lv) {
      int32_t o[2];
      int no = 0;
      for (int j = 0; j < 4; ++j)
        if (j != f && j != lv) o[no++] = q[j];
      if (o[0] < v || o[1] < v) return;  // v is not the face's smallest vertex
      const uint32_t y = uint32_t(std::min(o[0], o[1])), z = uint32_t(std::max(o[0], o[1]));
      faces_.push_back({uint64_t(y) << 32 | z, t, int8_t(f)});
    });
    std::sort(faces_.begin(), faces_.end(), [](const FaceAt& x, const FaceAt& y) { return x.key < y.key; });
    for (size_t i = 0; i < faces_.size();) {
      size_t j = i + 1;
      while (j < faces_.size() && faces_[j].key == faces_[i].key) ++j;
      for (size_t k = i; k < j; ++k)
        nbr_[4 * size_t(faces_[k].t) + size_t(faces_[k].f)] =
            j - i == 1 ? -1 : j - i == 2 ? faces_[k == i ? i + 1 : i].t : -2;
      i = j;
    }
  }
}

int64_t SeqMesh::verify_nbr() const {
  int64_t bad = 0;
  for (int32_t t = 0; t < nt_; ++t)
    if (talive_[t])
      for (int f = 0; f < 4; ++f) bad += nbr_[4 * size_t(t) + size_t(f)] != scan_across(t, f) ? 1 : 0;
  return bad;
}

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

uint8_t SeqMesh::owned_sface(int32_t t, int f, uint8_t* on_s) const {
  const int32_t o = across(t, f);
  uint8_t kind = 0, own = 0;
  if (o < 0) {  // no tet across, or several (an invalid input: boundary for each)
    kind = own = TCC_BOUNDARY;
  } else if (labels_ && label(t) != label(o)) {
    kind = TCC_INTERFACE;
    own = label(t) < label(o) ? TCC_INTERFACE : 0;
  }
  if (on_s) *on_s = kind;
  return own;
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
  for (int side = 0; side < 2; ++side) {
    const int32_t z = side == 0 ? x : y, w = side == 0 ? y : x;
    const int32_t* rz = ring(z);
    for (uint32_t i = 0; i < rlen_[z]; ++i) {
      const int32_t t = rz[i];
      const int32_t* q = tet(t);
      if (has(q, w)) continue;  // removed by the collapse, or seen from ring(x)
      for (int f = 0; f < 4; ++f) {
        if (q[f] == z) continue;  // the face opposite z does not contain it
        // a face taken below is on S now, or glued to one through a removed tet: either way its
        // two vertices other than z are on S now (cheap, and it spares most ring scans)
        bool others_on_s = true;
        for (int j = 0; j < 4 && others_on_s; ++j) others_on_s = j == f || q[j] == z || vflags_[q[j]] != 0;
        if (!others_on_s) continue;
        const int32_t o = across(t, f);
        bool take;
        if (o >= 0 && has(tet(o), x) && has(tet(o), y)) {  // glued through the removed tet o
          const int32_t ac = across(o, local(tet(o), z));
          take = ac < 0 || (labels_ && label(t) != label(ac));
        } else {
          if (side == 1 && !moves_y) continue;  // unchanged
          take = o < 0 || (labels_ && label(t) != label(o));
        }
        if (!take) continue;
        NewTri nt;
        for (int k = 0; k < 3; ++k) {
          int32_t v = q[geo::TC_TET_FACES[f][k]];
          if (v == x) v = y;
          nt.id[k] = v;
          nt.pos[k] = v == y ? p : point(v);
        }
        newtris_.push_back(nt);
      }
    }
  }
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
