// Atomic-min conflict detection (CollapseOptions::AtomicMin): the method of Gautron and Kenzel
// 2023 as the paper's Sec. 4 describes it, over the admissible edges of admissible(). Kernels,
// descriptor layout and why the result is conflict-free: cl/collapse_atomic_min.cl.
#include "collapse/select_atomic_min.hpp"

#include <memory>
#include <string>

#include "collapse/admissible.hpp"
#include "collapse/edge_state.hpp"
#include "collapse/selection.hpp"
#include "tetcollapse/error.hpp"

namespace tc::collapse_detail {

namespace {

// The fewest bits k >= 1 with ne - 1 < 2^k: the low bits of a descriptor that hold the index.
cl_uint index_bits(uint32_t ne) {
  cl_uint k = 1;
  while (k < 32 && (uint64_t(1) << k) < ne) ++k;
  return k;
}

}  // namespace

uint32_t conflicts_atomic_min(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s) {
  const DeviceInfo& dev = ctx.info();
  if (!dev.int64_atomics_extended)
    throw DeviceError("device '" + dev.name + "' lacks cl_khr_int64_extended_atomics (64-bit atomic min), which the " +
                      "atomic-min conflict detection needs; use --conflicts two-pass or another device");
  const std::string F = "collapse_atomic_min.cl";
  const cl_uint ne = c.ne, nt = dm.nt, k = index_bits(c.ne);
  ensure(s.result.edges_are_final, ctx, ne);
  ensure(s.result.edges_pass1, ctx, ne);
  ensure(s.result.verts2collapse, ctx, dm.nv);
  s.result.verts2collapse.fill(-1);
  // One descriptor (ulong) per tet in c.scratch: build_connectivity's scratch area (12 ints per
  // tet), unused until the next build_connectivity.
  if (c.scratch.size() < size_t(nt) * 2) ensure(c.scratch, ctx, size_t(nt) * 2);
  const cl::Buffer& desc = c.scratch.buffer();
  auto run = [&](const char* name, size_t n, const auto&... args) {
    collapse_detail::run(ctx, F, name, n, args...);
  };
  run("atomic_min_reset", nt, arg("nt", nt), arg("desc", desc));
  run("atomic_min_propagate", ne, arg("ne", ne), arg("edges", c.edges), arg("edges_are_admissible", s.result.edges_are_admissible), arg("edges2cost", s.cost.edges2cost), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("idx_bits", k), arg("desc", desc));
  run("atomic_min_select", ne, arg("ne", ne), arg("edges", c.edges), arg("edges_are_admissible", s.result.edges_are_admissible), arg("edges2cost", s.cost.edges2cost), arg("vt_off", c.vt_off), arg("vt", c.vt), arg("idx_bits", k), arg("desc", desc), arg("edges_are_final", s.result.edges_are_final), arg("edges_pass1", s.result.edges_pass1), arg("verts2collapse", s.result.verts2collapse), arg("counters", s.cost.counters));
  uint32_t n = 0;
  s.cost.counters.download(&n, 1, 3);
  return n;
}


namespace {

// Every marked edge tested (admissible()), then the atomic minima.
class AtomicMinSelection final : public Selection {
  Chosen choose(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                const IterationStats&) override {
    Chosen r;
    admissible(ctx, dm, c, s, p);
    r.candidates = read_counter(s.cost, 5);
    r.tested = r.candidates;
    r.selected = conflicts_atomic_min(ctx, dm, c, s);
    return r;
  }
};

}  // namespace

std::unique_ptr<Selection> make_atomic_min_selection() { return std::make_unique<AtomicMinSelection>(); }

}  // namespace tc::collapse_detail
