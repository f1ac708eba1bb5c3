// Stage 1 (device connectivity of an iteration) against the CPU reference tc::build_topology.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <map>
#include <string>

#include "collapse/stages.hpp"
#include "geometry.h"
#include "tetcollapse/io.hpp"
#include "tetcollapse/topology.hpp"
#include "test_support.hpp"

using namespace tc;
using namespace tc::collapse_detail;

namespace {

// A cube of cube_tets(n) with the upper half (z > 0.5 at the centroid) labelled 2, the rest 1.
Mesh two_materials(int n) {
  Mesh m = test::cube_tets(n);
  Labels l{"material", {}};
  for (int64_t t = 0; t < m.num_tets(); ++t) {
    double z = 0;
    for (int k = 0; k < 4; ++k) z += m.points[3 * m.tets[4 * t + k] + 2];
    l.values.push_back(z / 4 > 0.5 ? 2 : 1);
  }
  m.tet_labels.push_back(l);
  return m;
}

// tet_nbr as collapse_common.h defines it, by a map of the faces' sorted vertex triples: the
// tet across face f (opposite local vertex f), -1 when none, -2 when several.
std::vector<int32_t> reference_tet_nbr(const Mesh& mesh) {
  std::map<std::array<int32_t, 3>, std::vector<int32_t>> tets_of_face;
  auto face = [&](int64_t t, int f) {
    std::array<int32_t, 3> k;
    for (int i = 0, n = 0; i < 4; ++i)
      if (i != f) k[n++] = mesh.tets[4 * t + i];
    std::sort(k.begin(), k.end());
    return k;
  };
  for (int64_t t = 0; t < mesh.num_tets(); ++t)
    for (int f = 0; f < 4; ++f) tets_of_face[face(t, f)].push_back(int32_t(t));
  std::vector<int32_t> nbr;
  for (int64_t t = 0; t < mesh.num_tets(); ++t)
    for (int f = 0; f < 4; ++f) {
      const std::vector<int32_t>& all = tets_of_face[face(t, f)];
      nbr.push_back(all.size() == 1 ? -1 : all.size() == 2 ? (all[0] == t ? all[1] : all[0]) : -2);
    }
  return nbr;
}

std::vector<int32_t> device_tet_nbr(Context& ctx, const Mesh& mesh) {
  CollapseOptions o;
  DeviceMesh dm;
  upload_mesh(ctx, mesh, o, dm);
  Connectivity c;
  build_connectivity(ctx, dm, c, params_from(o));
  return c.tet_nbr.download_range(0, 4 * size_t(dm.nt));
}

// What build_connectivity must reproduce: tc::build_topology's arrays (with the same thresholds
// and label option) and reference_tet_nbr.
struct Reference {
  Topology topo;
  std::vector<int32_t> tet_nbr;
  TopologyOptions opt;
};

Reference reference(const Mesh& mesh, const TopologyOptions& opt = {}) {
  return {build_topology(mesh, opt), reference_tet_nbr(mesh), opt};
}

// TCC_MAX_VERTEX_SFACES (cl/collapse_common.h) as the kernels are built by default.
constexpr int kMaxVertexSfaces = 64;

// max_vertex_sfaces: TCC_MAX_VERTEX_SFACES as the program is built. A vertex with more S-faces
// is a corner (conn_surface_flags: that only protects it more; its edges' flags come from ring
// scans and still equal the reference's); every other vertex has its reference class. Below
// the default (a test builds the program with a small cap), some vertices must be capped.
// device_rings: the rings by the device's count, scatter and sort (a GPU's way) even when the
// upload filled them on the host (a CPU device's).
// What the product does not keep (tet -> edges, edge -> tets, the S-face normals and the
// vertex / edge -> S-face lists) is not compared; the S-faces are, through smask and owns_s.
void compare_with(Context& ctx, const Mesh& mesh, const Reference& r, int max_vertex_sfaces = kMaxVertexSfaces,
                  bool device_rings = false) {
  CollapseOptions o;
  o.use_labels = r.opt.use_labels;
  o.eps_f = r.opt.eps_f;
  o.eps_r = r.opt.eps_r;
  StageParams p = params_from(o);
  DeviceMesh dm;
  upload_mesh(ctx, mesh, o, dm);
  EXPECT_EQ(dm.has_rings, ctx.cpu_tuning());
  if (device_rings) dm.has_rings = false;
  Connectivity c;
  build_connectivity(ctx, dm, c, p);
  const Topology& ref = r.topo;

  ASSERT_EQ(int64_t(dm.nv), int64_t(ref.num_vertices));
  ASSERT_EQ(int64_t(dm.nt), int64_t(ref.num_tets));
  ASSERT_EQ(int64_t(c.ne), int64_t(ref.num_edges()));
  EXPECT_EQ(c.edges.download_range(0, 2 * size_t(c.ne)), ref.edges);
  EXPECT_EQ(c.vt_off.download_range(0, dm.nv + 1),
            std::vector<uint32_t>(ref.vertex_tets_offsets.begin(), ref.vertex_tets_offsets.end()));
  EXPECT_EQ(c.vt.download_range(0, 4 * size_t(dm.nt)), ref.vertex_tets);
  // vertex -> edges: the same sets (our list is ordered by neighbour, the reference by edge id)
  std::vector<uint32_t> nb_off = c.nb_off.download_range(0, dm.nv + 1);
  EXPECT_EQ(nb_off, std::vector<uint32_t>(ref.vertex_edges_offsets.begin(), ref.vertex_edges_offsets.end()));
  std::vector<int32_t> nb_edge = c.nb_edge.download_range(0, nb_off.back());
  std::vector<int32_t> nb = c.nb.download_range(0, nb_off.back());
  for (int32_t v = 0; v < ref.num_vertices; ++v) {
    std::vector<int32_t> mine(nb_edge.begin() + nb_off[v], nb_edge.begin() + nb_off[v + 1]);
    std::sort(mine.begin(), mine.end());
    std::vector<int32_t> theirs(ref.vertex_edges.begin() + ref.vertex_edges_offsets[v],
                                ref.vertex_edges.begin() + ref.vertex_edges_offsets[v + 1]);
    ASSERT_EQ(mine, theirs) << "vertex " << v;
    ASSERT_TRUE(std::is_sorted(nb.begin() + nb_off[v], nb.begin() + nb_off[v + 1])) << "N(" << v << ") not ascending";
    for (uint32_t k = nb_off[v]; k < nb_off[v + 1]; ++k) {
      int32_t e = nb_edge[k];
      int32_t u = nb[k];
      ASSERT_TRUE((ref.edges[2 * e] == v && ref.edges[2 * e + 1] == u) || (ref.edges[2 * e] == u && ref.edges[2 * e + 1] == v));
    }
  }
  std::vector<uint8_t> eflags = c.eflags.download_range(0, c.ne), vflags = c.vflags.download_range(0, dm.nv),
                       vclass = c.vclass.download_range(0, dm.nv);
  for (int32_t e = 0; e < ref.num_edges(); ++e) {
    ASSERT_EQ(eflags[e] & 3, ref.edge_boundary[e]) << "edge " << e;
    ASSERT_EQ((eflags[e] >> 2) & 1, ref.edge_ridge[e]) << "edge " << e;
  }
  EXPECT_EQ(vflags, ref.vertex_boundary);
  {
    ASSERT_EQ(vclass.size(), ref.vertex_class.size());
    std::vector<uint8_t> expected = ref.vertex_class;
    int capped = 0;
    for (int32_t v = 0; v < ref.num_vertices; ++v)
      if (ref.vertex_sfaces_offsets[v + 1] - ref.vertex_sfaces_offsets[v] > max_vertex_sfaces) {
        capped += expected[v] != uint8_t(VertexClass::Corner) ? 1 : 0;
        expected[v] = uint8_t(VertexClass::Corner);
      }
    for (int32_t v = 0; v < ref.num_vertices; ++v) {
      ASSERT_EQ(int(vclass[v]), int(expected[v]))
          << "vertex " << v << " (reference class " << int(ref.vertex_class[v]) << ", "
          << ref.vertex_sfaces_offsets[v + 1] - ref.vertex_sfaces_offsets[v] << " S-faces)";
    }
    if (max_vertex_sfaces < kMaxVertexSfaces) {
      EXPECT_GT(capped, 0) << "no vertex above the cap";
    }
  }
  const std::vector<int32_t> tet_nbr = c.tet_nbr.download_range(0, 4 * size_t(dm.nt));
  EXPECT_EQ(tet_nbr, r.tet_nbr);
  // The S-faces (reference: sfaces, sface_tet, sface_local, sface_interface): each one owned by
  // the reference's tet at the reference's local face (smask), no other (owns_s, the count);
  // oriented as the reference's (TC_TET_FACES of the owner); an interface face where tet_nbr
  // has a tet across, a boundary face where it has none.
  const std::vector<uint8_t> smask = c.smask.download_range(0, dm.nt);
  const std::vector<uint32_t> owns_s = c.owns_s.download_range(0, dm.nt);
  const std::vector<int32_t> tets = dm.tets.download_range(0, 4 * size_t(dm.nt));
  int64_t owned = 0;
  for (uint32_t t = 0; t < dm.nt; ++t) {
    ASSERT_LT(smask[t], 16) << "tet " << t;
    ASSERT_EQ(owns_s[t], smask[t] != 0 ? 1u : 0u) << "tet " << t;
    for (int f = 0; f < 4; ++f) owned += (smask[t] >> f) & 1;
  }
  ASSERT_EQ(owned, int64_t(ref.num_sfaces()));
  for (int32_t s = 0; s < ref.num_sfaces(); ++s) {
    const int32_t t = ref.sface_tet[s];
    const int f = ref.sface_local[s];
    ASSERT_TRUE((smask[t] >> f) & 1) << "S-face " << s << " (tet " << t << ", face " << f << ") not owned";
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(tets[4 * size_t(t) + geo::TC_TET_FACES[f][k]], ref.sfaces[3 * size_t(s) + k]) << "S-face " << s;
    ASSERT_EQ(tet_nbr[4 * size_t(t) + f] >= 0, ref.sface_interface[s] != 0) << "S-face " << s;
  }
}

void compare_with_reference(Context& ctx, const Mesh& mesh, int max_vertex_sfaces = kMaxVertexSfaces,
                            bool device_rings = false, const TopologyOptions& opt = {}) {
  compare_with(ctx, mesh, reference(mesh, opt), max_vertex_sfaces, device_rings);
}

// compare_with for several work-group sizes (the first again at the end: the same result
// twice), the rings by the upload and by the device for each.
void compare_work_group_sizes(Context& ctx, const Mesh& mesh, const TopologyOptions& opt = {},
                              std::initializer_list<size_t> sizes = {64, 8, 64}) {
  const Reference r = reference(mesh, opt);
  for (size_t wg : sizes) {
    ctx.set_work_group_size(wg);
    for (bool device_rings : {false, true}) {
      SCOPED_TRACE("work-group size " + std::to_string(wg) + (device_rings ? ", device rings" : ", upload's rings"));
      compare_with(ctx, mesh, r, kMaxVertexSfaces, device_rings);
    }
    if (::testing::Test::HasFailure()) break;
  }
  ctx.set_work_group_size(0);
}

// cube_tets(n) with the tets of centroid x < 0.5 labelled 2, the others 1: the interface faces
// owned by the tets on the x > 0.5 side (the smaller label), unlike two_materials.
Mesh two_materials_x(int n) { return test::split_materials(n, 0, 2, 1); }

}  // namespace

TEST(CollapseConnectivity, CubeMatchesBuildTopology) {
  Context ctx;
  for (bool device_rings : {false, true}) {
    SCOPED_TRACE(device_rings ? "device rings" : "upload's rings");
    compare_with_reference(ctx, test::cube_tets(4), kMaxVertexSfaces, device_rings);
  }
}

TEST(CollapseConnectivity, MaterialInterfaceMatchesBuildTopology) {
  Context ctx;
  Mesh m = two_materials(4);
  compare_with_reference(ctx, m);
  compare_with_reference(ctx, m, kMaxVertexSfaces, true);
  Topology ref = build_topology(m);
  int interface_vertices = 0;
  for (uint8_t b : ref.vertex_boundary) interface_vertices += (b & kOnInterface) ? 1 : 0;
  EXPECT_EQ(interface_vertices, 25);  // the z = 0.5 plane of a 4 x 4 x 4 grid
}

TEST(CollapseConnectivity, IndependentOfWorkGroupSize) {
  Context ctx;
  Mesh m = two_materials(3);
  std::vector<int32_t> first;
  for (size_t wg : {1, 8, 64}) {
    ctx.set_work_group_size(wg);
    CollapseOptions o;
    DeviceMesh dm;
    upload_mesh(ctx, m, o, dm);
    Connectivity c;
    build_connectivity(ctx, dm, c, params_from(o));
    std::vector<int32_t> all = c.vt.download_range(0, 4 * size_t(dm.nt));
    std::vector<int32_t> nb = c.nb.download();
    all.insert(all.end(), nb.begin(), nb.end());
    if (first.empty()) first = all;
    EXPECT_EQ(all, first) << "work-group size " << wg;
  }
}

// The face matching of conn_tet_neighbours on an invalid input: a face in three tets is -2 on
// each side, also when the vertex's private face list overflows (capped at 1, TCC_MAX_MIN_FACES)
// and its faces take the ring scan.
TEST(CollapseConnectivity, TetNeighboursOfAFaceInThreeTets) {
  Mesh m;
  m.points = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 1, 1, -1};
  m.tets = {0, 1, 2, 3, 0, 2, 1, 4, 0, 1, 2, 5};  // face (0, 1, 2) in all three
  const std::vector<int32_t> expected = reference_tet_nbr(m);
  ASSERT_EQ(std::count(expected.begin(), expected.end(), -2), 3);
  {
    Context ctx;
    EXPECT_EQ(device_tet_nbr(ctx, m), expected);
  }
  test::EnvVar cap("TETCOLLAPSE_CL_OPTIONS", "-DTCC_MAX_MIN_FACES=1");
  Context ctx;  // builds its programs with the cap
  EXPECT_EQ(device_tet_nbr(ctx, m), expected);
}

// The private lists of the connectivity kernels capped at 4 entries (a ring, N(v), the faces a
// vertex matches) and the gather's bitmap at 32 ids, so that most vertices take the fallbacks:
// insertion sort and gather in the global scratch (conn_ring_sort_and_gather), the ring scan per
// face (conn_tet_neighbours).
TEST(CollapseConnectivity, SmallListCapsTakeTheFallbacks) {
  test::EnvVar cap("TETCOLLAPSE_CL_OPTIONS", "-DTCC_MAX_NB=4 -DTCC_MAX_MIN_FACES=4 -DTCC_GATHER_BITS=32");
  Context ctx;
  {
    SCOPED_TRACE("cube");
    compare_with_reference(ctx, test::cube_tets(3));
  }
  SCOPED_TRACE("two materials");
  compare_with_reference(ctx, two_materials(3));
}

// More than TCC_MAX_VERTEX_SFACES (capped at 2) owned S-faces at a vertex: conn_surface_flags
// makes it a corner and takes the flags of the edges it owns from ring scans (tcc_edge_flags_of),
// which must still equal the reference, ridges and interfaces included.
TEST(CollapseConnectivity, SurfaceFlagsFallbackWhenTheFaceListOverflows) {
  test::EnvVar cap("TETCOLLAPSE_CL_OPTIONS", "-DTCC_MAX_VERTEX_SFACES=2");
  Context ctx;
  {
    SCOPED_TRACE("cube");
    compare_with_reference(ctx, test::cube_tets(3), 2);
  }
  SCOPED_TRACE("two materials");
  compare_with_reference(ctx, two_materials(3), 2);
}

// Every shared volume mesh up to 300k tets (bench_connectivity times the larger ones), for two
// work-group sizes with the device's rings, and with the upload's. (The robot 283k has a vertex
// with 68 S-faces, above TCC_MAX_VERTEX_SFACES: a corner here, a face vertex in the reference.)
TEST(CollapseConnectivity, SharedMeshesMatchBuildTopology) {
  TC_SKIP_IF_NO_SHARED();
  Context ctx;
  int done = 0;
  for (const std::string& path : test::shared_volume_meshes()) {
    Mesh m = read_mesh(path);  // every shared mesh must load (tests/io checks the counts)
    if (m.num_tets() > 300000) {
      std::printf("[ skipped  ] %s: %lld tets, compared by bench_connectivity instead\n", path.c_str(),
                  (long long)m.num_tets());
      continue;
    }
    SCOPED_TRACE(path);
    const Reference r = reference(m);
    for (size_t wg : {size_t(128), size_t(16)}) {
      SCOPED_TRACE("work-group size " + std::to_string(wg) + ", device rings");
      ctx.set_work_group_size(wg);
      compare_with(ctx, m, r, kMaxVertexSfaces, true);
    }
    ctx.set_work_group_size(0);
    {
      SCOPED_TRACE("default work-group size, upload's rings");
      compare_with(ctx, m, r);
    }
    if (HasFailure()) break;
    ++done;
  }
  EXPECT_GT(done, 0) << "no shared mesh compared";
}

TEST(CollapseConnectivity, SingleTetAndEmptyMesh) {
  Context ctx;
  {
    SCOPED_TRACE("single tet");
    compare_work_group_sizes(ctx, test::single_tet());
  }
  SCOPED_TRACE("two unused vertices, no tets");
  Mesh empty;
  empty.points = {0, 0, 0, 1, 1, 1};
  compare_work_group_sizes(ctx, empty);
}

TEST(CollapseConnectivity, CubesAndTheirClasses) {
  Context ctx;
  for (int n : {1, 3, 8}) {
    SCOPED_TRACE("cube " + std::to_string(n));
    compare_work_group_sizes(ctx, test::cube_tets(n));
  }
  // the classes of the device's own arrays: 8 corners, 12 ridges of 6 edges and 5 inner
  // vertices, 6 faces of 5 x 5 inner vertices
  Mesh m = test::cube_tets(6);
  CollapseOptions o;
  DeviceMesh dm;
  upload_mesh(ctx, m, o, dm);
  Connectivity c;
  build_connectivity(ctx, dm, c, params_from(o));
  const std::vector<uint8_t> vclass = c.vclass.download_range(0, dm.nv), eflags = c.eflags.download_range(0, c.ne);
  auto count_class = [&](VertexClass k) { return std::count(vclass.begin(), vclass.end(), uint8_t(k)); };
  EXPECT_EQ(count_class(VertexClass::Corner), 8);
  EXPECT_EQ(count_class(VertexClass::Ridge), 12 * 5);
  EXPECT_EQ(count_class(VertexClass::Face), 6 * 25);
  EXPECT_EQ(std::count_if(eflags.begin(), eflags.end(), [](uint8_t f) { return (f >> 2) & 1; }), 12 * 6);
}

// Labels on and off, and other thresholds, with the interface owned by the +x side.
TEST(CollapseConnectivity, LabelsAndThresholdOptions) {
  Context ctx;
  Mesh m = two_materials_x(4);
  {
    SCOPED_TRACE("defaults");
    compare_work_group_sizes(ctx, m);
  }
  TopologyOptions opt;
  opt.use_labels = false;
  {
    SCOPED_TRACE("use_labels false");
    compare_work_group_sizes(ctx, m, opt);
  }
  opt.use_labels = true;
  opt.eps_r = 1.5;
  opt.eps_f = 0.5;
  SCOPED_TRACE("eps_r 1.5, eps_f 0.5");
  compare_work_group_sizes(ctx, m, opt);
}

// A tet with an index out of range or a repeated vertex never reaches the device.
TEST(CollapseConnectivity, UploadRejectsBadTets) {
  Context ctx;
  Mesh m = test::cube_tets(2);
  m.tets[4 * 17 + 2] = 1000;
  CollapseOptions o;
  DeviceMesh dm;
  try {
    upload_mesh(ctx, m, o, dm);
    FAIL() << "index out of range accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("tet 17 has vertex index 1000"), std::string::npos) << e.what();
  }
  m.tets[4 * 17 + 2] = m.tets[4 * 17];
  EXPECT_THROW(upload_mesh(ctx, m, o, dm), InputError);
}

// Connectivity carried from the previous iteration (build_connectivity with the EdgeState after
// note_compaction) equals a fresh build of the coarsened mesh, through several iterations.
TEST(CollapseConnectivity, CarriedAfterCollapsesEqualsFreshBuild) {
  Context ctx;
  std::vector<std::pair<std::string, Mesh>> inputs{{"two materials", two_materials(6)}};
  std::string path = test::shared_mesh("polyfem_bimetal.msh");
  if (!path.empty()) {
    try {
      inputs.emplace_back("polyfem_bimetal.msh", read_mesh(path));
    } catch (const std::exception&) {
    }
  }
  for (const auto& [name, mesh] : inputs) {
    SCOPED_TRACE(name);
    CollapseOptions o;
    StageParams p = params_from(o);
    DeviceMesh dm, next;
    upload_mesh(ctx, mesh, o, dm);
    Connectivity c;
    EdgeState s;
    TwoPassState two_pass;
    DeviceBuffer<int32_t> origin(ctx, 0);
    build_connectivity(ctx, dm, c, p);
    std::vector<double> len = [&] {
      StageParams q = p;
      q.target = 1e300;  // every edge marked: cost = length
      cost_and_mark(ctx, dm, c, s, q);
      return s.cost.edges2cost.download_range(0, c.ne);
    }();
    std::nth_element(len.begin(), len.begin() + len.size() / 2, len.end());
    p.target = 2 * len[len.size() / 2];
    int carried_iterations = 0;
    for (int it = 0; it < 4; ++it) {
      cost_and_mark(ctx, dm, c, s, p);
      uint32_t passed_q = 0, tested = 0;
      lazy_admissible_pass1(ctx, dm, c, s, p, passed_q, tested);
      if (conflict_pass2(ctx, dm, c, s, two_pass) == 0) break;
      remember_for_carry(ctx, dm, c, s);
      collapse_and_compact(ctx, p, dm, next, c, s, origin, 0);
      note_compaction(ctx, dm, c, s);
      Connectivity fresh;
      build_connectivity(ctx, dm, fresh, p);
      EXPECT_TRUE(s.compact.has_update);  // the rings and tet_nbr of collapse_update.cl are taken over
      build_connectivity(ctx, dm, c, p, &s);
      EXPECT_FALSE(s.compact.has_update);
      carry_verdicts(ctx, dm, c, s);
      ASSERT_EQ(c.ne, fresh.ne);
      // rings and tet_nbr carried through the compaction (collapse_update.cl) = rebuilt ones
      EXPECT_EQ(c.vt_off.download_range(0, size_t(dm.nv) + 1), fresh.vt_off.download_range(0, size_t(dm.nv) + 1));
      EXPECT_EQ(c.vt.download_range(0, 4 * size_t(dm.nt)), fresh.vt.download_range(0, 4 * size_t(dm.nt)));
      EXPECT_EQ(c.nb.download_range(0, 2 * size_t(c.ne)), fresh.nb.download_range(0, 2 * size_t(c.ne)));
      EXPECT_EQ(c.nb_edge.download_range(0, 2 * size_t(c.ne)), fresh.nb_edge.download_range(0, 2 * size_t(c.ne)));
      EXPECT_EQ(c.eflags.download_range(0, c.ne), fresh.eflags.download_range(0, c.ne));
      EXPECT_EQ(c.edges.download_range(0, 2 * size_t(c.ne)), fresh.edges.download_range(0, 2 * size_t(c.ne)));
      EXPECT_EQ(c.tet_nbr.download_range(0, 4 * size_t(dm.nt)), fresh.tet_nbr.download_range(0, 4 * size_t(dm.nt)));
      EXPECT_EQ(c.vflags.download_range(0, dm.nv), fresh.vflags.download_range(0, dm.nv));
      EXPECT_EQ(c.vclass.download_range(0, dm.nv), fresh.vclass.download_range(0, dm.nv));
      EXPECT_EQ(c.eflags.download_range(0, c.ne), fresh.eflags.download_range(0, c.ne));
      // some vertices were carried, not recomputed (else this test would test nothing)
      std::vector<uint8_t> nd = s.carry.verts_are_dirty.download_range(0, dm.nv);
      EXPECT_GT(std::count(nd.begin(), nd.end(), uint8_t(0)), 0) << "iteration " << it;
      ++carried_iterations;
    }
    EXPECT_GE(carried_iterations, 2);
  }
}
