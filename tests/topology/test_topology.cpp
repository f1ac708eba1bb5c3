// The single-threaded connectivity and classification (host/topology/topology.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "geometry.h"
#include "test_support.hpp"
#include "tetcollapse/error.hpp"
#include "tetcollapse/topology.hpp"
#include "topology/topology_detail.hpp"
#include "topology_checks.hpp"

using namespace tc;
using tc::test::check_invariants;

namespace {

geo::tc_d3 pt(const Mesh& m, int32_t v) { return geo::tc_point(m.points.data(), v); }

// A cylinder of radius 1 and height 1 around the z axis: a disk (centre, a ring of m points at
// radius 0.5 and one of m points at radius 1) extruded in nz layers. Each prism is split into
// three tets by the vertex-index rule (the diagonal of every quad runs from its lower-index
// bottom corner to its higher-index top corner), which two prisms sharing a quad agree on.
Mesh cylinder(int m, int nz) {
  Mesh mesh;
  const int per_layer = 1 + 2 * m;
  for (int k = 0; k <= nz; ++k) {
    const double z = double(k) / nz;
    mesh.points.insert(mesh.points.end(), {0.0, 0.0, z});
    for (int ring = 1; ring <= 2; ++ring)
      for (int i = 0; i < m; ++i) {
        const double a = 2 * M_PI * i / m, r = 0.5 * ring;
        mesh.points.insert(mesh.points.end(), {r * std::cos(a), r * std::sin(a), z});
      }
  }
  std::vector<std::array<int, 3>> tris;
  auto inner = [&](int i) { return 1 + (i % m); };
  auto outer = [&](int i) { return 1 + m + (i % m); };
  for (int i = 0; i < m; ++i) {
    tris.push_back({0, inner(i), inner(i + 1)});
    tris.push_back({inner(i), outer(i), outer(i + 1)});
    tris.push_back({inner(i), outer(i + 1), inner(i + 1)});
  }
  for (int k = 0; k < nz; ++k)
    for (auto tri : tris) {
      std::sort(tri.begin(), tri.end());
      const int32_t a = tri[0] + k * per_layer, b = tri[1] + k * per_layer, c = tri[2] + k * per_layer;
      const int32_t A = a + per_layer, B = b + per_layer, C = c + per_layer;
      const int32_t tets[3][4] = {{a, b, c, C}, {a, b, B, C}, {a, A, B, C}};
      for (const auto& t : tets) {
        int32_t v[4] = {t[0], t[1], t[2], t[3]};
        if (geo::tc_orient3d(pt(mesh, v[0]), pt(mesh, v[1]), pt(mesh, v[2]), pt(mesh, v[3])) < 0) std::swap(v[2], v[3]);
        mesh.tets.insert(mesh.tets.end(), v, v + 4);
      }
    }
  return mesh;
}

int count_class(const Topology& t, VertexClass c) {
  return int(std::count(t.vertex_class.begin(), t.vertex_class.end(), uint8_t(c)));
}

}  // namespace

TEST(Topology, SingleTet) {
  Mesh m = test::single_tet();
  Topology t = build_topology(m);
  check_invariants(m, t);
  EXPECT_EQ(t.num_edges(), 6);
  EXPECT_EQ(t.num_sfaces(), 4);
  EXPECT_EQ(count_class(t, VertexClass::Corner), 4);
  EXPECT_EQ(std::count(t.edge_ridge.begin(), t.edge_ridge.end(), 1), 6);
  for (uint8_t b : t.vertex_boundary) EXPECT_EQ(b, kOnBoundary);
  for (uint8_t b : t.edge_boundary) EXPECT_EQ(b, kOnBoundary);
}

TEST(Topology, CubeCountsAndClassification) {
  for (int n : {1, 2, 4, 5}) {
    SCOPED_TRACE("n = " + std::to_string(n));
    Mesh m = test::cube_tets(n);
    Topology t = build_topology(m);
    check_invariants(m, t);
    const int64_t V = m.num_vertices(), T = m.num_tets(), E = t.num_edges(), B = t.num_sfaces();
    EXPECT_EQ(B, 2 * 6 * n * n);
    ASSERT_EQ((4 * T + B) % 2, 0);
    const int64_t F = (4 * T + B) / 2;  // interior faces counted twice by 4T, boundary once
    EXPECT_EQ(V - E + F - T, 1);
    // closed surface: area-weighted normals sum to zero; total area 6
    double sx = 0, sy = 0, sz = 0, area = 0;
    for (int32_t s = 0; s < t.num_sfaces(); ++s) {
      const geo::tc_d3 an = geo::tc_triangle_normal(pt(m, t.sfaces[3 * s]), pt(m, t.sfaces[3 * s + 1]),
                                                     pt(m, t.sfaces[3 * s + 2]));
      sx += an.x, sy += an.y, sz += an.z, area += 0.5 * geo::length(an);
    }
    EXPECT_NEAR(sx, 0, 1e-12);
    EXPECT_NEAR(sy, 0, 1e-12);
    EXPECT_NEAR(sz, 0, 1e-12);
    EXPECT_NEAR(area, 6.0, 1e-12);
    EXPECT_EQ(count_class(t, VertexClass::Corner), 8);
    EXPECT_EQ(count_class(t, VertexClass::Ridge), 12 * (n - 1));
    EXPECT_EQ(count_class(t, VertexClass::Face), 6 * (n - 1) * (n - 1));
    EXPECT_EQ(count_class(t, VertexClass::Interior), (n - 1) * (n - 1) * (n - 1));
    // each vertex by its position: number of coordinates on {0, 1} gives its class
    for (int32_t v = 0; v < t.num_vertices; ++v) {
      int on = 0;
      for (int k = 0; k < 3; ++k) on += m.points[3 * v + k] == 0.0 || m.points[3 * v + k] == 1.0;
      const VertexClass want[4] = {VertexClass::Interior, VertexClass::Face, VertexClass::Ridge, VertexClass::Corner};
      ASSERT_EQ(t.vertex_class[v], uint8_t(want[on])) << "vertex " << v;
    }
    // ridge edges are exactly the segments on the 12 cube edges
    int ridge = 0;
    for (int32_t e = 0; e < t.num_edges(); ++e) {
      int both = 0;  // coordinates on {0,1} shared by both ends
      for (int k = 0; k < 3; ++k) {
        double a = m.points[3 * t.edges[2 * e] + k], b = m.points[3 * t.edges[2 * e + 1] + k];
        both += a == b && (a == 0.0 || a == 1.0);
      }
      ASSERT_EQ(t.edge_ridge[e], both >= 2 ? 1 : 0) << "edge " << e;
      ridge += t.edge_ridge[e];
      ASSERT_EQ(t.edge_boundary[e] != 0, both >= 1) << "edge " << e;
    }
    EXPECT_EQ(ridge, 12 * n);
    TopologySummary s = summarize(m, t);
    EXPECT_EQ(s.ridge_edges, 12 * n);
    EXPECT_EQ(s.corner_vertices, 8);
    EXPECT_EQ(s.boundary_faces, 12 * n * n);
    EXPECT_EQ(s.interface_faces, 0);
    EXPECT_NEAR(s.total_volume, 1.0, 1e-12);
    EXPECT_NEAR(s.edge_length_min, 1.0 / n, 1e-12);
    EXPECT_NEAR(s.edge_length_max, std::sqrt(3.0) / n, 1e-12);
    EXPECT_NEAR(s.min_dihedral_deg, 45.0, 1e-9);  // Kuhn tets: 45, 60 and 90 degrees
    EXPECT_NEAR(s.max_dihedral_deg, 90.0, 1e-9);
  }
}

TEST(Topology, Cylinder) {
  const int m = 64, nz = 3;  // 1 - cos(2 pi / 64) = 0.0048 <= eps_F: the side is smooth enough
  Mesh mesh = cylinder(m, nz);
  Topology t = build_topology(mesh);
  check_invariants(mesh, t);
  EXPECT_EQ(count_class(t, VertexClass::Corner), 0);
  EXPECT_EQ(count_class(t, VertexClass::Ridge), 2 * m);
  EXPECT_EQ(count_class(t, VertexClass::Face), 2 * (1 + m) + m * (nz - 1));
  EXPECT_EQ(count_class(t, VertexClass::Interior), (1 + m) * (nz - 1));
  for (int32_t v = 0; v < t.num_vertices; ++v) {
    const double x = mesh.points[3 * v], y = mesh.points[3 * v + 1], z = mesh.points[3 * v + 2];
    const bool rim = std::abs(std::hypot(x, y) - 1.0) < 1e-9, cap = z == 0.0 || z == 1.0;
    const VertexClass want = rim && cap ? VertexClass::Ridge : (rim || cap) ? VertexClass::Face : VertexClass::Interior;
    ASSERT_EQ(t.vertex_class[v], uint8_t(want)) << "vertex " << v << " at " << x << " " << y << " " << z;
  }
  int ridge = 0;
  for (int32_t e = 0; e < t.num_edges(); ++e) {
    if (!t.edge_ridge[e]) continue;
    ++ridge;
    for (int k = 0; k < 2; ++k) ASSERT_EQ(t.vertex_class[t.edges[2 * e + k]], uint8_t(VertexClass::Ridge));
  }
  EXPECT_EQ(ridge, 2 * m);  // the two rims
  TopologySummary s = summarize(mesh, t);
  EXPECT_NEAR(s.total_volume, 0.5 * m * std::sin(2 * M_PI / m), 1e-12);  // the inscribed polygon prism
}

TEST(Topology, CoarseCylinderSideNeedsLargerEpsF) {
  // 32 segments: adjacent side facets differ by 1 - cos(2 pi / 32) = 0.019, more than
  // eps_F = 0.01 but less than eps_R = 0.1: the side vertices are curved "corners" with the
  // paper's thresholds, and become face vertices with eps_F = 0.03. The rims stay ridges.
  const int m = 32, nz = 2;
  Mesh mesh = cylinder(m, nz);
  Topology strict = build_topology(mesh);
  EXPECT_EQ(count_class(strict, VertexClass::Ridge), 2 * m);
  EXPECT_EQ(count_class(strict, VertexClass::Corner), m * (nz - 1));
  TopologyOptions loose;
  loose.eps_f = 0.03;
  Topology t = build_topology(mesh, loose);
  EXPECT_EQ(count_class(t, VertexClass::Ridge), 2 * m);
  EXPECT_EQ(count_class(t, VertexClass::Corner), 0);
  EXPECT_EQ(count_class(t, VertexClass::Face), 2 * (1 + m) + m * (nz - 1));
  // a large eps_R turns the rims into smooth edges: 1 - dot = 1 there, so eps_R = 1.5 hides them
  TopologyOptions no_ridges;
  no_ridges.eps_r = 1.5;
  Topology r = build_topology(mesh, no_ridges);
  EXPECT_EQ(std::count(r.edge_ridge.begin(), r.edge_ridge.end(), 1), 0);
  EXPECT_EQ(count_class(r, VertexClass::Ridge), 0);
}

TEST(Topology, TwoMaterialBlock) {
  const int n = 4;
  Mesh m = test::split_materials(n, 0, 7, 3);
  Topology t = build_topology(m);
  check_invariants(m, t);
  int iface = 0;
  for (int32_t s = 0; s < t.num_sfaces(); ++s) {
    if (!t.sface_interface[s]) continue;
    ++iface;
    for (int k = 0; k < 3; ++k) ASSERT_EQ(m.points[3 * t.sfaces[3 * s + k]], 0.5);
    // owned by the smaller label (3, the x > 0.5 side), normal into label 7: -x
    EXPECT_EQ(m.tet_labels[0].values[t.sface_tet[s]], 3);
    EXPECT_NEAR(t.sface_normals[3 * s], -1.0, 1e-15);
  }
  EXPECT_EQ(iface, 2 * n * n);
  EXPECT_EQ(t.num_sfaces() - iface, 12 * n * n);
  // Expected classes: the interface plane x = 0.5 is one more feature sheet. Its interior
  // vertices are face vertices; where it meets a cube face, the edges have three S-faces
  // (non-manifold) and are ridges; where it crosses a cube edge, four ridges meet: corner.
  for (int32_t v = 0; v < t.num_vertices; ++v) {
    const double* p = &m.points[3 * v];
    int on = 0;
    for (int k = 0; k < 3; ++k) on += p[k] == 0.0 || p[k] == 1.0;
    const bool mid = p[0] == 0.5;
    VertexClass want;
    if (!mid) want = on == 0 ? VertexClass::Interior : on == 1 ? VertexClass::Face : on == 2 ? VertexClass::Ridge : VertexClass::Corner;
    else want = on == 0 ? VertexClass::Face : on == 1 ? VertexClass::Ridge : VertexClass::Corner;
    ASSERT_EQ(t.vertex_class[v], uint8_t(want)) << "vertex " << v << " at " << p[0] << " " << p[1] << " " << p[2];
    const uint8_t bits = (on ? kOnBoundary : 0) | (mid ? kOnInterface : 0);
    ASSERT_EQ(t.vertex_boundary[v], bits) << "vertex " << v;
  }
  EXPECT_EQ(count_class(t, VertexClass::Corner), 12);
  EXPECT_EQ(count_class(t, VertexClass::Ridge), 12 * (n - 1) - 4 + 4 * (n - 1));
  EXPECT_EQ(std::count(t.edge_ridge.begin(), t.edge_ridge.end(), 1), 12 * n + 4 * n);
  // Without labels the interface disappears.
  TopologyOptions nolabels;
  nolabels.use_labels = false;
  Topology u = build_topology(m, nolabels);
  EXPECT_EQ(u.num_sfaces(), 12 * n * n);
  EXPECT_EQ(count_class(u, VertexClass::Corner), 8);
}

TEST(Topology, RadixSortIsStableAndSorted) {
  std::vector<topology_detail::KeyPayload> a;
  uint64_t x = 88172645463325252ull;
  for (uint32_t i = 0; i < 100000; ++i) {
    x ^= x << 13, x ^= x >> 7, x ^= x << 17;
    a.push_back({(x % 1000) << 40 | (x >> 60), i});
  }
  auto b = a;
  std::stable_sort(b.begin(), b.end(), [](auto& p, auto& q) { return p.key < q.key; });
  topology_detail::radix_sort(a);
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].key, b[i].key);
    ASSERT_EQ(a[i].payload, b[i].payload);
  }
}

TEST(Topology, RejectsBadTets) {
  Mesh m = test::single_tet();
  m.tets[2] = 4;
  EXPECT_THROW(build_topology(m), InputError);
  m.tets[2] = -1;
  EXPECT_THROW(build_topology(m), InputError);
  m.tets[2] = 1;
  try {
    build_topology(m);
    FAIL() << "repeated vertex accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("repeats vertex 1"), std::string::npos) << e.what();
  }
  Mesh empty;
  Topology t = build_topology(empty);
  EXPECT_EQ(t.num_edges(), 0);
  EXPECT_EQ(t.vertex_tets_offsets.size(), 1u);
}
