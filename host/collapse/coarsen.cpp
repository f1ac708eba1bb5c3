// The coarsening command as one library call (tetcollapse/coarsen.hpp).
#include "tetcollapse/coarsen.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <utility>

#include "collapse/programs.hpp"
#include "tetcollapse/device_fields.hpp"
#include "tetcollapse/fields.hpp"

namespace tc {

namespace {

size_t field_index(const Mesh& mesh, const std::string& name, const char* option) {
  for (size_t i = 0; i < mesh.vertex_fields.size(); ++i)
    if (mesh.vertex_fields[i].name == name) return i;
  throw std::invalid_argument(std::string(option) + ": no vertex field named '" + name + "'");
}

// The user cost sees the first vertex field: the one that drives the cost goes first for the
// run (and back after it).
struct FieldFirst {
  Mesh& mesh;
  size_t index = 0;
  FieldFirst(Mesh& m, size_t i) : mesh(m), index(i) { std::swap(mesh.vertex_fields[0], mesh.vertex_fields[index]); }
  ~FieldFirst() { std::swap(mesh.vertex_fields[0], mesh.vertex_fields[index]); }
};

}  // namespace

std::string sizing_cost_source() {
  return "double tc_user_cost(double3 p0, double3 p1, double f0, double f1) {\n"
         "  double h = 0.5 * (f0 + f1);\n"
         "  return h > 0.0 ? length(p1 - p0) / h : INFINITY;\n"
         "}\n";
}

size_t apply_field_options(const Mesh& mesh, const CoarsenOptions& options, CollapseOptions& co) {
  if (!options.preserve_field.empty() && co.max_field_error > 0) {
    field_index(mesh, options.preserve_field, "preserve_field");
    co.bounded_field = options.preserve_field;
    return 0;
  }
  if (!options.preserve_field.empty()) {
    // the paper's cost |Phi(v0) - Phi(v1)| below T x (max Phi - min Phi)
    const size_t first = field_index(mesh, options.preserve_field, "preserve_field");
    const Field& f = mesh.vertex_fields[first];
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < f.values.size(); i += size_t(f.components)) {
      lo = std::min(lo, f.values[i]);
      hi = std::max(hi, f.values[i]);
    }
    co.field_difference_cost = true;
    co.target_length = options.field_tolerance * (hi - lo);
    co.field_check = options.field_check;
    if (!(co.target_length > 0))
      throw std::invalid_argument("vertex field '" + options.preserve_field + "' is constant: nothing bounds a collapse");
    return first;
  }
  if (!options.sizing_field.empty()) {
    const size_t first = field_index(mesh, options.sizing_field, "sizing_field");
    co.cost_cl_source = sizing_cost_source();
    co.target_length = 1.0;
    return first;
  }
  return 0;
}

double default_max_boundary_error(CollapseOptions::Boundary mode) {
  return mode == CollapseOptions::Features ? kDefaultMaxBoundaryError : 0.0;
}

bool improvement_follows(const CoarsenOptions& options) {
  // A user's predicate or placement states rules the improvement cannot know; the improvement's
  // moves are not checked against a field error bound; with its every operation off it would
  // change nothing (and the collapse may then have all of a boundary error bound).
  const CollapseOptions& co = options.collapse;
  const ImproveOptions& io = options.improvement;
  return options.improve && co.predicate_cl_source.empty() && co.placement_cl_source.empty() &&
         !(co.max_field_error > 0) && io.max_iterations > 0 &&
         (io.flips || io.smoothing || (io.collapse && io.collapse_rounds > 0));
}

const ImproveReport& last_improvement(const CoarsenReport& r) {
  const ImproveReport* last = &r.improvement;
  for (const CycleReport& c : r.later_cycles)
    if (c.improved) last = &c.improvement;
  return *last;
}

CoarsenReport coarsen(Mesh& mesh, const CoarsenOptions& options, Context* ctx, const Mesh* original) {
  CollapseOptions co = options.collapse;
  if (!ctx && co.method != CollapseOptions::Sequential)
    throw std::invalid_argument("coarsen: the parallel method needs a device context");
  const bool by_field = !options.preserve_field.empty() || !options.sizing_field.empty();
  if (!options.preserve_field.empty() && !options.sizing_field.empty())
    throw std::invalid_argument("preserve_field and sizing_field cannot be combined");
  if (by_field && !co.cost_cl_source.empty())
    throw std::invalid_argument("preserve_field and sizing_field replace the cost: not with cost_cl_source");
  if (co.max_field_error > 0 && options.preserve_field.empty() && co.bounded_field.empty())
    throw std::invalid_argument("max_field_error needs preserve_field (the field it bounds)");

  // the vertex fields' values at new places come from the input
  const bool resample = options.resample_fields && !mesh.vertex_fields.empty();
  Mesh copy;
  if (resample && !original) copy = mesh;
  const Mesh& input = original ? *original : copy;
  const size_t first = apply_field_options(mesh, options, co);
  const bool improve_phase = improvement_follows(options);
  const double bound = boundary_error_bound(mesh, co);
  if (bound > 0 && improve_phase) {
    co.max_boundary_error_abs = kCollapseShareOfBound * bound;
    co.max_boundary_error = 0;
  }

  if (options.cycles < 1) throw std::invalid_argument("cycles must be >= 1");
  if (options.cycles > 1 && improve_phase && !co.vertex_mask.empty() && !options.improve_mask)
    throw std::invalid_argument("cycles > 1 with a collapse vertex_mask needs improve_mask (the mask of the coarse mesh)");

  if (ctx) collapse_detail::prefetch_programs(*ctx, co);
  if (ctx && improve_phase) improve_detail::prefetch_programs(*ctx);
  if (ctx && resample) fields_detail::prefetch_programs(*ctx);
  // the cost's field first for the collapse, as its cost reads the first vertex field
  const bool cost_by_field = by_field && !(co.max_field_error > 0);
  auto collapse_now = [&](const CollapseOptions& o) {
    std::optional<FieldFirst> front;
    if (cost_by_field) front.emplace(mesh, first);
    return o.method == CollapseOptions::Sequential ? collapse_sequential(mesh, o) : collapse(mesh, o, *ctx);
  };
  // the improvement with the collapse's boundary rules and the whole boundary error bound, from
  // what the collapse spent at each vertex
  const int64_t tets_in = mesh.num_tets();
  auto improve_now = [&](const std::vector<double>& spent) {
    ImproveOptions io = options.improvement;
    // (its splits add tets: never past the input's count, which a coarsening only lowers)
    if (io.max_tets <= 0 || io.max_tets > tets_in) io.max_tets = tets_in;
    io.boundary = co.boundary;
    io.eps_f = co.eps_f;
    io.eps_r = co.eps_r;
    io.use_labels = co.use_labels;
    if (bound > 0) {
      io.max_boundary_error_abs = bound;
      io.vertex_boundary_error = spent;
    }
    if (options.improve_mask) io.vertex_mask = options.improve_mask(mesh);
    // A mesh that hardly coarsened (a thin plate in strict mode) may end past the input's count
    // all the same, its flips adding tets after the splits' cap: then the improvement again
    // without splits (the copy kept only for such a mesh).
    std::optional<Mesh> before;
    if (io.splits && 10 * mesh.num_tets() > 9 * tets_in) before = mesh;
    ImproveReport report = ctx ? improve(mesh, io, *ctx) : improve(mesh, io);
    if (before && mesh.num_tets() > tets_in) {
      mesh = std::move(*before);
      io.splits = false;
      report = ctx ? improve(mesh, io, *ctx) : improve(mesh, io);
    }
    return report;
  };

  CoarsenReport r;
  r.collapse = collapse_now(co);
  if (bound > 0) r.collapse.boundary_error_bound = bound;
  if (improve_phase) {
    r.improvement = improve_now(r.collapse.vertex_boundary_error);
    r.improved = true;
  }
  // Later cycles: the edges the improvement made collapsible, with the first cycle's target and
  // the bounds the improvement left, then the improvement again.
  std::vector<double> spent = r.improvement.vertex_boundary_error;
  for (int cycle = 1; improve_phase && cycle < options.cycles; ++cycle) {
    CycleReport c;
    c.tets_before = mesh.num_tets();
    CollapseOptions again = co;
    again.target_length = r.collapse.target_length;
    again.eps_v = r.collapse.eps_v;  // the input's volume threshold, not this coarser mesh's
    again.eps_v_scale = CollapseOptions::Absolute;
    again.vertex_boundary_error = std::move(spent);
    again.boundary_reference = r.collapse.boundary_reference;  // the input's S, not this mesh's
    again.vertex_mask = options.improve_mask ? options.improve_mask(mesh) : std::vector<uint8_t>();
    again.min_quality = std::max(co.min_quality, kLaterCycleMinQuality);
    c.collapse = collapse_now(again);
    c.tets_collapsed = mesh.num_tets();
    const int64_t removed = c.tets_before - c.tets_collapsed;
    const bool last = double(removed) < kCycleMinShare * double(c.tets_before);
    spent = c.collapse.vertex_boundary_error;
    if (removed > 0) {  // (a collapse leaves slivers where it works: improve after every one)
      c.improvement = improve_now(spent);
      c.improved = true;
      spent = c.improvement.vertex_boundary_error;
    }
    c.tets_after = mesh.num_tets();
    r.collapse.boundary_error = std::max(r.collapse.boundary_error, c.collapse.boundary_error);
    r.later_cycles.push_back(std::move(c));
    if (last) break;
  }
  // the output's counts (the improvement's collapse step may remove a few more)
  r.collapse.vertices_out = mesh.num_vertices();
  r.collapse.tets_out = mesh.num_tets();
  if (resample) r.outside = ctx ? resample_vertex_fields(input, mesh, *ctx) : resample_vertex_fields(input, mesh);
  return r;
}

}  // namespace tc
