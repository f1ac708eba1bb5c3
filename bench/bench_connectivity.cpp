// Connectivity and classification: the collapse's stage 1 on the OpenCL device (PoCL here,
// collapse_detail::build_connectivity, cl/collapse_connectivity.cl) against the single-threaded
// C++ construction (tc::build_topology), medians of several runs in the same process, and the
// peak memory the device construction needs, in bytes per tet.
//
//   bench_connectivity [--runs N] [--generated N] [MESH ...]
//
// Without meshes it uses the shared robot-514k and rocker-arm-964k meshes. --generated N adds
// cube_tets-style [0,1]^3 Kuhn meshes of 6 N^3 tets (N = 95 gives 5.1M tets).
//
// The device build is timed three ways, each on a mesh already uploaded (upload_mesh) and into
// a fresh Connectivity, up to the queue's finish:
//   rings on the device       ring(v) by the device's count, scatter and sort (a GPU's way)
//   rings from the upload     ring(v) filled on the host by upload_mesh (a CPU device's way,
//                             Context::cpu_tuning; their host time is in the upload's)
//   spatial order             the mesh renumbered as collapse() uploads it (tuning.spatial_order),
//                             with this device's rings
// The first two are on the input's numbering, so their arrays are compared with the CPU
// reference's (what build_connectivity keeps: edges, rings, N(v), the S-faces of smask and
// tet_nbr, flags and classes; it has no tet -> edge, edge -> tet or S-face lists and keeps no
// normals). A vertex with more than TCC_MAX_VERTEX_SFACES (64) S-faces is a corner on the
// device whatever its reference class; such vertices are counted, not called a difference.
// TETCOLLAPSE_PROFILE_KERNELS=1 prints the time of every kernel at the end (runtime.cpp).
//
// Peak device memory: on a CPU device (PoCL) buffers live in the process, so the bench resets
// the process's peak resident size (/proc/self/clear_refs, "5") just before one device build on
// already uploaded inputs and reads VmHWM after it: peak = input buffers + (VmHWM - VmRSS before),
// after malloc_trim so that freed heap pages are not silently reused.
// On a GPU this reads as ~0 and only the result size (the Connectivity's arrays) is meaningful.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <malloc.h>
#include <string>
#include <vector>

#include "collapse/stages.hpp"
#include "tetcollapse/io.hpp"
#include "tetcollapse/topology.hpp"

using namespace tc;
using namespace tc::collapse_detail;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  if (v.empty()) return 0;
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// VmRSS / VmHWM of this process in bytes (0 when /proc is not there).
size_t proc_status(const char* key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  const size_t klen = std::strlen(key);
  while (std::getline(in, line))
    if (line.compare(0, klen, key) == 0 && line.size() > klen && line[klen] == ':')
      return size_t(std::stoull(line.substr(klen + 1))) * 1024;  // "kB"
  return 0;
}

bool reset_peak_rss() {
  std::ofstream o("/proc/self/clear_refs");
  o << "5";
  return bool(o);
}

// Bytes of the arrays a Connectivity keeps for the later stages, and of its scratch.
size_t result_bytes(const Connectivity& c) {
  return c.vt_off.bytes() + c.vt.bytes() + c.nb_off.bytes() + c.nb.bytes() + c.nb_edge.bytes() + c.edge_off.bytes() +
         c.edges.bytes() + c.tet_nbr.bytes() + c.vflags.bytes() + c.vclass.bytes() + c.eflags.bytes() +
         c.owns_s.bytes() + c.smask.bytes();
}
size_t scratch_bytes(const Connectivity& c) {
  return c.count.bytes() + c.cursor.bytes() + c.up_count.bytes() + c.scratch.bytes() + c.dirty_list.bytes();
}

size_t input_bytes(const DeviceMesh& dm) {
  size_t b = dm.points.bytes() + dm.tets.bytes() + dm.vfields.bytes() + dm.tfields.bytes() + dm.vmask.bytes();
  for (const auto& l : dm.labels) b += l.bytes();
  if (dm.has_rings) b += dm.vt_off.bytes() + dm.vt.bytes();
  return b;
}

// TCC_MAX_VERTEX_SFACES (cl/collapse_common.h) as the kernels are built by default: a vertex
// with more S-faces is a corner (conn_surface_flags), whatever its class in the reference.
constexpr int kMaxVertexSfaces = 64;

// "" when the device's arrays are those of the reference (as far as build_connectivity keeps
// them; the classes with the cap above), else the first that differs. *capped: the vertices the
// cap made corners that the reference does not.
std::string differs(const DeviceMesh& dm, const Connectivity& c, const Topology& ref, int64_t* capped) {
  *capped = 0;
  if (int64_t(dm.nv) != ref.num_vertices || int64_t(dm.nt) != ref.num_tets) return "counts";
  if (int64_t(c.ne) != ref.num_edges()) return "edge count";
  if (c.edges.download_range(0, 2 * size_t(c.ne)) != ref.edges) return "edges";
  auto as_u32 = [](const std::vector<int32_t>& v) { return std::vector<uint32_t>(v.begin(), v.end()); };
  if (c.vt_off.download_range(0, size_t(dm.nv) + 1) != as_u32(ref.vertex_tets_offsets)) return "vertex_tets_offsets";
  if (c.vt.download_range(0, 4 * size_t(dm.nt)) != ref.vertex_tets) return "vertex_tets";
  const std::vector<uint32_t> nb_off = c.nb_off.download_range(0, size_t(dm.nv) + 1);
  if (nb_off != as_u32(ref.vertex_edges_offsets)) return "vertex_edges_offsets";
  std::vector<int32_t> nb_edge = c.nb_edge.download_range(0, nb_off.back());
  const std::vector<int32_t> nb = c.nb.download_range(0, nb_off.back());
  for (uint32_t v = 0; v < dm.nv; ++v) {
    for (uint32_t k = nb_off[v]; k < nb_off[v + 1]; ++k) {
      const int32_t e = nb_edge[k];
      if (e < 0 || e >= ref.num_edges() || std::min<int32_t>(v, nb[k]) != ref.edges[2 * size_t(e)] ||
          std::max<int32_t>(v, nb[k]) != ref.edges[2 * size_t(e) + 1])
        return "N(v) / nb_edge";
    }
    std::sort(nb_edge.begin() + nb_off[v], nb_edge.begin() + nb_off[v + 1]);
  }
  if (nb_edge != ref.vertex_edges) return "vertex_edges";
  if (c.vflags.download_range(0, dm.nv) != ref.vertex_boundary) return "vertex_boundary";
  std::vector<uint8_t> expected = ref.vertex_class;
  for (int32_t v = 0; v < ref.num_vertices; ++v)
    if (ref.vertex_sfaces_offsets[v + 1] - ref.vertex_sfaces_offsets[v] > kMaxVertexSfaces &&
        expected[v] != uint8_t(VertexClass::Corner)) {
      expected[v] = uint8_t(VertexClass::Corner);
      ++*capped;
    }
  if (c.vclass.download_range(0, dm.nv) != expected) return "vertex_class";
  const std::vector<uint8_t> eflags = c.eflags.download_range(0, c.ne);
  for (uint32_t e = 0; e < c.ne; ++e) {
    if ((eflags[e] & 3) != ref.edge_boundary[e]) return "edge_boundary";
    if (((eflags[e] >> 2) & 1) != ref.edge_ridge[e]) return "edge_ridge";
  }
  const std::vector<uint8_t> smask = c.smask.download_range(0, dm.nt);
  const std::vector<int32_t> tet_nbr = c.tet_nbr.download_range(0, 4 * size_t(dm.nt));
  int64_t owned = 0;
  for (uint8_t m : smask) owned += __builtin_popcount(m);
  if (owned != ref.num_sfaces()) return "S-face count";
  for (int32_t s = 0; s < ref.num_sfaces(); ++s) {
    const int32_t t = ref.sface_tet[s];
    const int f = ref.sface_local[s];
    if (!((smask[t] >> f) & 1)) return "S-faces (smask)";
    if ((tet_nbr[4 * size_t(t) + f] >= 0) != (ref.sface_interface[s] != 0)) return "sface_interface";
  }
  return "";
}

// Copies every array build_connectivity keeps to the host (what a host-side consumer would pay).
void download_all(const DeviceMesh& dm, const Connectivity& c) {
  const size_t nv = dm.nv, nt = dm.nt, nnb = 2 * size_t(c.ne);
  (void)c.vt_off.download_range(0, nv + 1);
  (void)c.vt.download_range(0, 4 * nt);
  (void)c.nb_off.download_range(0, nv + 1);
  (void)c.nb.download_range(0, nnb);
  (void)c.nb_edge.download_range(0, nnb);
  (void)c.edge_off.download_range(0, nv + 1);
  (void)c.edges.download_range(0, 2 * size_t(c.ne));
  (void)c.tet_nbr.download_range(0, 4 * nt);
  (void)c.vflags.download_range(0, nv);
  (void)c.vclass.download_range(0, nv);
  (void)c.eflags.download_range(0, c.ne);
  (void)c.owns_s.download_range(0, nt);
  (void)c.smask.download_range(0, nt);
}

enum class Rings { Device, Upload };

// Median time of build_connectivity on dm (rings as asked; dm.vt_off / dm.vt hold the upload's
// rings when from the upload, and are put back before each run), into a fresh Connectivity.
// The last run's Connectivity goes to *last.
double time_builds(Context& ctx, DeviceMesh& dm, const StageParams& p, Rings rings, int runs, Connectivity* last) {
  DeviceBuffer<uint32_t> keep_off(ctx, 0);
  DeviceBuffer<int32_t> keep_vt(ctx, 0);
  if (rings == Rings::Upload) {
    keep_off.copy_from(dm.vt_off, size_t(dm.nv) + 1);
    keep_vt.copy_from(dm.vt, 4 * size_t(dm.nt));
  }
  std::vector<double> t;
  for (int r = 0; r < runs; ++r) {
    if (rings == Rings::Upload) {
      dm.vt_off = DeviceBuffer<uint32_t>(ctx, 0);
      dm.vt = DeviceBuffer<int32_t>(ctx, 0);
      dm.vt_off.copy_from(keep_off, size_t(dm.nv) + 1);
      dm.vt.copy_from(keep_vt, 4 * size_t(dm.nt));
    }
    dm.has_rings = rings == Rings::Upload;
    ctx.finish();
    Connectivity c;
    const auto t0 = std::chrono::steady_clock::now();
    build_connectivity(ctx, dm, c, p);
    ctx.finish();
    t.push_back(seconds_since(t0));
    if (last && r + 1 == runs) *last = std::move(c);
  }
  if (rings == Rings::Upload) {  // as uploaded again
    dm.vt_off = std::move(keep_off);
    dm.vt = std::move(keep_vt);
    dm.has_rings = true;
  }
  return median(t);
}

void bench(Context& ctx, const std::string& name, const Mesh& mesh, int runs) {
  const size_t nt = size_t(mesh.num_tets());
  std::printf("\n== %s: %lld vertices, %zu tets, %d runs (medians)\n", name.c_str(), (long long)mesh.num_vertices(), nt,
              runs);
  std::vector<TopologyTimings> cpu_t(runs);
  Topology cpu;
  for (int r = 0; r < runs; ++r) cpu = build_topology(mesh, {}, &cpu_t[r]);
  auto cpu_median = [&](const std::function<double(const TopologyTimings&)>& f) {
    std::vector<double> v;
    for (const auto& r : cpu_t) v.push_back(f(r));
    return median(v);
  };

  CollapseOptions o;  // the library's thresholds and labels, as build_topology's defaults
  const StageParams p = params_from(o);
  auto t0 = std::chrono::steady_clock::now();
  DeviceMesh dm;
  upload_mesh(ctx, mesh, o, dm);
  ctx.finish();
  const double upload = seconds_since(t0);
  const size_t in_bytes = input_bytes(dm);

  // one build for the memory peak, on inputs already on the device, the rings as this device
  // has them (a copy of the upload's kept aside first, outside the measurement: the build takes
  // them over): give freed heap pages back first, so the device allocations below must fault in
  // new pages instead of silently reusing memory the CPU runs left in the allocator
  const bool upload_rings = dm.has_rings;
  DeviceBuffer<uint32_t> ring_off(ctx, 0);
  DeviceBuffer<int32_t> ring_vt(ctx, 0);
  if (upload_rings) {
    ring_off.copy_from(dm.vt_off, size_t(dm.nv) + 1);
    ring_vt.copy_from(dm.vt, 4 * size_t(dm.nt));
    ctx.finish();
  }
  malloc_trim(0);
  const size_t rss_before = proc_status("VmRSS");
  const bool reset = reset_peak_rss();
  size_t res_bytes = 0, scr_bytes = 0;
  {
    Connectivity c;
    build_connectivity(ctx, dm, c, p);
    ctx.finish();
    res_bytes = result_bytes(c);
    scr_bytes = scratch_bytes(c);
  }
  const size_t hwm = proc_status("VmHWM");
  if (upload_rings) {
    dm.vt_off = std::move(ring_off);
    dm.vt = std::move(ring_vt);
    dm.has_rings = true;
  }

  Connectivity on_device, from_upload;
  const double dev_rings = time_builds(ctx, dm, p, Rings::Device, runs, &on_device);
  const double up_rings = upload_rings ? time_builds(ctx, dm, p, Rings::Upload, runs, &from_upload) : 0;
  t0 = std::chrono::steady_clock::now();
  download_all(dm, on_device);
  const double download = seconds_since(t0);
  int64_t capped = 0, capped_upload = 0;
  const std::string diff_device = differs(dm, on_device, cpu, &capped);
  const std::string diff_upload = upload_rings ? differs(dm, from_upload, cpu, &capped_upload) : "";
  on_device = Connectivity();
  from_upload = Connectivity();
  double spatial = 0, spatial_upload = 0;
  uint32_t spatial_ne = 0;
  {
    DeviceMesh sm;
    std::vector<int32_t> vertex_new;
    t0 = std::chrono::steady_clock::now();
    upload_mesh(ctx, mesh, o, sm, &vertex_new);
    ctx.finish();
    spatial_upload = seconds_since(t0);
    Connectivity c;
    spatial = time_builds(ctx, sm, p, sm.has_rings ? Rings::Upload : Rings::Device, runs, &c);
    spatial_ne = c.ne;
  }

  const char* names[8] = {"check tets", "edges", "vertex->tets/edges", "boundary faces+normals",
                          "vertex/edge->S-faces", "boundary flags", "classification", "total"};
  const std::function<double(const TopologyTimings&)> cols[8] = {
      [](const TopologyTimings& t) { return t.check; },        [](const TopologyTimings& t) { return t.edges; },
      [](const TopologyTimings& t) { return t.vertex_lists; }, [](const TopologyTimings& t) { return t.faces; },
      [](const TopologyTimings& t) { return t.sface_lists; },  [](const TopologyTimings& t) { return t.flags; },
      [](const TopologyTimings& t) { return t.classify; },     [](const TopologyTimings& t) { return t.total(); }};
  const double cpu_total = cpu_median(cols[7]);
  std::printf("%-40s %12s %8s\n", "stage", "seconds", "CPU/this");
  std::printf("CPU build_topology, 1 thread\n");
  for (int i = 0; i < 8; ++i) std::printf("  %-38s %12.4f\n", names[i], cpu_median(cols[i]));
  std::printf("device build_connectivity\n");
  auto row = [&](const char* what, double s) {
    std::printf("  %-38s %12.4f %8.2f\n", what, s, s > 0 ? cpu_total / s : 0.0);
  };
  row("rings on the device", dev_rings);
  if (upload_rings) row("rings from the upload", up_rings);
  else std::printf("  %-38s %12s\n", "rings from the upload", "n/a (a CPU device's only)");
  row(upload_rings ? "spatial order, rings from the upload" : "spatial order, rings on the device", spatial);
  std::printf("upload %.4f s (spatial order %.4f s), download %.4f s (not in the totals)\n", upload, spatial_upload,
              download);
  auto verdict = [](const std::string& d) { return d.empty() ? std::string("yes") : "NO (" + d + ")"; };
  std::printf("arrays equal to the CPU reference: rings on the device %s", verdict(diff_device).c_str());
  if (upload_rings) std::printf(", rings from the upload %s", verdict(diff_upload).c_str());
  std::printf("; spatial order: %s edges\n", int64_t(spatial_ne) == cpu.num_edges() ? "as many" : "NOT as many");
  if (capped)
    std::printf("  (%lld vertices with more than %d S-faces: corners on the device, not in the reference)\n",
                (long long)capped, kMaxVertexSfaces);
  const TopologySummary s = summarize(mesh, cpu);
  std::printf("edges %lld, boundary faces %lld, interface faces %lld; face/ridge/corner vertices %lld/%lld/%lld, "
              "ridge edges %lld\n",
              (long long)s.edges, (long long)s.boundary_faces, (long long)s.interface_faces,
              (long long)s.face_vertices, (long long)s.ridge_vertices, (long long)s.corner_vertices,
              (long long)s.ridge_edges);
  std::printf("device result arrays: %zu bytes = %.1f bytes/tet (scratch kept %.1f bytes/tet); inputs %.1f bytes/tet\n",
              res_bytes, double(res_bytes) / double(nt), double(scr_bytes) / double(nt), double(in_bytes) / double(nt));
  if (reset && hwm >= rss_before)
    std::printf("peak device memory (process peak RSS on %s): %.1f bytes/tet (%.1f MiB)\n", ctx.info().name.c_str(),
                double(in_bytes + hwm - rss_before) / double(nt), double(in_bytes + hwm - rss_before) / 1048576.0);
  else
    std::printf("peak device memory: not measurable here (no /proc/self/clear_refs)\n");
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 5;
  std::vector<std::string> files;
  std::vector<int> generated;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--runs" && i + 1 < argc) runs = std::max(1, std::atoi(argv[++i]));
    else if (a == "--generated" && i + 1 < argc) generated.push_back(std::max(1, std::atoi(argv[++i])));
    else if (a == "-h" || a == "--help") {
      std::printf("usage: bench_connectivity [--runs N] [--generated N] [MESH ...]\n");
      return 0;
    } else files.push_back(a);
  }
  if (files.empty() && generated.empty())
    for (const char* f : {"gen_tetgen_thingi255172_make-robot_514k.msh", "gen_tetgen_rocker-arm_964k.msh"})
      files.push_back(std::string(TC_SHARED_MESHES) + "/" + f);
  try {
    Context ctx;
    std::printf("device: %s (%s), %u compute units\n", ctx.info().name.c_str(), ctx.info().platform_name.c_str(),
                ctx.info().compute_units);
    {  // compile (or load from the cache) every kernel on a tiny mesh before measuring
      const Mesh cube = tc::make_cube_mesh(2);
      CollapseOptions o;
      DeviceMesh dm;
      upload_mesh(ctx, cube, o, dm);
      dm.has_rings = false;  // the device's ring kernels too
      Connectivity c;
      build_connectivity(ctx, dm, c, params_from(o));
      ctx.finish();
    }
    for (const auto& f : files) {
      auto t0 = std::chrono::steady_clock::now();
      Mesh m = read_mesh(f);
      std::printf("\nread %s in %.2f s\n", f.c_str(), seconds_since(t0));
      bench(ctx, f.substr(f.find_last_of('/') + 1), m, runs);
    }
    for (int n : generated) bench(ctx, "generated Kuhn cube n=" + std::to_string(n), tc::make_cube_mesh(n), runs);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_connectivity: %s\n", e.what());
    return 1;
  }
  return 0;
}
