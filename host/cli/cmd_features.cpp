#include <iostream>

#include "cli/common.hpp"
#include "tetcollapse/topology.hpp"

namespace tc::cli {

void register_features(CLI::App& app, int& exit_code) {
  struct Opts {
    std::string in, out;
    InputOptions input;
    OutputOptions output;
    double eps_f = 0.01, eps_r = 0.1;
    bool no_labels = false;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "features",
      "Write the boundary classification for viewing (e.g. in ParaView): the mesh with per-vertex fields\n"
      "'vertex_class' (0 interior, 1 face, 2 ridge, 3 corner) and 'on_surface' (1 boundary, 2 interface,\n"
      "3 both), the feature surface as triangles tagged 1 (boundary) / 2 (interface) and the ridge edges");
  cmd->add_option("MESH", o->in, "Input mesh")->required();
  cmd->add_option("OUT", o->out, "Output file, e.g. features.vtu")->required();
  cmd->add_option("--eps-f", o->eps_f, "Face-vertex threshold (paper: 0.01)")->capture_default_str();
  cmd->add_option("--eps-r", o->eps_r, "Ridge-edge threshold (paper: 0.1)")->capture_default_str();
  cmd->add_flag("--no-labels", o->no_labels, "Ignore material labels (no interface surfaces)");
  add_input_options(*cmd, o->input);
  add_output_options(*cmd, o->output);
  cmd->callback([o, &exit_code] {
    check_output_path(o->out, &o->output);
    Mesh m = read_input(o->in, o->input, false);
    TopologyOptions to{o->eps_f, o->eps_r, !o->no_labels};
    Topology topo = build_topology(m, to);
    Field cls{"vertex_class", 1, {}}, on{"on_surface", 1, {}};
    cls.values.assign(topo.vertex_class.begin(), topo.vertex_class.end());
    on.values.assign(topo.vertex_boundary.begin(), topo.vertex_boundary.end());
    m.vertex_fields.push_back(std::move(cls));
    m.vertex_fields.push_back(std::move(on));
    m.tris = topo.sfaces;
    m.tri_tags.clear();
    for (uint8_t i : topo.sface_interface) m.tri_tags.push_back(i ? 2 : 1);
    m.edges.clear();
    m.edge_tags.clear();
    for (int32_t e = 0; e < topo.num_edges(); ++e)
      if (topo.edge_ridge[e]) {
        m.edges.push_back(topo.edges[2 * e]);
        m.edges.push_back(topo.edges[2 * e + 1]);
        m.edge_tags.push_back(1);
      }
    write_mesh(o->out, m, write_options(o->output));
    TopologySummary s = summarize(m, topo);
    std::cerr << "wrote " << o->out << ": " << s.face_vertices << " face, " << s.ridge_vertices << " ridge, "
              << s.corner_vertices << " corner vertices, " << s.ridge_edges << " ridge edges\n";
    exit_code = kOk;
  });
}

}  // namespace tc::cli
