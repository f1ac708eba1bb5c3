// Vertex relocation on the device (cl/improve_relocate.cl): the smoothing pass's vertices off
// curved surfaces move in rounds of vertices no two of which share a tet; the host then applies
// the moves round by round and relocates the rest (the surface guard is host code).
#include <algorithm>

#include "collapse/launch.hpp"
#include "stopwatch.hpp"
#include "improve/device_mesh.hpp"

namespace tc::improve_detail {

using collapse_detail::arg;
using collapse_detail::profile_line;
using collapse_detail::run;

namespace {

constexpr size_t kMaxStar = 128;  // TCI_MAX_STAR of cl/improve_relocate.cl
constexpr const char* kFile = "improve_relocate.cl";

}  // namespace

void smooth_pass(ImpMesh& m, Context& ctx, const std::vector<int32_t>& bad, ImprovePassStats& stats) {
  const double t0 = Stopwatch::now();
  const int32_t nv = m.num_vertices();
  std::vector<int32_t> cands, on_host;
  for (int32_t v : smoothing_candidates(m, bad)) {
    if (m.settled(m.smooth_failed_at, v)) continue;
    if (m.bends_surface(v) || m.tets_of(v).size() > kMaxStar) on_host.push_back(v);
    else cands.push_back(v);
  }
  if (!cands.empty()) {
    ImpDeviceMesh dm(ctx, m);  // (the kernels move points and re-measure tets in it)
    std::vector<double> direction(3 * static_cast<size_t>(nv));
    std::vector<uint8_t> motion(static_cast<size_t>(nv)), flags(static_cast<size_t>(nv), 0);
    for (int32_t v = 0; v < nv; ++v) {
      motion[size_t(v)] = m.motion(v);
      const tc_d3 d = m.motion_direction(v);
      direction[3 * size_t(v)] = d.x;
      direction[3 * size_t(v) + 1] = d.y;
      direction[3 * size_t(v) + 2] = d.z;
    }
    for (int32_t v : cands) flags[size_t(v)] = 1;
    DeviceBuffer<double> d_direction(ctx, direction);
    DeviceBuffer<int32_t> d_cands(ctx, cands), d_round(ctx, size_t(nv));
    d_round.fill(0);
    DeviceBuffer<uint32_t> counters(ctx, 1);
    DeviceBuffer<uint8_t> d_flags(ctx, flags), d_motion(ctx, motion);
    DeviceBuffer<uint64_t> verts2key(ctx, size_t(nv));
    verts2key.fill(~uint64_t(0));
    const uint32_t nc = uint32_t(cands.size());
    profile_line(ctx, "relocation: upload", cands.size(), t0);
    const double t1 = Stopwatch::now();
    uint32_t round = 1;
    for (;; ++round) {
      run(ctx, kFile, "relocate_keys", nc, arg("nc", nc), arg("cands", d_cands), arg("verts2tets_offsets", dm.verts2tets_offsets),
          arg("verts2tets", dm.verts2tets), arg("tets2quality", dm.quality), arg("verts_are_cands", d_flags),
          arg("verts2key", verts2key));
      counters.fill(0);
      run(ctx, kFile, "relocate_chosen", nc, arg("nc", nc), arg("round", round), arg("cands", d_cands),
          arg("verts2tets_offsets", dm.verts2tets_offsets), arg("verts2tets", dm.verts2tets), arg("tets", dm.tets), arg("verts2key", verts2key),
          arg("verts2motion", d_motion), arg("verts2direction", d_direction), arg("cos_threshold", m.cos_threshold()),
          arg("pts", dm.pts), arg("tets2quality", dm.quality), arg("verts_are_cands", d_flags),
          arg("verts2round", d_round), arg("counters", counters));
      uint32_t left = 0;
      counters.download(&left, 1);
      if (left == 0) break;
    }
    profile_line(ctx, "relocation: rounds", round, t1);
    const double t2 = Stopwatch::now();
    const std::vector<double> pts = dm.pts.download();
    const std::vector<int32_t> rounds = d_round.download();
    // Round by round, as the device did them: a move interpolates the vertex fields in the star
    // as it was then, and a vertex that found nothing is settled only until a later move
    // changes its star. (Vertices of one round share no tet: their order does not matter.)
    std::stable_sort(cands.begin(), cands.end(),
                     [&](int32_t a, int32_t b) { return std::abs(rounds[size_t(a)]) < std::abs(rounds[size_t(b)]); });
    for (int32_t v : cands) {
      if (rounds[size_t(v)] < 0) {
        m.failed(m.smooth_failed_at, v);
        continue;
      }
      m.move(v, geo::tc_point(pts.data(), v));
      if (m.motion(v) != kFree) m.surface_moved(v);
      ++stats.relocated;
    }
    profile_line(ctx, "relocation: apply", cands.size(), t2);
  }
  const double t3 = Stopwatch::now();
  for (int32_t v : on_host) {
    if (m.settled(m.smooth_failed_at, v)) continue;
    if (try_smooth(m, v)) ++stats.relocated;
    else m.failed(m.smooth_failed_at, v);
  }
  profile_line(ctx, "relocation: on the host", on_host.size(), t3);
}

}  // namespace tc::improve_detail
