#include <iostream>

#include "cli/common.hpp"

namespace tc::cli {

void register_convert(CLI::App& app, int& exit_code) {
  struct Opts {
    std::string in, out;
    InputOptions input;
    OutputOptions output;
    bool quiet = false;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand("convert", "Read a mesh and write it in another format (formats from the extensions)");
  cmd->add_option("IN", o->in, "Input mesh")->required();
  cmd->add_option("OUT", o->out, "Output mesh (written to a temporary file and renamed)")->required();
  add_input_options(*cmd, o->input);
  add_output_options(*cmd, o->output);
  cmd->add_flag("-q,--quiet", o->quiet, "Print nothing but errors");
  cmd->callback([o, &exit_code] {
    check_output_path(o->out, &o->output);
    Mesh m = read_input(o->in, o->input, o->quiet);
    write_mesh(o->out, m, write_options(o->output));
    if (!o->quiet)
      std::cerr << "wrote " << o->out << ": " << m.num_vertices() << " vertices, " << m.num_tets() << " tets\n";
    exit_code = kOk;
  });
}

}  // namespace tc::cli
