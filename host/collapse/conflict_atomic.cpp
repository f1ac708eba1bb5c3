// Atomic-min conflict detection (CollapseOptions::AtomicMin): the method of Gautron and Kenzel
// 2023 as the paper's Sec. 4 describes it, over the admissible edges of admissible(). Kernels,
// descriptor layout and why the result is conflict-free: cl/collapse_atomic_min.cl.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "collapse/stages.hpp"
#include "tetcollapse/error.hpp"

namespace tc::collapse_detail {

namespace {

// The fewest bits k >= 1 with ne - 1 < 2^k: the low bits of a descriptor that hold the index.
cl_uint index_bits(uint32_t ne) {
  cl_uint k = 1;
  while (k < 32 && (uint64_t(1) << k) < ne) ++k;
  return k;
}

// TETCOLLAPSE_PROFILE=1 prints the wall time of every kernel launch on stderr.
const bool kProfile = std::getenv("TETCOLLAPSE_PROFILE") != nullptr;

}  // namespace

uint32_t conflicts_atomic_min(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s) {
  const DeviceInfo& dev = ctx.info();
  if (!dev.int64_atomics_extended)
    throw DeviceError("device '" + dev.name + "' lacks cl_khr_int64_extended_atomics (64-bit atomic min), which the " +
                      "atomic-min conflict detection needs; use --conflicts two-pass or another device");
  const std::string F = "collapse_atomic_min.cl";
  const cl_uint ne = c.ne, nt = dm.nt, k = index_bits(c.ne);
  ensure(s.fin, ctx, ne);
  ensure(s.p1, ctx, ne);
  ensure(s.vaff, ctx, dm.nv);
  s.vaff.fill(-1);
  // One descriptor (ulong) per tet in c.scratch: build_connectivity's scratch area (12 ints per
  // tet), unused until the next build_connectivity.
  if (c.scratch.size() < size_t(nt) * 2) ensure(c.scratch, ctx, size_t(nt) * 2);
  const cl::Buffer& desc = c.scratch.buffer();
  auto run = [&](const char* name, size_t n, const auto&... args) {
    cl::Kernel kern = ctx.kernel(F, name);
    detail::cl_call(name, [&] {
      cl_uint i = 0;
      (kern.setArg(i++, args), ...);
    });
    const auto t0 = std::chrono::steady_clock::now();
    ctx.launch(kern, n, name);
    if (kProfile) {  // as the stages of stages.cpp do
      ctx.finish();
      std::fprintf(stderr, "  %-28s n=%-9zu %8.4f s\n", name, n,
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
  };
  run("atomic_min_reset", nt, nt, desc);
  run("atomic_min_propagate", ne, ne, c.edges.buffer(), s.adm.buffer(), s.cost.buffer(), c.vt_off.buffer(),
      c.vt.buffer(), k, desc);
  run("atomic_min_select", ne, ne, c.edges.buffer(), s.adm.buffer(), s.cost.buffer(), c.vt_off.buffer(),
      c.vt.buffer(), k, desc, s.fin.buffer(), s.p1.buffer(), s.vaff.buffer(), s.counters.buffer());
  uint32_t n = 0;
  s.counters.download(&n, 1, 3);
  return n;
}

}  // namespace tc::collapse_detail
