// Writes the seed corpora of the fuzz harnesses: small valid meshes (a single tet and a
// cube of 6 tets with labels, fields, boundary triangles and edges) in every format and
// encoding the project's writers produce, packed as the harnesses expect (fuzz_input.hpp).
//   make_fuzz_seeds OUT_DIR      -> OUT_DIR/<format>/<name>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "fuzz_input.hpp"
#include "tetcollapse/io.hpp"

namespace fs = std::filesystem;
using tc::Format;
using tc::Mesh;

namespace {

Mesh single_tet() {
  Mesh m;
  m.points = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  m.tets = {0, 1, 2, 3};
  return m;
}

// The unit cube in 6 positively oriented tets (Kuhn), two materials, a vertex field with
// 3 components, a scalar tet field, its 12 boundary triangles and 3 tagged edges.
Mesh decorated_cube() {
  Mesh m;
  for (int k = 0; k <= 1; ++k)
    for (int j = 0; j <= 1; ++j)
      for (int i = 0; i <= 1; ++i) m.points.insert(m.points.end(), {double(i), double(j), double(k)});
  auto id = [](int i, int j, int k) { return int32_t(k * 4 + j * 2 + i); };
  static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (const auto& p : perms) {
    std::array<int, 3> c = {0, 0, 0};
    int32_t v[4];
    v[0] = id(0, 0, 0);
    for (int s = 0; s < 3; ++s) {
      c[p[s]] += 1;
      v[s + 1] = id(c[0], c[1], c[2]);
    }
    const bool odd = (p[0] == 0 && p[1] == 2) || (p[0] == 1 && p[1] == 0) || (p[0] == 2 && p[1] == 1);
    if (odd) std::swap(v[2], v[3]);
    m.tets.insert(m.tets.end(), v, v + 4);
  }
  m.tet_labels.push_back({"material", {1, 1, 1, 2, 2, 2}});
  tc::Field vf;
  vf.name = "displacement";
  vf.components = 3;
  for (int i = 0; i < 24; ++i) vf.values.push_back(0.125 * i);
  m.vertex_fields.push_back(vf);
  tc::Field tf;
  tf.name = "quality";
  tf.components = 1;
  tf.values = {0.5, 0.25, 1.0, 0.75, 0.125, 2.0};
  m.tet_fields.push_back(tf);
  // Boundary: two triangles per cube face, tagged by face.
  const int32_t faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  for (int f = 0; f < 6; ++f) {
    m.tris.insert(m.tris.end(), {faces[f][0], faces[f][1], faces[f][2], faces[f][0], faces[f][2], faces[f][3]});
    m.tri_tags.insert(m.tri_tags.end(), {f + 1, f + 1});
  }
  m.edges = {0, 1, 1, 3, 3, 7};
  m.edge_tags = {10, 10, 11};
  return m;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Packs the files a reader would open into one fuzz input.
std::string pack(const fs::path& dir, Format f) {
  const tc::fuzz::Layout layout = tc::fuzz::layout_of(f);
  std::string out;
  size_t present = 0;
  for (size_t i = 0; i < layout.names.size(); ++i)
    if (fs::exists(dir / layout.names[i])) present = i + 1;
  for (size_t i = 0; i < present; ++i) {
    if (i) out += tc::fuzz::kPartSeparator;
    if (fs::exists(dir / layout.names[i])) out += slurp(dir / layout.names[i]);
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: make_fuzz_seeds OUT_DIR\n";
    return 1;
  }
  const fs::path out = argv[1];
  const fs::path tmp = fs::temp_directory_path() / ("tc-seeds-" + std::to_string(::getpid()));
  struct Variant {
    const char* dir;
    const char* name;
    Format format;
    const char* file;  // written as this (the extension picks the Medit encoding)
    tc::WriteOptions options;
  };
  auto opts = [](bool binary, int gmsh_version = 41,
                 tc::WriteOptions::VtuEncoding enc = tc::WriteOptions::VtuEncoding::Appended) {
    tc::WriteOptions o;
    o.binary = binary;
    o.gmsh_version = gmsh_version;
    o.vtu_encoding = enc;
    return o;
  };
  using Enc = tc::WriteOptions::VtuEncoding;
  const std::vector<Variant> variants = {
      {"gmsh", "v41-ascii", Format::Gmsh, "x.msh", opts(false, 41)},
      {"gmsh", "v41-binary", Format::Gmsh, "x.msh", opts(true, 41)},
      {"gmsh", "v22-ascii", Format::Gmsh, "x.msh", opts(false, 22)},
      {"gmsh", "v22-binary", Format::Gmsh, "x.msh", opts(true, 22)},
      {"medit", "ascii", Format::Medit, "x.mesh", opts(false)},
      {"medit", "binary", Format::Medit, "x.meshb", opts(true)},
      {"vtk", "ascii", Format::Vtk, "x.vtk", opts(false)},
      {"vtk", "binary", Format::Vtk, "x.vtk", opts(true)},
      {"vtu", "ascii", Format::Vtu, "x.vtu", opts(true, 41, Enc::Ascii)},
      {"vtu", "base64", Format::Vtu, "x.vtu", opts(true, 41, Enc::Base64)},
      {"vtu", "appended", Format::Vtu, "x.vtu", opts(true, 41, Enc::Appended)},
      {"tetgen", "text", Format::TetGen, "x.node", opts(false)},
  };
  const std::vector<std::pair<const char*, Mesh>> meshes = {{"tet", single_tet()}, {"cube", decorated_cube()}};
  int written = 0;
  for (const auto& [mname, mesh] : meshes)
    for (const Variant& v : variants) {
      fs::remove_all(tmp);
      fs::create_directories(tmp);
      tc::WriteOptions o = v.options;
      o.format = v.format;
      tc::write_mesh((tmp / v.file).string(), mesh, o);
      // The harness always names the Medit files x.mesh / x.sol (the encoding is told from
      // the content), so rename the binary ones.
      if (fs::exists(tmp / "x.meshb")) fs::rename(tmp / "x.meshb", tmp / "x.mesh");
      if (fs::exists(tmp / "x.solb")) fs::rename(tmp / "x.solb", tmp / "x.sol");
      fs::create_directories(out / v.dir);
      std::ofstream(out / v.dir / (std::string(mname) + "-" + v.name), std::ios::binary) << pack(tmp, v.format);
      ++written;
    }
  fs::remove_all(tmp);
  std::cout << "wrote " << written << " seeds under " << out.string() << "\n";
  return 0;
}
