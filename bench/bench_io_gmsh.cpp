// Reads and writes the largest shared Gmsh mesh (4.1 binary, ~1M tets) and prints the
// median of 5 runs for each step. Usage: bench_io_gmsh [mesh.msh]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "bench_util.hpp"
#include "tetcollapse/io.hpp"

namespace {

using tc::bench::median_seconds;


}  // namespace

int main(int argc, char** argv) {
  std::string path = argc > 1 ? argv[1] : std::string(TC_SHARED_MESHES) + "/gen_tetgen_rocker-arm_964k.msh";
  if (!std::filesystem::exists(path)) {
    std::printf("skipped: %s is not present\n", path.c_str());
    return 0;
  }
  try {
    tc::Mesh mesh;
    double read = median_seconds([&] {
      tc::ReadNotes notes;
      mesh = tc::read_gmsh(path, notes);
    });
    std::printf("%s: %lld vertices, %lld tets, %.1f MB\n", path.c_str(), (long long)mesh.num_vertices(),
                (long long)mesh.num_tets(), std::filesystem::file_size(path) / 1e6);
    std::printf("read  (4.1 binary)        median of 5: %8.1f ms\n", read * 1e3);

    auto tmp = std::filesystem::temp_directory_path() / "bench_io_gmsh_out.msh";
    struct Variant {
      const char* name;
      int version;
      bool binary;
    };
    const Variant variants[] = {{"4.1 binary", 41, true}, {"2.2 binary", 22, true}, {"4.1 ASCII ", 41, false}, {"2.2 ASCII ", 22, false}};
    for (const Variant& v : variants) {
      tc::WriteOptions o;
      o.gmsh_version = v.version;
      o.binary = v.binary;
      double w = median_seconds([&] { tc::write_gmsh(tmp.string(), mesh, o); });
      double r = median_seconds([&] {
        tc::ReadNotes notes;
        tc::Mesh back = tc::read_gmsh(tmp.string(), notes);
      });
      std::printf("write (%s)        median of 5: %8.1f ms   read back: %8.1f ms   (%.1f MB)\n", v.name, w * 1e3,
                  r * 1e3, std::filesystem::file_size(tmp) / 1e6);
    }
    std::filesystem::remove(tmp);
  } catch (const std::exception& e) {
    std::printf("error: %s\n", e.what());
    return 1;
  }
  return 0;
}
