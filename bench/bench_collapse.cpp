// Workload W1: the robot mesh (514k tets) coarsened to 2 x its median edge length,
// eps_c = 0 and eps_c = 700 (paper Sec. 4.4, Fig. 9, Table 2). File I/O is excluded.
//
//   bench_collapse [MESH] [--runs N] [--json FILE] [--wg N] [--max-iterations N]
//                  [--eps-c N[,N...]] [--min-quality Q[,Q...]] [--rounds N] [--host-tail F]
//                  [--conflicts greedy|two-pass|atomic-min|matching[,...]]
// Defaults: eps_c 0 and 700, min_quality 0 (the paper: no quality guard) and 0.1 (the library's
// default), the library's default conflict detection (matching); every combination is run, the
// conflict detections one after another for each run index (so that they share the machine's
// load).
// Prints a table (median of N runs of collapse(), iterations, collapses per iteration, time per
// stage summed over the iterations of the median run, tets in/out) and the same as JSON.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "stopwatch.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/io.hpp"

using namespace tc;

namespace {

struct Result {
  int64_t eps_c = 0;
  double min_quality = 0;
  std::string conflicts;
  std::vector<double> walls;
  CollapseReport report;  // of the median run
};


std::vector<double> parse_list(const char* s) {
  std::vector<double> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ',')) out.push_back(std::atof(item.c_str()));
  return out;
}

std::vector<std::string> parse_names(const char* s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ',')) out.push_back(item);
  return out;
}

bool conflicts_from(const std::string& name, CollapseOptions::Conflicts& c) {
  if (name == "greedy") c = CollapseOptions::Greedy;
  else if (name == "two-pass") c = CollapseOptions::TwoPass;
  else if (name == "atomic-min") c = CollapseOptions::AtomicMin;
  else if (name == "matching") c = CollapseOptions::Matching;
  else return false;
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  std::string path = std::string(TC_SHARED_MESHES) + "/gen_tetgen_thingi255172_make-robot_514k.msh";
  std::string json_path;
  int runs = 5;
  size_t wg = 0;
  int max_iterations = 1000;
  int rounds = CollapseOptions{}.selection_rounds;
  double host_tail = CollapseTuning{}.host_tail;
  std::vector<double> eps_cs = {0, 700}, qualities = {0, CollapseOptions{}.min_quality};
  std::vector<std::string> conflicts = {"matching"};  // the library's default
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--runs") && i + 1 < argc) runs = std::max(1, std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--json") && i + 1 < argc) json_path = argv[++i];
    else if (!std::strcmp(argv[i], "--wg") && i + 1 < argc) wg = size_t(std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--max-iterations") && i + 1 < argc) max_iterations = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--rounds") && i + 1 < argc) rounds = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--host-tail") && i + 1 < argc) host_tail = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--eps-c") && i + 1 < argc) eps_cs = parse_list(argv[++i]);
    else if (!std::strcmp(argv[i], "--min-quality") && i + 1 < argc) qualities = parse_list(argv[++i]);
    else if (!std::strcmp(argv[i], "--conflicts") && i + 1 < argc) conflicts = parse_names(argv[++i]);
    else path = argv[i];
  }
  for (const std::string& c : conflicts) {
    CollapseOptions::Conflicts x;
    if (!conflicts_from(c, x)) {
      std::fprintf(stderr, "bench_collapse: unknown --conflicts %s (greedy, two-pass, atomic-min, matching)\n", c.c_str());
      return 2;
    }
  }
  Mesh input;
  const Stopwatch read_clock;
  try {
    input = read_mesh(path);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_collapse: cannot read %s: %s\n", path.c_str(), e.what());
    return 1;
  }
  const double read_s = read_clock.peek();
  Context ctx;
  ctx.set_work_group_size(wg);
  std::printf("mesh %s: %lld vertices, %lld tets (read in %.3f s)\ndevice %s\n", path.c_str(),
              (long long)input.num_vertices(), (long long)input.num_tets(), read_s, ctx.info().name.c_str());
  {  // warm-up: kernel compilation / binary cache
    Mesh m = input;
    CollapseOptions o;
    o.max_iterations = 1;
    collapse(m, o, ctx);
  }

  std::vector<Result> results;
  for (double q : qualities)
  for (double ec : eps_cs) {
    const int64_t eps_c = int64_t(ec);
    std::vector<Result> rs(conflicts.size());
    std::vector<std::vector<std::pair<double, CollapseReport>>> all(conflicts.size());
    for (int i = 0; i < runs; ++i)
      for (size_t k = 0; k < conflicts.size(); ++k) {  // interleaved: the same load for each
        Mesh m = input;
        CollapseOptions o;
        o.target_factor = 2;
        o.eps_c = eps_c;
        o.min_quality = q;
        o.selection_rounds = rounds;
        o.tuning.host_tail = host_tail;
        o.max_iterations = max_iterations;
        conflicts_from(conflicts[k], o.conflicts);
        const Stopwatch clock;
        CollapseReport rep = collapse(m, o, ctx);
        double wall = clock.peek();
        rs[k].walls.push_back(wall);
        all[k].emplace_back(wall, rep);
      }
    for (size_t k = 0; k < conflicts.size(); ++k) {
      Result& r = rs[k];
      r.eps_c = eps_c;
      r.min_quality = q;
      r.conflicts = conflicts[k];
      std::sort(all[k].begin(), all[k].end(), [](auto& a, auto& b) { return a.first < b.first; });
      r.report = all[k][all[k].size() / 2].second;
      std::sort(r.walls.begin(), r.walls.end());
      results.push_back(r);
    }
  }

  std::ostringstream js;
  js << "{\"mesh\": \"" << path << "\", \"device\": \"" << ctx.info().name << "\", \"runs\": " << runs
     << ", \"vertices_in\": " << input.num_vertices() << ", \"tets_in\": " << input.num_tets() << ", \"workloads\": [";
  for (size_t w = 0; w < results.size(); ++w) {
    const Result& r = results[w];
    const CollapseReport& rep = r.report;
    constexpr int kStages = 5;
    double st[kStages] = {0, 0, 0, 0, 0};
    for (const auto& s : rep.iterations) {
      st[0] += s.seconds_connectivity;
      st[1] += s.seconds_cost;
      st[2] += s.seconds_select;
      st[3] += s.seconds_guard;
      st[4] += s.seconds_collapse;
    }
    const char* names[kStages] = {"connectivity", "cost", "select", "guard", "collapse"};
    int dom = int(std::max_element(st, st + kStages) - st);
    double median = r.walls[r.walls.size() / 2];
    std::printf("\n== eps_c = %lld, min_quality %g, conflicts %s: target %.6g (2 x median %.6g)\n",
                (long long)r.eps_c, r.min_quality, r.conflicts.c_str(), rep.target_length, rep.median_edge_length);
    std::printf("wall time of collapse(): median %.3f s (min %.3f, max %.3f) over %d runs; upload %.3f s, download %.3f s\n",
                median, r.walls.front(), r.walls.back(), runs, rep.seconds_upload, rep.seconds_download);
    std::printf("tets %lld -> %lld, vertices %lld -> %lld, %zu iterations\n", (long long)rep.tets_in,
                (long long)rep.tets_out, (long long)rep.vertices_in, (long long)rep.vertices_out, rep.iterations.size());
    std::printf("%4s %9s %9s %9s %9s %9s %9s %9s | %7s %7s %7s %7s %7s %7s\n", "it", "tets", "marked", "cand",
                "tested", "selected", "refused", "collapsed", "conn", "cost", "select", "guard", "coll", "total");
    for (const auto& s : rep.iterations)
      std::printf("%4d %9lld %9lld %9lld %9lld %9lld %9lld %9lld | %7.4f %7.4f %7.4f %7.4f %7.4f %7.4f\n",
                  s.iteration, (long long)s.tets, (long long)s.marked, (long long)s.candidates, (long long)s.tested,
                  (long long)s.selected, (long long)s.refused_by_guard, (long long)s.collapsed,
                  s.seconds_connectivity, s.seconds_cost, s.seconds_select, s.seconds_guard, s.seconds_collapse,
                  s.seconds_total);
    std::printf("stage totals:");
    double sum = 0;
    for (int k = 0; k < kStages; ++k) {
      std::printf(" %s %.3f s", names[k], st[k]);
      sum += st[k];
    }
    std::printf("\ndominant stage: %s (%.0f%% of the iterations' time)\n", names[dom], 100 * st[dom] / std::max(1e-12, sum));

    js << (w ? ", " : "") << "{\"eps_c\": " << r.eps_c << ", \"min_quality\": " << r.min_quality << ", \"conflicts\": \"" << r.conflicts << "\", \"seconds_median\": " << median << ", \"seconds_runs\": [";
    for (size_t i = 0; i < r.walls.size(); ++i) js << (i ? ", " : "") << r.walls[i];
    js << "], \"target_length\": " << rep.target_length << ", \"tets_out\": " << rep.tets_out
       << ", \"vertices_out\": " << rep.vertices_out << ", \"iterations\": " << rep.iterations.size()
       << ", \"collapses_per_iteration\": [";
    for (size_t i = 0; i < rep.iterations.size(); ++i) js << (i ? ", " : "") << rep.iterations[i].collapsed;
    js << "], \"stage_seconds\": {";
    for (int k = 0; k < kStages; ++k) js << (k ? ", " : "") << "\"" << names[k] << "\": " << st[k];
    js << "}, \"dominant_stage\": \"" << names[dom] << "\"}";
  }
  js << "]}";
  std::printf("\nJSON: %s\n", js.str().c_str());
  if (!json_path.empty()) std::ofstream(json_path) << js.str() << "\n";
  return 0;
}
