// Point location for the fields (the paper's Section 4.5): the host's grid (TetLocator) against
// the device's linear BVH (DeviceTetLocator), on a mesh and a random point in every fourth of its
// tets: build, locate, medians of RUNS.
//
//   build/bench/bench_locate [MESH] [RUNS] [COMMIT] > bench/results/locate.json
//
// (MESH "" for W1; COMMIT is recorded as given: git rev-parse --short HEAD.)
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

#include "bench_util.hpp"
#include "tetcollapse/device_fields.hpp"
#include "tetcollapse/fields.hpp"
#include "tetcollapse/io.hpp"

using namespace tc;

int main(int argc, char** argv) {
  const std::string path =
      argc > 1 && *argv[1] ? argv[1] : std::string(TC_SHARED_MESHES) + "/gen_tetgen_thingi255172_make-robot_514k.msh";
  const int runs = argc > 2 ? std::max(1, std::atoi(argv[2])) : 5;
  const std::string commit = argc > 3 ? argv[3] : "";
  const Mesh m = read_mesh(path);
  // the queries: points inside the mesh, as a coarse mesh's vertices are (a moved vertex outside
  // goes to the host's nearest-tet search either way): a random point of every fourth tet
  std::vector<double> q;
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0, 1);
  for (int64_t t = 0; t < m.num_tets(); t += 4) {
    double w[4], sum = 0;
    for (double& x : w) sum += (x = u(rng));
    for (int c = 0; c < 3; ++c) {
      double x = 0;
      for (int k = 0; k < 4; ++k) x += w[k] / sum * m.points[3 * size_t(m.tets[size_t(4 * t + k)]) + size_t(c)];
      q.push_back(x);
    }
  }
  const size_t nq = q.size() / 3;
  Context ctx;
  int64_t found_host = 0, found_device = 0;
  const double host_build = bench::median_seconds([&] { TetLocator loc(m); }, runs);
  const TetLocator host(m);
  const double host_locate = bench::median_seconds(
      [&] {
        found_host = 0;
        double b[4];
        bool out = false;
        for (size_t i = 0; i < nq; ++i) {
          host.locate(&q[3 * i], b, &out);
          found_host += !out;
        }
      },
      runs);
  { DeviceTetLocator warm(m, ctx); }  // the kernels compiled
  const double device_build = bench::median_seconds([&] { DeviceTetLocator loc(m, ctx); }, runs);
  const DeviceTetLocator dev(m, ctx);
  std::vector<int32_t> tets;
  std::vector<double> bary;
  const double device_locate = bench::median_seconds(
      [&] {
        dev.locate(q, tets, bary);
        found_device = 0;
        for (int32_t t : tets) found_device += t >= 0;
      },
      runs);
  std::printf("{\n \"command\": \"build/bench/bench_locate \\\"%s\\\" %d %s\",\n \"commit\": \"%s\",\n",
              argc > 1 ? argv[1] : "", runs, commit.c_str(), commit.c_str());
  std::printf(" \"mesh\": \"%s\",\n \"tets\": %lld,\n \"queries\": %zu,\n \"runs\": %d,\n \"device\": \"%s\",\n",
              path.substr(path.find_last_of('/') + 1).c_str(), static_cast<long long>(m.num_tets()), nq, runs,
              ctx.info().name.c_str());
  std::printf(" \"host_build\": %.4f,\n \"host_locate\": %.4f,\n \"device_build\": %.4f,\n \"device_locate\": %.4f,\n",
              host_build, host_locate, device_build, device_locate);
  std::printf(" \"found_host\": %lld,\n \"found_device\": %lld\n}\n", static_cast<long long>(found_host),
              static_cast<long long>(found_device));
  return found_host == found_device ? 0 : 1;
}
