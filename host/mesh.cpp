#include "tetcollapse/mesh.hpp"

#include <gmpxx.h>

#include <algorithm>
#include <cmath>

#include "geometry.h"
#include "tetcollapse/error.hpp"

namespace tc {

// ---------------------------------------------------------------- errors

namespace {
// "FILE:LINE: reason", "FILE: byte OFFSET: reason" or "FILE: reason". Built with append
// (GCC 12 warns falsely about -Wrestrict on the equivalent operator+ chain).
std::string input_error_text(const std::string& file, int64_t line, int64_t offset, const std::string& reason) {
  std::string s = file;
  if (line >= 0) {
    s.append(":").append(std::to_string(line));
  } else if (offset >= 0) {
    s.append(": byte ").append(std::to_string(offset));
  }
  s.append(": ").append(reason);
  return s;
}
}  // namespace

InputError::InputError(const std::string& file, int64_t line, int64_t offset, const std::string& reason)
    : std::runtime_error(input_error_text(file, line, offset, reason)),
      file_(file), line_(line), offset_(offset), reason_(reason) {}
InputError::InputError(const std::string& file, const std::string& reason) : InputError(file, -1, -1, reason) {}
InputError::InputError(const std::string& file, int64_t line, const std::string& reason)
    : InputError(file, line, -1, reason) {}
InputError InputError::at_byte(const std::string& file, int64_t offset, const std::string& reason) {
  return InputError(file, -1, offset, reason);
}

// ---------------------------------------------------------------- mesh

const Labels* Mesh::find_labels(const std::string& name) const {
  for (const auto& l : tet_labels)
    if (l.name == name) return &l;
  return nullptr;
}

const Field* Mesh::find_vertex_field(const std::string& name) const {
  for (const auto& f : vertex_fields)
    if (f.name == name) return &f;
  return nullptr;
}

namespace {

// Exact sign of orient3d: a floating-point filter, and GMP rationals when the filter
// cannot decide (rare: nearly flat tets).
int orient_sign(const geo::tc_d3& a, const geo::tc_d3& b, const geo::tc_d3& c, const geo::tc_d3& d) {
  double det = geo::tc_orient3d(a, b, c, d);
  double bound = geo::tc_orient3d_errbound(a, b, c, d);
  if (det > bound) return 1;
  if (-det > bound) return -1;
  mpq_class ax(a.x), ay(a.y), az(a.z);
  mpq_class bx = mpq_class(b.x) - ax, by = mpq_class(b.y) - ay, bz = mpq_class(b.z) - az;
  mpq_class cx = mpq_class(c.x) - ax, cy = mpq_class(c.y) - ay, cz = mpq_class(c.z) - az;
  mpq_class dx = mpq_class(d.x) - ax, dy = mpq_class(d.y) - ay, dz = mpq_class(d.z) - az;
  mpq_class e = (by * cz - bz * cy) * dx + (bz * cx - bx * cz) * dy + (bx * cy - by * cx) * dz;
  return sgn(e);
}

}  // namespace

OrientationReport normalize_orientation(Mesh& mesh, OrientationPolicy policy) {
  OrientationReport r;
  const int64_t nt = mesh.num_tets();
  std::vector<int8_t> sign(static_cast<size_t>(nt));
  for (int64_t t = 0; t < nt; ++t) {
    const int32_t* v = &mesh.tets[4 * t];
    auto p = [&](int i) { return geo::tc_point(mesh.points.data(), v[i]); };
    int s = orient_sign(p(0), p(1), p(2), p(3));
    sign[t] = static_cast<int8_t>(s);
    if (s > 0) ++r.positive;
    else if (s < 0) ++r.negative;
    else ++r.degenerate;
  }
  if (r.negative == 0) return r;
  if (r.positive == 0) {
    for (int64_t t = 0; t < nt; ++t) std::swap(mesh.tets[4 * t + 2], mesh.tets[4 * t + 3]);
    r.flipped_all = true;
    r.flipped = r.negative;
    return r;
  }
  if (policy == OrientationPolicy::Keep) return r;
  if (policy == OrientationPolicy::Refuse)
    throw InputError("mesh", "mixed tet orientation: " + std::to_string(r.positive) + " positive, " +
                                 std::to_string(r.negative) + " negative, " + std::to_string(r.degenerate) +
                                 " degenerate (use --fix-orientation to flip the negative ones)");
  for (int64_t t = 0; t < nt; ++t)
    if (sign[t] < 0) {
      std::swap(mesh.tets[4 * t + 2], mesh.tets[4 * t + 3]);
      ++r.flipped;
    }
  return r;
}

Mesh make_cube_mesh(int n) {
  Mesh m;
  if (n < 1) return m;
  auto id = [n](int64_t i, int64_t j, int64_t k) { return int32_t((k * (n + 1) + j) * (n + 1) + i); };
  m.points.reserve(size_t(n + 1) * (n + 1) * (n + 1) * 3);
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) m.points.insert(m.points.end(), {double(i) / n, double(j) / n, double(k) / n});
  // Each cell is cut into the 6 tets along its main diagonal: one per order in which the
  // path from corner (i,j,k) to (i+1,j+1,k+1) steps along x, y and z. Odd orders give
  // negatively oriented paths, so their last two vertices are swapped.
  static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  m.tets.reserve(size_t(n) * n * n * 24);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (const auto& p : perms) {
          int c[3] = {i, j, k};
          int32_t v[4];
          v[0] = id(i, j, k);
          for (int s = 0; s < 3; ++s) {
            c[p[s]] += 1;
            v[s + 1] = id(c[0], c[1], c[2]);
          }
          bool odd = (p[0] == 0 && p[1] == 2) || (p[0] == 1 && p[1] == 0) || (p[0] == 2 && p[1] == 1);
          if (odd) std::swap(v[2], v[3]);
          m.tets.insert(m.tets.end(), v, v + 4);
        }
  return m;
}

bool geometry_is_sound(const Mesh& mesh) {
  for (double x : mesh.points)
    if (!std::isfinite(x)) return false;
  const int64_t nv = mesh.num_vertices();
  for (int32_t v : mesh.tets)
    if (v < 0 || v >= nv) return false;
  return true;
}

void validate_structure(const Mesh& mesh, const std::string& source) {
  validate_arrays(mesh, source);
  const int64_t nv = mesh.num_vertices(), nt = mesh.num_tets();
  for (size_t i = 0; i < mesh.points.size(); ++i)
    if (!std::isfinite(mesh.points[i]))
      throw InputError(source, "vertex " + std::to_string(i / 3 + 1) + " has a non-finite coordinate");
  for (int64_t t = 0; t < nt; ++t)
    for (int k = 0; k < 4; ++k) {
      int32_t v = mesh.tets[4 * t + k];
      if (v < 0 || v >= nv)
        throw InputError(source, "tet " + std::to_string(t + 1) + " refers to vertex " + std::to_string(int64_t(v) + 1) +
                                     ", outside 1.." + std::to_string(nv));
    }
}

void validate_arrays(const Mesh& mesh, const std::string& source) {
  if (mesh.points.size() % 3 != 0) throw InputError(source, "internal: coordinate array not a multiple of 3");
  if (mesh.tets.size() % 4 != 0) throw InputError(source, "internal: tet array not a multiple of 4");
  const int64_t nv = mesh.num_vertices(), nt = mesh.num_tets();
  if (nt == 0) throw InputError(source, "the mesh has no tetrahedra");
  for (int64_t i = 0; i < static_cast<int64_t>(mesh.tris.size()); ++i)
    if (mesh.tris[i] < 0 || mesh.tris[i] >= nv)
      throw InputError(source, "triangle " + std::to_string(i / 3 + 1) + " refers to a vertex outside 1.." + std::to_string(nv));
  for (int64_t i = 0; i < static_cast<int64_t>(mesh.edges.size()); ++i)
    if (mesh.edges[i] < 0 || mesh.edges[i] >= nv)
      throw InputError(source, "edge " + std::to_string(i / 2 + 1) + " refers to a vertex outside 1.." + std::to_string(nv));
  for (const auto& l : mesh.tet_labels)
    if (static_cast<int64_t>(l.values.size()) != nt)
      throw InputError(source, "label '" + l.name + "' has " + std::to_string(l.values.size()) + " values for " +
                                   std::to_string(nt) + " tets");
  for (const auto& f : mesh.vertex_fields)
    if (f.components < 1 || static_cast<int64_t>(f.values.size()) != nv * f.components)
      throw InputError(source, "vertex field '" + f.name + "' has " + std::to_string(f.values.size()) +
                                   " values for " + std::to_string(nv) + " vertices");
  for (const auto& f : mesh.tet_fields)
    if (f.components < 1 || static_cast<int64_t>(f.values.size()) != nt * f.components)
      throw InputError(source, "tet field '" + f.name + "' has " + std::to_string(f.values.size()) + " values for " +
                                   std::to_string(nt) + " tets");
  if (mesh.tri_tags.size() != mesh.tris.size() / 3) throw InputError(source, "internal: triangle tags size mismatch");
  if (mesh.edge_tags.size() != mesh.edges.size() / 2) throw InputError(source, "internal: edge tags size mismatch");
}

double bbox_diagonal(const Mesh& mesh) {
  const int64_t nv = mesh.num_vertices();
  if (nv == 0) return 0;
  double lo[3], hi[3];
  for (int k = 0; k < 3; ++k) lo[k] = hi[k] = mesh.points[size_t(k)];
  for (int64_t v = 0; v < nv; ++v)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], mesh.points[size_t(3 * v + k)]);
      hi[k] = std::max(hi[k], mesh.points[size_t(3 * v + k)]);
    }
  return std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
}

double mean_tet_volume(const Mesh& mesh, const std::vector<uint8_t>* skip) {
  double sum = 0;
  int64_t n = 0;
  for (int64_t t = 0; t < mesh.num_tets(); ++t) {
    if (skip && (*skip)[size_t(t)]) continue;
    geo::tc_d3 p[4];
    for (size_t k = 0; k < 4; ++k) p[k] = geo::tc_point(mesh.points.data(), mesh.tets[size_t(4 * t) + k]);
    sum += std::fabs(geo::tc_tet_volume(p[0], p[1], p[2], p[3]));
    ++n;
  }
  return n > 0 ? sum / double(n) : 0;
}

}  // namespace tc
