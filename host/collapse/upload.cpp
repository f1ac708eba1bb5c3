// The mesh to the device and back.
#include "collapse/upload.hpp"

#include <algorithm>
#include <exception>
#include <numeric>
#include <limits>
#include <stdexcept>
#include <system_error>
#include <thread>

#include "collapse/spatial_order.hpp"
#include "tetcollapse/error.hpp"

namespace tc::collapse_detail {

void check_collapse_input(const Mesh& mesh) {
  if (mesh.points.size() % 3 != 0 || mesh.tets.size() % 4 != 0)
    throw InputError("<mesh>", "point or tet array length is not a multiple of 3 or 4");
  const int64_t nv = mesh.num_vertices(), nt = mesh.num_tets();
  // Edges and N(v) entries must fit 31-bit indices: 12 nt scratch slots bound both.
  if (nv >= std::numeric_limits<int32_t>::max() || nt >= std::numeric_limits<int32_t>::max() / 12)
    throw InputError("<mesh>", "mesh too large for the collapse's 32-bit indices: " + std::to_string(nv) +
                                   " vertices, " + std::to_string(nt) + " tets");
  for (int64_t t = 0; t < nt; ++t) {
    const int32_t* q = &mesh.tets[4 * t];
    for (int i = 0; i < 4; ++i) {
      if (q[i] < 0 || q[i] >= nv)
        throw InputError("<mesh>", "tet " + std::to_string(t) + " has vertex index " + std::to_string(q[i]) +
                                       " outside [0, " + std::to_string(nv) + ")");
      for (int j = 0; j < i; ++j)
        if (q[i] == q[j]) throw InputError("<mesh>", "tet " + std::to_string(t) + " repeats vertex " + std::to_string(q[i]));
    }
  }
  for (const Labels& l : mesh.tet_labels)
    if (l.values.size() != size_t(nt))
      throw InputError("<mesh>", "label array '" + l.name + "' has " + std::to_string(l.values.size()) +
                                     " values for " + std::to_string(nt) + " tets");
}

uint64_t device_bytes_estimate(const Mesh& mesh, const CollapseOptions& o) {
  const uint64_t nv = uint64_t(mesh.num_vertices()), nt = uint64_t(mesh.num_tets()), ne = nv + nt;
  uint64_t vcomps = 0, tcomps = 0;
  for (const Field& f : mesh.vertex_fields) vcomps += uint64_t(std::max(f.components, 0));
  for (const Field& f : mesh.tet_fields) tcomps += uint64_t(std::max(f.components, 0));
  const uint64_t labels = std::max<uint64_t>(mesh.tet_labels.size(), 1);
  // Bytes per entity of the buffers alive through the first iteration's selection:
  // per tet: the tets, rings, tet neighbours, S-face flags, qualities, the matching's dead and
  // killer tets, the surface guard's S-tet lists; plus the labels and tet fields;
  const uint64_t quality = o.min_quality > 0 ? 8 : 0;
  const uint64_t per_tet = 16 + 16 + 16 + 4 + 1 + quality + 1 + 4 + 4 + 4 + 4 + 1 + 4 * labels + 8 * tcomps;
  // per vertex: points, origin, mask, offsets and counts, flags, the selection's claims and
  // lists, the matching's backup of the points, the guard's cells; plus the vertex fields (twice:
  // the backup);
  const uint64_t per_vertex = 24 + 4 + 1 + 6 * 4 + 2 + 4 + 5 * 4 + 8 + 24 + 4 + 4 + 6 + 16 * vcomps;
  // per edge: N(v) and its edge ids, the edges, flags and verdicts, the cost and marks, the
  // selection's result, priorities, turn lists, queues and waiting lists, the matching's rounds.
  const uint64_t per_edge = 8 + 8 + 8 + 1 + 1 + 8 + 4 + 1 + 1 + 4 + 4 + 1 + 4 + 8 + 4 + 4 + 4 + 8 + 4 + 4 + 4 + 3 + 1;
  const uint64_t selection = nt * per_tet + nv * per_vertex + ne * per_edge;
  // the connectivity build: the mesh, its rings and neighbours, and 12 candidate slots per tet
  const uint64_t connectivity = nt * (16 + 16 + 16 + 4 * labels + 8 * tcomps + 48) + nv * (24 + 4 + 1 + 6 * 4 + 2 + 8 * vcomps) +
                                ne * (8 + 8 + 8 + 1 + 1);
  const uint64_t peak = std::max(selection, connectivity);
  return peak + peak / 10;
}

void check_device_memory(const Context& ctx, const Mesh& mesh, const CollapseOptions& o) {
  const uint64_t need = device_bytes_estimate(mesh, o), have = ctx.info().global_mem_bytes;
  if (have > 0 && need > have)
    throw DeviceError("the mesh is too large for device '" + ctx.info().name + "': coarsening its " +
                      std::to_string(mesh.num_tets()) + " tets needs about " + std::to_string(need >> 20) +
                      " MiB of device memory, and the device has " + std::to_string(have >> 20) +
                      " MiB (CL_DEVICE_GLOBAL_MEM_SIZE); use a larger device or --method sequential");
}

namespace {

// ring(v) for every vertex: counted, then filled in tet order, so each ring is ascending. Why
// on the host for a CPU device (Context::cpu_tuning): one sequential pass over the tets is
// cheaper than the device's atomic count and scatter and a sort of every ring (conn_count,
// conn_scatter, conn_ring_sort_and_gather's sort) on the same cores; the tets are in spatial
// order, so the writes are near each other. A GPU does its own.
void host_rings(const std::vector<int32_t>& tets, uint32_t nv, std::vector<uint32_t>& off, std::vector<int32_t>& vt) {
  off.assign(size_t(nv) + 1, 0);
  for (int32_t v : tets) ++off[size_t(v) + 1];
  for (size_t v = 0; v < nv; ++v) off[v + 1] += off[v];
  vt.resize(tets.size());
  std::vector<uint32_t> cursor(off.begin(), off.end() - 1);
  for (size_t i = 0; i < tets.size(); ++i) vt[cursor[size_t(tets[i])]++] = int32_t(i / 4);
}

}  // namespace

void upload_mesh(Context& ctx, const Mesh& mesh, const CollapseOptions& o, DeviceMesh& dm,
                 std::vector<int32_t>* vertex_new) {
  check_collapse_input(mesh);
  const int64_t nv = mesh.num_vertices(), nt = mesh.num_tets();
  SpatialOrder spatial;
  const SpatialOrder* order = nullptr;
  if (vertex_new) {  // the indices are checked: the order may use them
    spatial = spatial_order(mesh);
    order = &spatial;
  }
  // entity i of the device mesh is entity old(i) of `mesh` (the identity without an order)
  auto vold = [&](int64_t i) { return order ? int64_t(order->vertex_old[size_t(i)]) : i; };
  auto told = [&](int64_t i) { return order ? int64_t(order->tet_old[size_t(i)]) : i; };
  auto gather = [&](const auto& values, int64_t count, size_t per, auto old) {
    std::remove_cvref_t<decltype(values)> out(values.size());
    for (int64_t i = 0; i < count; ++i)
      for (size_t c = 0; c < per; ++c) out[size_t(i) * per + c] = values[size_t(old(i)) * per + c];
    return out;
  };
  dm.nv = uint32_t(nv);
  dm.nt = uint32_t(nt);
  const std::vector<int32_t>& tets = order ? spatial.tets : mesh.tets;
  // The rings (Context::cpu_tuning: a CPU device) on a second thread while this one gathers and
  // uploads the rest: the device's threads are idle during the upload, and the two take
  // about as long.
  dm.has_rings = ctx.cpu_tuning();
  std::vector<uint32_t> ring_off;
  std::vector<int32_t> ring_vt;
  std::exception_ptr ring_error;
  std::jthread rings;  // after what it reads and writes: joined first when this function throws
  bool rings_here = false;
  if (dm.has_rings) {
    try {
      rings = std::jthread([&tets, nv = dm.nv, &ring_off, &ring_vt, &ring_error] {
        try {
          host_rings(tets, nv, ring_off, ring_vt);
        } catch (...) {
          ring_error = std::current_exception();
        }
      });
    } catch (const std::system_error&) {  // no thread to be had: on this one, below
      rings_here = true;
    }
  }
  dm.points = order ? DeviceBuffer<double>(ctx, gather(mesh.points, nv, 3, vold)) : DeviceBuffer<double>(ctx, mesh.points);
  dm.tets = DeviceBuffer<int32_t>(ctx, tets);
  dm.labels.clear();
  for (const Labels& l : mesh.tet_labels) {  // lengths checked by check_collapse_input
    dm.labels.emplace_back(ctx, order ? gather(l.values, nt, 1, told) : l.values);
  }
  dm.has_labels = !dm.labels.empty() && o.use_labels;
  if (dm.labels.empty()) dm.labels.emplace_back(ctx, 0);  // placeholder argument
  auto pack = [&](const std::vector<Field>& fields, int64_t count, const char* kind, uint32_t& comps,
                  DeviceBuffer<double>& out, auto old) {
    comps = 0;
    for (const Field& f : fields) {
      if (f.components <= 0 || f.values.size() != size_t(count) * size_t(f.components))
        throw InputError("<mesh>", std::string(kind) + " field '" + f.name + "' has " + std::to_string(f.values.size()) +
                                       " values, expected " + std::to_string(count) + " x " + std::to_string(f.components));
      comps += uint32_t(f.components);
    }
    std::vector<double> packed(size_t(count) * comps);
    uint32_t c0 = 0;
    for (const Field& f : fields) {
      for (int64_t i = 0; i < count; ++i)
        for (int c = 0; c < f.components; ++c)
          packed[size_t(i) * comps + c0 + c] = f.values[size_t(old(i)) * f.components + c];
      c0 += uint32_t(f.components);
    }
    out = DeviceBuffer<double>(ctx, packed);
  };
  pack(mesh.vertex_fields, nv, "vertex", dm.vfield_comps, dm.vfields, vold);
  pack(mesh.tet_fields, nt, "tet", dm.tfield_comps, dm.tfields, told);
  dm.has_mask = !o.vertex_mask.empty();
  if (dm.has_mask && o.vertex_mask.size() != size_t(nv))
    throw std::invalid_argument("vertex_mask has " + std::to_string(o.vertex_mask.size()) + " entries for " +
                                std::to_string(nv) + " vertices");
  dm.vmask = DeviceBuffer<uint8_t>(ctx, order && dm.has_mask ? gather(o.vertex_mask, nv, 1, vold) : o.vertex_mask);
  if (dm.has_rings) {
    if (rings_here) host_rings(tets, dm.nv, ring_off, ring_vt);
    else rings.join();
    if (ring_error) std::rethrow_exception(ring_error);
    dm.vt_off = DeviceBuffer<uint32_t>(ctx, ring_off);
    dm.vt = DeviceBuffer<int32_t>(ctx, ring_vt);
  }
  if (vertex_new) *vertex_new = std::move(spatial.vertex_new);
}

void download_mesh(const DeviceMesh& dm, Mesh& mesh) {
  mesh.points = dm.points.download_range(0, size_t(dm.nv) * 3);
  mesh.tets = dm.tets.download_range(0, size_t(dm.nt) * 4);
  for (size_t l = 0; l < mesh.tet_labels.size(); ++l) mesh.tet_labels[l].values = dm.labels[l].download_range(0, dm.nt);
  auto unpack = [](std::vector<Field>& fields, const DeviceBuffer<double>& buf, uint32_t comps, uint32_t count) {
    std::vector<double> packed = buf.download_range(0, size_t(count) * comps);
    uint32_t c0 = 0;
    for (Field& f : fields) {
      f.values.assign(size_t(count) * f.components, 0.0);
      for (uint32_t i = 0; i < count; ++i)
        for (int c = 0; c < f.components; ++c) f.values[size_t(i) * f.components + c] = packed[size_t(i) * comps + c0 + c];
      c0 += uint32_t(f.components);
    }
  };
  unpack(mesh.vertex_fields, dm.vfields, dm.vfield_comps, dm.nv);
  unpack(mesh.tet_fields, dm.tfields, dm.tfield_comps, dm.nt);
}

DeviceBuffer<int32_t> upload_with_origin(Context& ctx, const Mesh& mesh, const CollapseOptions& o, DeviceMesh& dm) {
  std::vector<int32_t> origin;
  upload_mesh(ctx, mesh, o, dm, o.tuning.spatial_order ? &origin : nullptr);
  if (!o.tuning.spatial_order) {
    origin.resize(dm.nv);
    std::iota(origin.begin(), origin.end(), 0);
  }
  return DeviceBuffer<int32_t>(ctx, origin);
}

void remap_elements(std::vector<int32_t>& elems, std::vector<int32_t>& tags, int arity,
                    const std::vector<int32_t>& origin) {
  const size_t n = elems.size() / arity;
  size_t m = 0, kt = 0;  // elements and tags kept (in place: m <= i)
  for (size_t i = 0; i < n; ++i) {
    int32_t v[3];
    bool ok = true;
    for (int k = 0; k < arity && ok; ++k) {
      const int32_t x = elems[i * arity + k];
      ok = x >= 0 && size_t(x) < origin.size();
      if (!ok) break;
      v[k] = origin[x];
      for (int j = 0; j < k; ++j) ok = ok && v[j] != v[k];
    }
    if (!ok) continue;
    std::copy(v, v + arity, elems.begin() + m * arity);
    if (i < tags.size()) tags[kt++] = tags[i];
    ++m;
  }
  elems.resize(m * arity);
  tags.resize(kt);
}

void download_result(const DeviceMesh& dm, const DeviceBuffer<int32_t>& origin, Mesh& mesh) {
  download_mesh(dm, mesh);
  if (mesh.tris.empty() && mesh.edges.empty()) return;
  const std::vector<int32_t> org = origin.download();
  remap_elements(mesh.tris, mesh.tri_tags, 3, org);
  remap_elements(mesh.edges, mesh.edge_tags, 2, org);
}

}  // namespace tc::collapse_detail
