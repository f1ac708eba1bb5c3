#include <algorithm>
#include <cstdio>
#include <iostream>
#include <map>

#include "cli/common.hpp"
#include "json.hpp"
#include "tetcollapse/topology.hpp"

namespace tc::cli {

namespace {

struct LabelCount {
  std::string name;
  std::map<int32_t, int64_t> counts;
};

std::vector<LabelCount> count_labels(const Mesh& m) {
  std::vector<LabelCount> out;
  for (const auto& l : m.tet_labels) {
    LabelCount c{l.name, {}};
    for (int32_t v : l.values) ++c.counts[v];
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace

void register_info(CLI::App& app, int& exit_code) {
  struct Opts {
    std::string path;
    InputOptions input;
    bool json = false;
    double eps_f = 0.01, eps_r = 0.1;
    bool no_labels = false;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("info", "Print counts, sizes, quality and boundary features of a mesh");
  cmd->add_option("MESH", o->path, "Mesh file")->required();
  cmd->add_flag("--json", o->json, "Print one JSON object on stdout (keys documented in README.md)");
  cmd->add_option("--eps-f", o->eps_f, "Face-vertex threshold on 1 - dot(n_i, n_j) (paper: 0.01)")->capture_default_str();
  cmd->add_option("--eps-r", o->eps_r, "Ridge-edge threshold on 1 - dot(n_1, n_2) (paper: 0.1)")->capture_default_str();
  cmd->add_flag("--no-labels", o->no_labels, "Ignore material labels (no interface surfaces)");
  add_input_options(*cmd, o->input);
  cmd->callback([o, &exit_code] {
    Mesh m = read_input(o->path, o->input, o->json);
    TopologyOptions to;
    to.eps_f = o->eps_f;
    to.eps_r = o->eps_r;
    to.use_labels = !o->no_labels;
    Topology topo = build_topology(m, to);
    TopologySummary s = summarize(m, topo);
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (int64_t v = 0; v < m.num_vertices(); ++v)
      for (int k = 0; k < 3; ++k) {
        double x = m.points[3 * v + k];
        if (v == 0 || x < lo[k]) lo[k] = x;
        if (v == 0 || x > hi[k]) hi[k] = x;
      }
    auto labels = count_labels(m);
    if (o->json) {
      JsonWriter w;
      w.begin_object()
          .field("file", o->path)
          .field("vertices", s.vertices)
          .field("tets", s.tets)
          .field("edges", s.edges)
          .field("boundary_faces", s.boundary_faces)
          .field("interface_faces", s.interface_faces)
          .field("boundary_vertices", s.boundary_vertices)
          .field("boundary_edges", s.boundary_edges);
      w.key("labels").begin_object();
      for (const auto& l : labels) {
        w.key(l.name).begin_object();
        for (const auto& [value, count] : l.counts) w.field(std::to_string(value), count);
        w.end_object();
      }
      w.end_object();
      w.key("vertex_fields").begin_array();
      for (const auto& f : m.vertex_fields)
        w.begin_object().field("name", f.name).field("components", f.components).end_object();
      w.end_array();
      w.key("tet_fields").begin_array();
      for (const auto& f : m.tet_fields)
        w.begin_object().field("name", f.name).field("components", f.components).end_object();
      w.end_array();
      w.key("bounding_box").begin_object();
      w.key("min").begin_array().value(lo[0]).value(lo[1]).value(lo[2]).end_array();
      w.key("max").begin_array().value(hi[0]).value(hi[1]).value(hi[2]).end_array();
      w.end_object();
      w.key("edge_length")
          .begin_object()
          .field("min", s.edge_length_min)
          .field("median", s.edge_length_median)
          .field("max", s.edge_length_max)
          .end_object();
      w.field("volume", s.total_volume)
          .field("min_dihedral_deg", s.min_dihedral_deg)
          .field("max_dihedral_deg", s.max_dihedral_deg)
          .field("interior_vertices", s.interior_vertices)
          .field("face_vertices", s.face_vertices)
          .field("ridge_vertices", s.ridge_vertices)
          .field("corner_vertices", s.corner_vertices)
          .field("ridge_edges", s.ridge_edges)
          .field("eps_f", o->eps_f)
          .field("eps_r", o->eps_r)
          .end_object();
      std::cout << w.str() << "\n";
    } else {
      char buf[512];
      std::cout << o->path << "\n";
      std::snprintf(buf, sizeof buf,
                    "  vertices %lld, tets %lld, edges %lld\n"
                    "  boundary faces %lld, interface faces %lld\n",
                    (long long)s.vertices, (long long)s.tets, (long long)s.edges, (long long)s.boundary_faces,
                    (long long)s.interface_faces);
      std::cout << buf;
      for (const auto& l : labels) {
        std::cout << "  labels '" << l.name << "': " << l.counts.size() << " values (";
        int shown = 0;
        for (const auto& [value, count] : l.counts) {
          if (shown++ == 8) { std::cout << ", ..."; break; }
          std::cout << (shown > 1 ? ", " : "") << value << ": " << count;
        }
        std::cout << ")\n";
      }
      for (const auto& f : m.vertex_fields)
        std::cout << "  vertex field '" << f.name << "' (" << f.components << " components)\n";
      for (const auto& f : m.tet_fields)
        std::cout << "  tet field '" << f.name << "' (" << f.components << " components)\n";
      std::snprintf(buf, sizeof buf,
                    "  bounding box [%g, %g] x [%g, %g] x [%g, %g]\n"
                    "  edge length min %.6g, median %.6g, max %.6g\n"
                    "  volume %.10g\n"
                    "  dihedral angle min %.4g deg, max %.4g deg\n"
                    "  vertices: %lld interior, %lld face, %lld ridge, %lld corner; %lld ridge edges "
                    "(eps_F %g, eps_R %g)\n",
                    lo[0], hi[0], lo[1], hi[1], lo[2], hi[2], s.edge_length_min, s.edge_length_median,
                    s.edge_length_max, s.total_volume, s.min_dihedral_deg, s.max_dihedral_deg,
                    (long long)s.interior_vertices, (long long)s.face_vertices, (long long)s.ridge_vertices,
                    (long long)s.corner_vertices, (long long)s.ridge_edges, o->eps_f, o->eps_r);
      std::cout << buf;
    }
    exit_code = kOk;
  });
}

}  // namespace tc::cli
