#include "part.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <stdexcept>
#include <string>

namespace tc::mpi {

namespace {

// Tagged simplices (triangles, edges) by their sorted vertices, to find the first tet that has
// each: sorted once, then looked up by every tet's faces or edges.
template <size_t N>
class SimplexIndex {
 public:
  SimplexIndex(const std::vector<int32_t>& verts) {
    const size_t n = verts.size() / N;
    keys_.reserve(n);
    for (size_t i = 0; i < n; ++i) {
      std::array<int32_t, N> k;
      for (size_t j = 0; j < N; ++j) k[j] = verts[N * i + j];
      std::sort(k.begin(), k.end());
      keys_.push_back({k, int32_t(i)});
    }
    std::sort(keys_.begin(), keys_.end());
  }
  // Sets owner[i] = p for every simplex i with these (sorted) vertices that has no owner yet.
  void claim(const std::array<int32_t, N>& k, int32_t p, std::vector<int32_t>& owner) const {
    auto it = std::lower_bound(keys_.begin(), keys_.end(), std::make_pair(k, int32_t(-1)));
    for (; it != keys_.end() && it->first == k; ++it)
      if (owner[size_t(it->second)] < 0) owner[size_t(it->second)] = p;
  }
  bool empty() const { return keys_.empty(); }

 private:
  std::vector<std::pair<std::array<int32_t, N>, int32_t>> keys_;
};

template <class T>
void append_selected(std::vector<T>& out, const std::vector<T>& in, size_t width, size_t i) {
  out.insert(out.end(), in.begin() + std::ptrdiff_t(width * i), in.begin() + std::ptrdiff_t(width * (i + 1)));
}

bool same_position(const std::vector<double>& a, int64_t i, const std::vector<double>& b, int64_t j) {
  return std::memcmp(&a[size_t(3 * i)], &b[size_t(3 * j)], 3 * sizeof(double)) == 0;
}

}  // namespace

Splitter::Splitter(const Mesh& whole, const std::vector<int32_t>& tet_part, int /*nparts*/)
    : whole_(whole), tet_part_(tet_part) {
  const int64_t nv = whole.num_vertices(), nt = whole.num_tets();
  std::vector<int32_t> first(size_t(nv), -1);
  shared_.assign(size_t(nv), 0);
  for (int64_t t = 0; t < nt; ++t)
    for (int k = 0; k < 4; ++k) {
      const size_t v = size_t(whole.tets[size_t(4 * t + k)]);
      if (first[v] < 0) first[v] = tet_part[size_t(t)];
      else if (first[v] != tet_part[size_t(t)]) shared_[v] = 1;
    }
  interface_vertices_ = std::count(shared_.begin(), shared_.end(), uint8_t(1));

  // Tagged triangles and edges go with the first tet that has them.
  tri_part_.assign(size_t(whole.num_tris()), -1);
  edge_part_.assign(whole.edges.size() / 2, -1);
  const SimplexIndex<3> tris(whole.tris);
  const SimplexIndex<2> edges(whole.edges);
  if (!tris.empty() || !edges.empty())
    for (int64_t t = 0; t < nt; ++t) {
      std::array<int32_t, 4> q;
      for (int k = 0; k < 4; ++k) q[size_t(k)] = whole.tets[size_t(4 * t + k)];
      std::sort(q.begin(), q.end());
      const int32_t p = tet_part[size_t(t)];
      if (!tris.empty())
        for (int skip = 3; skip >= 0; --skip) {
          std::array<int32_t, 3> f;
          for (int k = 0, j = 0; k < 4; ++k)
            if (k != skip) f[size_t(j++)] = q[size_t(k)];
          tris.claim(f, p, tri_part_);
        }
      if (!edges.empty())
        for (int a = 0; a < 4; ++a)
          for (int b = a + 1; b < 4; ++b) edges.claim({q[size_t(a)], q[size_t(b)]}, p, edge_part_);
    }
  dropped_tris_ = std::count(tri_part_.begin(), tri_part_.end(), -1);
  dropped_edges_ = std::count(edge_part_.begin(), edge_part_.end(), -1);
}

Part Splitter::extract(int p, const std::vector<uint8_t>& select) const {
  const Mesh& w = whole_;
  const int64_t nv = w.num_vertices(), nt = w.num_tets();
  std::vector<int32_t> local(size_t(nv), -1);
  for (int64_t t = 0; t < nt; ++t)
    if (tet_part_[size_t(t)] == p)
      for (int k = 0; k < 4; ++k) local[size_t(w.tets[size_t(4 * t + k)])] = 0;
  Part part;
  Mesh& m = part.mesh;
  for (const Field& f : w.vertex_fields) m.vertex_fields.push_back({f.name, f.components, {}});
  int32_t n = 0;
  for (int64_t v = 0; v < nv; ++v) {
    if (local[size_t(v)] < 0) continue;
    local[size_t(v)] = n++;
    append_selected(m.points, w.points, 3, size_t(v));
    for (size_t i = 0; i < w.vertex_fields.size(); ++i)
      append_selected(m.vertex_fields[i].values, w.vertex_fields[i].values, size_t(w.vertex_fields[i].components),
                      size_t(v));
    part.gid.push_back(v);
    part.frozen.push_back(shared_[size_t(v)]);
    if (!select.empty()) part.select.push_back(select[size_t(v)]);
  }
  for (const Labels& l : w.tet_labels) m.tet_labels.push_back({l.name, {}});
  for (const Field& f : w.tet_fields) m.tet_fields.push_back({f.name, f.components, {}});
  for (int64_t t = 0; t < nt; ++t) {
    if (tet_part_[size_t(t)] != p) continue;
    for (int k = 0; k < 4; ++k) m.tets.push_back(local[size_t(w.tets[size_t(4 * t + k)])]);
    for (size_t i = 0; i < w.tet_labels.size(); ++i) m.tet_labels[i].values.push_back(w.tet_labels[i].values[size_t(t)]);
    for (size_t i = 0; i < w.tet_fields.size(); ++i)
      append_selected(m.tet_fields[i].values, w.tet_fields[i].values, size_t(w.tet_fields[i].components), size_t(t));
  }
  for (size_t i = 0; i < tri_part_.size(); ++i) {
    if (tri_part_[i] != p) continue;
    for (int k = 0; k < 3; ++k) m.tris.push_back(local[size_t(w.tris[3 * i + size_t(k)])]);
    m.tri_tags.push_back(i < w.tri_tags.size() ? w.tri_tags[i] : 0);
  }
  for (size_t i = 0; i < edge_part_.size(); ++i) {
    if (edge_part_[i] != p) continue;
    for (int k = 0; k < 2; ++k) m.edges.push_back(local[size_t(w.edges[2 * i + size_t(k)])]);
    m.edge_tags.push_back(i < w.edge_tags.size() ? w.edge_tags[i] : 0);
  }
  return part;
}

std::vector<uint8_t> grow(const Mesh& mesh, std::vector<uint8_t> seed, int rings) {
  const int64_t nt = mesh.num_tets();
  for (int r = 0; r < rings; ++r) {
    std::vector<uint8_t> next = seed;
    for (int64_t t = 0; t < nt; ++t) {
      const int32_t* q = &mesh.tets[size_t(4 * t)];
      if (seed[size_t(q[0])] || seed[size_t(q[1])] || seed[size_t(q[2])] || seed[size_t(q[3])])
        for (int k = 0; k < 4; ++k) next[size_t(q[k])] = 1;
    }
    seed = std::move(next);
  }
  return seed;
}

Merger::Merger(int64_t whole_vertices, const std::vector<uint8_t>& band)
    : band_(band), new_index_(size_t(whole_vertices), -1) {}

void Merger::add(Part&& part) {
  Mesh& m = part.mesh;
  if (first_) {
    for (const Field& f : m.vertex_fields) out_.vertex_fields.push_back({f.name, f.components, {}});
    for (const Labels& l : m.tet_labels) out_.tet_labels.push_back({l.name, {}});
    for (const Field& f : m.tet_fields) out_.tet_fields.push_back({f.name, f.components, {}});
    first_ = false;
  }
  if (m.vertex_fields.size() != out_.vertex_fields.size() || m.tet_labels.size() != out_.tet_labels.size() ||
      m.tet_fields.size() != out_.tet_fields.size())
    throw std::runtime_error("the parts came back with different labels or fields");
  const int64_t nv = m.num_vertices();
  std::vector<int32_t> map(static_cast<size_t>(nv));
  for (int64_t v = 0; v < nv; ++v) {
    int32_t& known = part.frozen[size_t(v)] ? new_index_.at(size_t(part.gid[size_t(v)])) : map[size_t(v)];
    if (part.frozen[size_t(v)] && known >= 0) {
      if (!same_position(out_.points, known, m.points, v))
        throw std::runtime_error("frozen vertex " + std::to_string(part.gid[size_t(v)]) + " moved in a part");
      map[size_t(v)] = known;
      continue;
    }
    map[size_t(v)] = known = int32_t(out_.num_vertices());
    append_selected(out_.points, m.points, 3, size_t(v));
    for (size_t i = 0; i < m.vertex_fields.size(); ++i)
      append_selected(out_.vertex_fields[i].values, m.vertex_fields[i].values, size_t(m.vertex_fields[i].components),
                      size_t(v));
    was_frozen_.push_back(part.frozen[size_t(v)] && (band_.empty() || band_[size_t(part.gid[size_t(v)])]));
  }
  for (int32_t v : m.tets) out_.tets.push_back(map[size_t(v)]);
  for (size_t i = 0; i < m.tet_labels.size(); ++i)
    out_.tet_labels[i].values.insert(out_.tet_labels[i].values.end(), m.tet_labels[i].values.begin(),
                                     m.tet_labels[i].values.end());
  for (size_t i = 0; i < m.tet_fields.size(); ++i)
    out_.tet_fields[i].values.insert(out_.tet_fields[i].values.end(), m.tet_fields[i].values.begin(),
                                     m.tet_fields[i].values.end());
  for (int32_t v : m.tris) out_.tris.push_back(map[size_t(v)]);
  out_.tri_tags.insert(out_.tri_tags.end(), m.tri_tags.begin(), m.tri_tags.end());
  for (int32_t v : m.edges) out_.edges.push_back(map[size_t(v)]);
  out_.edge_tags.insert(out_.edge_tags.end(), m.edge_tags.begin(), m.edge_tags.end());
  m = Mesh();  // the part's memory goes before the next arrives
}

Mesh Merger::finish() { return std::move(out_); }

}  // namespace tc::mpi
