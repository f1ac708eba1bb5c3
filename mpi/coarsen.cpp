#include "coarsen.hpp"

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "cli/masks.hpp"
#include "improve_collapse.hpp"
#include "stopwatch.hpp"

namespace tc::mpi {

namespace {

// The library renumbers vertices (spatial order, compaction) but carries vertex fields with
// them, and leaves a vertex outside the mask untouched, fields included: the id travels as a
// field and comes back exact (doubles hold integers to 2^53). The others carry kSelected or kLeft:
// an edge collapses only between two selected vertices, whose survivor (the average of both)
// stays kSelected, so the field also says where the round may still work after a collapse.
const char* const kIdField = "tetcollapse-mpi:frozen-id";
constexpr double kSelected = -1, kLeft = -2;

std::vector<uint8_t> selected_by_field(const Mesh& m) {
  const std::vector<double>& ids = m.vertex_fields.back().values;
  std::vector<uint8_t> sel(ids.size());
  for (size_t v = 0; v < ids.size(); ++v) sel[v] = ids[v] == kSelected;
  return sel;
}

}  // namespace

RankReport coarsen_part(Part& part, Phase phase, const Settings& s, Context* ctx) {
  Mesh& m = part.mesh;
  RankReport r;
  r.tets_in = m.num_tets();
  r.vertices_in = m.num_vertices();
  const size_t nv = size_t(m.num_vertices());
  // Where each frozen vertex is, to know it again by id and place.
  std::unordered_map<int64_t, size_t> frozen_at;
  Field id{kIdField, 1, std::vector<double>(nv, kSelected)};
  std::vector<uint8_t> mask(nv, 1);
  const std::vector<uint8_t> chosen = cli::region_and_label_mask(m, s.region, s.labels);
  for (size_t v = 0; v < nv; ++v)
    if (part.frozen[v]) {
      mask[v] = 0;
      id.values[v] = double(part.gid[v]);
      frozen_at.emplace(part.gid[v], v);
    } else if ((!part.select.empty() && !part.select[v]) || (!chosen.empty() && !chosen[v])) {
      mask[v] = 0;
      id.values[v] = kLeft;
    }
  r.frozen = int64_t(frozen_at.size());
  const std::vector<double> points_in = m.points;  // only the frozen ones are read back
  m.vertex_fields.push_back(std::move(id));

  // An all-ones mask would only stop the improvement's collapse step: no mask then.
  const bool masked = !frozen_at.empty() || !part.select.empty() || !chosen.empty();
  Stopwatch clock;
  if (m.num_tets() > 0 && phase == Phase::Collapse) {
    CollapseOptions co = s.collapse;
    if (masked) co.vertex_mask = mask;
    if (s.boundary_bound > 0) co.max_boundary_error = 0, co.max_boundary_error_abs = s.boundary_bound;
    r.boundary_error = (ctx ? collapse(m, co, *ctx) : collapse_sequential(m, co)).boundary_error;
    r.seconds_collapse = clock.lap();
  } else if (m.num_tets() > 0) {
    ImproveOptions io = s.improve;
    if (masked) io.vertex_mask = mask;
    // ImproveOptions::max_boundary_move is relative to the diagonal of the mesh it is given:
    // scale it so that the bound is the whole mesh's.
    const double d = bbox_diagonal(m);
    if (d > 0) io.max_boundary_move *= s.whole_diagonal / d;
    // under a bound: a third each to the passes, the collapse step and the passes after it (three
    // calls, each bounded from where it starts)
    const bool step = masked && io.collapse;
    if (s.boundary_bound > 0) {
      io.max_boundary_error_abs = step ? s.boundary_bound / 3 : s.boundary_bound;
      r.boundary_error = s.boundary_bound;  // not measured: all of it
    }
    ctx ? improve(m, io, *ctx) : improve(m, io);
    // Under a mask the library leaves out its collapse step: run it here, then the passes again.
    // The improvement keeps the numbering under a mask but gives a moved vertex the fields
    // interpolated at its new place (-1 from -1s need not come out exact): mark the vertices
    // again by the mask before the collapse.
    if (step) {
      std::vector<double>& marks = m.vertex_fields.back().values;
      for (size_t v = 0; v < nv; ++v)
        if (!part.frozen[v]) marks[v] = mask[v] ? kSelected : kLeft;
      if (collapse_bad_tets(m, selected_by_field(m), io, s.collapse_length) > 0) {
        io.vertex_mask = selected_by_field(m);
        ctx ? improve(m, io, *ctx) : improve(m, io);
      }
    }
    r.seconds_improve = clock.lap();
  }

  // The frozen vertices again: the id field exact and the position bit for bit.
  const std::vector<double> ids = std::move(m.vertex_fields.back().values);
  m.vertex_fields.pop_back();
  const size_t n_out = size_t(m.num_vertices());
  part.gid.assign(n_out, -1);
  part.frozen.assign(n_out, 0);
  size_t found = 0;
  for (size_t v = 0; v < n_out; ++v) {
    const double x = ids[v];
    if (!(x >= 0) || x != std::floor(x)) continue;
    auto it = frozen_at.find(int64_t(x));
    if (it == frozen_at.end() ||
        std::memcmp(&points_in[3 * it->second], &m.points[3 * v], 3 * sizeof(double)) != 0)
      continue;
    part.gid[v] = int64_t(x);
    part.frozen[v] = 1;
    ++found;
  }
  if (found != frozen_at.size())
    throw std::runtime_error("a part lost " + std::to_string(frozen_at.size() - found) + " of its " +
                             std::to_string(frozen_at.size()) + " frozen vertices");
  r.tets_out = m.num_tets();
  r.vertices_out = m.num_vertices();
  return r;
}

}  // namespace tc::mpi
