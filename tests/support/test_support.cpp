#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <sys/wait.h>

#include "geometry.h"
#include "tetcollapse/io.hpp"
#include "tetcollapse/topology.hpp"

namespace tc::test {

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

void expect_same_mesh(const Mesh& a, const Mesh& b, const std::string& what) {
  EXPECT_TRUE(same_bits(a.points, b.points)) << "points differ " << what;
  EXPECT_EQ(a.tets, b.tets) << what;
  ASSERT_EQ(a.tet_labels.size(), b.tet_labels.size()) << what;
  for (size_t i = 0; i < a.tet_labels.size(); ++i) {
    EXPECT_EQ(a.tet_labels[i].name, b.tet_labels[i].name) << what;
    EXPECT_EQ(a.tet_labels[i].values, b.tet_labels[i].values) << a.tet_labels[i].name << " " << what;
  }
  auto same_fields = [&](const std::vector<Field>& x, const std::vector<Field>& y) {
    ASSERT_EQ(x.size(), y.size()) << what;
    for (size_t i = 0; i < x.size(); ++i) {
      EXPECT_EQ(x[i].name, y[i].name) << what;
      EXPECT_EQ(x[i].components, y[i].components) << x[i].name << " " << what;
      EXPECT_TRUE(same_bits(x[i].values, y[i].values)) << "field " << x[i].name << " differs " << what;
    }
  };
  same_fields(a.vertex_fields, b.vertex_fields);
  same_fields(a.tet_fields, b.tet_fields);
}

std::string shared_meshes_dir() {
  std::filesystem::path p(TC_SHARED_MESHES);
  std::error_code ec;
  if (std::filesystem::is_directory(p, ec)) return p.string();
  return "";
}

std::string shared_mesh(const std::string& name) {
  std::string dir = shared_meshes_dir();
  if (dir.empty()) return "";
  std::filesystem::path p = std::filesystem::path(dir) / name;
  std::error_code ec;
  return std::filesystem::exists(p, ec) ? p.string() : "";
}

std::vector<std::string> shared_volume_meshes() {
  std::vector<std::string> out;
  std::string dir = shared_meshes_dir();
  if (dir.empty()) return out;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    std::string ext = e.path().extension().string();
    if (ext == ".msh" || ext == ".mesh" || ext == ".vtk" || ext == ".vtu") out.push_back(e.path().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string project_mesh(const std::string& name) { return (std::filesystem::path(TC_PROJECT_MESHES) / name).string(); }

EnvVar::EnvVar(const char* name, const std::string& value) : name_(name) {
  if (const char* old = std::getenv(name)) {
    had_old_ = true;
    old_ = old;
  }
  ::setenv(name, value.c_str(), 1);
}

EnvVar::~EnvVar() {
  if (had_old_)
    ::setenv(name_, old_.c_str(), 1);
  else
    ::unsetenv(name_);
}

TempDir::TempDir() {
  std::random_device rd;
  path_ = std::filesystem::temp_directory_path() / ("tctest_" + std::to_string(rd()) + std::to_string(rd()));
  std::filesystem::create_directories(path_);
}
TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream o(path, std::ios::binary);
  o << text;
}

std::string read_text(const std::string& path) {
  std::ifstream i(path, std::ios::binary);
  std::stringstream s;
  s << i.rdbuf();
  return s.str();
}

Mesh single_tet() {
  Mesh m;
  m.points = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  m.tets = {0, 1, 2, 3};
  return m;
}

Mesh cube_tets(int n) { return make_cube_mesh(n); }

Mesh split_materials(int n, int axis, int32_t below, int32_t above) {
  Mesh m = cube_tets(n);
  Labels l{"material", {}};
  for (int64_t t = 0; t < m.num_tets(); ++t) {
    double c = 0;
    for (int k = 0; k < 4; ++k) c += m.points[3 * m.tets[4 * t + k] + axis] / 4;
    l.values.push_back(c > 0.5 ? above : below);
  }
  m.tet_labels.push_back(l);
  return m;
}

Mesh two_materials(int n) { return split_materials(n, 2, 1, 2); }

Mesh notched_cube(int n) {
  const Mesh cube = cube_tets(n);
  const double from = 1 - 1.0 / n;
  return sub_mesh(cube, [&](int64_t t) {
    double c[3] = {0, 0, 0};
    for (int k = 0; k < 4; ++k)
      for (int d = 0; d < 3; ++d) c[d] += cube.points[3 * size_t(cube.tets[4 * size_t(t) + size_t(k)]) + size_t(d)] / 4;
    return !(c[0] > from && c[1] > from && c[2] > from);
  });
}

Mesh sub_mesh(const Mesh& m, const std::function<bool(int64_t)>& keep) {
  Mesh out;
  std::vector<int32_t> map(size_t(m.num_vertices()), -1);
  for (int64_t t = 0; t < m.num_tets(); ++t) {
    if (!keep(t)) continue;
    for (int k = 0; k < 4; ++k) {
      int32_t& v = map[size_t(m.tets[4 * t + k])];
      if (v < 0) {
        v = int32_t(out.num_vertices());
        for (int d = 0; d < 3; ++d) out.points.push_back(m.points[3 * size_t(m.tets[4 * t + k]) + d]);
      }
      out.tets.push_back(v);
    }
  }
  return out;
}

Mesh slab(int n) {
  const Mesh c = cube_tets(n);
  return sub_mesh(c, [&](int64_t t) {
    bool low = true;
    for (int k = 0; k < 4; ++k) low = low && c.points[3 * size_t(c.tets[4 * t + k]) + 2] <= 1.0 / n + 1e-12;
    return low;
  });
}

namespace {
// cube_tets(n) moved to [-1, 1]^3 and pushed out radially: a point p goes to p / |p|_2 x |p|_inf x
// radius(p / |p|_2), so the cube's shells become the shells of the star-shaped solid `radius`
// gives the size of in each direction.
Mesh pushed_out_cube(int n, const std::function<double(const double*)>& radius) {
  Mesh m = cube_tets(n);
  for (size_t i = 0; i < m.points.size(); i += 3) {
    double p[3], inf = 0, two = 0;
    for (int c = 0; c < 3; ++c) {
      p[c] = 2 * m.points[i + size_t(c)] - 1;
      inf = std::max(inf, std::fabs(p[c]));
      two += p[c] * p[c];
    }
    two = std::sqrt(two);
    const double d[3] = {two > 0 ? p[0] / two : 0, two > 0 ? p[1] / two : 0, two > 0 ? p[2] / two : 0};
    const double r = two > 0 ? radius(d) : 0;
    for (int c = 0; c < 3; ++c) m.points[i + size_t(c)] = d[c] * inf * r;
  }
  return m;
}
}  // namespace

Mesh ball(int n) {
  return pushed_out_cube(n, [](const double*) { return 1.0; });
}

Mesh filleted_cylinder(int n, double fillet) {
  // the signed distance to the surface: a cylinder of radius and half-height 1 - fillet, grown by
  // the fillet
  const double core = 1 - fillet;
  const auto sdf = [&](const double* q) {
    const double a = std::hypot(q[0], q[1]) - core, b = std::fabs(q[2]) - core;
    return std::hypot(std::max(a, 0.0), std::max(b, 0.0)) + std::min(std::max(a, b), 0.0) - fillet;
  };
  // where the ray along d leaves the shape (convex, around the origin): bisection
  return pushed_out_cube(n, [&](const double* d) {
    double lo = 0, hi = 2;
    for (int it = 0; it < 60; ++it) {
      const double mid = (lo + hi) / 2, q[3] = {d[0] * mid, d[1] * mid, d[2] * mid};
      (sdf(q) < 0 ? lo : hi) = mid;
    }
    return lo;
  });
}

Mesh torus(int n, int ring) {
  Mesh m;
  const auto id = [&](int i, int j, int k) { return int32_t(((i % ring) * (n + 1) + j) * (n + 1) + k); };
  for (int i = 0; i < ring; ++i)
    for (int j = 0; j <= n; ++j)
      for (int k = 0; k <= n; ++k) {
        double x = 2.0 * j / n - 1, y = 2.0 * k / n - 1;
        const double inf = std::max(std::fabs(x), std::fabs(y)), two = std::hypot(x, y);
        if (two > 0) x *= inf / two, y *= inf / two;
        const double theta = 2 * std::acos(-1.0) * i / ring, r = 2 + x;
        m.points.insert(m.points.end(), {r * std::cos(theta), r * std::sin(theta), y});
      }
  // Kuhn: the six paths from corner 000 to 111 of each cell, one axis at a time (conforming
  // across cells, and across the ring's seam)
  const int order[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int i = 0; i < ring; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        for (const auto& o : order) {
          int c[3] = {i, j, k};
          std::array<int32_t, 4> t;
          t[0] = id(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[o[s]];
            t[size_t(s + 1)] = id(c[0], c[1], c[2]);
          }
          if (geo::tc_orient3d(geo::tc_point(m.points.data(), t[0]), geo::tc_point(m.points.data(), t[1]),
                               geo::tc_point(m.points.data(), t[2]), geo::tc_point(m.points.data(), t[3])) < 0)
            std::swap(t[0], t[1]);
          m.tets.insert(m.tets.end(), t.begin(), t.end());
        }
  return m;
}

Mesh cone_boundary(const Mesh& m, double x, double y, double z) {
  TopologyOptions no_labels;
  no_labels.use_labels = false;  // the boundary faces only, not material interfaces
  const Topology topo = build_topology(m, no_labels);
  Mesh out;  // points, tets and labels (a cone tet has the label of the tet it closes)
  out.points = m.points;
  out.tets = m.tets;
  out.tet_labels = m.tet_labels;
  const int32_t apex = int32_t(m.num_vertices());
  out.points.insert(out.points.end(), {x, y, z});
  auto p = [&](int32_t v) { return geo::tc_point(out.points.data(), v); };
  for (int32_t f = 0; f < topo.num_sfaces(); ++f) {
    std::array<int32_t, 4> t{topo.sfaces[3 * f], topo.sfaces[3 * f + 1], topo.sfaces[3 * f + 2], apex};
    if (geo::tc_orient3d(p(t[0]), p(t[1]), p(t[2]), p(t[3])) < 0) std::swap(t[0], t[1]);
    out.tets.insert(out.tets.end(), t.begin(), t.end());
    for (Labels& l : out.tet_labels) l.values.push_back(l.values[size_t(topo.sface_tet[f])]);
  }
  return out;
}

int run_command(const std::string& cmd, std::string* output) {
  std::string full = cmd + " 2>&1";
  FILE* p = popen(full.c_str(), "r");
  if (!p) return -1;
  std::array<char, 4096> buf;
  std::string out;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) out.append(buf.data(), n);
  int st = pclose(p);
  if (output) *output = out;
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

std::vector<uint8_t> mask_x_below(const Mesh& m, double x_max, std::set<Point3>* unselected) {
  std::vector<uint8_t> mask(size_t(m.num_vertices()), 0);
  for (int64_t v = 0; v < m.num_vertices(); ++v) {
    if (m.points[3 * v] < x_max) mask[size_t(v)] = 1;
    else if (unselected) unselected->insert({m.points[3 * v], m.points[3 * v + 1], m.points[3 * v + 2]});
  }
  return mask;
}

std::set<Point3> vertex_positions(const Mesh& m) {
  std::set<Point3> s;
  for (int64_t v = 0; v < m.num_vertices(); ++v) s.insert({m.points[3 * v], m.points[3 * v + 1], m.points[3 * v + 2]});
  return s;
}

std::pair<int64_t, int64_t> tets_kept(const Mesh& in, const Mesh& out, const std::function<bool(int64_t)>& which) {
  using Quad = std::array<Point3, 4>;
  auto quad = [](const Mesh& m, int64_t t) {
    Quad q;
    for (int k = 0; k < 4; ++k) {
      const int64_t v = m.tets[size_t(4 * t + k)];
      q[size_t(k)] = {m.points[size_t(3 * v)], m.points[size_t(3 * v + 1)], m.points[size_t(3 * v + 2)]};
    }
    std::sort(q.begin(), q.end());
    return q;
  };
  std::set<Quad> have;
  for (int64_t t = 0; t < out.num_tets(); ++t) have.insert(quad(out, t));
  std::pair<int64_t, int64_t> r{0, 0};
  for (int64_t t = 0; t < in.num_tets(); ++t)
    if (which(t)) {
      ++r.second;
      r.first += have.count(quad(in, t)) > 0;
    }
  return r;
}

Mesh two_material_bracket() {
  Mesh m = read_mesh(project_mesh("bracket.msh"));
  m.tet_labels.clear();
  m.tet_fields.clear();
  m.vertex_fields.clear();
  double cx = 0;
  for (int64_t v = 0; v < m.num_vertices(); ++v) cx += m.points[size_t(3 * v)] / double(m.num_vertices());
  Labels lab{"material", {}};
  for (int64_t t = 0; t < m.num_tets(); ++t) {
    double x = 0;
    for (int k = 0; k < 4; ++k) x += m.points[size_t(3 * m.tets[size_t(4 * t + k)])] / 4;
    lab.values.push_back(x < cx ? 7 : 9);
  }
  m.tet_labels.push_back(lab);
  return m;
}

std::vector<std::pair<std::string, std::function<bool(int64_t)>>> restricted_runs(const Mesh& in) {
  const auto outside_region = [&in](int64_t t) {
    for (int k = 0; k < 4; ++k)
      if (in.points[size_t(3 * in.tets[size_t(4 * t + k)])] <= 2) return false;
    return true;
  };
  const auto label_9 = [&in](int64_t t) { return in.tet_labels[0].values[size_t(t)] == 9; };
  return {{"--region box:0,0,0,2,2,1.3", outside_region}, {"--labels 7", label_9}};
}

std::set<std::array<int32_t, 3>> sface_keys(const Mesh& m) {
  const Topology t = build_topology(m);
  std::set<std::array<int32_t, 3>> faces;
  for (int32_t f = 0; f < t.num_sfaces(); ++f) {
    std::array<int32_t, 3> k{t.sfaces[3 * f], t.sfaces[3 * f + 1], t.sfaces[3 * f + 2]};
    std::sort(k.begin(), k.end());
    faces.insert(k);
  }
  return faces;
}

std::vector<size_t> triangles_off_surface(const Mesh& m) {
  const std::set<std::array<int32_t, 3>> faces = sface_keys(m);
  std::vector<size_t> off;
  for (size_t i = 0; 3 * i + 2 < m.tris.size(); ++i) {
    std::array<int32_t, 3> k{m.tris[3 * i], m.tris[3 * i + 1], m.tris[3 * i + 2]};
    std::sort(k.begin(), k.end());
    if (!faces.count(k)) off.push_back(i);
  }
  return off;
}

}  // namespace tc::test
