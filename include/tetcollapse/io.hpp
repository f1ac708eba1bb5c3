// Reading and writing meshes. The format is chosen from the file extension unless given.
#pragma once

#include <string>

#include "tetcollapse/error.hpp"
#include "tetcollapse/mesh.hpp"

namespace tc {

enum class Format {
  Auto,         // from the extension
  Gmsh,         // .msh  (reads 2.2 and 4.1, ASCII and binary)
  Medit,        // .mesh (ASCII) / .meshb (binary); scalar fields in a .sol beside it
  Vtk,          // .vtk legacy (ASCII and binary)
  Vtu,          // .vtu XML (ASCII, base64 binary, appended raw; zlib-compressed on read)
  TetGen,       // .node + .ele (either name may be given)
};

struct WriteOptions {
  Format format = Format::Auto;
  bool binary = true;       // binary where the format has it
  int gmsh_version = 41;    // 22 or 41
  enum class VtuEncoding { Ascii, Base64, Appended } vtu_encoding = VtuEncoding::Appended;
};

struct ReadOptions {
  Format format = Format::Auto;
  OrientationPolicy orientation = OrientationPolicy::Refuse;
  bool read_sol = true;     // Medit: read FILE.sol beside FILE.mesh when present
  // The checker's reading: a mesh with non-finite coordinates or tets referring to missing
  // vertices is returned as it is (tc::check_mesh reports them), and a mixed orientation is
  // left as it is (a consistently negative mesh is still flipped). Only a file that cannot be
  // parsed, or whose arrays do not fit together, is an error.
  bool as_is = false;
};

Format format_from_name(const std::string& path);  // throws InputError when unknown
Format parse_format(const std::string& name);      // "msh", "gmsh", "mesh", "vtk", ...
const char* format_name(Format f);

// Reads a mesh; tets come back positively oriented (see normalize_orientation).
Mesh read_mesh(const std::string& path, const ReadOptions& options = {}, ReadNotes* notes = nullptr,
               OrientationReport* orientation = nullptr);

// Writes to a temporary file in the same folder and renames it over `path`, so a
// failure never leaves a half-written file. Throws OutputError.
void write_mesh(const std::string& path, const Mesh& mesh, const WriteOptions& options = {});

// Per-format entry points (used by read_mesh / write_mesh and by tests). Readers do not
// normalise orientation; read_mesh does. `display_name` is what error messages show.
Mesh read_gmsh(const std::string& path, ReadNotes& notes);
void write_gmsh(const std::string& path, const Mesh& mesh, const WriteOptions& options);
Mesh read_medit(const std::string& path, ReadNotes& notes, bool read_sol);
void write_medit(const std::string& path, const Mesh& mesh, const WriteOptions& options);
Mesh read_vtk(const std::string& path, ReadNotes& notes);
void write_vtk(const std::string& path, const Mesh& mesh, const WriteOptions& options);
Mesh read_vtu(const std::string& path, ReadNotes& notes);
void write_vtu(const std::string& path, const Mesh& mesh, const WriteOptions& options);
Mesh read_tetgen(const std::string& path, ReadNotes& notes);
void write_tetgen(const std::string& path, const Mesh& mesh, const WriteOptions& options);

}  // namespace tc
