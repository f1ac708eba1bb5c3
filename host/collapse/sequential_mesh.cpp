// The dynamic mesh of the sequential method: see sequential_mesh.hpp.
#include "collapse/sequential_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "collapse/stages.hpp"  // collapse_detail::Reason
#include "collapse_classify.h"  // the classification rules, the device's own
#include "collapse_predicate.h"
#include "tetcollapse/error.hpp"

namespace tc::sequential_detail {

using namespace collapse_detail;
using geo::tc_d3;

namespace {

// The list limit of the kernels, so that the verdicts agree even where it bites:
// TCC_MAX_VERTEX_SFACES (collapse_connectivity.cl). (The link test's, TCC_MAX_LINK, is
// cl/collapse_checks.h's own.)
constexpr size_t kMaxVertexSFaces = 64;
tc_d3 face_normal(const std::vector<double>& pts, const int32_t* q, int f) {
  tc_d3 p0 = geo::tc_point(pts.data(), q[geo::TC_TET_FACES[f][0]]);
  tc_d3 p1 = geo::tc_point(pts.data(), q[geo::TC_TET_FACES[f][1]]);
  tc_d3 p2 = geo::tc_point(pts.data(), q[geo::TC_TET_FACES[f][2]]);
  return geo::normalize(geo::cross(p1 - p0, p2 - p0));
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
  rebuild_rings();
  if (rebuild_guard) build_guard(guard_h_req_);
}

// --- tet neighbours and S-faces ---

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

}  // namespace tc::sequential_detail
