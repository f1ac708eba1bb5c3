// Device connectivity and classification (host/device/connectivity.cpp) against the
// single-threaded reference (host/topology/topology.cpp): arrays equal, element by element,
// for two work-group sizes and across runs.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>

#include "device/connectivity.hpp"
#include "test_support.hpp"
#include "tetcollapse/io.hpp"
#include "tetcollapse/topology.hpp"

using namespace tc;

namespace {

Context* shared_context() {
  static std::unique_ptr<Context> ctx;
  static std::string error;
  if (!ctx && error.empty()) {
    try {
      ctx = std::make_unique<Context>();
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  return ctx.get();
}

#define TC_CONTEXT_OR_SKIP(ctx)                                            \
  Context* ctx = shared_context();                                         \
  if (!ctx) GTEST_SKIP() << "no usable OpenCL device; device test skipped"

template <class T>
::testing::AssertionResult same(const char* name, const std::vector<T>& cpu, const std::vector<T>& dev) {
  if (cpu.size() != dev.size())
    return ::testing::AssertionFailure() << name << ": size " << dev.size() << " on the device, " << cpu.size()
                                         << " on the CPU";
  for (size_t i = 0; i < cpu.size(); ++i)
    if (!(cpu[i] == dev[i]))
      return ::testing::AssertionFailure() << name << "[" << i << "]: " << +dev[i] << " on the device, " << +cpu[i]
                                           << " on the CPU";
  return ::testing::AssertionSuccess();
}

void expect_equal(const Topology& c, const Topology& d) {
  EXPECT_EQ(c.num_vertices, d.num_vertices);
  EXPECT_EQ(c.num_tets, d.num_tets);
#define TC_SAME(field) EXPECT_TRUE(same(#field, c.field, d.field))
  TC_SAME(edges);
  TC_SAME(tet_edges);
  TC_SAME(vertex_tets_offsets);
  TC_SAME(vertex_tets);
  TC_SAME(vertex_edges_offsets);
  TC_SAME(vertex_edges);
  TC_SAME(edge_tets_offsets);
  TC_SAME(edge_tets);
  TC_SAME(sfaces);
  TC_SAME(sface_tet);
  TC_SAME(sface_local);
  TC_SAME(sface_interface);
  TC_SAME(sface_normals);  // bit-identical: same operations, no contraction, correctly rounded / and sqrt
  TC_SAME(vertex_sfaces_offsets);
  TC_SAME(vertex_sfaces);
  TC_SAME(edge_sfaces_offsets);
  TC_SAME(edge_sfaces);
  TC_SAME(vertex_boundary);
  TC_SAME(edge_boundary);
  TC_SAME(vertex_class);
  TC_SAME(edge_ridge);
#undef TC_SAME
}

// Device result for two work-group sizes (and a second run with the first): all equal to the CPU.
void check_mesh(Context& ctx, const Mesh& m, const TopologyOptions& opt = {}) {
  const Topology cpu = build_topology(m, opt);
  for (size_t wg : {size_t(64), size_t(8), size_t(64)}) {
    SCOPED_TRACE("work-group size " + std::to_string(wg));
    ctx.set_work_group_size(wg);
    const Topology dev = dev::build_device_topology(ctx, m, opt).download();
    expect_equal(cpu, dev);
    if (::testing::Test::HasFailure()) break;
  }
  ctx.set_work_group_size(0);
}

Mesh two_material_cube(int n) {
  Mesh m = test::cube_tets(n);
  Labels lab{"material", {}};
  for (int64_t i = 0; i < m.num_tets(); ++i) {
    double cx = 0;
    for (int k = 0; k < 4; ++k) cx += m.points[3 * m.tets[4 * i + k]] / 4;
    lab.values.push_back(cx < 0.5 ? 2 : 1);
  }
  m.tet_labels.push_back(lab);
  return m;
}

}  // namespace

TEST(DeviceConnectivity, SingleTetAndEmpty) {
  TC_CONTEXT_OR_SKIP(ctx);
  check_mesh(*ctx, test::single_tet());
  Mesh empty;
  empty.points = {0, 0, 0, 1, 1, 1};  // two unused vertices, no tets
  check_mesh(*ctx, empty);
}

TEST(DeviceConnectivity, Cubes) {
  TC_CONTEXT_OR_SKIP(ctx);
  for (int n : {1, 3, 8}) {
    SCOPED_TRACE("cube " + std::to_string(n));
    check_mesh(*ctx, test::cube_tets(n));
  }
  const Topology d = dev::build_device_topology(*ctx, test::cube_tets(6)).download();
  const TopologySummary s = summarize(test::cube_tets(6), d);
  EXPECT_EQ(s.corner_vertices, 8);
  EXPECT_EQ(s.ridge_edges, 12 * 6);
  EXPECT_EQ(s.ridge_vertices, 12 * 5);
  EXPECT_EQ(s.face_vertices, 6 * 25);
}

TEST(DeviceConnectivity, TwoMaterialsAndOptions) {
  TC_CONTEXT_OR_SKIP(ctx);
  Mesh m = two_material_cube(4);
  check_mesh(*ctx, m);
  TopologyOptions opt;
  opt.use_labels = false;
  check_mesh(*ctx, m, opt);
  opt.use_labels = true;
  opt.eps_r = 1.5;
  opt.eps_f = 0.5;
  check_mesh(*ctx, m, opt);
}

TEST(DeviceConnectivity, RejectsBadTets) {
  TC_CONTEXT_OR_SKIP(ctx);
  Mesh m = test::cube_tets(2);
  m.tets[4 * 17 + 2] = 1000;
  try {
    dev::build_device_topology(*ctx, m);
    FAIL() << "index out of range accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("tet 17 has vertex index 1000"), std::string::npos) << e.what();
  }
  m.tets[4 * 17 + 2] = m.tets[4 * 17];
  EXPECT_THROW(dev::build_device_topology(*ctx, m), InputError);
}

TEST(DeviceConnectivity, SharedMeshes) {
  TC_SKIP_IF_NO_SHARED();
  TC_CONTEXT_OR_SKIP(ctx);
  int done = 0;
  for (const std::string& path : test::shared_volume_meshes()) {
    Mesh m = read_mesh(path);  // every shared mesh must load (tests/io checks the counts)
    if (m.num_tets() > 300000) {  // keeps the test short; bench_connectivity compares those
      std::printf("[ skipped  ] %s: %lld tets, compared by bench_connectivity instead\n", path.c_str(),
                  (long long)m.num_tets());
      continue;
    }
    SCOPED_TRACE(path);
    const Topology cpu = build_topology(m);
    for (size_t wg : {size_t(128), size_t(16)}) {
      SCOPED_TRACE("work-group size " + std::to_string(wg));
      ctx->set_work_group_size(wg);
      expect_equal(cpu, dev::build_device_topology(*ctx, m).download());
    }
    ctx->set_work_group_size(0);
    if (HasFailure()) break;
    ++done;
  }
  EXPECT_GT(done, 0) << "no shared mesh compared";
}
