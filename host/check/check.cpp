// The validity and quality checker (see include/tetcollapse/check.hpp). Plain C++: the
// exact predicates and the surface algorithms are in exact.cpp and surface.cpp (CGAL).
//
// Face matching and edge enumeration sort integer keys (one radix sort pass per 11 bits)
// instead of using std::map or hashing: a 1M-tet mesh has 4M faces and 6M edge slots, and
// a linear-time sort of flat arrays is the fastest way to group them.
#include "tetcollapse/check.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <numeric>
#include <sstream>

#include "check/check_cgal.hpp"
#include "geometry.h"

namespace tc {

const CheckFinding* CheckReport::find(const std::string& code) const {
  for (const auto& f : findings)
    if (f.code == code) return &f;
  return nullptr;
}

namespace {

using check_detail::Soup;
constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = 180.0 / kPi;

// ------------------------------------------------------------------ small tools

class PhaseTimer {
 public:
  explicit PhaseTimer(std::vector<std::pair<std::string, double>>& out) : out_(out), t0_(now()) {}
  void lap(const char* name) {
    double t = now();
    out_.emplace_back(name, t - t0_);
    t0_ = t;
  }

 private:
  static double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  }
  std::vector<std::pair<std::string, double>>& out_;
  double t0_;
};

// Collects one kind of finding: counts every offender, keeps the first few.
class FindingBuilder {
 public:
  FindingBuilder(Severity s, std::string code, std::string what, int max_offenders)
      : max_(std::max(0, max_offenders)), what_(std::move(what)) {
    f_.severity = s;
    f_.code = std::move(code);
  }
  void add(std::vector<int64_t> tuple, std::string description) {
    ++f_.count;
    if (int64_t(f_.offenders.size()) < max_) {
      f_.offenders.push_back(std::move(tuple));
      names_.push_back(std::move(description));
    }
  }
  bool wants_more() const { return int64_t(f_.offenders.size()) < max_; }
  int64_t count() const { return f_.count; }
  // Adds the finding to the report when there was any offender.
  void finish(CheckReport& r) {
    if (f_.count == 0) return;
    std::ostringstream m;
    m << f_.code << ": " << f_.count << " " << what_;
    if (!names_.empty()) {
      m << "; first: ";
      for (size_t i = 0; i < names_.size(); ++i) m << (i ? ", " : "") << names_[i];
    }
    f_.message = m.str();
    push(r, std::move(f_));
  }
  static void push(CheckReport& r, CheckFinding f) {
    if (f.severity == Severity::Error) {
      r.valid = false;
      r.errors.push_back(f.message);
    } else {
      r.warnings.push_back(f.message);
    }
    r.findings.push_back(std::move(f));
  }

 private:
  int64_t max_;
  std::string what_;
  CheckFinding f_;
  std::vector<std::string> names_;
};

void add_simple(CheckReport& r, Severity s, const std::string& code, const std::string& message) {
  CheckFinding f;
  f.severity = s;
  f.code = code;
  f.count = 1;
  f.message = code + ": " + message;
  FindingBuilder::push(r, std::move(f));
}

// LSD radix sort of records by an unsigned 64-bit key (11 bits per pass, only as many
// passes as the largest key needs). Stable.
template <class T, class KeyFn>
void radix_sort(std::vector<T>& v, KeyFn key) {
  uint64_t maxkey = 0;
  for (const T& x : v) maxkey = std::max<uint64_t>(maxkey, key(x));
  int bits = 0;
  while (bits < 64 && (maxkey >> bits) != 0) ++bits;
  if (v.size() < 2 || bits == 0) return;
  constexpr int kDigit = 11;
  constexpr size_t kBuckets = size_t(1) << kDigit;
  std::vector<T> tmp(v.size());
  std::vector<size_t> count(kBuckets);
  for (int shift = 0; shift < bits; shift += kDigit) {
    std::fill(count.begin(), count.end(), 0);
    for (const T& x : v) ++count[(key(x) >> shift) & (kBuckets - 1)];
    size_t sum = 0;
    for (auto& c : count) {
      size_t n = c;
      c = sum;
      sum += n;
    }
    for (const T& x : v) tmp[count[(key(x) >> shift) & (kBuckets - 1)]++] = x;
    v.swap(tmp);
  }
}

struct UnionFind {
  std::vector<int64_t> parent;
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), int64_t(0)); }
  int64_t find(int64_t x) {
    while (parent[x] != x) {
      parent[x] = parent[parent[x]];
      x = parent[x];
    }
    return x;
  }
  void unite(int64_t a, int64_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

Stats stats_of(std::vector<double>& values) {  // reorders values
  Stats s;
  s.count = int64_t(values.size());
  if (values.empty()) return s;
  double sum = 0, lo = values[0], hi = values[0];
  for (double x : values) {
    sum += x;
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  s.min = lo;
  s.max = hi;
  s.mean = sum / double(values.size());
  auto mid = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), mid, values.end());
  s.median = *mid;
  return s;
}

Histogram histogram_of(const std::string& name, const std::vector<double>& values, double lo, double hi, int bins) {
  Histogram h;
  h.name = name;
  h.lo = lo;
  h.hi = hi;
  h.counts.assign(size_t(std::max(1, bins)), 0);
  const double scale = double(h.counts.size()) / (hi - lo);
  for (double x : values) {
    if (!std::isfinite(x)) continue;
    double b = std::floor((x - lo) * scale);
    int64_t i = b < 0 ? 0 : b >= double(h.counts.size()) ? int64_t(h.counts.size()) - 1 : int64_t(b);
    ++h.counts[size_t(i)];
  }
  return h;
}

std::string tets_str(int64_t a) { return "tet " + std::to_string(a); }

std::string num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", x);
  return buf;
}

// ------------------------------------------------------------------ the analysis

// What the reference comparison needs from one mesh besides its report.
struct Extra {
  Soup boundary_soup;  // pinched vertices split; empty when the surface is not a valid halfedge mesh
  bool soup_ok = false;
};

struct Analysis {
  Analysis(const Mesh& mesh, const CheckOptions& o, CheckReport& report, Extra& e, bool q, bool si)
      : m(mesh), opt(o), r(report), extra(e), want_quality(q), want_self_intersection(si) {}
  const Mesh& m;
  const CheckOptions& opt;
  CheckReport& r;
  Extra& extra;
  bool want_quality, want_self_intersection;

  int64_t nv = 0, nt = 0;
  std::vector<uint8_t> unusable;  // per tet: indices out of range or repeated vertex
  std::vector<int8_t> sign;       // exact orientation per tet
  std::vector<int32_t> btris;     // boundary triangles, oriented out of their tet
  std::vector<int64_t> btri_tet;  // (tet << 2) | local face of each boundary triangle
  bool surface_ok = true;         // boundary edge-manifold, closed, consistently oriented
  std::vector<std::array<int64_t, 2>> edge_pairs;  // for pinch splitting: (corner, corner) pairs

  geo::tc_d3 P(int64_t v) const { return geo::tc_point(m.points.data(), int(v)); }

  void structure();
  void orientation();
  void faces();
  void boundary();
  void self_intersection();
  void duplicate_vertices();
  void quality();
  void run();
};

void Analysis::structure() {
  nv = m.num_vertices();
  nt = m.num_tets();
  r.vertices = nv;
  r.tets = nt;
  if (m.points.size() % 3 != 0)
    add_simple(r, Severity::Error, "malformed_arrays", "points has " + std::to_string(m.points.size()) + " values, not a multiple of 3");
  if (m.tets.size() % 4 != 0)
    add_simple(r, Severity::Error, "malformed_arrays", "tets has " + std::to_string(m.tets.size()) + " values, not a multiple of 4");

  FindingBuilder nonfinite(Severity::Error, "non_finite_coordinate", "vertices with a NaN or infinite coordinate", opt.max_offenders);
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (int64_t v = 0; v < nv; ++v) {
    bool finite = true;
    for (int a = 0; a < 3; ++a) {
      double x = m.points[3 * v + a];
      if (!std::isfinite(x)) {
        finite = false;
        continue;
      }
      lo[a] = std::min(lo[a], x);
      hi[a] = std::max(hi[a], x);
    }
    if (!finite) nonfinite.add({v}, "vertex " + std::to_string(v));
  }
  nonfinite.finish(r);
  if (nv > 0 && lo[0] <= hi[0]) {
    double d2 = 0;
    for (int a = 0; a < 3; ++a) {
      r.bbox_min[a] = lo[a];
      r.bbox_max[a] = hi[a];
      d2 += (hi[a] - lo[a]) * (hi[a] - lo[a]);
    }
    r.bbox_diagonal = std::sqrt(d2);
  }
  std::vector<uint8_t> bad_vertex(size_t(nv), 0);
  for (int64_t v = 0; v < nv; ++v)
    for (int a = 0; a < 3; ++a)
      if (!std::isfinite(m.points[3 * v + a])) bad_vertex[size_t(v)] = 1;

  FindingBuilder range(Severity::Error, "index_out_of_range", "tet corners with a vertex index out of range", opt.max_offenders);
  FindingBuilder repeated(Severity::Error, "repeated_vertex", "tets repeating a vertex", opt.max_offenders);
  FindingBuilder unref(Severity::Warning, "unreferenced_vertex", "vertices used by no tet", opt.max_offenders);
  unusable.assign(size_t(nt), 0);
  std::vector<uint8_t> used(size_t(nv), 0);
  for (int64_t t = 0; t < nt; ++t) {
    const int32_t* v = &m.tets[4 * t];
    bool in_range = true;
    for (int c = 0; c < 4; ++c) {
      if (v[c] < 0 || v[c] >= nv) {
        in_range = false;
        range.add({t, c, v[c]}, "tet " + std::to_string(t) + " corner " + std::to_string(c) + " = " + std::to_string(v[c]));
      } else {
        used[size_t(v[c])] = 1;
      }
    }
    if (!in_range) {
      unusable[size_t(t)] = 1;
      continue;
    }
    if (v[0] == v[1] || v[0] == v[2] || v[0] == v[3] || v[1] == v[2] || v[1] == v[3] || v[2] == v[3]) {
      unusable[size_t(t)] = 1;
      repeated.add({t}, tets_str(t));
      continue;
    }
    for (int c = 0; c < 4; ++c)
      if (bad_vertex[size_t(v[c])]) unusable[size_t(t)] = 1;  // already reported as non-finite
  }
  int64_t referenced = 0;
  for (int64_t v = 0; v < nv; ++v) {
    if (used[size_t(v)]) ++referenced;
    else unref.add({v}, "vertex " + std::to_string(v));
  }
  r.referenced_vertices = referenced;
  range.finish(r);
  repeated.finish(r);
  unref.finish(r);
}

void Analysis::orientation() {
  check_detail::exact_orientation(m.points, m.tets, unusable, sign);
  FindingBuilder inv(Severity::Error, "inverted_tet", "tets with negative orientation (exact)", opt.max_offenders);
  FindingBuilder flat(Severity::Error, "flat_tet", "tets with zero volume (exact)", opt.max_offenders);
  double small_below = opt.eps_volume;
  if (!opt.eps_volume_absolute) {  // x the mean tet volume, as the collapse's threshold
    const double mean = mean_tet_volume(m, &unusable);
    small_below *= mean > 0 ? mean : 1.0;
  }
  FindingBuilder small(opt.small_volume_is_error ? Severity::Error : Severity::Warning, "small_volume",
                       "positive tets with volume below " + num(small_below), opt.max_offenders);
  double total = 0, minv = INFINITY;
  for (int64_t t = 0; t < nt; ++t) {
    if (unusable[size_t(t)]) continue;
    const int32_t* v = &m.tets[4 * t];
    double vol = geo::tc_tet_volume(P(v[0]), P(v[1]), P(v[2]), P(v[3]));
    total += vol;
    minv = std::min(minv, vol);
    if (sign[size_t(t)] < 0) inv.add({t}, tets_str(t));
    else if (sign[size_t(t)] == 0) flat.add({t}, tets_str(t));
    else if (vol < small_below) small.add({t}, tets_str(t));
  }
  r.volume = total;
  r.min_volume = std::isfinite(minv) ? minv : NAN;
  r.inverted_tets = inv.count();
  r.flat_tets = flat.count();
  r.small_volume_tets = small.count();
  inv.finish(r);
  flat.finish(r);
  small.finish(r);
}

// Key of a triangle: its sorted vertices. Payload: tet, local face, parity of the sort.
struct Face64 {
  uint64_t key;
  uint64_t code;  // (tet << 3) | (face << 1) | parity
};
struct Face128 {
  unsigned __int128 key;
  uint64_t code;
};

// Sorts three vertices; returns 1 when an odd permutation was needed.
inline int sort3(int32_t& a, int32_t& b, int32_t& c) {
  int p = 0;
  if (a > b) std::swap(a, b), p ^= 1;
  if (b > c) std::swap(b, c), p ^= 1;
  if (a > b) std::swap(a, b), p ^= 1;
  return p;
}

void Analysis::faces() {
  // Collect the four outward faces of every usable tet.
  int bitsv = 1;
  while (bitsv < 31 && (int64_t(1) << bitsv) < nv) ++bitsv;
  const bool narrow = 3 * bitsv <= 64;
  std::vector<Face64> f64;
  std::vector<Face128> f128;
  int64_t nf = 0;
  for (int64_t t = 0; t < nt; ++t) nf += unusable[size_t(t)] ? 0 : 4;
  (narrow ? (void)f64.reserve(size_t(nf)) : (void)f128.reserve(size_t(nf)));
  for (int64_t t = 0; t < nt; ++t) {
    if (unusable[size_t(t)]) continue;
    const int32_t* v = &m.tets[4 * t];
    for (int f = 0; f < 4; ++f) {
      int32_t a = v[geo::TC_TET_FACES[f][0]], b = v[geo::TC_TET_FACES[f][1]], c = v[geo::TC_TET_FACES[f][2]];
      int p = sort3(a, b, c);
      uint64_t code = (uint64_t(t) << 3) | (uint64_t(f) << 1) | uint64_t(p);
      if (narrow)
        f64.push_back({(uint64_t(a) << (2 * bitsv)) | (uint64_t(b) << bitsv) | uint64_t(c), code});
      else
        f128.push_back({(static_cast<unsigned __int128>(uint64_t(a)) << 64) | (uint64_t(b) << 32) | uint64_t(c), code});
    }
  }
  if (narrow) radix_sort(f64, [](const Face64& x) { return x.key; });
  else std::sort(f128.begin(), f128.end(), [](const Face128& x, const Face128& y) { return x.key < y.key; });

  FindingBuilder many(Severity::Error, "face_in_many_tets", "faces in more than two tets", opt.max_offenders);
  FindingBuilder same(Severity::Error, "face_same_orientation", "faces shared by two tets in the same orientation", opt.max_offenders);
  FindingBuilder dup(Severity::Error, "duplicate_tet", "pairs of tets on the same four vertices", opt.max_offenders);
  auto sorted_tet = [&](int64_t t) {
    std::array<int32_t, 4> s{m.tets[4 * t], m.tets[4 * t + 1], m.tets[4 * t + 2], m.tets[4 * t + 3]};
    std::sort(s.begin(), s.end());
    return s;
  };
  auto code_at = [&](size_t i) { return narrow ? f64[i].code : f128[i].code; };
  auto same_key = [&](size_t i, size_t j) { return narrow ? f64[i].key == f64[j].key : f128[i].key == f128[j].key; };
  auto face_verts = [&](uint64_t code) {
    int64_t t = int64_t(code >> 3);
    int f = int((code >> 1) & 3);
    const int32_t* v = &m.tets[4 * t];
    std::array<int32_t, 3> o{v[geo::TC_TET_FACES[f][0]], v[geo::TC_TET_FACES[f][1]], v[geo::TC_TET_FACES[f][2]]};
    return o;
  };
  auto face_name = [](const std::array<int32_t, 3>& s) {
    return "face (" + std::to_string(s[0]) + ", " + std::to_string(s[1]) + ", " + std::to_string(s[2]) + ")";
  };

  const size_t n = size_t(nf);
  int64_t interior = 0;
  for (size_t i = 0; i < n;) {
    size_t j = i + 1;
    while (j < n && same_key(i, j)) ++j;
    const size_t k = j - i;
    const uint64_t c0 = code_at(i);
    if (k == 1) {
      auto o = face_verts(c0);
      btris.insert(btris.end(), o.begin(), o.end());
      btri_tet.push_back(int64_t(c0 >> 1));
    } else {
      auto s = face_verts(c0);
      std::sort(s.begin(), s.end());
      if (k == 2) {
        ++interior;
        if ((c0 & 1) == (code_at(i + 1) & 1)) {
          int64_t ta = int64_t(c0 >> 3), tb = int64_t(code_at(i + 1) >> 3);
          same.add({s[0], s[1], s[2], ta, tb}, face_name(s) + " in tets " + std::to_string(ta) + " and " + std::to_string(tb));
        }
      } else {
        std::vector<int64_t> tuple{s[0], s[1], s[2]};
        std::string name = face_name(s) + " in tets";
        for (size_t q = i; q < j; ++q) {
          tuple.push_back(int64_t(code_at(q) >> 3));
          name += (q == i ? " " : ", ") + std::to_string(code_at(q) >> 3);
        }
        many.add(std::move(tuple), name);
      }
      // Duplicate tets share all four faces; each pair is reported at the face made of
      // its three smallest vertices. Groups are tiny unless the mesh is badly broken, so
      // comparing within a group is bounded by checking at most 32 members.
      const size_t lim = std::min<size_t>(j, i + 32);
      for (size_t a = i; a < lim; ++a) {
        int64_t ta = int64_t(code_at(a) >> 3);
        auto sa = sorted_tet(ta);
        if (sa[0] != s[0] || sa[1] != s[1] || sa[2] != s[2]) continue;
        for (size_t b = a + 1; b < lim; ++b) {
          int64_t tb = int64_t(code_at(b) >> 3);
          if (sorted_tet(tb) == sa)
            dup.add({std::min(ta, tb), std::max(ta, tb)}, "tets " + std::to_string(std::min(ta, tb)) + " and " + std::to_string(std::max(ta, tb)));
        }
      }
    }
    i = j;
  }
  r.interior_faces = interior;
  r.boundary_faces = int64_t(btri_tet.size());
  dup.finish(r);
  many.finish(r);
  same.finish(r);
}

void Analysis::boundary() {
  const int64_t nb = int64_t(btri_tet.size());
  // Half-edges of the boundary: key = (min, max) vertex pair, payload = corner and direction.
  struct HalfEdge {
    uint64_t key;
    uint64_t code;  // (triangle * 3 + k) << 1 | reversed, edge k runs corner k -> corner k+1
  };
  std::vector<HalfEdge> he;
  he.reserve(size_t(3 * nb));
  double enclosed = 0;
  for (int64_t f = 0; f < nb; ++f) {
    const int32_t* t = &btris[3 * f];
    enclosed += geo::dot(P(t[0]), geo::cross(P(t[1]), P(t[2]))) / 6.0;
    for (int k = 0; k < 3; ++k) {
      uint32_t a = uint32_t(t[k]), b = uint32_t(t[(k + 1) % 3]);
      bool rev = a > b;
      if (rev) std::swap(a, b);
      he.push_back({(uint64_t(a) << 32) | b, (uint64_t(3 * f + k) << 1) | uint64_t(rev)});
    }
  }
  r.boundary_volume = enclosed;
  radix_sort(he, [](const HalfEdge& x) { return x.key; });

  FindingBuilder open(Severity::Error, "boundary_open_edge", "boundary edges in a single boundary triangle (surface not closed)", opt.max_offenders);
  FindingBuilder nonman(Severity::Error, "boundary_nonmanifold_edge", "boundary edges in more than two boundary triangles", opt.max_offenders);
  FindingBuilder orient(Severity::Error, "boundary_orientation", "boundary edges run in the same direction by both their triangles", opt.max_offenders);
  UnionFind tri_uf{size_t(nb)};
  int64_t edges = 0;
  auto edge_name = [](uint64_t key) {
    return "edge (" + std::to_string(key >> 32) + ", " + std::to_string(key & 0xffffffffu) + ")";
  };
  for (size_t i = 0; i < he.size();) {
    size_t j = i + 1;
    while (j < he.size() && he[j].key == he[i].key) ++j;
    ++edges;
    const uint64_t key = he[i].key;
    const int64_t u = int64_t(key >> 32), v = int64_t(key & 0xffffffffu);
    for (size_t q = i + 1; q < j; ++q) tri_uf.unite(int64_t(he[i].code >> 1) / 3, int64_t(he[q].code >> 1) / 3);
    if (j - i == 1) {
      open.add({u, v}, edge_name(key));
    } else if (j - i > 2) {
      nonman.add({u, v, int64_t(j - i)}, edge_name(key) + " in " + std::to_string(j - i) + " triangles");
    } else if ((he[i].code & 1) == (he[i + 1].code & 1)) {
      orient.add({u, v}, edge_name(key));
    } else {
      // A manifold edge: the corners at u in both triangles are one umbrella, same at v.
      int64_t ca = int64_t(he[i].code >> 1), cb = int64_t(he[i + 1].code >> 1);
      // Half-edge corner k runs k -> k+1; the other end is corner (k+1)%3 of that triangle.
      auto next = [](int64_t c) { return c - c % 3 + (c % 3 + 1) % 3; };
      // Triangle a runs x->y, b runs y->x: corner ca (at x) pairs with next(cb) (at x).
      edge_pairs.push_back({ca, next(cb)});
      edge_pairs.push_back({next(ca), cb});
    }
    i = j;
  }
  surface_ok = open.count() == 0 && nonman.count() == 0 && orient.count() == 0;
  open.finish(r);
  nonman.finish(r);
  orient.finish(r);

  // Topology: vertices, edges, faces, components (through edges), Euler characteristic.
  std::vector<uint8_t> on_boundary(size_t(nv), 0);
  int64_t bverts = 0;
  for (int32_t v : btris)
    if (!on_boundary[size_t(v)]) on_boundary[size_t(v)] = 1, ++bverts;
  int64_t comps = 0;
  for (int64_t f = 0; f < nb; ++f)
    if (tri_uf.find(f) == f) ++comps;
  r.boundary.vertices = bverts;
  r.boundary.edges = edges;
  r.boundary.faces = nb;
  r.boundary.components = comps;
  r.boundary.euler = bverts - edges + nb;

  // Split pinched vertices: corners joined through manifold edges form one umbrella each;
  // each umbrella becomes its own point of the soup.
  UnionFind corner_uf{size_t(3 * nb)};
  for (const auto& p : edge_pairs) corner_uf.unite(p[0], p[1]);
  edge_pairs.clear();
  edge_pairs.shrink_to_fit();
  std::vector<int32_t> point_of_root(size_t(3 * nb), -1);
  std::vector<int32_t> umbrellas(size_t(nv), 0);
  Soup& soup = extra.boundary_soup;
  soup = Soup{};
  soup.tris.resize(size_t(3 * nb));
  for (int64_t c = 0; c < 3 * nb; ++c) {
    int64_t root = corner_uf.find(c);
    int32_t& p = point_of_root[size_t(root)];
    if (p < 0) {
      int32_t v = btris[size_t(c)];
      p = int32_t(soup.origin.size());
      soup.origin.push_back(v);
      soup.points.insert(soup.points.end(), &m.points[3 * size_t(v)], &m.points[3 * size_t(v)] + 3);
      ++umbrellas[size_t(v)];
    }
    soup.tris[size_t(c)] = p;
  }
  FindingBuilder pinched(Severity::Warning, "boundary_nonmanifold_vertex", "boundary vertices where separate sheets of the surface touch", opt.max_offenders);
  for (int64_t v = 0; v < nv; ++v)
    if (umbrellas[size_t(v)] > 1) pinched.add({v, umbrellas[size_t(v)]}, "vertex " + std::to_string(v) + " (" + std::to_string(umbrellas[size_t(v)]) + " umbrellas)");
  r.boundary.nonmanifold_vertices = pinched.count();
  pinched.finish(r);
  extra.soup_ok = surface_ok;
}

void Analysis::self_intersection() {
  if (!extra.soup_ok) {
    add_simple(r, Severity::Warning, "self_intersection_skipped",
               "the boundary is not a closed, consistently oriented, edge-manifold surface; self-intersection not tested");
    return;
  }
  constexpr int64_t kMaxPairs = 100000;
  auto si = check_detail::self_intersections(extra.boundary_soup, kMaxPairs);
  if (!si.ran) {
    add_simple(r, Severity::Warning, "self_intersection_skipped", si.why_not);
    return;
  }
  r.self_intersection_checked = true;
  FindingBuilder b(Severity::Error, "boundary_self_intersection",
                   si.capped ? "(at least) pairs of intersecting boundary triangles" : "pairs of intersecting boundary triangles",
                   opt.max_offenders);
  const Soup& s = extra.boundary_soup;
  for (const auto& [fa, fb] : si.pairs) {
    // Triangles that only touch at a pinched vertex (split apart in the soup) are fine.
    // PMP judges triangles sharing a soup point correctly; a pair that shares a vertex of
    // the mesh only through split copies touches there by construction, so it is skipped.
    bool share_origin = false, share_point = false;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        int32_t pa = s.tris[3 * fa + i], pb = s.tris[3 * fb + j];
        share_point = share_point || pa == pb;
        share_origin = share_origin || s.origin[size_t(pa)] == s.origin[size_t(pb)];
      }
    if (share_origin && !share_point) continue;
    int64_t ca = std::min(btri_tet[size_t(fa)], btri_tet[size_t(fb)]), cb = std::max(btri_tet[size_t(fa)], btri_tet[size_t(fb)]);
    b.add({ca >> 2, ca & 3, cb >> 2, cb & 3}, "tet " + std::to_string(ca >> 2) + " face " + std::to_string(ca & 3) + " and tet " +
                                                  std::to_string(cb >> 2) + " face " + std::to_string(cb & 3));
  }
  r.self_intersections = b.count();
  b.finish(r);
}

// Vertices within duplicate_tol on every axis. Sorting by x and sweeping a window is
// quadratic when many vertices share an x (axis-aligned planar faces), so the sweep
// recurses: runs of vertices chained by x-gaps below tol are split again by y, then by z,
// and only the final z-window compares pairs.
void Analysis::duplicate_vertices() {
  FindingBuilder dup(Severity::Error, "duplicate_vertices", "pairs of vertices closer than " + num(opt.duplicate_tol) + " on every axis", opt.max_offenders);
  const double tol = opt.duplicate_tol;
  std::vector<int32_t> idx;
  idx.reserve(size_t(nv));
  for (int64_t v = 0; v < nv; ++v) {
    const double* p = &m.points[3 * v];
    if (std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2])) idx.push_back(int32_t(v));
  }
  const double* X = m.points.data();
  auto close = [&](int32_t a, int32_t b) {
    for (int ax = 0; ax < 3; ++ax)
      if (!(std::fabs(X[3 * size_t(a) + ax] - X[3 * size_t(b) + ax]) < tol)) return false;
    return true;
  };
  std::vector<std::pair<int32_t, int32_t>> pairs;
  // (begin, end, axis) ranges still to process.
  std::vector<std::array<size_t, 3>> work{{0, idx.size(), 0}};
  while (!work.empty()) {
    auto [b, e, ax] = work.back();
    work.pop_back();
    std::sort(idx.begin() + long(b), idx.begin() + long(e), [&](int32_t p, int32_t q) {
      double xp = X[3 * size_t(p) + ax], xq = X[3 * size_t(q) + ax];
      return xp < xq || (xp == xq && p < q);
    });
    if (ax == 2) {
      for (size_t i = b; i < e; ++i)
        for (size_t j = i + 1; j < e && X[3 * size_t(idx[j]) + 2] - X[3 * size_t(idx[i]) + 2] < tol; ++j)
          if (close(idx[i], idx[j])) pairs.emplace_back(std::min(idx[i], idx[j]), std::max(idx[i], idx[j]));
      continue;
    }
    for (size_t i = b; i < e;) {
      size_t j = i + 1;
      while (j < e && X[3 * size_t(idx[j]) + ax] - X[3 * size_t(idx[j - 1]) + ax] < tol) ++j;
      if (j - i > 1) work.push_back({i, j, ax + 1});
      i = j;
    }
  }
  std::sort(pairs.begin(), pairs.end());
  for (const auto& [a, b] : pairs)
    dup.add({a, b}, "vertices " + std::to_string(a) + " and " + std::to_string(b));
  dup.finish(r);
}

// Conformal AMIPS energy ||J||_F^2 / (3 det(J)^(2/3)) of the map from the regular tet of
// unit edges to (p0, p1, p2, p3); 1 for a regular tet, +inf when not positive.
double amips(geo::tc_d3 p0, geo::tc_d3 p1, geo::tc_d3 p2, geo::tc_d3 p3) {
  // Inverse of the regular tet's edge matrix W = [e1 e2 e3] with
  // e1 = (1,0,0), e2 = (1/2, sqrt3/2, 0), e3 = (1/2, sqrt3/6, sqrt(2/3)).
  static const double Wi[3][3] = {{1.0, -1.0 / std::sqrt(3.0), -1.0 / std::sqrt(6.0)},
                                  {0.0, 2.0 / std::sqrt(3.0), -1.0 / std::sqrt(6.0)},
                                  {0.0, 0.0, std::sqrt(3.0 / 2.0)}};
  geo::tc_d3 d[3] = {p1 - p0, p2 - p0, p3 - p0};
  double J[3][3];  // J = D * Wi, D has columns d[k]
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double s = 0;
      for (int k = 0; k < 3; ++k) {
        double dik = i == 0 ? d[k].x : i == 1 ? d[k].y : d[k].z;
        s += dik * Wi[k][j];
      }
      J[i][j] = s;
    }
  double det = J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) - J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
               J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
  if (!(det > 0)) return INFINITY;
  double f2 = 0;
  for (auto& row : J)
    for (double x : row) f2 += x * x;
  return f2 / (3.0 * std::cbrt(det * det));
}

// 3 * inradius / circumradius (1 for a regular tet, 0 when flat or inverted).
double radius_ratio(geo::tc_d3 p0, geo::tc_d3 p1, geo::tc_d3 p2, geo::tc_d3 p3) {
  geo::tc_d3 a = p1 - p0, b = p2 - p0, c = p3 - p0;
  double det = geo::dot(a, geo::cross(b, c));  // 6 V
  if (!(det > 0)) return 0.0;
  double area = geo::length(geo::cross(a, b)) + geo::length(geo::cross(a, c)) + geo::length(geo::cross(b, c)) +
                geo::length(geo::cross(p2 - p1, p3 - p1));  // 2 x total face area
  double inr = det / area;                                   // 3V / A
  geo::tc_d3 num = geo::cross(b, c) * geo::dot(a, a) + geo::cross(c, a) * geo::dot(b, b) + geo::cross(a, b) * geo::dot(c, c);
  double circ = geo::length(num) / (2.0 * det);
  return circ > 0 ? 3.0 * inr / circ : 0.0;
}

void Analysis::quality() {
  QualityReport& q = r.quality;
  q.computed = true;
  std::vector<double> mind, maxd, rr, am, mr, all;
  mind.reserve(size_t(nt));
  maxd.reserve(size_t(nt));
  rr.reserve(size_t(nt));
  am.reserve(size_t(nt));
  mr.reserve(size_t(nt));
  all.reserve(size_t(6 * nt));
  FindingBuilder gate(Severity::Error, "min_dihedral_gate",
                      "tets with a dihedral angle below " + num(opt.min_dihedral_gate_deg) + " degrees", opt.max_offenders);
  for (int64_t t = 0; t < nt; ++t) {
    if (unusable[size_t(t)]) continue;
    const int32_t* v = &m.tets[4 * t];
    geo::tc_d3 p[4] = {P(v[0]), P(v[1]), P(v[2]), P(v[3])};
    double lo = INFINITY, hi = -INFINITY;
    for (const auto& e : geo::TC_TET_EDGES) {
      int o[2], k = 0;
      for (int c = 0; c < 4; ++c)
        if (c != e[0] && c != e[1]) o[k++] = c;
      double ang = geo::tc_dihedral_angle(p[e[0]], p[e[1]], p[o[0]], p[o[1]]) * kDeg;
      all.push_back(ang);
      lo = std::min(lo, ang);
      hi = std::max(hi, ang);
    }
    mind.push_back(lo);
    maxd.push_back(hi);
    q.below_5_deg += lo < 5;
    q.below_10_deg += lo < 10;
    q.below_13_deg += lo < 13;
    if (opt.min_dihedral_gate_deg >= 0 && lo < opt.min_dihedral_gate_deg) gate.add({t}, tets_str(t));
    rr.push_back(radius_ratio(p[0], p[1], p[2], p[3]));
    double e = amips(p[0], p[1], p[2], p[3]);
    if (std::isfinite(e)) am.push_back(e);
    mr.push_back(geo::tc_tet_quality(p[0], p[1], p[2], p[3]));
  }
  q.tets = int64_t(mind.size());
  const int bins = opt.histogram_bins;
  q.histograms.push_back(histogram_of("min_dihedral_deg", mind, 0, 90, bins));
  q.histograms.push_back(histogram_of("max_dihedral_deg", maxd, 0, 180, bins));
  q.histograms.push_back(histogram_of("radius_ratio", rr, 0, 1, bins));
  q.histograms.push_back(histogram_of("mean_ratio", mr, 0, 1, bins));
  q.min_dihedral_deg = stats_of(mind);
  q.max_dihedral_deg = stats_of(maxd);
  if (!all.empty()) {
    auto mid = all.begin() + long(all.size() / 2);
    std::nth_element(all.begin(), mid, all.end());
    q.median_dihedral_deg = *mid;
  }
  all = {};
  q.radius_ratio = stats_of(rr);
  q.amips = stats_of(am);
  q.mean_ratio = stats_of(mr);

  // Unique edges: sort the six (min, max) keys of every tet.
  std::vector<uint64_t> ek;
  ek.reserve(size_t(6 * q.tets));
  for (int64_t t = 0; t < nt; ++t) {
    if (unusable[size_t(t)]) continue;
    const int32_t* v = &m.tets[4 * t];
    for (const auto& e : geo::TC_TET_EDGES) {
      uint32_t a = uint32_t(v[e[0]]), b = uint32_t(v[e[1]]);
      if (a > b) std::swap(a, b);
      ek.push_back((uint64_t(a) << 32) | b);
    }
  }
  radix_sort(ek, [](uint64_t x) { return x; });
  ek.erase(std::unique(ek.begin(), ek.end()), ek.end());
  std::vector<double> len;
  len.reserve(ek.size());
  for (uint64_t k : ek) len.push_back(geo::length(P(int64_t(k >> 32)) - P(int64_t(k & 0xffffffffu))));
  q.edge_length = stats_of(len);
  gate.finish(r);
}

void Analysis::run() {
  PhaseTimer timer(r.timings);
  structure();
  timer.lap("structure");
  orientation();
  timer.lap("orientation");
  faces();
  timer.lap("faces");
  boundary();
  timer.lap("boundary");
  if (want_self_intersection) {
    self_intersection();
    timer.lap("self_intersection");
  }
  duplicate_vertices();
  timer.lap("duplicate_vertices");
  if (want_quality) {
    quality();
    timer.lap("quality");
  }
}

// Volume per primary label (the first label array when it has one value per tet).
std::map<int32_t, double> label_volumes(const Mesh& m) {
  std::map<int32_t, double> out;
  if (m.tet_labels.empty() || int64_t(m.tet_labels[0].values.size()) != m.num_tets()) return out;
  const int64_t nv = m.num_vertices();
  for (int64_t t = 0; t < m.num_tets(); ++t) {
    const int32_t* v = &m.tets[4 * t];
    bool ok = true;
    for (int c = 0; c < 4; ++c) ok = ok && v[c] >= 0 && v[c] < nv;
    if (!ok) continue;
    auto P = [&](int c) { return geo::tc_point(m.points.data(), v[c]); };
    out[m.tet_labels[0].values[size_t(t)]] += geo::tc_tet_volume(P(0), P(1), P(2), P(3));
  }
  return out;
}

void compare(const Mesh& mesh, const Mesh& ref, const CheckOptions& opt, CheckReport& r, const Extra& mine) {
  PhaseTimer timer(r.timings);
  CheckOptions ro = opt;
  ro.quality = false;
  ro.self_intersection = false;
  ro.hausdorff = false;
  ro.min_dihedral_gate_deg = -1;
  CheckReport rr;
  Extra theirs;
  {
    Analysis a(ref, ro, rr, theirs, false, false);
    a.run();
  }
  timer.lap("reference_check");
  r.has_reference = true;
  ReferenceComparison& c = r.reference;
  c.reference_vertices = rr.vertices;
  c.reference_tets = rr.tets;
  c.tet_reduction = rr.tets > 0 ? 1.0 - double(r.tets) / double(rr.tets) : 0.0;
  c.vertex_reduction = rr.vertices > 0 ? 1.0 - double(r.vertices) / double(rr.vertices) : 0.0;
  c.volume = r.volume;
  c.reference_volume = rr.volume;
  c.volume_change = r.volume - rr.volume;
  c.volume_change_rel = rr.volume != 0 ? c.volume_change / rr.volume : NAN;
  c.reference_boundary = rr.boundary;
  c.reference_valid = rr.valid;
  if (!rr.valid)
    add_simple(r, Severity::Warning, "reference_invalid",
               "the reference mesh is itself invalid (" + rr.errors.front() + ")");

  if (!mesh.tet_labels.empty() && !ref.tet_labels.empty()) {
    c.label_name = mesh.tet_labels[0].name;
    auto a = label_volumes(mesh), b = label_volumes(ref);
    for (const auto& [l, v] : b) a.emplace(l, 0.0);
    for (const auto& [l, v] : a) {
      LabelVolume lv;
      lv.label = l;
      lv.volume = v;
      auto it = b.find(l);
      lv.reference_volume = it == b.end() ? 0.0 : it->second;
      lv.change = lv.volume - lv.reference_volume;
      lv.change_rel = lv.reference_volume != 0 ? lv.change / lv.reference_volume : NAN;
      c.labels.push_back(lv);
    }
  }

  if (r.boundary.components != rr.boundary.components || r.boundary.euler != rr.boundary.euler) {
    c.topology_changed = true;
    add_simple(r, Severity::Error, "topology_changed",
               "boundary components " + std::to_string(rr.boundary.components) + " -> " + std::to_string(r.boundary.components) +
                   ", Euler characteristic " + std::to_string(rr.boundary.euler) + " -> " + std::to_string(r.boundary.euler));
  }
  if (opt.max_volume_change_rel_gate >= 0 && !(std::fabs(c.volume_change_rel) <= opt.max_volume_change_rel_gate))
    add_simple(r, Severity::Error, "volume_change_gate",
               "relative volume change " + num(c.volume_change_rel) + " exceeds " + num(opt.max_volume_change_rel_gate));

  if (opt.hausdorff) {
    const double diag = rr.bbox_diagonal;
    c.hausdorff_error_bound = opt.hausdorff_rel_error * diag;
    if (!mine.soup_ok || !theirs.soup_ok) {
      add_simple(r, Severity::Warning, "hausdorff_skipped", "a boundary surface is not a closed manifold surface");
    } else {
      auto h = check_detail::hausdorff(mine.boundary_soup, theirs.boundary_soup, c.hausdorff_error_bound);
      if (!h.ran) {
        add_simple(r, Severity::Warning, "hausdorff_skipped", h.why_not);
      } else {
        c.hausdorff_computed = true;
        c.hausdorff_to_reference = h.a_to_b;
        c.hausdorff_from_reference = h.b_to_a;
        c.hausdorff = std::max(h.a_to_b, h.b_to_a);
        c.hausdorff_rel = diag > 0 ? c.hausdorff / diag : NAN;
        if (opt.max_hausdorff_rel_gate >= 0 && !(c.hausdorff_rel <= opt.max_hausdorff_rel_gate))
          add_simple(r, Severity::Error, "hausdorff_gate",
                     "Hausdorff distance " + num(c.hausdorff_rel) + " x bbox diagonal exceeds " +
                         num(opt.max_hausdorff_rel_gate));
      }
    }
    timer.lap("hausdorff");
  }
  c.fields = field_errors(ref, mesh, opt.field_samples);
  timer.lap("fields");
}

}  // namespace

CheckReport check_mesh(const Mesh& mesh, const CheckOptions& options, const Mesh* reference) {
  CheckReport r;
  Extra extra;
  Analysis a(mesh, options, r, extra, options.quality, options.self_intersection);
  a.run();
  if (reference) compare(mesh, *reference, options, r, extra);
  return r;
}

}  // namespace tc
