// JSON and text renderings of a CheckReport.
#include <cstdio>
#include <sstream>

#include "json.hpp"
#include "tetcollapse/check.hpp"

namespace tc {

namespace {

void stats_json(JsonWriter& w, const char* name, const Stats& s) {
  w.key(name).begin_object();
  w.field("count", s.count).field("min", s.min).field("max", s.max).field("mean", s.mean).field("median", s.median);
  w.end_object();
}

void topology_json(JsonWriter& w, const char* name, const SurfaceTopology& t) {
  w.key(name).begin_object();
  w.field("vertices", t.vertices).field("edges", t.edges).field("faces", t.faces);
  w.field("components", t.components).field("euler_characteristic", t.euler);
  w.field("nonmanifold_vertices", t.nonmanifold_vertices);
  w.end_object();
}

const char* severity_name(Severity s) { return s == Severity::Error ? "error" : "warning"; }

std::string num(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace

std::string check_report_json(const CheckReport& r) {
  JsonWriter w;
  w.begin_object();
  w.field("valid", r.valid);
  w.array("errors", r.errors);
  w.array("warnings", r.warnings);
  w.key("findings").begin_array();
  for (const auto& f : r.findings) {
    w.begin_object();
    w.field("severity", severity_name(f.severity)).field("code", f.code).field("count", f.count);
    w.key("offenders").begin_array();
    for (const auto& o : f.offenders) {
      w.begin_array();
      for (int64_t x : o) w.value(x);
      w.end_array();
    }
    w.end_array();
    w.field("message", f.message);
    w.end_object();
  }
  w.end_array();

  w.field("vertices", r.vertices).field("tets", r.tets).field("referenced_vertices", r.referenced_vertices);
  w.field("interior_faces", r.interior_faces).field("boundary_faces", r.boundary_faces);
  w.field("inverted_tets", r.inverted_tets).field("flat_tets", r.flat_tets).field("small_volume_tets", r.small_volume_tets);
  w.field("volume", r.volume).field("boundary_volume", r.boundary_volume).field("min_volume", r.min_volume);
  w.key("bbox_min").begin_array().value(r.bbox_min[0]).value(r.bbox_min[1]).value(r.bbox_min[2]).end_array();
  w.key("bbox_max").begin_array().value(r.bbox_max[0]).value(r.bbox_max[1]).value(r.bbox_max[2]).end_array();
  w.field("bbox_diagonal", r.bbox_diagonal);
  topology_json(w, "boundary", r.boundary);
  w.field("self_intersection_checked", r.self_intersection_checked).field("self_intersections", r.self_intersections);

  const QualityReport& q = r.quality;
  w.key("quality").begin_object();
  w.field("computed", q.computed);
  if (q.computed) {
    w.field("tets", q.tets);
    stats_json(w, "min_dihedral_deg", q.min_dihedral_deg);
    stats_json(w, "max_dihedral_deg", q.max_dihedral_deg);
    w.field("median_dihedral_deg", q.median_dihedral_deg);
    w.field("tets_below_5_deg", q.below_5_deg).field("tets_below_10_deg", q.below_10_deg).field("tets_below_13_deg", q.below_13_deg);
    stats_json(w, "radius_ratio", q.radius_ratio);
    stats_json(w, "amips", q.amips);
    stats_json(w, "mean_ratio", q.mean_ratio);
    stats_json(w, "edge_length", q.edge_length);
    w.key("histograms").begin_object();
    for (const auto& h : q.histograms) {
      w.key(h.name).begin_object();
      w.field("lo", h.lo).field("hi", h.hi).array("counts", h.counts);
      w.end_object();
    }
    w.end_object();
  }
  w.end_object();

  if (r.has_reference) {
    const ReferenceComparison& c = r.reference;
    w.key("reference").begin_object();
    w.field("vertices", c.reference_vertices).field("tets", c.reference_tets);
    w.field("tet_reduction", c.tet_reduction).field("vertex_reduction", c.vertex_reduction);
    w.field("volume", c.volume).field("reference_volume", c.reference_volume);
    w.field("volume_change", c.volume_change).field("volume_change_rel", c.volume_change_rel);
    w.field("label_name", c.label_name);
    w.key("labels").begin_array();
    for (const auto& l : c.labels) {
      w.begin_object();
      w.field("label", int64_t(l.label)).field("volume", l.volume).field("reference_volume", l.reference_volume);
      w.field("change", l.change).field("change_rel", l.change_rel);
      w.end_object();
    }
    w.end_array();
    topology_json(w, "reference_boundary", c.reference_boundary);
    w.field("topology_changed", c.topology_changed).field("reference_valid", c.reference_valid);
    w.field("hausdorff_computed", c.hausdorff_computed);
    w.field("hausdorff", c.hausdorff).field("hausdorff_rel", c.hausdorff_rel);
    w.field("hausdorff_to_reference", c.hausdorff_to_reference).field("hausdorff_from_reference", c.hausdorff_from_reference);
    w.field("hausdorff_error_bound", c.hausdorff_error_bound);
    w.key("fields").begin_array();
    for (const FieldError& f : c.fields)
      w.begin_object()
          .field("name", f.name)
          .field("range", f.range)
          .field("max_abs", f.max_abs)
          .field("rms_abs", f.rms_abs)
          .field("max_rel", f.max_rel)
          .field("rms_rel", f.rms_rel)
          .field("max_vertex_abs", f.max_vertex_abs)
          .field("max_vertex_rel", f.max_vertex_rel)
          .field("samples", f.samples)
          .end_object();
    w.end_array();
    w.end_object();
  }

  w.key("timings_s").begin_object();
  for (const auto& [name, s] : r.timings) w.field(name, s);
  w.end_object();
  w.end_object();
  return w.str();
}

std::string check_report_text(const CheckReport& r) {
  std::ostringstream o;
  o << (r.valid ? "VALID" : "INVALID") << ": " << r.vertices << " vertices, " << r.tets << " tets, volume " << num(r.volume)
    << "\n";
  o << "boundary: " << r.boundary.faces << " triangles, " << r.boundary.components << " component(s), Euler characteristic "
    << r.boundary.euler;
  if (r.boundary.nonmanifold_vertices) o << ", " << r.boundary.nonmanifold_vertices << " pinched vertices";
  o << (r.self_intersection_checked ? ", self-intersection tested" : ", self-intersection not tested") << "\n";
  for (const auto& e : r.errors) o << "error: " << e << "\n";
  for (const auto& w : r.warnings) o << "warning: " << w << "\n";
  const QualityReport& q = r.quality;
  if (q.computed && q.tets > 0) {
    o << "dihedral angles: min " << num(q.min_dihedral_deg.min) << ", median " << num(q.median_dihedral_deg) << ", max "
      << num(q.max_dihedral_deg.max) << " deg; tets below 5/10/13 deg: " << q.below_5_deg << "/" << q.below_10_deg << "/"
      << q.below_13_deg << "\n";
    o << "radius ratio: min " << num(q.radius_ratio.min) << ", mean " << num(q.radius_ratio.mean) << "; AMIPS: mean "
      << num(q.amips.mean) << ", max " << num(q.amips.max) << "\n";
    o << "edge length: min " << num(q.edge_length.min) << ", mean " << num(q.edge_length.mean) << ", max "
      << num(q.edge_length.max) << "\n";
  }
  if (r.has_reference) {
    const ReferenceComparison& c = r.reference;
    o << "reference: " << c.reference_vertices << " vertices, " << c.reference_tets << " tets; reduction tets "
      << num(100 * c.tet_reduction) << "%, vertices " << num(100 * c.vertex_reduction) << "%\n";
    o << "volume change: " << num(c.volume_change) << " (" << num(100 * c.volume_change_rel) << "%)\n";
    for (const auto& l : c.labels)
      o << "  " << (c.label_name.empty() ? "label" : c.label_name) << " " << l.label << ": " << num(l.change) << " ("
        << num(100 * l.change_rel) << "%)\n";
    o << "topology: components " << c.reference_boundary.components << " -> " << r.boundary.components << ", Euler "
      << c.reference_boundary.euler << " -> " << r.boundary.euler << (c.topology_changed ? " (CHANGED)" : " (unchanged)")
      << "\n";
    if (c.hausdorff_computed)
      o << "Hausdorff distance: " << num(c.hausdorff) << " (" << num(c.hausdorff_rel) << " x bbox diagonal; to reference "
        << num(c.hausdorff_to_reference) << ", from reference " << num(c.hausdorff_from_reference) << ")\n";
    for (const FieldError& f : c.fields)
      o << "field '" << f.name << "': max difference " << num(f.max_abs) << " (" << num(100 * f.max_rel)
        << "% of its range), RMS " << num(f.rms_abs) << " (" << num(100 * f.rms_rel) << "%) at " << f.samples
        << " points; at the reference's vertices max " << num(f.max_vertex_abs) << " (" << num(100 * f.max_vertex_rel)
        << "%)\n";
  }
  return o.str();
}

}  // namespace tc
