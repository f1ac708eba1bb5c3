#include "tetcollapse/io.hpp"

#include <algorithm>

#include "io/io_util.hpp"

namespace tc {

Format parse_format(const std::string& name_in) {
  std::string name = name_in;
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (!name.empty() && name[0] == '.') name.erase(0, 1);
  if (name == "msh" || name == "gmsh") return Format::Gmsh;
  if (name == "mesh" || name == "meshb" || name == "medit") return Format::Medit;
  if (name == "vtk") return Format::Vtk;
  if (name == "vtu") return Format::Vtu;
  if (name == "node" || name == "ele" || name == "tetgen") return Format::TetGen;
  throw InputError(name_in, "unknown mesh format (known: msh, mesh, meshb, vtk, vtu, node/ele)");
}

Format format_from_name(const std::string& path) {
  std::string ext = io::extension_of(path);
  if (ext.empty()) throw InputError(path, "no file extension to tell the format from (give --format)");
  try {
    return parse_format(ext);
  } catch (const InputError&) {
    throw InputError(path, "unknown file extension '" + ext + "' (known: .msh .mesh .meshb .vtk .vtu .node .ele)");
  }
}

const char* format_name(Format f) {
  switch (f) {
    case Format::Auto: return "auto";
    case Format::Gmsh: return "gmsh";
    case Format::Medit: return "medit";
    case Format::Vtk: return "vtk";
    case Format::Vtu: return "vtu";
    case Format::TetGen: return "tetgen";
  }
  return "?";
}

Mesh read_mesh(const std::string& path, const ReadOptions& options, ReadNotes* notes_out,
               OrientationReport* orientation_out) {
  Format f = options.format == Format::Auto ? format_from_name(path) : options.format;
  ReadNotes notes;
  Mesh mesh;
  const io::Lenient lenient(options.as_is);
  switch (f) {
    case Format::Gmsh: mesh = read_gmsh(path, notes); break;
    case Format::Medit: mesh = read_medit(path, notes, options.read_sol); break;
    case Format::Vtk: mesh = read_vtk(path, notes); break;
    case Format::Vtu: mesh = read_vtu(path, notes); break;
    case Format::TetGen: mesh = read_tetgen(path, notes); break;
    case Format::Auto: break;
  }
  if (mesh.num_tets() == 0) {
    std::string why = "the mesh has no tetrahedra";
    if (notes.skipped_elements > 0)
      why += " (" + std::to_string(notes.skipped_elements) + " non-tetrahedral elements were skipped)";
    throw InputError(path, why);
  }
  OrientationReport orient;
  if (options.as_is) {
    validate_arrays(mesh, path);
    // (orientation needs every tet's points; the checker reports the rest)
    if (geometry_is_sound(mesh))
      orient = normalize_orientation(
          mesh, options.orientation == OrientationPolicy::Fix ? OrientationPolicy::Fix : OrientationPolicy::Keep);
  } else {
    validate_structure(mesh, path);
    try {
      orient = normalize_orientation(mesh, options.orientation);
    } catch (const InputError& e) {
      throw InputError(path, e.reason());
    }
  }
  if (orient.flipped_all)
    notes.notes.push_back("all " + std::to_string(orient.flipped) + " tets were negatively oriented; flipped");
  else if (orient.flipped > 0)
    notes.notes.push_back("flipped " + std::to_string(orient.flipped) + " negatively oriented tets");
  if (orient.degenerate > 0)
    notes.notes.push_back(std::to_string(orient.degenerate) + " tets have exactly zero volume");
  if (notes_out) *notes_out = std::move(notes);
  if (orientation_out) *orientation_out = orient;
  return mesh;
}

Format io::output_format(const std::string& path, Format f) {
  if (f != Format::Auto) return f;
  try {
    return format_from_name(path);
  } catch (const InputError& e) {
    throw OutputError(e.what());
  }
}

void write_mesh(const std::string& path, const Mesh& mesh, const WriteOptions& options) {
  switch (io::output_format(path, options.format)) {
    case Format::Gmsh: write_gmsh(path, mesh, options); break;
    case Format::Medit: write_medit(path, mesh, options); break;
    case Format::Vtk: write_vtk(path, mesh, options); break;
    case Format::Vtu: write_vtu(path, mesh, options); break;
    case Format::TetGen: write_tetgen(path, mesh, options); break;
    case Format::Auto: break;
  }
}

}  // namespace tc
