#include "improve/improve_mesh.hpp"

#include <algorithm>
#include <limits>
#include <map>
#include <stdexcept>

#include "tetcollapse/error.hpp"
#include "tetcollapse/topology.hpp"

namespace tc::improve_detail {

uint64_t ImpMesh::key2(int32_t a, int32_t b) {
  if (a > b) std::swap(a, b);
  return uint64_t(uint32_t(a)) << 32 | uint32_t(b);
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
  mark_motion(options);
  if (options.boundary != CollapseOptions::Strict && options.max_boundary_move > 0 && nv > 0) {
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) lo[k] = hi[k] = points_[size_t(k)];
    for (int64_t v = 0; v < nv; ++v)
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], points_[size_t(3 * v + k)]);
        hi[k] = std::max(hi[k], points_[size_t(3 * v + k)]);
      }
    max_boundary_move_ = options.max_boundary_move * std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  }
}

int32_t ImpMesh::across(int32_t t, int32_t a, int32_t b, int32_t c) const {
  for (int32_t s : vtets_[size_t(a)]) {
    if (s == t) continue;
    const Tet& q = tets_[size_t(s)];
    const bool hb = q[0] == b || q[1] == b || q[2] == b || q[3] == b;
    const bool hc = q[0] == c || q[1] == c || q[2] == c || q[3] == c;
    if (hb && hc) return s;
  }
  return -1;
}

bool ImpMesh::remove_boundary_tet(int32_t t, const std::array<std::array<int32_t, 3>, 2>& gone,
                                  const std::array<std::array<int32_t, 3>, 2>& exposed) {
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
  replace({t}, {}, t);
  return true;
}

// Interior vertices move freely. On the feature surface (boundary and interfaces) a Face vertex
// moves only where its surface triangles are coplanar, and then within that plane, so the
// surface keeps its shape; curved faces, ridges and corners stay (bounding the error of a
// move on a curved surface is not done here). In strict mode no surface vertex moves. Vertices
// of tagged triangles and edges that are not plain Face vertices stay too.
void ImpMesh::mark_motion(const ImproveOptions& options) {
  const int32_t nv = num_vertices();
  motion_.assign(size_t(nv), kFree);
  normal_.assign(size_t(nv), tc_d3{0, 0, 0});
  Topology topo = build_topology(mesh_, TopologyOptions{options.eps_f, options.eps_r, options.use_labels});
  for (int32_t v = 0; v < nv; ++v) {
    const auto cls = VertexClass(topo.vertex_class[size_t(v)]);
    if (cls == VertexClass::Interior) continue;
    motion_[size_t(v)] = kFixed;
    if (cls != VertexClass::Face || options.boundary == CollapseOptions::Strict) continue;
    const int32_t b = topo.vertex_sfaces_offsets[size_t(v)], e = topo.vertex_sfaces_offsets[size_t(v) + 1];
    tc_d3 n0 = geo::tc_point(topo.sface_normals.data(), topo.vertex_sfaces[size_t(b)]);
    bool flat = geo::dot(n0, n0) > 0.5;
    for (int32_t i = b + 1; i < e && flat; ++i) {
      tc_d3 n = geo::tc_point(topo.sface_normals.data(), topo.vertex_sfaces[size_t(i)]);
      flat = 1.0 - geo::dot(n0, n) < 1e-12;
    }
    if (flat) {
      motion_[size_t(v)] = kInPlane;
      normal_[size_t(v)] = n0;
    }
  }
  // Vertices of tagged triangles off the feature surface, and of tagged edges, stay.
  for (int64_t i = 0; i < 3 * mesh_.num_tris(); ++i)
    if (topo.vertex_class[size_t(mesh_.tris[size_t(i)])] == uint8_t(VertexClass::Interior))
      motion_[size_t(mesh_.tris[size_t(i)])] = kFixed;
  for (int32_t v : mesh_.edges) motion_[size_t(v)] = kFixed;
  for (int32_t v = 0; v < nv; ++v)
    if (!selected(v)) motion_[size_t(v)] = kFixed;
}

void ImpMesh::move(int32_t v, tc_d3 p) {
  if (!mesh_.vertex_fields.empty()) {
    // The tet of the star (as it is) holding p, by its barycentric coordinates: the one whose
    // smallest coordinate is largest (p is inside the star, so that one holds it).
    int32_t best = -1;
    double best_min = -std::numeric_limits<double>::infinity(), bary[4] = {0, 0, 0, 0};
    for (int32_t t : vtets_[size_t(v)]) {
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
  for (int32_t t : l) {
    const Tet& q = tets_[size_t(t)];
    if (q[0] == other || q[1] == other || q[2] == other || q[3] == other) return true;
  }
  return false;
}

bool ImpMesh::has_face(int32_t a, int32_t b, int32_t c) const {
  for (int32_t t : vtets_[size_t(a)]) {
    const Tet& q = tets_[size_t(t)];
    const bool hb = q[0] == b || q[1] == b || q[2] == b || q[3] == b;
    const bool hc = q[0] == c || q[1] == c || q[2] == c || q[3] == c;
    if (hb && hc) return true;
  }
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
