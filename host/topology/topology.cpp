// Single-threaded construction of the connectivity and the boundary classification.
// See include/tetcollapse/topology.hpp for the definitions and the order of every array; the
// collapse's device connectivity (cl/collapse_connectivity.cl) is checked against it.
#include "tetcollapse/topology.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "geometry.h"
#include "tetcollapse/error.hpp"
#include "topology/topology_detail.hpp"

namespace tc {

const char* vertex_class_name(VertexClass c) {
  switch (c) {
    case VertexClass::Interior: return "interior";
    case VertexClass::Face: return "face";
    case VertexClass::Ridge: return "ridge";
    case VertexClass::Corner: return "corner";
  }
  return "?";
}

namespace topology_detail {

// Stable LSD radix sort of (key, payload) records by key, 8 bits per pass, skipping the
// passes whose byte is the same in every key. We write it ourselves rather than calling
// std::stable_sort because it is faster on the millions of 64-bit keys a mesh gives, and
// it sorts exactly like the device's stable radix sort (equal keys keep their input order).
void radix_sort(std::vector<KeyPayload>& a) {
  const size_t n = a.size();
  if (n < 2) return;
  uint64_t all_or = 0, all_and = ~uint64_t(0);
  for (const auto& r : a) {
    all_or |= r.key;
    all_and &= r.key;
  }
  const uint64_t varying = all_or ^ all_and;
  std::vector<KeyPayload> tmp(n);
  std::vector<size_t> count(256);
  for (int shift = 0; shift < 64; shift += 8) {
    if (((varying >> shift) & 0xff) == 0) continue;
    std::fill(count.begin(), count.end(), 0);
    for (const auto& r : a) ++count[(r.key >> shift) & 0xff];
    size_t sum = 0;
    for (auto& c : count) {
      size_t t = c;
      c = sum;
      sum += t;
    }
    for (const auto& r : a) tmp[count[(r.key >> shift) & 0xff]++] = r;
    a.swap(tmp);
  }
}

// CSR by counting sort: entry i goes to list keys[i], and the entries of a list keep the order
// in which they appear (so a list is ascending when values ascend with i).
void build_csr(int32_t num_lists, const std::vector<int32_t>& keys, const std::vector<int32_t>& values,
               std::vector<int32_t>& offsets, std::vector<int32_t>& indices) {
  offsets.assign(size_t(num_lists) + 1, 0);
  for (int32_t k : keys) ++offsets[size_t(k) + 1];
  for (int32_t i = 0; i < num_lists; ++i) offsets[i + 1] += offsets[i];
  indices.resize(keys.size());
  std::vector<int32_t> fill(offsets.begin(), offsets.end() - 1);
  for (size_t i = 0; i < keys.size(); ++i) indices[fill[keys[i]]++] = values[i];
}

int local_edge(int i, int j) {
  for (int e = 0; e < 6; ++e)
    if ((geo::TC_TET_EDGES[e][0] == i && geo::TC_TET_EDGES[e][1] == j) ||
        (geo::TC_TET_EDGES[e][0] == j && geo::TC_TET_EDGES[e][1] == i))
      return e;
  return -1;
}

}  // namespace topology_detail

using namespace topology_detail;

namespace {

[[noreturn]] void bad(const std::string& why) { throw InputError("<mesh>", why); }

void check_mesh(const Mesh& mesh) {
  if (mesh.points.size() % 3 != 0) bad("point array length is not a multiple of 3");
  if (mesh.tets.size() % 4 != 0) bad("tet array length is not a multiple of 4");
  const int64_t nv = mesh.num_vertices(), nt = mesh.num_tets();
  // 6 * tets must fit the 32-bit payload (tet * 6 + local edge) of the sort records.
  if (nv > std::numeric_limits<int32_t>::max() || nt > std::numeric_limits<int32_t>::max() / 6)
    bad("mesh too large for 32-bit indices: " + std::to_string(nv) + " vertices, " + std::to_string(nt) + " tets");
  for (int64_t t = 0; t < nt; ++t) {
    const int32_t* v = &mesh.tets[4 * t];
    for (int i = 0; i < 4; ++i) {
      if (v[i] < 0 || v[i] >= nv)
        bad("tet " + std::to_string(t) + " has vertex index " + std::to_string(v[i]) + " outside [0, " +
            std::to_string(nv) + ")");
      for (int j = 0; j < i; ++j)
        if (v[i] == v[j]) bad("tet " + std::to_string(t) + " repeats vertex " + std::to_string(v[i]));
    }
  }
}

}  // namespace

namespace topology_detail {

// Is (p, q) a directed edge of triangle f?
static bool traverses(const int32_t* f, int32_t p, int32_t q) {
  return (f[0] == p && f[1] == q) || (f[1] == p && f[2] == q) || (f[2] == p && f[0] == q);
}

uint8_t classify_edge(const Topology& t, int32_t e, double eps_r) {
  const int32_t b = t.edge_sfaces_offsets[e], n = t.edge_sfaces_offsets[e + 1] - b;
  if (n == 0) return 0;
  if (n != 2) return 1;  // (a) non-manifold edge of S
  const int32_t f0 = t.edge_sfaces[b], f1 = t.edge_sfaces[b + 1];
  const int32_t v0 = t.edges[2 * e], v1 = t.edges[2 * e + 1];
  const bool d0 = traverses(&t.sfaces[3 * size_t(f0)], v0, v1);
  const bool d1 = traverses(&t.sfaces[3 * size_t(f1)], v0, v1);
  if (d0 == d1) return 1;  // (b) not consistently oriented
  const double* n0 = &t.sface_normals[3 * size_t(f0)];
  const double* n1 = &t.sface_normals[3 * size_t(f1)];
  const double d = n0[0] * n1[0] + n0[1] * n1[1] + n0[2] * n1[2];
  return 1.0 - d > eps_r ? 1 : 0;  // (c) a sharp crease
}

uint8_t classify_vertex(const Topology& t, int32_t v, double eps_f) {
  const int32_t fb = t.vertex_sfaces_offsets[v], fn = t.vertex_sfaces_offsets[v + 1] - fb;
  if (fn == 0) return uint8_t(VertexClass::Interior);
  int ridges = 0;
  for (int32_t i = t.vertex_edges_offsets[v]; i < t.vertex_edges_offsets[v + 1]; ++i)
    ridges += t.edge_ridge[t.vertex_edges[i]];
  if (ridges == 2) return uint8_t(VertexClass::Ridge);
  if (ridges != 0) return uint8_t(VertexClass::Corner);
  // Face candidate: every pair of normals within eps_F ...
  for (int32_t i = 0; i < fn; ++i) {
    const double* a = &t.sface_normals[3 * size_t(t.vertex_sfaces[fb + i])];
    for (int32_t j = i + 1; j < fn; ++j) {
      const double* b = &t.sface_normals[3 * size_t(t.vertex_sfaces[fb + j])];
      if (1.0 - (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) > eps_f) return uint8_t(VertexClass::Corner);
    }
  }
  // ... and the triangles form one closed fan: writing each as (v, a, b), following b -> the
  // unique triangle whose a equals it must run through all fn triangles and close.
  auto other = [&](int32_t f, int k) {  // k = 1: vertex after v, k = 2: vertex before v
    const int32_t* tri = &t.sfaces[3 * size_t(f)];
    int p = tri[0] == v ? 0 : tri[1] == v ? 1 : 2;
    return tri[(p + k) % 3];
  };
  int32_t cur = 0;
  for (int32_t step = 1; step <= fn; ++step) {
    const int32_t want = other(t.vertex_sfaces[fb + cur], 2);
    int32_t next = -1, found = 0;
    for (int32_t j = 0; j < fn; ++j)
      if (other(t.vertex_sfaces[fb + j], 1) == want) {
        next = j;
        ++found;
      }
    if (found != 1) return uint8_t(VertexClass::Corner);
    cur = next;
    if (cur == 0 && step != fn) return uint8_t(VertexClass::Corner);  // a fan closed early: pinched
  }
  return cur == 0 ? uint8_t(VertexClass::Face) : uint8_t(VertexClass::Corner);
}

}  // namespace topology_detail

Topology build_topology(const Mesh& mesh, const TopologyOptions& options, TopologyTimings* timings) {
  TopologyTimings tm;
  auto last = std::chrono::steady_clock::now();
  auto lap = [&last] {
    auto now = std::chrono::steady_clock::now();
    double s = std::chrono::duration<double>(now - last).count();
    last = now;
    return s;
  };
  check_mesh(mesh);
  tm.check = lap();
  Topology t;
  t.num_vertices = int32_t(mesh.num_vertices());
  t.num_tets = int32_t(mesh.num_tets());
  const int32_t nv = t.num_vertices, nt = t.num_tets;
  const int32_t* tets = mesh.tets.data();

  // --- edges: sort (v0 << 32 | v1) keys with payload tet * 6 + local edge ---
  std::vector<KeyPayload> rec(size_t(nt) * 6);
  for (int32_t i = 0; i < nt; ++i)
    for (int e = 0; e < 6; ++e) {
      uint32_t a = uint32_t(tets[4 * size_t(i) + geo::TC_TET_EDGES[e][0]]);
      uint32_t b = uint32_t(tets[4 * size_t(i) + geo::TC_TET_EDGES[e][1]]);
      if (a > b) std::swap(a, b);
      rec[6 * size_t(i) + e] = {(uint64_t(a) << 32) | b, uint32_t(6 * i + e)};
    }
  radix_sort(rec);
  t.tet_edges.resize(size_t(nt) * 6);
  t.edge_tets.resize(rec.size());
  t.edge_tets_offsets.clear();
  for (size_t i = 0; i < rec.size(); ++i) {
    if (i == 0 || rec[i].key != rec[i - 1].key) {
      t.edge_tets_offsets.push_back(int32_t(i));
      t.edges.push_back(int32_t(rec[i].key >> 32));
      t.edges.push_back(int32_t(rec[i].key & 0xffffffffu));
    }
    t.tet_edges[rec[i].payload] = int32_t(t.edge_tets_offsets.size() - 1);
    t.edge_tets[i] = int32_t(rec[i].payload / 6);
  }
  t.edge_tets_offsets.push_back(int32_t(rec.size()));
  const int32_t ne = t.num_edges();
  tm.edges = lap();

  // --- vertex -> tets and vertex -> edges (counting sort keeps ascending order) ---
  {
    std::vector<int32_t> vals(mesh.tets.size());
    for (size_t i = 0; i < vals.size(); ++i) vals[i] = int32_t(i / 4);
    build_csr(nv, mesh.tets, vals, t.vertex_tets_offsets, t.vertex_tets);
    vals.resize(t.edges.size());
    for (size_t i = 0; i < vals.size(); ++i) vals[i] = int32_t(i / 2);
    build_csr(nv, t.edges, vals, t.vertex_edges_offsets, t.vertex_edges);
  }
  tm.vertex_lists = lap();

  // --- faces: key (edge_id(a, b) << 32 | c) for the sorted triangle a < b < c ---
  rec.resize(size_t(nt) * 4);
  for (int32_t i = 0; i < nt; ++i)
    for (int f = 0; f < 4; ++f) {
      int l[3] = {geo::TC_TET_FACES[f][0], geo::TC_TET_FACES[f][1], geo::TC_TET_FACES[f][2]};
      // sort the three local corners by global index (a three-element sorting network)
      auto gv = [&](int k) { return tets[4 * size_t(i) + k]; };
      if (gv(l[0]) > gv(l[1])) std::swap(l[0], l[1]);
      if (gv(l[1]) > gv(l[2])) std::swap(l[1], l[2]);
      if (gv(l[0]) > gv(l[1])) std::swap(l[0], l[1]);
      const uint32_t ab = uint32_t(t.tet_edges[6 * size_t(i) + local_edge(l[0], l[1])]);
      rec[4 * size_t(i) + f] = {(uint64_t(ab) << 32) | uint32_t(gv(l[2])), uint32_t(4 * i + f)};
    }
  radix_sort(rec);
  const std::vector<int32_t>* labels = nullptr;
  if (options.use_labels && !mesh.tet_labels.empty() && mesh.tet_labels[0].values.size() == size_t(nt))
    labels = &mesh.tet_labels[0].values;
  auto add_sface = [&](uint32_t payload, uint8_t interface) {
    const int32_t tet = int32_t(payload / 4), f = int32_t(payload % 4);
    int32_t v[3];
    for (int k = 0; k < 3; ++k) v[k] = tets[4 * size_t(tet) + geo::TC_TET_FACES[f][k]];
    t.sfaces.insert(t.sfaces.end(), v, v + 3);
    t.sface_tet.push_back(tet);
    t.sface_local.push_back(int8_t(f));
    t.sface_interface.push_back(interface);
    geo::tc_d3 p[3];
    for (int k = 0; k < 3; ++k) p[k] = geo::tc_point(mesh.points.data(), v[k]);
    const geo::tc_d3 n = geo::normalize(geo::tc_triangle_normal(p[0], p[1], p[2]));
    t.sface_normals.insert(t.sface_normals.end(), {n.x, n.y, n.z});
  };
  for (size_t i = 0; i < rec.size();) {
    size_t j = i + 1;
    while (j < rec.size() && rec[j].key == rec[i].key) ++j;
    if (j - i == 2) {
      const uint32_t p0 = rec[i].payload, p1 = rec[i + 1].payload;
      if (labels) {
        const int32_t l0 = (*labels)[p0 / 4], l1 = (*labels)[p1 / 4];
        if (l0 != l1) add_sface(l0 < l1 ? p0 : p1, 1);
      }
    } else {
      // one tet: boundary face; more than two (invalid input): each side counts as boundary
      for (size_t k = i; k < j; ++k) add_sface(rec[k].payload, 0);
    }
    i = j;
  }
  const int32_t ns = t.num_sfaces();
  tm.faces = lap();

  // --- S-face adjacency: vertex -> S-faces, edge -> S-faces ---
  {
    std::vector<int32_t> keys(size_t(ns) * 3), vals(size_t(ns) * 3);
    for (int32_t s = 0; s < ns; ++s)
      for (int k = 0; k < 3; ++k) {
        keys[3 * size_t(s) + k] = t.sfaces[3 * size_t(s) + k];
        vals[3 * size_t(s) + k] = s;
      }
    build_csr(nv, keys, vals, t.vertex_sfaces_offsets, t.vertex_sfaces);
    static const int face_edges[4][3] = {{3, 4, 5}, {1, 2, 5}, {0, 2, 4}, {0, 1, 3}};  // edges avoiding vertex f
    for (int32_t s = 0; s < ns; ++s)
      for (int k = 0; k < 3; ++k)
        keys[3 * size_t(s) + k] = t.tet_edges[6 * size_t(t.sface_tet[s]) + face_edges[t.sface_local[s]][k]];
    build_csr(ne, keys, vals, t.edge_sfaces_offsets, t.edge_sfaces);
  }
  tm.sface_lists = lap();

  // --- boundary flags ---
  t.vertex_boundary.assign(size_t(nv), 0);
  t.edge_boundary.assign(size_t(ne), 0);
  for (int32_t v = 0; v < nv; ++v)
    for (int32_t i = t.vertex_sfaces_offsets[v]; i < t.vertex_sfaces_offsets[v + 1]; ++i)
      t.vertex_boundary[v] |= t.sface_interface[t.vertex_sfaces[i]] ? kOnInterface : kOnBoundary;
  for (int32_t e = 0; e < ne; ++e)
    for (int32_t i = t.edge_sfaces_offsets[e]; i < t.edge_sfaces_offsets[e + 1]; ++i)
      t.edge_boundary[e] |= t.sface_interface[t.edge_sfaces[i]] ? kOnInterface : kOnBoundary;
  tm.flags = lap();

  // --- classification ---
  t.edge_ridge.resize(size_t(ne));
  for (int32_t e = 0; e < ne; ++e) t.edge_ridge[e] = classify_edge(t, e, options.eps_r);
  t.vertex_class.resize(size_t(nv));
  for (int32_t v = 0; v < nv; ++v) t.vertex_class[v] = classify_vertex(t, v, options.eps_f);
  tm.classify = lap();
  if (timings) *timings = tm;
  return t;
}

TopologySummary summarize(const Mesh& mesh, const Topology& t) {
  TopologySummary s;
  s.vertices = t.num_vertices;
  s.tets = t.num_tets;
  s.edges = t.num_edges();
  for (uint8_t i : t.sface_interface) (i ? s.interface_faces : s.boundary_faces)++;
  for (uint8_t b : t.vertex_boundary) s.boundary_vertices += b != 0;
  for (uint8_t b : t.edge_boundary) s.boundary_edges += b != 0;
  for (uint8_t r : t.edge_ridge) s.ridge_edges += r;
  for (uint8_t c : t.vertex_class) switch (VertexClass(c)) {
      case VertexClass::Interior: ++s.interior_vertices; break;
      case VertexClass::Face: ++s.face_vertices; break;
      case VertexClass::Ridge: ++s.ridge_vertices; break;
      case VertexClass::Corner: ++s.corner_vertices; break;
    }
  const double* p = mesh.points.data();
  if (s.edges > 0) {
    std::vector<double> len(size_t(s.edges));
    for (int64_t e = 0; e < s.edges; ++e)
      len[e] = geo::length(geo::tc_point(p, t.edges[2 * e + 1]) - geo::tc_point(p, t.edges[2 * e]));
    auto [mn, mx] = std::minmax_element(len.begin(), len.end());
    s.edge_length_min = *mn;
    s.edge_length_max = *mx;
    // median: the middle element, or the mean of the two middle ones
    const size_t mid = len.size() / 2;
    std::nth_element(len.begin(), len.begin() + mid, len.end());
    double m = len[mid];
    if (len.size() % 2 == 0) m = 0.5 * (m + *std::max_element(len.begin(), len.begin() + mid));
    s.edge_length_median = m;
  }
  double mind = std::numeric_limits<double>::infinity(), maxd = 0;
  for (int64_t i = 0; i < s.tets; ++i) {
    const int32_t* v = &mesh.tets[4 * i];
    geo::tc_d3 a = geo::tc_point(p, v[0]), b = geo::tc_point(p, v[1]), c = geo::tc_point(p, v[2]),
               d = geo::tc_point(p, v[3]);
    s.total_volume += geo::tc_tet_volume(a, b, c, d);
    mind = std::min(mind, geo::tc_min_dihedral(a, b, c, d));
    maxd = std::max(maxd, geo::tc_max_dihedral(a, b, c, d));
  }
  const double deg = 180.0 / 3.14159265358979323846;
  s.min_dihedral_deg = s.tets > 0 ? mind * deg : 0;
  s.max_dihedral_deg = maxd * deg;
  return s;
}

}  // namespace tc
