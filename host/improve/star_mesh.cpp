// The improvement's collapse step on the stars of its vertices (star_mesh.hpp).
#include "improve/star_mesh.hpp"

#include "collapse/upload.hpp"

namespace tc::improve_detail {

StarMesh star_mesh(const Mesh& whole, const std::vector<uint8_t>& mask) {
  StarMesh s;
  std::vector<int32_t> local(size_t(whole.num_vertices()), -1);
  for (int64_t t = 0; t < whole.num_tets(); ++t) {
    const int32_t* q = &whole.tets[size_t(4 * t)];
    if (mask[size_t(q[0])] || mask[size_t(q[1])] || mask[size_t(q[2])] || mask[size_t(q[3])]) {
      s.tets.push_back(int32_t(t));
      for (int k = 0; k < 4; ++k) local[size_t(q[k])] = 0;
    }
  }
  for (int64_t v = 0; v < whole.num_vertices(); ++v)
    if (local[size_t(v)] == 0) {
      local[size_t(v)] = int32_t(s.verts.size());
      s.verts.push_back(int32_t(v));
      s.mesh.points.insert(s.mesh.points.end(), &whole.points[size_t(3 * v)], &whole.points[size_t(3 * v + 3)]);
    }
  for (int32_t t : s.tets)
    for (int k = 0; k < 4; ++k) s.mesh.tets.push_back(local[size_t(whole.tets[size_t(4 * t + k)])]);
  for (const Labels& l : whole.tet_labels) {
    s.mesh.tet_labels.push_back({l.name, {}});
    for (int32_t t : s.tets) s.mesh.tet_labels.back().values.push_back(l.values[size_t(t)]);
  }
  for (const Field& f : whole.vertex_fields) {
    s.mesh.vertex_fields.push_back({f.name, f.components, {}});
    for (int32_t v : s.verts)
      for (int c = 0; c < f.components; ++c)
        s.mesh.vertex_fields.back().values.push_back(f.values[size_t(v) * size_t(f.components) + size_t(c)]);
  }
  // which tets survive, through the compaction (tet fields travel with their tets)
  Field index{"tetcollapse:tet", 1, {}};
  for (int32_t t : s.tets) index.values.push_back(double(t));
  s.mesh.tet_fields.push_back(std::move(index));
  return s;
}

void splice(Mesh& whole, const StarMesh& s, const sequential_detail::SequentialRun& run) {
  const Mesh& r = s.mesh;
  const std::vector<int32_t>& origin = run.origin();  // star vertex -> the star mesh's vertex now
  std::vector<int32_t> star_of(size_t(whole.num_vertices()), -1), from(size_t(r.num_vertices()));
  std::vector<uint8_t> alive(size_t(whole.num_vertices()), 1);
  for (size_t i = 0; i < s.verts.size(); ++i) star_of[size_t(s.verts[i])] = int32_t(i), alive[size_t(s.verts[i])] = 0;
  for (size_t k = 0; k < from.size(); ++k) alive[size_t(from[k] = s.verts[size_t(run.source()[k])])] = 1;
  std::vector<int32_t> to(size_t(whole.num_vertices()), -1);  // whole vertex -> new index (alive ones)
  int32_t n = 0;
  for (size_t v = 0; v < to.size(); ++v)
    if (alive[v]) to[v] = n++;
  Mesh out;
  for (size_t v = 0; v < to.size(); ++v) {
    if (!alive[v]) continue;
    const int32_t i = star_of[v];
    const double* p = i < 0 ? &whole.points[3 * v] : &r.points[3 * size_t(origin[size_t(i)])];
    out.points.insert(out.points.end(), p, p + 3);
  }
  for (size_t k = 0; k < whole.vertex_fields.size(); ++k) {
    const Field& f = whole.vertex_fields[k];
    const size_t c = size_t(f.components);
    out.vertex_fields.push_back({f.name, f.components, {}});
    for (size_t v = 0; v < to.size(); ++v) {
      if (!alive[v]) continue;
      const int32_t i = star_of[v];
      const double* x = i < 0 ? &f.values[v * c] : &r.vertex_fields[k].values[size_t(origin[size_t(i)]) * c];
      out.vertex_fields.back().values.insert(out.vertex_fields.back().values.end(), x, x + c);
    }
  }
  // tets in the whole mesh's order: those of the star mesh as the run left them, or gone
  std::vector<int32_t> now(size_t(whole.num_tets()), -2);  // -2: not in the star mesh, -1: gone
  for (int32_t t : s.tets) now[size_t(t)] = -1;
  const Field& index = r.tet_fields.back();  // star_mesh's tet index
  for (int64_t t = 0; t < r.num_tets(); ++t) now[size_t(index.values[size_t(t)])] = int32_t(t);
  std::vector<int32_t> kept;
  for (int64_t t = 0; t < whole.num_tets(); ++t) {
    const int32_t u = now[size_t(t)];
    if (u == -1) continue;
    kept.push_back(int32_t(t));
    for (int k = 0; k < 4; ++k)
      out.tets.push_back(u == -2 ? to[size_t(whole.tets[size_t(4 * t + k)])] : to[size_t(from[size_t(r.tets[size_t(4 * u + k)])])]);
  }
  for (const Labels& l : whole.tet_labels) {
    out.tet_labels.push_back({l.name, {}});
    for (int32_t t : kept) out.tet_labels.back().values.push_back(l.values[size_t(t)]);
  }
  for (const Field& f : whole.tet_fields) {
    const size_t c = size_t(f.components);
    out.tet_fields.push_back({f.name, f.components, {}});
    for (int32_t t : kept)
      out.tet_fields.back().values.insert(out.tet_fields.back().values.end(), &f.values[size_t(t) * c],
                                          &f.values[size_t(t) * c + c]);
  }
  // the input's triangles and edges through each whole vertex's survivor, as the run remaps them
  std::vector<int32_t> survivor(to.size());
  for (size_t v = 0; v < to.size(); ++v)
    survivor[v] = star_of[v] < 0 ? to[v] : to[size_t(from[size_t(origin[size_t(star_of[v])])])];
  out.tris = std::move(whole.tris), out.tri_tags = std::move(whole.tri_tags);
  out.edges = std::move(whole.edges), out.edge_tags = std::move(whole.edge_tags);
  collapse_detail::remap_elements(out.tris, out.tri_tags, 3, survivor);
  collapse_detail::remap_elements(out.edges, out.edge_tags, 2, survivor);
  whole = std::move(out);
}

}  // namespace tc::improve_detail
