// Device connectivity: chains the kernels of cl/connectivity.cl and cl/classify.cl with the
// runtime's primitives. Each step mirrors a step of host/topology/topology.cpp:
//   sort with a stable radix sort   <->  the reference's stable radix sort / counting sort,
//   segment heads + starts          <->  its runs of equal keys,
//   binary search for CSR offsets   <->  its prefix sums of counts,
// so the arrays come out identical (tests/device/test_connectivity.cpp checks exactly that).
#include "device/connectivity.hpp"

#include <bit>
#include <chrono>
#include <limits>
#include <string>

#include "device/primitives.hpp"

namespace tc::dev {

namespace {

const char* const kConn = "connectivity.cl";
const char* const kClassify = "classify.cl";

// Launches kernel `name` of `file` over n work items with the given arguments (DeviceBuffers
// by their cl::Buffer, scalars as the exact OpenCL types). Nothing to do when n == 0.
template <class... A>
void run(Context& ctx, const char* file, const char* name, size_t n, const A&... args) {
  if (n == 0) return;
  cl::Kernel k = ctx.kernel(file, name);
  detail::cl_call(name, [&] {
    cl_uint i = 0;
    (k.setArg(i++, args), ...);
  });
  ctx.launch(k, n, name);
}

// Number of bits needed for values 0 .. max_value (at least 1): the radix sort skips the rest.
int bits_for(uint64_t max_value) { return max_value == 0 ? 1 : 64 - std::countl_zero(max_value); }

cl_uint u32(size_t v) { return static_cast<cl_uint>(v); }

// CSR of `lists` lists from keys already in `keys` (n of them, each < lists) with payloads in
// `vals`: sorts stably, then offsets by binary search. The sorted payloads become the list.
void csr_from_sorted(Context& ctx, DeviceBuffer<uint64_t>& keys, DeviceBuffer<uint32_t>& vals, size_t n,
                     uint32_t lists, DeviceBuffer<uint32_t>& offsets, DeviceBuffer<uint32_t>& list) {
  radix_sort(ctx, keys, vals, n, bits_for(lists == 0 ? 0 : lists - 1));
  offsets = DeviceBuffer<uint32_t>(ctx, size_t(lists) + 1);
  run(ctx, kConn, "tc_csr_offsets", size_t(lists) + 1, keys.buffer(), u32(n), cl_uint(lists), offsets.buffer());
  list = vals;
  list.resize(n);
}

// CSR where entry i of `src` (n entries) belongs to list src[i] and its payload is i / per.
void csr_of_index_array(Context& ctx, const DeviceBuffer<uint32_t>& src, size_t n, uint32_t per, uint32_t lists,
                        DeviceBuffer<uint32_t>& offsets, DeviceBuffer<uint32_t>& list) {
  DeviceBuffer<uint64_t> keys(ctx, n);
  DeviceBuffer<uint32_t> vals(ctx, n);
  run(ctx, kConn, "tc_list_keys", n, src.buffer(), u32(n), cl_uint(per), keys.buffer(), vals.buffer());
  csr_from_sorted(ctx, keys, vals, n, lists, offsets, list);
}

class StageClock {
 public:
  explicit StageClock(Context& ctx) : ctx_(ctx), last_(std::chrono::steady_clock::now()) {}
  // Waits for the queue and returns the seconds since the previous call.
  double lap() {
    ctx_.finish();
    auto now = std::chrono::steady_clock::now();
    double s = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return s;
  }

 private:
  Context& ctx_;
  std::chrono::steady_clock::time_point last_;
};

}  // namespace

DeviceTopology build_device_topology(Context& ctx, const DeviceBuffer<double>& points, const DeviceBuffer<int32_t>& tets,
                                     uint32_t num_vertices, const DeviceBuffer<int32_t>* labels,
                                     const TopologyOptions& options, TopologyTimings* timings) {
  TopologyTimings tm;
  StageClock clock(ctx);
  DeviceTopology t;
  const size_t nt = tets.size() / 4;
  const uint32_t nv = num_vertices;
  // 6 * tets must fit the 32-bit payloads and the primitives' 2^31-element limit.
  if (nt > size_t(std::numeric_limits<int32_t>::max()) / 6 || nv > uint32_t(std::numeric_limits<int32_t>::max()))
    throw InputError("<mesh>", "mesh too large for 32-bit indices: " + std::to_string(nv) + " vertices, " +
                                   std::to_string(nt) + " tets");
  if (points.size() < size_t(nv) * 3)
    throw InputError("<mesh>", "point buffer holds " + std::to_string(points.size()) + " values, " +
                                   std::to_string(nv) + " vertices need " + std::to_string(size_t(nv) * 3));
  const bool has_labels = options.use_labels && labels && labels->size() == nt;
  t.num_vertices = nv;
  t.num_tets = u32(nt);
  const cl_uint n6 = u32(6 * nt), n4 = u32(4 * nt);

  // --- check the tets, so that no kernel below reads or writes out of bounds ---
  {
    DeviceBuffer<uint32_t> bad(ctx, 1);
    bad.fill(std::numeric_limits<uint32_t>::max());
    run(ctx, kConn, "tc_check_tets", nt, tets.buffer(), u32(nt), cl_int(nv), bad.buffer());
    const uint32_t b = bad.download()[0];
    if (b != std::numeric_limits<uint32_t>::max()) {
      // the same message as the reference: the first offending index of that tet
      std::vector<int32_t> v(4);
      tets.download(v.data(), 4, 4 * size_t(b));
      for (int i = 0; i < 4; ++i) {
        if (v[i] < 0 || uint32_t(v[i]) >= nv)
          throw InputError("<mesh>", "tet " + std::to_string(b) + " has vertex index " + std::to_string(v[i]) +
                                         " outside [0, " + std::to_string(nv) + ")");
        for (int j = 0; j < i; ++j)
          if (v[i] == v[j]) throw InputError("<mesh>", "tet " + std::to_string(b) + " repeats vertex " + std::to_string(v[i]));
      }
    }
  }
  tm.check = clock.lap();

  // --- edges, tet -> edges, edge -> tets ---
  {
    DeviceBuffer<uint64_t> keys(ctx, n6);
    DeviceBuffer<uint32_t> vals(ctx, n6);
    run(ctx, kConn, "tc_edge_keys", n6, tets.buffer(), n6, keys.buffer(), vals.buffer());
    radix_sort(ctx, keys, vals, n6, 32 + bits_for(nv == 0 ? 0 : nv - 1));
    DeviceBuffer<uint32_t> heads(ctx, n6);
    t.edge_tets_offsets = DeviceBuffer<uint32_t>(ctx, 1);
    t.num_edges = segment_heads(ctx, keys, n6, heads, t.edge_tets_offsets);
    t.edges = DeviceBuffer<uint32_t>(ctx, 2 * size_t(t.num_edges));
    t.tet_edges = DeviceBuffer<uint32_t>(ctx, n6);
    t.edge_tets = DeviceBuffer<uint32_t>(ctx, n6);
    run(ctx, kConn, "tc_edge_segments", t.num_edges, keys.buffer(), vals.buffer(), t.edge_tets_offsets.buffer(),
        cl_uint(t.num_edges), t.edges.buffer(), t.tet_edges.buffer(), t.edge_tets.buffer());
  }
  const uint32_t ne = t.num_edges;
  tm.edges = clock.lap();

  // --- vertex -> tets, vertex -> edges ---
  {
    // the tets buffer serves as the key source directly: indices are checked non-negative
    DeviceBuffer<uint64_t> keys(ctx, n4);
    DeviceBuffer<uint32_t> vals(ctx, n4);
    run(ctx, kConn, "tc_list_keys", n4, tets.buffer(), n4, cl_uint(4), keys.buffer(), vals.buffer());
    csr_from_sorted(ctx, keys, vals, n4, nv, t.vertex_tets_offsets, t.vertex_tets);
  }
  csr_of_index_array(ctx, t.edges, 2 * size_t(ne), 2, nv, t.vertex_edges_offsets, t.vertex_edges);
  tm.vertex_lists = clock.lap();

  // --- faces: boundary and interface faces, outward, with unit normals ---
  {
    DeviceBuffer<uint64_t> keys(ctx, n4);
    DeviceBuffer<uint32_t> vals(ctx, n4);
    run(ctx, kConn, "tc_face_keys", n4, tets.buffer(), t.tet_edges.buffer(), n4, keys.buffer(), vals.buffer());
    radix_sort(ctx, keys, vals, n4, 32 + bits_for(ne == 0 ? 0 : ne - 1));
    DeviceBuffer<uint32_t> heads(ctx, n4), starts(ctx, 1);
    const uint32_t nf = segment_heads(ctx, keys, n4, heads, starts);
    keys = DeviceBuffer<uint64_t>();  // release before the S-face arrays are allocated
    DeviceBuffer<int32_t> no_labels(ctx, 1);
    const cl::Buffer& lab = has_labels ? labels->buffer() : no_labels.buffer();
    DeviceBuffer<uint32_t> count(ctx, nf), offset(ctx, nf);
    run(ctx, kConn, "tc_face_count", nf, vals.buffer(), starts.buffer(), cl_uint(nf), lab, cl_uint(has_labels),
        count.buffer());
    const uint32_t ns = exclusive_scan(ctx, count, offset, nf);
    t.num_sfaces = ns;
    t.sfaces = DeviceBuffer<uint32_t>(ctx, 3 * size_t(ns));
    t.sface_tet = DeviceBuffer<uint32_t>(ctx, ns);
    t.sface_local = DeviceBuffer<int8_t>(ctx, ns);
    t.sface_interface = DeviceBuffer<uint8_t>(ctx, ns);
    t.sface_normals = DeviceBuffer<double>(ctx, 3 * size_t(ns));
    run(ctx, kConn, "tc_face_emit", nf, vals.buffer(), starts.buffer(), cl_uint(nf), lab, cl_uint(has_labels),
        offset.buffer(), tets.buffer(), points.buffer(), t.sfaces.buffer(), t.sface_tet.buffer(),
        t.sface_local.buffer(), t.sface_interface.buffer(), t.sface_normals.buffer());
  }
  const uint32_t ns = t.num_sfaces;
  tm.faces = clock.lap();

  // --- vertex -> S-faces, edge -> S-faces ---
  csr_of_index_array(ctx, t.sfaces, 3 * size_t(ns), 3, nv, t.vertex_sfaces_offsets, t.vertex_sfaces);
  {
    const size_t n3 = 3 * size_t(ns);
    DeviceBuffer<uint64_t> keys(ctx, n3);
    DeviceBuffer<uint32_t> vals(ctx, n3);
    run(ctx, kConn, "tc_sface_edge_keys", n3, t.sface_tet.buffer(), t.sface_local.buffer(), t.tet_edges.buffer(),
        u32(n3), keys.buffer(), vals.buffer());
    csr_from_sorted(ctx, keys, vals, n3, ne, t.edge_sfaces_offsets, t.edge_sfaces);
  }
  tm.sface_lists = clock.lap();

  // --- boundary flags ---
  t.vertex_boundary = DeviceBuffer<uint8_t>(ctx, nv);
  t.edge_boundary = DeviceBuffer<uint8_t>(ctx, ne);
  run(ctx, kConn, "tc_boundary_flags", nv, t.vertex_sfaces_offsets.buffer(), t.vertex_sfaces.buffer(), cl_uint(nv),
      t.sface_interface.buffer(), t.vertex_boundary.buffer());
  run(ctx, kConn, "tc_boundary_flags", ne, t.edge_sfaces_offsets.buffer(), t.edge_sfaces.buffer(), cl_uint(ne),
      t.sface_interface.buffer(), t.edge_boundary.buffer());
  tm.flags = clock.lap();

  // --- classification ---
  t.edge_ridge = DeviceBuffer<uint8_t>(ctx, ne);
  t.vertex_class = DeviceBuffer<uint8_t>(ctx, nv);
  run(ctx, kClassify, "tc_classify_edges", ne, t.edges.buffer(), t.edge_sfaces_offsets.buffer(),
      t.edge_sfaces.buffer(), cl_uint(ne), t.sfaces.buffer(), t.sface_normals.buffer(), cl_double(options.eps_r),
      t.edge_ridge.buffer());
  run(ctx, kClassify, "tc_classify_vertices", nv, t.vertex_edges_offsets.buffer(), t.vertex_edges.buffer(),
      t.edge_ridge.buffer(), t.vertex_sfaces_offsets.buffer(), t.vertex_sfaces.buffer(), cl_uint(nv),
      t.sfaces.buffer(), t.sface_normals.buffer(), cl_double(options.eps_f), t.vertex_class.buffer());
  tm.classify = clock.lap();
  if (timings) *timings = tm;
  return t;
}

DeviceTopology build_device_topology(Context& ctx, const Mesh& mesh, const TopologyOptions& options,
                                     TopologyTimings* timings) {
  if (mesh.points.size() % 3 != 0 || mesh.tets.size() % 4 != 0)
    throw InputError("<mesh>", "point or tet array length is not a multiple of 3 / 4");
  if (mesh.num_vertices() > std::numeric_limits<int32_t>::max())
    throw InputError("<mesh>", "mesh too large for 32-bit indices: " + std::to_string(mesh.num_vertices()) + " vertices");
  DeviceBuffer<double> points(ctx, mesh.points);
  DeviceBuffer<int32_t> tets(ctx, mesh.tets);
  const bool lab = !mesh.tet_labels.empty() && mesh.tet_labels[0].values.size() == size_t(mesh.num_tets());
  DeviceBuffer<int32_t> labels(ctx, lab ? mesh.tet_labels[0].values : std::vector<int32_t>{});
  return build_device_topology(ctx, points, tets, uint32_t(mesh.num_vertices()), lab ? &labels : nullptr, options,
                               timings);
}

namespace {

template <class T>
size_t b(const DeviceBuffer<T>& x) {
  return x.bytes();
}

template <class D, class S>
std::vector<D> get(const DeviceBuffer<S>& buf) {
  static_assert(sizeof(D) == sizeof(S));
  std::vector<D> out(buf.size());
  buf.download(reinterpret_cast<S*>(out.data()), out.size());  // int32 <-> uint32: same bits
  return out;
}

}  // namespace

size_t DeviceTopology::bytes() const {
  return b(edges) + b(tet_edges) + b(vertex_tets_offsets) + b(vertex_tets) + b(vertex_edges_offsets) +
         b(vertex_edges) + b(edge_tets_offsets) + b(edge_tets) + b(sfaces) + b(sface_tet) + b(sface_local) +
         b(sface_interface) + b(sface_normals) + b(vertex_sfaces_offsets) + b(vertex_sfaces) +
         b(edge_sfaces_offsets) + b(edge_sfaces) + b(vertex_boundary) + b(edge_boundary) + b(vertex_class) +
         b(edge_ridge);
}

Topology DeviceTopology::download() const {
  Topology t;
  t.num_vertices = int32_t(num_vertices);
  t.num_tets = int32_t(num_tets);
  t.edges = get<int32_t>(edges);
  t.tet_edges = get<int32_t>(tet_edges);
  t.vertex_tets_offsets = get<int32_t>(vertex_tets_offsets);
  t.vertex_tets = get<int32_t>(vertex_tets);
  t.vertex_edges_offsets = get<int32_t>(vertex_edges_offsets);
  t.vertex_edges = get<int32_t>(vertex_edges);
  t.edge_tets_offsets = get<int32_t>(edge_tets_offsets);
  t.edge_tets = get<int32_t>(edge_tets);
  t.sfaces = get<int32_t>(sfaces);
  t.sface_tet = get<int32_t>(sface_tet);
  t.sface_local = get<int8_t>(sface_local);
  t.sface_interface = get<uint8_t>(sface_interface);
  t.sface_normals = get<double>(sface_normals);
  t.vertex_sfaces_offsets = get<int32_t>(vertex_sfaces_offsets);
  t.vertex_sfaces = get<int32_t>(vertex_sfaces);
  t.edge_sfaces_offsets = get<int32_t>(edge_sfaces_offsets);
  t.edge_sfaces = get<int32_t>(edge_sfaces);
  t.vertex_boundary = get<uint8_t>(vertex_boundary);
  t.edge_boundary = get<uint8_t>(edge_boundary);
  t.vertex_class = get<uint8_t>(vertex_class);
  t.edge_ridge = get<uint8_t>(edge_ridge);
  return t;
}

}  // namespace tc::dev
