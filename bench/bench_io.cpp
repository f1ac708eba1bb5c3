// Read and write speed of every format on one mesh (default: the largest shared mesh,
// gen_tetgen_rocker-arm_964k.msh). Each step: median of RUNS (default 5). The baseline of the
// same run is io::load_file of the written file (the raw cost of getting the bytes), so the
// ratio says how much parsing adds.
//   bench_io [MESH] [RUNS]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "io/io_util.hpp"
#include "bench_util.hpp"
#include "tetcollapse/io.hpp"

namespace {

using tc::bench::median_seconds;


}  // namespace

int main(int argc, char** argv) {
  std::string path = argc > 1 ? argv[1] : std::string(TC_SHARED_MESHES) + "/gen_tetgen_rocker-arm_964k.msh";
  int runs = argc > 2 ? std::max(1, std::atoi(argv[2])) : 5;
  if (!std::filesystem::exists(path)) {
    std::printf("skipped: %s is not present\n", path.c_str());
    return 0;
  }
  try {
    tc::Mesh mesh;
    double read_in = median_seconds([&] { mesh = tc::read_mesh(path); }, runs);
    std::printf("mesh %s: %lld vertices, %lld tets; read_mesh %.1f ms (median of %d)\n", path.c_str(),
                (long long)mesh.num_vertices(), (long long)mesh.num_tets(), read_in * 1e3, runs);
    struct Variant {
      const char* name;
      const char* ext;
      tc::WriteOptions opt;
    };
    auto opt = [](bool binary, int gmsh, tc::WriteOptions::VtuEncoding enc) {
      tc::WriteOptions o;
      o.binary = binary;
      o.gmsh_version = gmsh;
      o.vtu_encoding = enc;
      return o;
    };
    using E = tc::WriteOptions::VtuEncoding;
    std::vector<Variant> variants = {
        {"gmsh 4.1 binary", ".msh", opt(true, 41, E::Appended)},  {"gmsh 2.2 binary", ".msh", opt(true, 22, E::Appended)},
        {"medit .meshb", ".meshb", opt(true, 41, E::Appended)},   {"vtk binary", ".vtk", opt(true, 41, E::Appended)},
        {"vtu appended", ".vtu", opt(true, 41, E::Appended)},     {"vtu base64", ".vtu", opt(true, 41, E::Base64)},
        {"gmsh 4.1 ascii", ".msh", opt(false, 41, E::Appended)},  {"medit .mesh", ".mesh", opt(false, 41, E::Appended)},
        {"vtk ascii", ".vtk", opt(false, 41, E::Ascii)},          {"tetgen .node/.ele", ".node", opt(false, 41, E::Ascii)},
    };
    auto dir = std::filesystem::temp_directory_path() / "tc_bench_io";
    std::filesystem::create_directories(dir);
    std::printf("%-20s %10s %10s %10s %12s %10s\n", "format", "MB", "write ms", "read ms", "raw read ms",
                "read/raw");
    for (const auto& v : variants) {
      std::string out = (dir / (std::string("bench") + v.ext)).string();
      double w = median_seconds([&] { tc::write_mesh(out, mesh, v.opt); }, runs);
      tc::Mesh back;
      double r = median_seconds([&] { back = tc::read_mesh(out); }, runs);
      bool tetgen = std::string(v.ext) == ".node";
      double raw = median_seconds([&] {
        (void)tc::io::load_file(out);
        if (tetgen) (void)tc::io::load_file(tc::io::replace_extension(out, ".ele"));
      }, runs);
      if (back.num_tets() != mesh.num_tets() || back.points != mesh.points) {
        std::printf("%s: round trip differs!\n", v.name);
        return 1;
      }
      double mb = std::filesystem::file_size(out) / 1e6;
      if (tetgen) mb += std::filesystem::file_size(tc::io::replace_extension(out, ".ele")) / 1e6;
      std::printf("%-20s %10.1f %10.1f %10.1f %12.1f %10.2f\n", v.name, mb, w * 1e3, r * 1e3, raw * 1e3, r / raw);
    }
    std::filesystem::remove_all(dir);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_io: %s\n", e.what());
    return 1;
  }
  return 0;
}
