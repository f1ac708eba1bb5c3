// Coarsen a mesh to twice its median edge length and check the result:
//   coarsen IN OUT
#include <tetcollapse/check.hpp>
#include <tetcollapse/collapse.hpp>
#include <tetcollapse/io.hpp>

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: coarsen IN OUT\n");
    return 2;
  }
  try {
    tc::Mesh mesh = tc::read_mesh(argv[1]);
    const tc::Mesh input = mesh;
    tc::Context device;  // $TETCOLLAPSE_DEVICE, else the first GPU, else the first CPU
    tc::CollapseOptions options;
    options.target_factor = 2;
    tc::CollapseReport report = tc::collapse(mesh, options, device);
    tc::CheckOptions check;
    check.hausdorff = false;
    tc::CheckReport verdict = tc::check_mesh(mesh, check, &input);
    tc::write_mesh(argv[2], mesh);
    std::printf("%lld -> %lld tets in %zu iterations on %s: %s\n", (long long)report.tets_in,
                (long long)report.tets_out, report.iterations.size(), report.device.c_str(),
                verdict.valid ? "valid" : "INVALID");
    return verdict.valid ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "coarsen: %s\n", e.what());
    return 2;
  }
}
