// StageParams from the user's options.
#include "collapse/params.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "tetcollapse/error.hpp"
#include "topology/faces_at_vertices.hpp"

namespace tc::collapse_detail {

void check_bound_mode(bool bounded, CollapseOptions::Boundary mode, const char* option) {
  if (bounded && mode != CollapseOptions::Features)
    throw std::invalid_argument(std::string(option) +
                                " applies to the features boundary mode (strict keeps the boundary exactly, free "
                                "does not bound it)");
}

void check_boundary_error_options(const CollapseOptions& o) {
  if (!(o.max_boundary_error >= 0) || !(o.max_boundary_error_abs >= 0) || std::isinf(o.max_boundary_error) ||
      std::isinf(o.max_boundary_error_abs))
    throw std::invalid_argument("max_boundary_error and max_boundary_error_abs must be finite and >= 0");
  check_bound_mode(o.bounds_boundary_error(), o.boundary, "max_boundary_error");
  if (!o.vertex_boundary_error.empty() && !o.bounds_boundary_error())
    throw std::invalid_argument("vertex_boundary_error needs a boundary error bound (max_boundary_error)");
}

bool measures_boundary_error(const CollapseOptions& o) {
  return o.tuning.remeasure_boundary_error &&
         (o.boundary_reference ||
          std::all_of(o.vertex_boundary_error.begin(), o.vertex_boundary_error.end(), [](double e) { return e == 0; }));
}

std::vector<double> initial_boundary_error(const Mesh& mesh, const CollapseOptions& o) {
  const size_t nv = size_t(mesh.num_vertices());
  if (o.vertex_boundary_error.empty()) return std::vector<double>(nv, 0.0);
  if (o.vertex_boundary_error.size() != nv)
    throw std::invalid_argument("vertex_boundary_error has " + std::to_string(o.vertex_boundary_error.size()) +
                                " values for " + std::to_string(nv) + " vertices");
  for (double e : o.vertex_boundary_error)
    if (!(e >= 0) || std::isinf(e)) throw std::invalid_argument("vertex_boundary_error: values must be finite and >= 0");
  return o.vertex_boundary_error;
}

void check_field_points_options(const CollapseOptions& o) {
  if (!(o.max_field_error > 0) &&
      !(o.field_points.empty() && o.field_point_values.empty() && o.field_point_tets.empty() && o.field_range.empty()))
    throw std::invalid_argument("field_points, field_point_values, field_point_tets and field_range need max_field_error");
}

CheckParams check_params_from(const CollapseOptions& o) {
  CheckParams p;
  p.mode = o.boundary == CollapseOptions::Strict ? 0 : o.boundary == CollapseOptions::Features ? 1 : 2;
  p.paper_rule = o.paper_boundary_rule;
  p.use_labels = o.use_labels;
  p.eps_f = o.eps_f;
  p.eps_r = o.eps_r;
  p.eps_v = o.eps_v;
  p.min_quality = o.min_quality;
  p.field_eps = o.field_difference_cost && o.field_check > 0 ? o.field_check * o.target_length : 0;
  return p;
}

StageParams params_from(const CollapseOptions& o) {
  StageParams p;
  static_cast<CheckParams&>(p) = check_params_from(o);
  p.priority_levels = o.tuning.priority_levels;
  p.mask_mode = o.vertex_mask.empty() ? 0 : o.mask_either ? 2 : 1;
  // the field difference is the user cost's slot filled by the library (sequential.cpp has its
  // host twin)
  p.cost_source = o.field_difference_cost
                      ? "double tc_user_cost(double3 p0, double3 p1, double f0, double f1) { return fabs(f0 - f1); }\n"
                      : o.cost_cl_source;
  // (#line: the compiler's messages give the line in the user's source, under its option's name)
  if (!o.placement_cl_source.empty()) {
    p.user_source += "#line 1 \"placement_cl_source\"\n" + o.placement_cl_source + "\n";
    p.user_defines += " -DTCC_USER_PLACEMENT";
  }
  if (!o.predicate_cl_source.empty()) {
    p.user_source += "#line 1 \"predicate_cl_source\"\n" + o.predicate_cl_source + "\n";
    p.user_defines += " -DTCC_USER_PREDICATE";
  }
  return p;
}

void check_options(const CollapseOptions& o, const Context& ctx) {
  check_boundary_error_options(o);
  check_field_points_options(o);
  if (o.max_iterations < 0) throw std::invalid_argument("max_iterations must be >= 0");
  if (o.selection_rounds < 1) throw std::invalid_argument("selection_rounds must be >= 1");
  if (o.selection_rounds > 1 && o.conflicts != CollapseOptions::TwoPass)
    throw std::invalid_argument("selection_rounds > 1 needs the two-pass conflict detection");
  if (!(o.tuning.priority_levels >= 0) || !std::isfinite(o.tuning.priority_levels))
    throw std::invalid_argument("priority_levels must be finite and >= 0");
  if (o.field_difference_cost && !o.cost_cl_source.empty())
    throw std::invalid_argument("field_difference_cost and cost_cl_source are two costs: choose one");
  if (o.field_difference_cost && !(o.target_length > 0))
    throw std::invalid_argument("field_difference_cost needs an explicit target_length > 0");
  if (!o.cost_cl_source.empty() && !(o.target_length > 0))
    throw std::invalid_argument("a user cost (cost_cl_source) needs an explicit target_length > 0");
  if (!(o.target_length > 0) && !(o.target_factor > 0))
    throw std::invalid_argument("target_factor must be > 0 when target_length is not given");
  if (o.conflicts == CollapseOptions::AtomicMin && !ctx.info().int64_atomics_extended)
    throw DeviceError("device '" + ctx.info().name +
                      "' lacks cl_khr_int64_extended_atomics (64-bit atomic min), which --conflicts atomic-min needs; "
                      "use --conflicts two-pass");
}

}  // namespace tc::collapse_detail

namespace tc {

std::vector<double> feature_surface_triangles(const Mesh& mesh, bool use_labels) {
  const std::vector<int32_t>* labels =
      use_labels && !mesh.tet_labels.empty() ? &mesh.tet_labels[0].values : nullptr;
  std::vector<double> out;
  const auto point = [&](int32_t v) { return &mesh.points[3 * size_t(v)]; };
  topology_detail::each_face_at_smallest_vertex(mesh, [&](int32_t v, const topology_detail::FaceSide* s, size_t n) {
    // one tet: the boundary; two of different labels: an interface; more (a defective input):
    // the boundary for each, as the collapse reads it
    if (n == 2 && !(labels && (*labels)[size_t(s[0].tet)] != (*labels)[size_t(s[1].tet)])) return;
    for (int32_t w : {v, s[0].a, s[0].b}) out.insert(out.end(), point(w), point(w) + 3);
  });
  return out;
}

}  // namespace tc
