// Speed of the VTK writers and readers on the largest shared mesh: VTU appended (raw) and
// VTK legacy BINARY, median of 5 runs each. Usage: bench_io_vtk [mesh file]
// Without the shared meshes it uses a generated cube of 50^3 * 6 tets.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <unistd.h>

#include "bench_util.hpp"
#include "tetcollapse/io.hpp"

namespace {

using tc::bench::median_seconds;


}  // namespace

int main(int argc, char** argv) {
  std::string src = argc > 1 ? argv[1] : std::string(TC_SHARED_MESHES) + "/gen_tetgen_rocker-arm_964k.msh";
  tc::Mesh mesh;
  if (std::filesystem::exists(src)) {
    mesh = tc::read_mesh(src);
  } else {
    std::printf("%s not found; using a generated cube of 50^3*6 tets\n", src.c_str());
    src = "cube 50^3*6";
    mesh = tc::make_cube_mesh(50);
  }
  if (mesh.vertex_fields.empty()) {
    tc::Field f{"x", 1, {}};
    for (int64_t v = 0; v < mesh.num_vertices(); ++v) f.values.push_back(mesh.points[3 * v]);
    mesh.vertex_fields.push_back(std::move(f));
  }
  if (mesh.tet_labels.empty()) mesh.tet_labels.push_back({"label", std::vector<int32_t>(mesh.tets.size() / 4, 1)});
  std::printf("mesh: %s, %lld vertices, %lld tets (+1 vertex field, 1 label)\n", src.c_str(),
              (long long)mesh.num_vertices(), (long long)mesh.num_tets());

  const std::string dir = std::filesystem::temp_directory_path() / ("tc_bench_io_vtk_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  struct Case {
    const char* name;
    std::string path;
    tc::WriteOptions opt;
  };
  tc::WriteOptions vtu_app, vtk_bin, vtu_b64, vtk_ascii;
  vtu_app.vtu_encoding = tc::WriteOptions::VtuEncoding::Appended;
  vtu_b64.vtu_encoding = tc::WriteOptions::VtuEncoding::Base64;
  vtk_bin.binary = true;
  vtk_ascii.binary = false;
  std::vector<Case> cases = {{"vtu appended", dir + "/m.vtu", vtu_app},
                             {"vtk binary", dir + "/m.vtk", vtk_bin},
                             {"vtu base64", dir + "/m64.vtu", vtu_b64},
                             {"vtk ascii", dir + "/ma.vtk", vtk_ascii}};
  for (const Case& c : cases) {
    const bool vtu = c.path.ends_with(".vtu");
    double w = median_seconds([&] { vtu ? tc::write_vtu(c.path, mesh, c.opt) : tc::write_vtk(c.path, mesh, c.opt); });
    int64_t tets = 0;
    double r = median_seconds([&] {
      tc::ReadNotes notes;
      tc::Mesh m = vtu ? tc::read_vtu(c.path, notes) : tc::read_vtk(c.path, notes);
      tets = m.num_tets();
    });
    const double mb = double(std::filesystem::file_size(c.path)) / 1e6;
    std::printf("%-13s  %7.1f MB  write %7.3f s (%6.0f MB/s)  read %7.3f s (%6.0f MB/s)  tets read %lld\n", c.name, mb, w,
                mb / w, r, mb / r, (long long)tets);
  }
  std::filesystem::remove_all(dir);
  return 0;
}
