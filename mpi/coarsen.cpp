#include "coarsen.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "cli/masks.hpp"
#include "stopwatch.hpp"

namespace tc::mpi {

namespace {

// The library renumbers vertices (spatial order, compaction) but carries vertex fields with
// them, and leaves a vertex outside the mask untouched, fields included: the id travels as a
// field and comes back exact (doubles hold integers to 2^53); the others carry kNone.
const char* const kIdField = "tetcollapse-mpi:frozen-id";
constexpr double kNone = -1;

// Takes the bound each vertex spent (kSpentField, the last vertex field) out of the mesh: the
// library gets it as its options' seed.
std::vector<double> take_spent(Mesh& m) {
  if (m.vertex_fields.empty() || m.vertex_fields.back().name != kSpentField)
    throw std::logic_error("a part without its boundary error field");
  std::vector<double> spent = std::move(m.vertex_fields.back().values);
  m.vertex_fields.pop_back();
  return spent;
}

}  // namespace

RankReport coarsen_part(Part& part, Phase phase, const Settings& s, Context* ctx) {
  Mesh& m = part.mesh;
  RankReport r;
  r.tets_in = m.num_tets();
  r.vertices_in = m.num_vertices();
  const size_t nv = size_t(m.num_vertices());
  const bool bounded = s.boundary_bound > 0;
  std::vector<double> spent = bounded ? take_spent(m) : std::vector<double>();
  // Where each frozen vertex is, to know it again by id and place.
  std::unordered_map<int64_t, size_t> frozen_at;
  Field id{kIdField, 1, std::vector<double>(nv, kNone)};
  std::vector<uint8_t> mask(nv, 1);
  const std::vector<uint8_t> chosen = cli::region_and_label_mask(m, s.region, s.labels);
  for (size_t v = 0; v < nv; ++v)
    if (part.frozen[v]) {
      mask[v] = 0;
      id.values[v] = double(part.gid[v]);
      frozen_at.emplace(part.gid[v], v);
    } else if ((!part.select.empty() && !part.select[v]) || (!chosen.empty() && !chosen[v])) {
      mask[v] = 0;
    }
  r.frozen = int64_t(frozen_at.size());
  const std::vector<double> points_in = m.points;  // only the frozen ones are read back
  // The user's functions read the first vertex field as f0, 0 when the mesh has none (as in
  // tetcollapse): a field of zeros keeps the id field from being the first.
  const bool placeholder = m.vertex_fields.empty() && s.collapse.has_user_functions();
  if (placeholder) m.vertex_fields.push_back({"tetcollapse-mpi:none", 1, std::vector<double>(nv, 0.0)});
  m.vertex_fields.push_back(std::move(id));

  // (an all-ones mask: none)
  const bool masked = !frozen_at.empty() || !part.select.empty() || !chosen.empty();
  Stopwatch clock;
  if (m.num_tets() > 0 && phase == Phase::Collapse) {
    CollapseOptions co = s.collapse;
    if (masked) co.vertex_mask = mask;
    if (bounded) {
      co.max_boundary_error = 0, co.max_boundary_error_abs = s.boundary_bound;
      co.vertex_boundary_error = std::move(spent);
      co.boundary_reference = s.boundary_reference;
    }
    if (co.max_field_error > 0) {
      co.field_points = std::move(part.field_points);
      co.field_point_values = std::move(part.field_values);
      co.field_point_tets = std::move(part.field_tets);
      co.field_range = s.field_range;
    }
    CollapseReport cr = ctx ? collapse(m, co, *ctx) : collapse_sequential(m, co);
    if (bounded) spent = std::move(cr.vertex_boundary_error);
    r.seconds_collapse = clock.lap();
  } else if (m.num_tets() > 0) {
    ImproveOptions io = s.improve;
    if (masked) io.vertex_mask = mask;
    // No splits: a part is improved in rounds with its interface frozen, and the vertices its
    // splits add stayed where one device's second cycle collapses them (the hammer, 3 ranks in
    // clusters: 5,356 tets with them, 5,279 without, one device 5,095)
    io.splits = false;
    // ImproveOptions::max_boundary_move is relative to the diagonal of the mesh it is given:
    // scale it so that the bound is the whole mesh's.
    const double d = bbox_diagonal(m);
    if (d > 0) io.max_boundary_move *= s.whole_diagonal / d;
    // the collapse step reaches as far as tc::improve's default on the whole mesh
    if (!(io.collapse_length > 0)) io.collapse_length = s.collapse_length;
    if (bounded) {  // (from the bounds spent, which it raises)
      io.max_boundary_error_abs = s.boundary_bound;
      io.vertex_boundary_error = std::move(spent);
    }
    ImproveReport ir = ctx ? improve(m, io, *ctx) : improve(m, io);
    if (bounded) spent = std::move(ir.vertex_boundary_error);
    r.seconds_improve = clock.lap();
  }

  // The frozen vertices again: the id field exact and the position bit for bit.
  const std::vector<double> ids = std::move(m.vertex_fields.back().values);
  m.vertex_fields.pop_back();
  if (placeholder) m.vertex_fields.pop_back();
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
  if (bounded) {
    if (spent.size() != n_out) throw std::logic_error("a part's boundary error bounds lost their vertices");
    for (double e : spent) r.boundary_error = std::max(r.boundary_error, e);
    m.vertex_fields.push_back({kSpentField, 1, std::move(spent)});
  }
  r.tets_out = m.num_tets();
  r.vertices_out = m.num_vertices();
  return r;
}

}  // namespace tc::mpi
