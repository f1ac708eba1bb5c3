// StageParams from the user's options.
#include "collapse/params.hpp"

namespace tc::collapse_detail {

StageParams params_from(const CollapseOptions& o) {
  StageParams p;
  p.mode = o.boundary == CollapseOptions::Strict ? 0 : o.boundary == CollapseOptions::Features ? 1 : 2;
  p.paper_rule = o.paper_boundary_rule;
  p.use_labels = o.use_labels;
  p.eps_f = o.eps_f;
  p.eps_r = o.eps_r;
  p.eps_v = o.eps_v;
  p.min_quality = o.min_quality;
  p.priority_levels = o.priority_levels;
  p.mask_mode = o.vertex_mask.empty() ? 0 : o.mask_either ? 2 : 1;
  p.cost_source = o.cost_cl_source;
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

}  // namespace tc::collapse_detail
