// Flips on the device (cl/improve_flip.cl): each round uploads the mesh, finds the first
// interior flip that improves each bad tet, picks flips that share no vertex (worst tet first),
// and applies them here; the flips that lost to a neighbour are sought again next round, on
// the mesh as it then is. The boundary's operations follow on the host (their tests read the
// surface's tags and shape, host data).
#include <algorithm>

#include "collapse/launch.hpp"
#include "improve/device_mesh.hpp"
#include "improve_flip.h"
#include "stopwatch.hpp"

namespace tc::improve_detail {

using collapse_detail::arg;
using collapse_detail::profile_line;
using collapse_detail::run;

namespace {

constexpr const char* kFile = "improve_flip.cl";
constexpr int kMaxNew = 2 * TCI_MAX_RING - 4;  // TCI_MAX_NEW of cl/improve_flip.cl
enum Kind { kNone = 0, kEdgeRemoval = 1, kFlip23 = 2 };
enum State { kCompeting = 0, kWon = 1, kDropped = 2 };
// The host tail: the flips left once fewer than this share of the bad tets remain to be sought.
constexpr double kHostTail = 0.25;

bool all_settled(const ImpMesh& m, int32_t t) {
  const Tet& q = m.tet(t);
  return m.settled(m.flip_failed_at, q[0]) && m.settled(m.flip_failed_at, q[1]) &&
         m.settled(m.flip_failed_at, q[2]) && m.settled(m.flip_failed_at, q[3]);
}

}  // namespace

void flip_pass(ImpMesh& m, Context& ctx, const std::vector<int32_t>& bad, ImprovePassStats& stats) {
  // Where every operation failed before and nothing changed since, they fail again.
  std::vector<int32_t> pending;
  for (int32_t t : bad)
    if (m.alive(t) && !all_settled(m, t)) pending.push_back(t);
  const int32_t nv = m.num_vertices();
  std::vector<uint8_t> selected(static_cast<size_t>(nv));
  for (int32_t v = 0; v < nv; ++v) selected[size_t(v)] = m.selected(v);
  const std::vector<uint64_t> edge_keys = m.tagged_edge_keys();
  DeviceBuffer<uint8_t> d_selected(ctx, selected), d_taken(ctx, size_t(nv));
  DeviceBuffer<uint64_t> d_edges(ctx, edge_keys);
  DeviceBuffer<uint32_t> d_claim(ctx, size_t(nv)), counters(ctx, 1);
  // Bad tets where the device found no interior flip, with the stamp of the mesh it searched.
  std::vector<std::pair<int32_t, uint32_t>> to_host;
  // Each round uploads the whole mesh: once few flips are left, the host finishes them.
  const size_t host_tail = size_t(kHostTail * double(pending.size()));
  for (int round = 0; pending.size() > host_tail; ++round) {
    const double t0 = Stopwatch::now();
    const int32_t nt = m.num_tet_slots();
    std::vector<int32_t> labels(static_cast<size_t>(nt));
    std::vector<double> max_cos(static_cast<size_t>(nt));
    for (int32_t t = 0; t < nt; ++t) {
      labels[size_t(t)] = m.label(t);
      max_cos[size_t(t)] = m.max_cos(t);
    }
    const ImpDeviceMesh dm(ctx, m);
    // The tags change with the boundary's flips: read each round.
    const std::vector<int32_t> face_records = m.tagged_face_records();
    DeviceBuffer<int32_t> d_labels(ctx, labels), d_faces(ctx, face_records), d_flips(ctx, pending);
    DeviceBuffer<double> d_max_cos(ctx, max_cos);
    const size_t nf = pending.size();
    DeviceBuffer<int32_t> kind(ctx, nf), old(ctx, TCI_MAX_RING * nf), n_old(ctx, nf), added(ctx, 4 * kMaxNew * nf),
        n_new(ctx, nf), state(ctx, nf);
    run(ctx, kFile, "flip_find", nf, arg("nf", nf), arg("flips2tet", d_flips), arg("tets", dm.tets),
        arg("tets2label", d_labels), arg("tets2quality", dm.quality), arg("tets2max_cos", d_max_cos),
        arg("verts2tets_offsets", dm.verts2tets_offsets), arg("verts2tets", dm.verts2tets), arg("verts_are_selected", d_selected),
        arg("tagged_edges", d_edges), arg("n_tagged_edges", edge_keys.size()), arg("tagged_faces", d_faces),
        arg("n_tagged_faces", face_records.size() / 4), arg("pts", dm.pts), arg("cos_threshold", m.cos_threshold()),
        arg("flips2kind", kind), arg("flips2old", old), arg("flips2n_old", n_old), arg("flips2new", added),
        arg("flips2n_new", n_new), arg("flips2state", state));
    d_taken.fill(0);
    for (;;) {
      d_claim.fill(~uint32_t(0));
      counters.fill(0);
      run(ctx, kFile, "flip_claim", nf, arg("nf", nf), arg("tets", dm.tets), arg("flips2old", old),
          arg("flips2n_old", n_old), arg("verts_are_taken", d_taken), arg("flips2state", state),
          arg("verts2claim", d_claim), arg("counters", counters));
      uint32_t competing = 0;
      counters.download(&competing, 1);
      if (competing == 0) break;
      run(ctx, kFile, "flip_won", nf, arg("nf", nf), arg("tets", dm.tets), arg("flips2old", old),
          arg("flips2n_old", n_old), arg("verts2claim", d_claim), arg("flips2state", state),
          arg("verts_are_taken", d_taken));
    }
    profile_line(ctx, "flips: device round", nf, t0);
    const std::vector<int32_t> h_kind = kind.download(), h_state = state.download(), h_old = old.download(),
                               h_n_old = n_old.download(), h_added = added.download(), h_n_new = n_new.download();
    // The winners share no vertex: applied in their order, each as the device found it.
    const uint32_t searched = m.stamp();
    std::vector<int32_t> next;
    for (size_t i = 0; i < nf; ++i) {
      if (h_kind[i] == kNone) {
        to_host.emplace_back(pending[i], searched);
      } else if (h_state[i] == kWon) {
        const std::vector<int32_t> gone(h_old.begin() + ptrdiff_t(TCI_MAX_RING * i),
                                        h_old.begin() + ptrdiff_t(TCI_MAX_RING * i + size_t(h_n_old[i])));
        std::vector<Tet> made(size_t(h_n_new[i]));
        for (size_t k = 0; k < made.size(); ++k)
          for (int c = 0; c < 4; ++c) made[k][size_t(c)] = h_added[4 * kMaxNew * i + 4 * k + size_t(c)];
        m.replace(gone, made, gone[0]);
        ++(h_kind[i] == kEdgeRemoval ? stats.edge_removals : stats.flips23);
      } else {
        next.push_back(pending[i]);  // lost to a neighbour: sought again on the changed mesh
      }
    }
    std::erase_if(next, [&](int32_t t) { return !m.alive(t); });
    pending = std::move(next);
  }
  const double t1 = Stopwatch::now();
  if (!pending.empty()) flip_pass(m, pending, stats);
  for (const auto& [t, searched] : to_host) {
    if (!m.alive(t) || try_boundary_flips(m, t, stats)) continue;
    // settled from the mesh the device searched: a change since then tries the tet again
    for (int32_t v : m.tet(t)) m.flip_failed_at[size_t(v)] = std::max(m.flip_failed_at[size_t(v)], searched);
  }
  profile_line(ctx, "flips: on the host", to_host.size() + pending.size(), t1);
}

}  // namespace tc::improve_detail
