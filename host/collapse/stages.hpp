// The stages of one collapse iteration over device buffers (used by collapse(), and by the
// tests one stage at a time). Kernels: cl/collapse_*.cl; shared helpers: cl/collapse_common.h.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tetcollapse/collapse.hpp"
#include "tetcollapse/device.hpp"
#include "tetcollapse/mesh.hpp"

namespace tc::collapse_detail {

// The current mesh on the device.
struct DeviceMesh {
  uint32_t nv = 0, nt = 0;
  DeviceBuffer<double> points;        // 3 per vertex
  DeviceBuffer<int32_t> tets;         // 4 per tet
  bool has_labels = false;            // primary labels drive material interfaces
  std::vector<DeviceBuffer<int32_t>> labels;  // every label array of the mesh, 1 per tet
  uint32_t vfield_comps = 0, tfield_comps = 0;  // all fields packed per entity
  DeviceBuffer<double> vfields, tfields;
  bool has_mask = false;
  DeviceBuffer<uint8_t> vmask;
};

// Stage 1 output.
struct Connectivity {
  uint32_t ne = 0;
  DeviceBuffer<uint32_t> vt_off;   // nv + 1
  DeviceBuffer<int32_t> vt;        // 4 nt: ring(v), ascending
  DeviceBuffer<uint32_t> nb_off;   // nv + 1
  DeviceBuffer<int32_t> nb;        // N(v), ascending
  DeviceBuffer<int32_t> nb_edge;   // edge id of each N(v) entry
  DeviceBuffer<uint32_t> edge_off; // nv + 1: edges owned by v (v is the smaller end)
  DeviceBuffer<int32_t> edges;     // 2 per edge, sorted lexicographically
  DeviceBuffer<int32_t> tet_nbr;   // 4 per tet: tet across each face (collapse_common.h)
  DeviceBuffer<uint8_t> vflags, vclass, eflags;  // see collapse_common.h
  // scratch
  DeviceBuffer<uint32_t> count, cursor, up_count;
  DeviceBuffer<int32_t> scratch;
};

// Per-edge and per-vertex state of the later stages.
struct EdgeState {
  DeviceBuffer<double> cost;
  DeviceBuffer<uint32_t> marked, adm, p1, fin;
  DeviceBuffer<uint8_t> state;      // conflict passes: 0 undecided, 1 in, 2 out
  DeviceBuffer<uint32_t> cand;      // lazy filter: marked and passing Q
  // Conflict rounds (collapse_conflict.cl): candidate edges, worklists of their slots, the
  // length of the next worklist, stored rivals per slot and their count.
  DeviceBuffer<uint32_t> cand_edges, work[2], work_n, rivals, rcount;
  DeviceBuffer<uint8_t> dir, reason;
  DeviceBuffer<int32_t> vaff;       // per vertex
  // marked, admissible, pass1, pass2, tested (lazy), passed Q (lazy)
  DeviceBuffer<uint32_t> counters;
};

enum Reason : uint8_t {
  kOk = 0, kNotMarked = 1, kRefusedQ = 2, kRefusedLink = 3, kRefusedVolume = 4, kRefusedQuality = 6,
  kUntested = 5  // lazy filter: passed Q, never tested because a cheaper rival won
};

struct StageParams {
  int mode = 1;  // 0 strict, 1 features, 2 free
  bool paper_rule = false;
  bool use_labels = true;
  double eps_f = 0.01, eps_r = 0.1, eps_v = 2e-12;
  double min_quality = 0;  // quality guard, 0 = off
  double target = 0;
  int mask_mode = 0;  // 0 none, 1 both, 2 either
  std::string cost_source;  // user cost, "" for the edge length
};
StageParams params_from(const CollapseOptions& o);

void upload_mesh(Context& ctx, const Mesh& mesh, const CollapseOptions& o, DeviceMesh& dm);

void build_connectivity(Context& ctx, DeviceMesh& dm, Connectivity& c, const StageParams& p);
// Returns the number of marked edges.
uint32_t cost_and_mark(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p);
// Tests every marked edge (adm, dir, reason); returns the number of admissible edges.
uint32_t admissible(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p);
// Conflict pass 1 over the admissible edges (s.adm); returns the number kept.
uint32_t conflict_pass1(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s);
// admissible() followed by conflict_pass1() with the same result (p1, vaff, dir of the kept
// edges), testing only the edges whose turn comes (cl/collapse_admissible.cl). Returns the
// number kept; passed_q and tested receive the number of marked edges passing Q and tested.
uint32_t lazy_admissible_pass1(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s, const StageParams& p,
                               uint32_t& passed_q, uint32_t& tested);
uint32_t conflict_pass2(Context& ctx, DeviceMesh& dm, Connectivity& c, EdgeState& s);
// Applies the final collapses: dm becomes the new mesh (via `next`, swapped in); origin (input
// vertex -> current vertex) is updated when non-empty.
void collapse_and_compact(Context& ctx, DeviceMesh& dm, DeviceMesh& next, Connectivity& c, EdgeState& s,
                          DeviceBuffer<int32_t>& origin, uint32_t n_origin);

void download_mesh(const DeviceMesh& dm, Mesh& mesh);

}  // namespace tc::collapse_detail
