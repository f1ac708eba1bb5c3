// tc::coarsen on an in-memory mesh (the command's sequence: the collapse, then the improvement),
// one Context for all calls: the C++ side of bench/python_overhead.py.
//
//   build/bench/bench_coarsen MESH [RUNS] [FACTOR]    prints {"seconds": median, ...} as JSON
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "tetcollapse/coarsen.hpp"
#include "tetcollapse/io.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_coarsen MESH [RUNS] [FACTOR]\n");
    return 2;
  }
  const tc::Mesh input = tc::read_mesh(argv[1]);
  const int runs = argc > 2 ? std::max(1, std::atoi(argv[2])) : 5;
  tc::CoarsenOptions o;
  o.collapse.target_factor = argc > 3 ? std::atof(argv[3]) : 2.0;
  tc::Context ctx;
  int64_t tets = 0;
  auto once = [&] {
    tc::Mesh m = input;
    tc::coarsen(m, o, &ctx);
  };
  once();  // the programs loaded
  std::vector<double> t;
  for (int i = 0; i < runs; ++i) {
    tc::Mesh m = input;
    const auto a = std::chrono::steady_clock::now();
    tc::coarsen(m, o, &ctx);
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count());
    tets = m.num_tets();
  }
  std::sort(t.begin(), t.end());
  std::printf("{\"seconds\": %.4f, \"runs\": %d, \"tets_out\": %lld, \"device\": \"%s\"}\n", t[t.size() / 2], runs,
              static_cast<long long>(tets), ctx.info().name.c_str());
  return 0;
}
