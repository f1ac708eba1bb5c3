// Connectivity and classification: time per stage on the OpenCL device (PoCL here) against the
// single-threaded C++ construction, medians of several runs in the same process, and the peak
// memory the device construction needs, in bytes per tet.
//
//   bench_connectivity [--runs N] [--generated N] [MESH ...]
//
// Without meshes it uses the shared robot-514k and rocker-arm-964k meshes. --generated N adds
// cube_tets-style [0,1]^3 Kuhn meshes of 6 N^3 tets (N = 95 gives 5.1M tets).
//
// Peak device memory: on a CPU device (PoCL) buffers live in the process, so the bench resets
// the process's peak resident size (/proc/self/clear_refs, "5") just before one device build on
// already uploaded inputs and reads VmHWM after it: peak = input buffers + (VmHWM - VmRSS before),
// after malloc_trim so that freed heap pages are not silently reused.
// On a GPU this reads as ~0 and only the result size (DeviceTopology::bytes) is meaningful.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <malloc.h>
#include <string>
#include <vector>

#include "device/connectivity.hpp"
#include "tetcollapse/io.hpp"
#include "tetcollapse/topology.hpp"

using namespace tc;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  if (v.empty()) return 0;
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
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


bool equal(const Topology& a, const Topology& b) {
  return a.edges == b.edges && a.tet_edges == b.tet_edges && a.vertex_tets_offsets == b.vertex_tets_offsets &&
         a.vertex_tets == b.vertex_tets && a.vertex_edges_offsets == b.vertex_edges_offsets &&
         a.vertex_edges == b.vertex_edges && a.edge_tets_offsets == b.edge_tets_offsets && a.edge_tets == b.edge_tets &&
         a.sfaces == b.sfaces && a.sface_tet == b.sface_tet && a.sface_local == b.sface_local &&
         a.sface_interface == b.sface_interface && a.sface_normals == b.sface_normals &&
         a.vertex_sfaces_offsets == b.vertex_sfaces_offsets && a.vertex_sfaces == b.vertex_sfaces &&
         a.edge_sfaces_offsets == b.edge_sfaces_offsets && a.edge_sfaces == b.edge_sfaces &&
         a.vertex_boundary == b.vertex_boundary && a.edge_boundary == b.edge_boundary &&
         a.vertex_class == b.vertex_class && a.edge_ridge == b.edge_ridge;
}

struct StageMedians {
  std::array<double, 8> s{};  // check, edges, vertex_lists, faces, sface_lists, flags, classify, total
};

StageMedians medians(const std::vector<TopologyTimings>& runs) {
  StageMedians m;
  auto col = [&](auto f) {
    std::vector<double> v;
    for (const auto& r : runs) v.push_back(f(r));
    return median(v);
  };
  m.s[0] = col([](const TopologyTimings& t) { return t.check; });
  m.s[1] = col([](const TopologyTimings& t) { return t.edges; });
  m.s[2] = col([](const TopologyTimings& t) { return t.vertex_lists; });
  m.s[3] = col([](const TopologyTimings& t) { return t.faces; });
  m.s[4] = col([](const TopologyTimings& t) { return t.sface_lists; });
  m.s[5] = col([](const TopologyTimings& t) { return t.flags; });
  m.s[6] = col([](const TopologyTimings& t) { return t.classify; });
  m.s[7] = col([](const TopologyTimings& t) { return t.total(); });
  return m;
}

void bench(Context& ctx, const std::string& name, const Mesh& mesh, int runs) {
  const size_t nt = size_t(mesh.num_tets());
  std::printf("\n== %s: %lld vertices, %zu tets, %d runs (medians)\n", name.c_str(), (long long)mesh.num_vertices(), nt,
              runs);
  std::vector<TopologyTimings> cpu_t(runs), dev_t(runs);
  Topology cpu;
  for (int r = 0; r < runs; ++r) cpu = build_topology(mesh, {}, &cpu_t[r]);

  auto t0 = std::chrono::steady_clock::now();
  DeviceBuffer<double> points(ctx, mesh.points);
  DeviceBuffer<int32_t> tets(ctx, mesh.tets);
  const bool lab = !mesh.tet_labels.empty() && mesh.tet_labels[0].values.size() == nt;
  DeviceBuffer<int32_t> labels(ctx, lab ? mesh.tet_labels[0].values : std::vector<int32_t>{});
  ctx.finish();
  const double upload = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const size_t input_bytes = points.bytes() + tets.bytes() + labels.bytes();

  // one build for the memory peak, on inputs already on the device
  // give freed heap pages back first, so the device allocations below must fault in new pages
  // instead of silently reusing memory the CPU runs left in the allocator
  malloc_trim(0);
  const size_t rss_before = proc_status("VmRSS");
  const bool reset = reset_peak_rss();
  size_t result_bytes = 0;
  {
    dev::DeviceTopology d = dev::build_device_topology(ctx, points, tets, uint32_t(mesh.num_vertices()),
                                                       lab ? &labels : nullptr);
    result_bytes = d.bytes();
  }
  const size_t hwm = proc_status("VmHWM");
  for (int r = 0; r < runs; ++r)
    dev::build_device_topology(ctx, points, tets, uint32_t(mesh.num_vertices()), lab ? &labels : nullptr, {},
                               &dev_t[r]);
  dev::DeviceTopology d = dev::build_device_topology(ctx, points, tets, uint32_t(mesh.num_vertices()),
                                                     lab ? &labels : nullptr);
  t0 = std::chrono::steady_clock::now();
  const Topology dev_host = d.download();
  const double download = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  const StageMedians c = medians(cpu_t), g = medians(dev_t);
  const char* names[8] = {"check tets", "edges", "vertex->tets/edges", "boundary faces+normals",
                          "vertex/edge->S-faces", "boundary flags", "classification", "total"};
  std::printf("%-24s %12s %12s %8s\n", "stage", "CPU 1 thr s", "device s", "CPU/dev");
  for (int i = 0; i < 8; ++i)
    std::printf("%-24s %12.4f %12.4f %8.2f\n", names[i], c.s[i], g.s[i], g.s[i] > 0 ? c.s[i] / g.s[i] : 0.0);
  std::printf("upload %.4f s, download %.4f s (not in the totals)\n", upload, download);
  std::printf("arrays equal to the CPU reference: %s\n", equal(cpu, dev_host) ? "yes" : "NO");
  const TopologySummary s = summarize(mesh, cpu);
  std::printf("edges %lld, boundary faces %lld, interface faces %lld; face/ridge/corner vertices %lld/%lld/%lld, "
              "ridge edges %lld\n",
              (long long)s.edges, (long long)s.boundary_faces, (long long)s.interface_faces,
              (long long)s.face_vertices, (long long)s.ridge_vertices, (long long)s.corner_vertices,
              (long long)s.ridge_edges);
  std::printf("device result arrays: %zu bytes = %.1f bytes/tet; inputs %.1f bytes/tet\n", result_bytes,
              double(result_bytes) / double(nt), double(input_bytes) / double(nt));
  if (reset && hwm >= rss_before)
    std::printf("peak device memory (process peak RSS on %s): %.1f bytes/tet (%.1f MiB)\n", ctx.info().name.c_str(),
                double(input_bytes + hwm - rss_before) / double(nt), double(input_bytes + hwm - rss_before) / 1048576.0);
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
    // compile (or load from the cache) every kernel on a tiny mesh before measuring
    dev::build_device_topology(ctx, tc::make_cube_mesh(2));
    for (const auto& f : files) {
      auto t0 = std::chrono::steady_clock::now();
      Mesh m = read_mesh(f);
      std::printf("\nread %s in %.2f s\n", f.c_str(),
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      bench(ctx, f.substr(f.find_last_of('/') + 1), m, runs);
    }
    for (int n : generated) bench(ctx, "generated Kuhn cube n=" + std::to_string(n), tc::make_cube_mesh(n), runs);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_connectivity: %s\n", e.what());
    return 1;
  }
  return 0;
}
