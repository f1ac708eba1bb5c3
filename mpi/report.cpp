#include "report.hpp"

#include <cstdio>
#include <fstream>

#include "json.hpp"

namespace tc::mpi {

int64_t peak_rss_kb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stoll(line.substr(6));
  return 0;
}

void RankStats::to(double* d) const {
  const double v[kCount] = {tets_in,         tets_out,    frozen,        seconds, seconds_collapse,
                            seconds_improve, peak_rss_kb, boundary_error};
  for (int i = 0; i < kCount; ++i) d[i] = v[i];
}

RankStats RankStats::from(const double* d) {
  RankStats s;
  s.tets_in = d[0], s.tets_out = d[1], s.frozen = d[2], s.seconds = d[3], s.seconds_collapse = d[4],
  s.seconds_improve = d[5], s.peak_rss_kb = d[6], s.boundary_error = d[7];
  return s;
}

std::string round_line(const RoundStats& r) {
  char buf[512];
  const double removed = r.tets_before ? 100.0 * double(r.tets_before - r.tets_after) / double(r.tets_before) : 0.0;
  std::snprintf(buf, sizeof buf,
                "round %d (%s): %zu parts, %lld interface vertices frozen (%lld of them in the band still to coarsen); "
                "tets %lld -> %lld (%.2f%% fewer); partition %.2f s, scatter %.2f s, coarsen %.2f s (slowest rank), "
                "gather %.2f s",
                r.round, r.phase.c_str(), r.ranks.size(), (long long)r.interface_vertices, (long long)r.refrozen_vertices,
                (long long)r.tets_before, (long long)r.tets_after, removed, r.seconds_partition, r.seconds_scatter,
                r.seconds_coarsen, r.seconds_gather);
  return buf;
}

std::string rank_line(int rank, const RankStats& s) {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "  rank %d: tets %.0f -> %.0f, %.0f frozen vertices, collapse %.2f s, improve %.2f s, peak memory %.0f MB",
                rank, s.tets_in, s.tets_out, s.frozen, s.seconds_collapse, s.seconds_improve, s.peak_rss_kb / 1024.0);
  return buf;
}

std::string stats_json(const RunStats& s) {
  JsonWriter w;
  w.begin_object()
      .field("input", s.input)
      .field("output", s.output)
      .field("device", s.device)
      .field("ranks", s.ranks)
      .field("boundary", s.boundary)
      .field("vertices_in", s.vertices_in)
      .field("tets_in", s.tets_in)
      .field("vertices_out", s.vertices_out)
      .field("tets_out", s.tets_out)
      .field("median_edge_length", s.median_edge_length)
      .field("target_length", s.target_length)
      .field("boundary_error_bound", s.boundary_error_bound)
      .field("boundary_error", s.boundary_error)
      .field("field_error_bound", s.field_error_bound)
      .field("field_error", s.field_error)
      .field("seconds_total", s.seconds_total)
      .field("seconds_read", s.seconds_read)
      .field("seconds_write", s.seconds_write);
  if (!s.check.empty()) w.field("check", s.check);
  w.array("peak_rss_kb", s.peak_rss_kb);
  w.key("rounds").begin_array();
  for (const RoundStats& r : s.rounds) {
    w.begin_object()
        .field("round", r.round)
        .field("phase", r.phase)
        .field("tets_before", r.tets_before)
        .field("tets_after", r.tets_after)
        .field("vertices_after", r.vertices_after)
        .field("interface_vertices", r.interface_vertices)
        .field("refrozen_vertices", r.refrozen_vertices)
        .field("seconds_partition", r.seconds_partition)
        .field("seconds_scatter", r.seconds_scatter)
        .field("seconds_coarsen", r.seconds_coarsen)
        .field("seconds_gather", r.seconds_gather)
        .field("boundary_bound", r.boundary_bound);
    w.key("ranks").begin_array();
    for (size_t i = 0; i < r.ranks.size(); ++i) {
      const RankStats& k = r.ranks[i];
      w.begin_object()
          .field("rank", int64_t(i))
          .field("tets_in", int64_t(k.tets_in))
          .field("tets_out", int64_t(k.tets_out))
          .field("frozen_vertices", int64_t(k.frozen))
          .field("seconds", k.seconds)
          .field("seconds_collapse", k.seconds_collapse)
          .field("seconds_improve", k.seconds_improve)
          .field("peak_rss_kb", int64_t(k.peak_rss_kb))
          .field("boundary_error", k.boundary_error)
          .end_object();
    }
    w.end_array().end_object();
  }
  w.end_array().end_object();
  return w.str();
}

}  // namespace tc::mpi
