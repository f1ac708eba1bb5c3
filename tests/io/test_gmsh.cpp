// Gmsh MSH reader / writer: shared meshes, round trips of the four variants, hand-made
// files (sparse tags, high-order and skipped elements, big-endian binary, fields) and one
// test per kind of bad input, plus a cross-check of our output with meshio.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>

#include "io/io_util.hpp"
#include "test_support.hpp"
#include "tetcollapse/io.hpp"

namespace {

using tc::Mesh;
using tc::ReadNotes;
using tc::test::TempDir;
using tc::test::write_text;

Mesh read(const std::string& path, ReadNotes* notes_out = nullptr) {
  ReadNotes notes;
  Mesh m = tc::read_gmsh(path, notes);
  if (notes_out) *notes_out = notes;
  return m;
}

// The message of the InputError thrown by reading `text` (written to a file), or "".
std::string read_error(const std::string& text, const std::string& name = "bad.msh") {
  TempDir dir;
  std::string path = dir.file(name);
  write_text(path, text);
  try {
    read(path);
  } catch (const tc::InputError& e) {
    return e.what();
  }
  return "";
}

std::map<int32_t, int64_t> histogram(const std::vector<int32_t>& v) {
  std::map<int32_t, int64_t> h;
  for (int32_t x : v) ++h[x];
  return h;
}

// Builds binary MSH files by hand, optionally byte-swapped (big-endian on this machine).
struct Bytes {
  bool swap = false;
  std::string s;
  Bytes& text(const std::string& t) {
    s += t;
    return *this;
  }
  template <class T>
  Bytes& put(T v) {
    if (swap) v = tc::io::BinaryCursor::byteswap_value(v);
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    s.append(b, sizeof(T));
    return *this;
  }
  Bytes& i32(int32_t v) { return put(v); }
  Bytes& u64(uint64_t v) { return put(v); }
  Bytes& f64(double v) { return put(v); }
};

const double kCoords[5][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.1, 0.2, -0.3}};
const uint64_t kTags[5] = {10, 20, 30, 40, 50};  // sparse node tags

// 4.1 binary: one volume entity 7 (physical 5), sparse nodes, one tet, one triangle on
// surface 3, a scalar $NodeData.
std::string make_41_binary(bool swap) {
  Bytes b;
  b.swap = swap;
  b.text("$MeshFormat\n4.1 1 8\n").i32(1).text("\n$EndMeshFormat\n");
  b.text("$Entities\n").u64(0).u64(0).u64(1).u64(1);
  b.i32(3);
  for (int k = 0; k < 6; ++k) b.f64(0);
  b.u64(0).u64(0);  // no physical, no bounding curves
  b.i32(7);
  for (int k = 0; k < 6; ++k) b.f64(0);
  b.u64(1).i32(5).u64(1).i32(3);
  b.text("\n$EndEntities\n$Nodes\n").u64(1).u64(5).u64(10).u64(50);
  b.i32(3).i32(7).i32(0).u64(5);
  for (uint64_t t : kTags) b.u64(t);
  for (const auto& p : kCoords) b.f64(p[0]).f64(p[1]).f64(p[2]);
  b.text("\n$EndNodes\n$Elements\n").u64(2).u64(2).u64(1).u64(2);
  b.i32(3).i32(7).i32(4).u64(1).u64(1).u64(10).u64(20).u64(30).u64(40);
  b.i32(2).i32(3).i32(2).u64(1).u64(2).u64(20).u64(30).u64(50);
  b.text("\n$EndElements\n$NodeData\n1\n\"temperature\"\n1\n0.0\n3\n0\n1\n5\n");
  for (int i = 0; i < 5; ++i) b.i32(static_cast<int32_t>(kTags[i])).f64(100.0 + i);
  b.text("\n$EndNodeData\n");
  return b.s;
}

// 2.2 binary with the same content (physical 5 / elementary 7 on the tet).
std::string make_22_binary(bool swap) {
  Bytes b;
  b.swap = swap;
  b.text("$MeshFormat\n2.2 1 8\n").i32(1).text("\n$EndMeshFormat\n$Nodes\n5\n");
  for (int i = 0; i < 5; ++i) b.i32(static_cast<int32_t>(kTags[i])).f64(kCoords[i][0]).f64(kCoords[i][1]).f64(kCoords[i][2]);
  b.text("\n$EndNodes\n$Elements\n2\n");
  b.i32(4).i32(1).i32(2).i32(1).i32(5).i32(7).i32(10).i32(20).i32(30).i32(40);
  b.i32(2).i32(1).i32(2).i32(2).i32(0).i32(3).i32(20).i32(30).i32(50);
  b.text("\n$EndElements\n$NodeData\n1\n\"temperature\"\n1\n0.0\n3\n0\n1\n5\n");
  for (int i = 0; i < 5; ++i) b.i32(static_cast<int32_t>(kTags[i])).f64(100.0 + i);
  b.text("\n$EndNodeData\n");
  return b.s;
}

void expect_small_binary_content(const Mesh& m) {
  ASSERT_EQ(m.num_vertices(), 5);
  for (int i = 0; i < 5; ++i)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(m.points[3 * i + k], kCoords[i][k]);
  EXPECT_EQ(m.tets, (std::vector<int32_t>{0, 1, 2, 3}));
  EXPECT_EQ(m.tris, (std::vector<int32_t>{1, 2, 4}));
  EXPECT_EQ(m.tri_tags, (std::vector<int32_t>{3}));
  ASSERT_NE(m.find_labels("gmsh:physical"), nullptr);
  EXPECT_EQ(m.find_labels("gmsh:physical")->values, (std::vector<int32_t>{5}));
  ASSERT_NE(m.find_labels("gmsh:geometrical"), nullptr);
  EXPECT_EQ(m.find_labels("gmsh:geometrical")->values, (std::vector<int32_t>{7}));
  const tc::Field* f = m.find_vertex_field("temperature");
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->components, 1);
  EXPECT_EQ(f->values, (std::vector<double>{100, 101, 102, 103, 104}));
}

// ------------------------------------------------------------------ shared meshes

struct SharedCase {
  const char* name;
  int64_t vertices, tets;
};
const SharedCase kShared[] = {
    {"polyfem_screw.msh", 1732, 6059},
    {"ipc_hammer.msh", 2705, 9683},
    {"polyfem_bimetal.msh", 3881, 16275},
    {"ipc_thingi32770_octocat.msh", 6133, 21426},
    {"polyfem_cubes_v41.msh", 7714, 32981},
    {"ipc_hollowCat7.5K.msh", 12827, 57636},
    {"polyfem_mat100x100t40.msh", 20000, 58806},
    {"gen_gmsh_wrenchnut_27k.msh", 6818, 27253},
    {"gen_gmsh_Angled_43k.msh", 10665, 42746},
    {"gen_gmsh_917_fusee_88k.msh", 22672, 87780},
    {"gen_gmsh_Block_250k.msh", 65471, 250339},
    {"gen_tetgen_octagonal_pocket_160k.msh", 36092, 159551},
    {"gen_tetgen_thingi255172_make-robot_283k.msh", 67878, 282780},
    {"gen_tetgen_featuretype_497k.msh", 98671, 497361},
    {"gen_tetgen_rocker-arm_964k.msh", 200574, 963536},
    {"gen_tetgen_thingi255172_make-robot_514k.msh", 110898, 514161},
};

TEST(GmshShared, EveryShared_mshLoadsWithTheDocumentedCounts) {
  TC_SKIP_IF_NO_SHARED();
  int checked = 0;
  for (const SharedCase& c : kShared) {
    std::string path = tc::test::shared_mesh(c.name);
    if (path.empty()) continue;
    SCOPED_TRACE(c.name);
    Mesh m = read(path);
    EXPECT_EQ(m.num_vertices(), c.vertices);
    EXPECT_EQ(m.num_tets(), c.tets);
    EXPECT_NO_THROW(tc::validate_structure(m, path));
    ++checked;
  }
  // Every .msh of the folder is in the table above.
  int files = 0;
  for (const auto& p : tc::test::shared_volume_meshes())
    if (std::filesystem::path(p).extension() == ".msh") ++files;
  EXPECT_EQ(checked, files);
}

TEST(GmshShared, BimetalHasTwoPhysicalVolumes) {
  std::string path = tc::test::shared_mesh("polyfem_bimetal.msh");
  if (path.empty()) GTEST_SKIP() << "polyfem_bimetal.msh is not present in ../shared/meshes";
  Mesh m = read(path);
  const tc::Labels* phys = m.find_labels("gmsh:physical");
  ASSERT_NE(phys, nullptr);
  EXPECT_EQ(m.tet_labels[0].name, "gmsh:physical");  // primary label
  auto h = histogram(phys->values);
  ASSERT_EQ(h.size(), 2u);
  std::vector<int64_t> counts;
  for (auto [k, n] : h) counts.push_back(n);
  std::sort(counts.begin(), counts.end());
  EXPECT_EQ(counts, (std::vector<int64_t>{8071, 8204}));
  EXPECT_EQ(h.count(1) + h.count(2), 2u);  // physical tags 1 and 2 ("bottom/top_material")
}

TEST(GmshShared, CubesHaveThreePhysicalVolumes) {
  std::string path = tc::test::shared_mesh("polyfem_cubes_v41.msh");
  if (path.empty()) GTEST_SKIP() << "polyfem_cubes_v41.msh is not present in ../shared/meshes";
  Mesh m = read(path);  // sparse node tags (7714 nodes, tags up to 11755)
  const tc::Labels* phys = m.find_labels("gmsh:physical");
  ASSERT_NE(phys, nullptr);
  std::vector<int64_t> counts;
  for (auto [k, n] : histogram(phys->values)) counts.push_back(n);
  EXPECT_EQ(counts, (std::vector<int64_t>{12285, 8726, 11970}));
}

TEST(GmshShared, WrenchnutEntitiesTrianglesAndFeatureLines) {
  std::string path = tc::test::shared_mesh("gen_gmsh_wrenchnut_27k.msh");
  if (path.empty()) GTEST_SKIP() << "gen_gmsh_wrenchnut_27k.msh is not present in ../shared/meshes";
  ReadNotes notes;
  Mesh m = read(path, &notes);
  EXPECT_EQ(m.find_labels("gmsh:physical"), nullptr);  // no physical groups in this file
  const tc::Labels* geo = m.find_labels("gmsh:geometrical");
  ASSERT_NE(geo, nullptr);
  auto h = histogram(geo->values);
  EXPECT_EQ(h, (std::map<int32_t, int64_t>{{1, 24431}, {2, 2822}}));
  EXPECT_EQ(m.edges.size() / 2, 971u);  // feature-curve segments (SOURCES.md)
  EXPECT_EQ(m.edge_tags.size(), 971u);
  EXPECT_GT(m.num_tris(), 0);
  EXPECT_EQ(m.tri_tags.size(), static_cast<size_t>(m.num_tris()));
  EXPECT_GT(histogram(m.tri_tags).size(), 10u);  // many CAD faces
  EXPECT_GT(notes.skipped_elements, 0);            // the corner "point" elements
  bool noted = false;
  for (const auto& n : notes.notes) noted |= n.find("point") != std::string::npos;
  EXPECT_TRUE(noted);
}

TEST(GmshShared, FeatureCurveCountsOfTheOtherGmshMeshes) {
  TC_SKIP_IF_NO_SHARED();
  const std::pair<const char*, size_t> cases[] = {
      {"gen_gmsh_Angled_43k.msh", 1405}, {"gen_gmsh_917_fusee_88k.msh", 4228}, {"gen_gmsh_Block_250k.msh", 11395}};
  for (auto [name, lines] : cases) {
    std::string path = tc::test::shared_mesh(name);
    if (path.empty()) continue;
    SCOPED_TRACE(name);
    Mesh m = read(path);
    EXPECT_EQ(m.edge_tags.size(), lines);
  }
}

// Files written by Gmsh itself in all four variants (converted from the shared mesh by
// the gmsh command line): the same mesh comes back from each.
TEST(GmshShared, GmshWrittenVariantsOfWrenchnutAgree) {
  std::string src = tc::test::shared_mesh("gen_gmsh_wrenchnut_27k.msh");
  if (src.empty()) GTEST_SKIP() << "gen_gmsh_wrenchnut_27k.msh is not present in ../shared/meshes";
  std::string out;
  if (tc::test::run_command("gmsh --version", &out) != 0) GTEST_SKIP() << "the gmsh command is not installed";
  Mesh ref = read(src);
  TempDir dir;
  const char* variants[] = {"msh22", "msh22 -bin", "msh41", "msh41 -bin"};
  for (const char* v : variants) {
    SCOPED_TRACE(v);
    std::string path = dir.file("w.msh");
    ASSERT_EQ(tc::test::run_command("gmsh '" + src + "' -0 -format " + v + " -o '" + path + "'", &out), 0) << out;
    ReadNotes notes;
    Mesh m = read(path, &notes);
    EXPECT_EQ(m.num_vertices(), ref.num_vertices());
    EXPECT_EQ(m.tets, ref.tets);
    EXPECT_EQ(m.tris, ref.tris);
    EXPECT_EQ(m.tri_tags, ref.tri_tags);
    EXPECT_EQ(m.edges, ref.edges);
    EXPECT_EQ(m.edge_tags, ref.edge_tags);
    ASSERT_NE(m.find_labels("gmsh:geometrical"), nullptr);
    EXPECT_EQ(m.find_labels("gmsh:geometrical")->values, ref.find_labels("gmsh:geometrical")->values);
    EXPECT_EQ(m.find_labels("gmsh:physical"), nullptr);  // 2.2: physical tag 0 everywhere
    if (std::string(v).find("-bin") != std::string::npos)
      EXPECT_EQ(0, std::memcmp(m.points.data(), ref.points.data(), m.points.size() * sizeof(double)));
    else
      for (size_t i = 0; i < m.points.size(); ++i) ASSERT_NEAR(m.points[i], ref.points[i], 1e-12 * (1 + std::fabs(ref.points[i])));
    EXPECT_GT(notes.skipped_elements, 0);
  }
}

// ------------------------------------------------------------------ round trips

struct Variant {
  int version;
  bool binary;
  const char* name;
};
const Variant kVariants[] = {{41, true, "41bin"}, {41, false, "41ascii"}, {22, true, "22bin"}, {22, false, "22ascii"}};

void expect_same(const Mesh& a, const Mesh& b) {
  ASSERT_EQ(a.points.size(), b.points.size());
  EXPECT_EQ(0, std::memcmp(a.points.data(), b.points.data(), a.points.size() * sizeof(double)));  // bit for bit
  EXPECT_EQ(a.tets, b.tets);
  EXPECT_EQ(a.tris, b.tris);
  EXPECT_EQ(a.tri_tags, b.tri_tags);
  EXPECT_EQ(a.edges, b.edges);
  EXPECT_EQ(a.edge_tags, b.edge_tags);
  ASSERT_EQ(a.tet_labels.size(), b.tet_labels.size());
  for (size_t i = 0; i < a.tet_labels.size(); ++i) {
    EXPECT_EQ(a.tet_labels[i].name, b.tet_labels[i].name);
    EXPECT_EQ(a.tet_labels[i].values, b.tet_labels[i].values) << a.tet_labels[i].name;
  }
  auto same_fields = [](const std::vector<tc::Field>& x, const std::vector<tc::Field>& y) {
    ASSERT_EQ(x.size(), y.size());
    for (size_t i = 0; i < x.size(); ++i) {
      EXPECT_EQ(x[i].name, y[i].name);
      EXPECT_EQ(x[i].components, y[i].components);
      ASSERT_EQ(x[i].values.size(), y[i].values.size());
      EXPECT_EQ(0, std::memcmp(x[i].values.data(), y[i].values.data(), x[i].values.size() * sizeof(double))) << x[i].name;
    }
  };
  same_fields(a.vertex_fields, b.vertex_fields);
  same_fields(a.tet_fields, b.tet_fields);
}

// A cube mesh with everything the format carries: two materials in interleaved order,
// coordinates that need all 17 digits, tagged triangles and lines, scalar / vector fields.
Mesh rich_mesh() {
  Mesh m = tc::test::cube_tets(3);
  for (size_t i = 0; i < m.points.size(); ++i) m.points[i] = m.points[i] * (1.0 / 3.0) + 1e-17 * double(i % 7) + 0.1;
  const int64_t nt = m.num_tets(), nv = m.num_vertices();
  tc::Labels phys{"gmsh:physical", {}}, geo{"gmsh:geometrical", {}};
  for (int64_t t = 0; t < nt; ++t) {
    phys.values.push_back(t % 3 == 0 ? 11 : 22);
    geo.values.push_back(t % 3 == 0 ? 1 : 4);
  }
  m.tet_labels = {phys, geo};
  for (int64_t t = 0; t < 10; ++t) {
    m.tris.insert(m.tris.end(), {m.tets[4 * t], m.tets[4 * t + 1], m.tets[4 * t + 2]});
    m.tri_tags.push_back(static_cast<int32_t>(t % 2 + 5));
  }
  m.edges = {0, 1, 1, 2, 2, 3};
  m.edge_tags = {9, 9, 8};
  tc::Field s{"pressure", 1, {}}, v{"velocity", 3, {}}, c{"stress", 1, {}};
  for (int64_t i = 0; i < nv; ++i) {
    s.values.push_back(std::sqrt(double(i)) - 0.3);
    for (int k = 0; k < 3; ++k) v.values.push_back(double(i * 3 + k) / 7.0);
  }
  for (int64_t t = 0; t < nt; ++t) c.values.push_back(std::exp(-double(t)));
  m.vertex_fields = {s, v};
  m.tet_fields = {c};
  return m;
}

TEST(GmshRoundTrip, AllFourVariantsAreExact) {
  Mesh m = rich_mesh();
  TempDir dir;
  for (const Variant& var : kVariants) {
    SCOPED_TRACE(var.name);
    tc::WriteOptions o;
    o.gmsh_version = var.version;
    o.binary = var.binary;
    std::string path = dir.file(std::string("rt_") + var.name + ".msh");
    tc::write_gmsh(path, m, o);
    Mesh back = read(path);
    expect_same(m, back);
    // Written again from what was read: byte-identical file.
    std::string path2 = dir.file(std::string("rt2_") + var.name + ".msh");
    tc::write_gmsh(path2, back, o);
    EXPECT_EQ(tc::test::read_text(path), tc::test::read_text(path2));
  }
  // Nothing but the four results is left in the folder (no temporaries).
  int files = 0;
  for (auto& e : std::filesystem::directory_iterator(dir.path())) (void)e, ++files;
  EXPECT_EQ(files, 8);
}

TEST(GmshRoundTrip, WrenchnutAllVariants) {
  std::string path = tc::test::shared_mesh("gen_gmsh_wrenchnut_27k.msh");
  if (path.empty()) GTEST_SKIP() << "gen_gmsh_wrenchnut_27k.msh is not present in ../shared/meshes";
  Mesh m = read(path);
  TempDir dir;
  for (const Variant& var : kVariants) {
    SCOPED_TRACE(var.name);
    tc::WriteOptions o;
    o.gmsh_version = var.version;
    o.binary = var.binary;
    std::string out = dir.file(std::string("w_") + var.name + ".msh");
    tc::write_gmsh(out, m, o);
    expect_same(m, read(out));
  }
}

TEST(GmshRoundTrip, OtherLabelsBecomeGmshGroups) {
  // A mesh from another format: its primary label becomes physical group and entity.
  Mesh m = tc::test::cube_tets(2);
  tc::Labels ref{"medit:ref", {}};
  for (int64_t t = 0; t < m.num_tets(); ++t) ref.values.push_back(t < 20 ? 2 : 3);
  m.tet_labels = {ref};
  TempDir dir;
  for (const Variant& var : kVariants) {
    SCOPED_TRACE(var.name);
    tc::WriteOptions o;
    o.gmsh_version = var.version;
    o.binary = var.binary;
    std::string out = dir.file(std::string("l_") + var.name + ".msh");
    tc::write_gmsh(out, m, o);
    Mesh back = read(out);
    ASSERT_NE(back.find_labels("gmsh:physical"), nullptr);
    EXPECT_EQ(back.find_labels("gmsh:physical")->values, ref.values);
    ASSERT_NE(back.find_labels("gmsh:geometrical"), nullptr);
    EXPECT_EQ(back.find_labels("gmsh:geometrical")->values, ref.values);
  }
}

TEST(GmshRoundTrip, GeometricalTagWithTwoPhysicalGroupsKeepsPhysical) {
  Mesh m = tc::test::cube_tets(1);
  m.tet_labels = {{"gmsh:physical", {1, 1, 2, 2, 1, 2}}, {"gmsh:geometrical", {4, 4, 4, 4, 4, 4}}};
  TempDir dir;
  std::string out = dir.file("split.msh");
  tc::write_gmsh(out, m, {});
  Mesh back = read(out);
  EXPECT_EQ(back.find_labels("gmsh:physical")->values, m.tet_labels[0].values);
  const auto& g = back.find_labels("gmsh:geometrical")->values;
  // Entity 4 stays for the first pair; the other pair gets a fresh, different tag.
  EXPECT_EQ(g[0], 4);
  EXPECT_NE(g[2], 4);
  EXPECT_EQ(g[2], g[3]);
  EXPECT_EQ(g[2], g[5]);
}

TEST(GmshWrite, MissingFolderIsAnOutputError) {
  Mesh m = tc::test::single_tet();
  EXPECT_THROW(tc::write_gmsh("/nonexistent_folder_tc/x.msh", m, {}), tc::OutputError);
}

TEST(GmshWrite, BadMeshIsAnOutputErrorAndLeavesNoFile) {
  Mesh m = tc::test::single_tet();
  m.tets[2] = 7;  // out of range
  TempDir dir;
  std::string out = dir.file("bad.msh");
  EXPECT_THROW(tc::write_gmsh(out, m, {}), tc::OutputError);
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
  tc::WriteOptions o;
  o.gmsh_version = 30;
  EXPECT_THROW(tc::write_gmsh(out, tc::test::single_tet(), o), tc::OutputError);
}

// ------------------------------------------------------------------ hand-written files

TEST(GmshRead, Ascii22QuadraticTetHexAndPhysical) {
  TempDir dir;
  std::string path = dir.file("q.msh");
  std::string nodes;
  // 10 nodes of a tet10 (tags 101..110), 8 of a hex (201..208).
  const double p10[10][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {.5, 0, 0}, {.5, .5, 0}, {0, .5, 0}, {0, 0, .5}, {0, .5, .5}, {.5, 0, .5}};
  for (int i = 0; i < 10; ++i)
    nodes += std::to_string(101 + i) + " " + std::to_string(p10[i][0]) + " " + std::to_string(p10[i][1]) + " " + std::to_string(p10[i][2]) + "\n";
  for (int i = 0; i < 8; ++i)
    nodes += std::to_string(201 + i) + " " + std::to_string(2 + (i & 1)) + " " + std::to_string((i >> 1) & 1) + " " + std::to_string(i >> 2) + "\n";
  write_text(path,
             "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n"
             "$PhysicalNames\n1\n3 9 \"steel\"\n$EndPhysicalNames\n"
             "$Nodes\n18\n" + nodes + "$EndNodes\n"
             "$Elements\n4\n"
             "1 11 2 9 3 101 102 103 104 105 106 107 108 109 110\n"
             "2 5 2 0 4 201 202 204 203 205 206 208 207\n"
             "3 4 2 9 3 101 102 103 104\n"
             "4 9 2 0 6 101 102 103 105 106 107\n"
             "$EndElements\n"
             "$ElementData\n1\n\"mat\"\n1\n0.0\n3\n0\n1\n3\n1 7.5\n2 1.0\n3 8.5\n$EndElementData\n");
  ReadNotes notes;
  Mesh m = read(path, &notes);
  EXPECT_EQ(m.num_vertices(), 18);
  ASSERT_EQ(m.num_tets(), 2);
  EXPECT_EQ(m.tets, (std::vector<int32_t>{0, 1, 2, 3, 0, 1, 2, 3}));
  EXPECT_EQ(notes.reduced_quadratic_tets, 1);
  EXPECT_EQ(notes.skipped_elements, 1);
  std::string all;
  for (auto& n : notes.notes) all += n + "\n";
  EXPECT_NE(all.find("1 hex"), std::string::npos) << all;
  EXPECT_NE(all.find("higher-order tets"), std::string::npos) << all;
  EXPECT_NE(all.find("higher-order triangles"), std::string::npos) << all;
  EXPECT_EQ(m.tris, (std::vector<int32_t>{0, 1, 2}));
  EXPECT_EQ(m.tri_tags, (std::vector<int32_t>{6}));
  EXPECT_EQ(m.find_labels("gmsh:physical")->values, (std::vector<int32_t>{9, 9}));
  EXPECT_EQ(m.find_labels("gmsh:geometrical")->values, (std::vector<int32_t>{3, 3}));
  ASSERT_EQ(m.tet_fields.size(), 1u);  // element 2 (the hex) is ignored
  EXPECT_EQ(m.tet_fields[0].values, (std::vector<double>{7.5, 8.5}));
}

TEST(GmshRead, Ascii41SparseParametricEntitiesAndTimeSteps) {
  TempDir dir;
  std::string path = dir.file("p.msh");
  write_text(path,
             "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
             "$Entities\n1 1 0 2\n"
             "1 0 0 0 0\n"
             "2 0 0 0 1 1 1 0 0\n"
             "5 0 0 0 1 1 1 1 42 0\n"
             "6 0 0 0 1 1 1 0 0\n"
             "$EndEntities\n"
             "$Nodes\n2 5 3 1000\n"
             "1 2 1 2\n1000\n7\n1 0 0 0.25\n0 1 0 0.75\n"
             "3 5 0 3\n3\n500\n9\n0 0 0\n0 0 1\n1 1 1\n"
             "$EndNodes\n"
             "$Elements\n3 3 1 3\n"
             "3 5 4 1\n1 3 1000 7 500\n"
             "3 6 4 1\n2 1000 7 500 9\n"
             "1 2 1 1\n3 1000 7\n"
             "$EndElements\n"
             "$NodeData\n1\n\"u\"\n1\n0.0\n3\n0\n3\n5\n3 1 2 3\n500 4 5 6\n9 7 8 9\n1000 0 0 0\n7 1 1 1\n$EndNodeData\n"
             "$NodeData\n1\n\"u\"\n1\n1.0\n3\n1\n3\n5\n3 -1 2 3\n500 4 5 6\n9 7 8 9\n1000 0 0 0\n7 1 1 1\n$EndNodeData\n"
             "$Periodic\n0\n$EndPeriodic\n");
  ReadNotes notes;
  Mesh m = read(path, &notes);
  ASSERT_EQ(m.num_vertices(), 5);
  // Node order = file order: 1000, 7, 3, 500, 9.
  EXPECT_EQ(m.points, (std::vector<double>{1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1}));
  EXPECT_EQ(m.tets, (std::vector<int32_t>{2, 0, 1, 3, 0, 1, 3, 4}));
  EXPECT_EQ(m.find_labels("gmsh:physical")->values, (std::vector<int32_t>{42, 0}));
  EXPECT_EQ(m.find_labels("gmsh:geometrical")->values, (std::vector<int32_t>{5, 6}));
  EXPECT_EQ(m.edges, (std::vector<int32_t>{0, 1}));
  EXPECT_EQ(m.edge_tags, (std::vector<int32_t>{2}));
  ASSERT_EQ(m.vertex_fields.size(), 1u);
  EXPECT_EQ(m.vertex_fields[0].components, 3);
  EXPECT_EQ(m.vertex_fields[0].values, (std::vector<double>{0, 0, 0, 1, 1, 1, -1, 2, 3, 4, 5, 6, 7, 8, 9}));  // last step
  std::string all;
  for (auto& n : notes.notes) all += n + "\n";
  EXPECT_NE(all.find("time steps"), std::string::npos) << all;
  EXPECT_NE(all.find("$Periodic"), std::string::npos) << all;
}

TEST(GmshRead, BinaryLittleAndBigEndian) {
  TempDir dir;
  for (bool swap : {false, true}) {
    SCOPED_TRACE(swap ? "big-endian" : "little-endian");
    std::string p41 = dir.file("b41.msh"), p22 = dir.file("b22.msh");
    write_text(p41, make_41_binary(swap));
    write_text(p22, make_22_binary(swap));
    expect_small_binary_content(read(p41));
    expect_small_binary_content(read(p22));
  }
}

TEST(GmshRead, FileWithoutTetsGivesEmptyTets) {
  TempDir dir;
  std::string path = dir.file("tri.msh");
  write_text(path, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n"
                   "$Elements\n1\n1 2 2 0 1 1 2 3\n$EndElements\n");
  Mesh m = read(path);
  EXPECT_EQ(m.num_tets(), 0);
  EXPECT_EQ(m.num_tris(), 1);
  EXPECT_TRUE(m.tet_labels.empty());
}

// ------------------------------------------------------------------ bad input

const std::string kHead22 = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
const std::string kNodes22 = "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n";  // lines 4..9

void expect_error(const std::string& msg, const std::string& where, const std::string& why) {
  EXPECT_NE(msg.find(where), std::string::npos) << "position '" << where << "' not in: " << msg;
  EXPECT_NE(msg.find(why), std::string::npos) << "reason '" << why << "' not in: " << msg;
  EXPECT_EQ(msg.find('\n'), std::string::npos) << "not one line: " << msg;
}

TEST(GmshErrors, TextFiles) {
  expect_error(read_error(""), "bad.msh", "empty file");
  expect_error(read_error("\n  \n"), "bad.msh", "empty file");
  expect_error(read_error("$MeshFormat\n3.0 0 8\n$EndMeshFormat\n"), "bad.msh:2:", "unsupported Gmsh MSH version 3.0");
  expect_error(read_error("$MeshFormat\n4 0 8\n$EndMeshFormat\n"), "bad.msh:2:", "version 4 ");
  expect_error(read_error("$NOD\n1\n1 0 0 0\n$ENDNOD\n"), "bad.msh:1:", "version 1");
  expect_error(read_error("solid foo\n"), "bad.msh:1:", "not a Gmsh file");
  expect_error(read_error("$MeshFormat\n2.2 7 8\n$EndMeshFormat\n"), "bad.msh:2:", "file-type");
  expect_error(read_error(kHead22), "bad.msh", "no $Nodes");
  // Missing $EndNodes: the next section header is found instead.
  expect_error(read_error(kHead22 + "$Nodes\n1\n1 0 0 0\n$Elements\n0\n$EndElements\n"), "bad.msh:7:", "expected $EndNodes");
  // Truncated in the middle of the nodes.
  expect_error(read_error(kHead22 + "$Nodes\n2\n1 0 0 0\n2 1"), "bad.msh:7:", "unexpected end of file");
  // Count larger than the file can hold (nothing allocated from it).
  expect_error(read_error(kHead22 + "$Nodes\n99999999999\n1 0 0 0\n$EndNodes\n"), "bad.msh:5:", "more than the rest of the file");
  expect_error(read_error(kHead22 + "$Nodes\n-3\n$EndNodes\n"), "bad.msh:5:", "node count -3");
  // Wrong count: fewer nodes than announced runs into $EndNodes.
  expect_error(read_error(kHead22 + "$Nodes\n3\n1 0 0 0\n2 1 0 0\n$EndNodes\n"), "bad.msh:8:", "expected an integer");
  // Non-finite coordinates.
  expect_error(read_error(kHead22 + "$Nodes\n2\n1 0 0 0\n2 nan 0 0\n$EndNodes\n"), "bad.msh:7:", "non-finite coordinate");
  expect_error(read_error(kHead22 + "$Nodes\n2\n1 0 0 0\n2 0 inf 0\n$EndNodes\n"), "bad.msh:7:", "non-finite coordinate");
  expect_error(read_error(kHead22 + "$Nodes\n2\n1 0 0 0\n1 0 1 0\n$EndNodes\n"), "bad.msh:7:", "node tag 1 appears twice");
  // Element node references: zero, negative, unknown.
  const std::string el = kHead22 + kNodes22 + "$Elements\n1\n";  // element on line 13
  expect_error(read_error(el + "1 4 2 0 1 1 2 3 0\n$EndElements\n"), "bad.msh:13:", "node tag 0, which is not in $Nodes");
  expect_error(read_error(el + "1 4 2 0 1 1 2 -3 4\n$EndElements\n"), "bad.msh:13:", "node tag -3");
  expect_error(read_error(el + "1 4 2 0 1 1 2 3 5\n$EndElements\n"), "bad.msh:13:", "node tag 5");
  expect_error(read_error(el + "1 4 2 0 1 1 2 3 99999999999999999999\n$EndElements\n"), "bad.msh:13:", "out of range");
  expect_error(read_error(el + "1 4 2 0 1 1 2 3 4\n"), "bad.msh", "expected $EndElements");
  expect_error(read_error(kHead22 + "$Elements\n0\n$EndElements\n" + kNodes22), "bad.msh:4:", "$Elements comes before $Nodes");
  expect_error(read_error(kHead22 + kNodes22 + "$Foo\n1 2 3\n"), "bad.msh:11:", "section $Foo has no $EndFoo");
  expect_error(read_error(kHead22 + kNodes22 + "garbage\n"), "bad.msh:11:", "expected a section name");
  expect_error(read_error(kHead22 + kNodes22 + "$NodeData\n1\n\"t\"\n0\n3\n0\n1\n2\n1 5\n7 5\n$EndNodeData\n"), "bad.msh:20:",
               "node tag 7");
  expect_error(read_error(kHead22 + kNodes22 + "$NodeData\n1\n\"t\"\n0\n3\n0\n1\n999999\n1 5\n$EndNodeData\n"), "bad.msh:18:",
               "value count 999999");

  // 4.1 text.
  const std::string h41 = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  const std::string n41 = "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n";  // lines 4..15
  expect_error(read_error(h41 + n41 + "$Elements\n1 1 1 1\n3 1 77 1\n1 1 2 3 4\n$EndElements\n"), "bad.msh:18:",
               "unknown element type 77");
  expect_error(read_error(h41 + n41 + "$Elements\n1 2 1 2\n3 1 4 1\n1 1 2 3 4\n$EndElements\n"), "bad.msh:19:",
               "announces 2 elements but its blocks hold 1");
  expect_error(read_error(h41 + "$Nodes\n1 5 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n"), "bad.msh:14:",
               "announces 5 nodes");
  expect_error(read_error(h41 + "$Nodes\n1 4 1 4\n3 1 0 9\n" + std::string(200, '\n')), "bad.msh:6:", "more than the 4 nodes announced");
  expect_error(read_error(h41 + "$Entities\n0 0 0 99999999\n$EndEntities\n"), "bad.msh:5:", "entity count 99999999");
}

TEST(GmshErrors, BinaryFiles) {
  const std::string good = make_41_binary(false);
  // Offsets inside the hand-made file.
  const size_t marker = good.find("4.1 1 8\n") + 8;
  const size_t nodes = good.find("$Nodes\n") + 7;  // the 4 size_t of the header
  const size_t elements = good.find("$Elements\n") + 10;
  const size_t first_tet_node = elements + 32 + 20 + 8;  // header, block header, element tag

  auto at = [](size_t off) { return "byte " + std::to_string(off) + ":"; };
  // Endianness marker neither 1 nor byte-swapped 1.
  {
    std::string s = good;
    s[marker] = 2;
    expect_error(read_error(s), at(marker), "endianness marker is 2");
  }
  // Truncation anywhere gives a byte-positioned error (or, cut between sections, a missing $End).
  for (size_t cut : {nodes + 3, nodes + 40, elements + 50, good.size() - 30}) {
    std::string msg = read_error(good.substr(0, cut));
    EXPECT_FALSE(msg.empty()) << "cut at " << cut;
    EXPECT_TRUE(msg.find("byte ") != std::string::npos) << msg;
  }
  const size_t entities = good.find("$Entities\n") + 10;
  expect_error(read_error(good.substr(0, entities + 10)), at(entities + 8), "unexpected end of file");
  // A huge node count in the header: refused before anything is allocated.
  {
    std::string s = good;
    uint64_t big = uint64_t(1) << 40;
    std::memcpy(&s[nodes + 8], &big, 8);
    expect_error(read_error(s), at(nodes + 8), "node count 1099511627776 is more than the rest of the file");
  }
  // A node tag of a tet that is not a node (offset of that value).
  {
    std::string s = good;
    uint64_t bad = 11;
    std::memcpy(&s[first_tet_node + 8], &bad, 8);
    expect_error(read_error(s), at(first_tet_node + 8), "node tag 11, which is not in $Nodes");
  }
  // NaN coordinate: offset of the node's first coordinate value read.
  {
    std::string s = good;
    const size_t coords = nodes + 32 + 20 + 5 * 8;
    double nan = std::nan("");
    std::memcpy(&s[coords + 24 + 8], &nan, 8);  // y of the second node
    expect_error(read_error(s), at(coords + 24 + 16), "node 20 has a non-finite coordinate");
  }
  // Unsupported data-size.
  {
    std::string s = good;
    s.replace(s.find("4.1 1 8"), 7, "4.1 1 2");
    expect_error(read_error(s), "bad.msh:2:", "data-size 2");
  }
  // 2.2 binary: element block larger than the announced total.
  {
    std::string s = make_22_binary(false);
    size_t e = s.find("$Elements\n2\n") + 12;
    int32_t count = 5;
    std::memcpy(&s[e + 4], &count, 4);
    expect_error(read_error(s), at(e + 4), "element block of 5 elements");
  }
}

// Every prefix and many corrupted copies of valid files: an InputError or a mesh, never a
// crash (run under the sanitizers to make this meaningful) or another exception.
TEST(GmshErrors, TruncatedAndCorruptedFilesNeverCrash) {
  Mesh m = rich_mesh();
  TempDir dir;
  std::mt19937 rng(12345);
  for (const Variant& var : kVariants) {
    SCOPED_TRACE(var.name);
    tc::WriteOptions o;
    o.gmsh_version = var.version;
    o.binary = var.binary;
    std::string good_path = dir.file("good.msh");
    tc::write_gmsh(good_path, m, o);
    const std::string good = tc::test::read_text(good_path);
    std::string path = dir.file("mutant.msh");
    int errors = 0, reads = 0;
    auto attempt = [&](const std::string& text) {
      write_text(path, text);
      try {
        read(path);
        ++reads;
      } catch (const tc::InputError& e) {
        ++errors;
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
      }
    };
    for (size_t cut = 0; cut < good.size(); cut += 1 + good.size() / 400) attempt(good.substr(0, cut));
    for (int i = 0; i < 300; ++i) {
      std::string s = good;
      for (int k = 0; k < 3; ++k) s[rng() % s.size()] = static_cast<char>(rng() % 256);
      attempt(s);
    }
    EXPECT_GT(errors, 300);  // every proper prefix is an error
    (void)reads;
  }
}

// ------------------------------------------------------------------ meshio

std::string meshio_python() {
  std::string out;
  if (tc::test::run_command("/usr/bin/python3 -c 'import meshio'", &out) != 0) return "";
  return "/usr/bin/python3";
}

// meshio 5.0 reads all four variants of our output; it maps node tags as 1..n and reads
// 2.2 binary cells in blocks, which is what we write.
TEST(GmshMeshio, SeesTheSamePointsAndTets) {
  std::string py = meshio_python();
  if (py.empty()) GTEST_SKIP() << "/usr/bin/python3 cannot import meshio; cross-check skipped";
  Mesh m = rich_mesh();
  // meshio 5.0 spreads an $ElementData over all element blocks and fails when it covers
  // only the tets (Gmsh allows that), so the cross-check leaves out the tet field.
  m.tet_fields.clear();
  TempDir dir;
  for (const Variant& var : kVariants) {
    SCOPED_TRACE(var.name);
    tc::WriteOptions o;
    o.gmsh_version = var.version;
    o.binary = var.binary;
    std::string path = dir.file(std::string("mio_") + var.name + ".msh");
    tc::write_gmsh(path, m, o);
    std::string script =
        "import meshio, numpy as np\n"
        "m = meshio.read('" + path + "', file_format='gmsh')\n"
        "t = sum(len(c.data) for c in m.cells if c.type == 'tetra')\n"
        "f = sum(len(c.data) for c in m.cells if c.type == 'triangle')\n"
        "print(len(m.points), t, f, repr(float(m.points[5][1])), repr(float(m.point_data['pressure'][7])))\n";
    std::string cmd = py + " -c \"" + script + "\"";
    std::string out;
    int rc = tc::test::run_command(cmd, &out);
    ASSERT_EQ(rc, 0) << out;
    std::string expect = std::to_string(m.num_vertices()) + " " + std::to_string(m.num_tets()) + " " +
                         std::to_string(m.num_tris()) + " " + tc::io::format_double(m.points[16]) + " " +
                         tc::io::format_double(m.vertex_fields[0].values[7]);
    EXPECT_NE(out.find(expect), std::string::npos) << "meshio printed: " << out << "expected: " << expect;
  }
}

}  // namespace

namespace {

// The resident kB of the mapping holding `p` (/proc/self/smaps), -1 when not found.
long mapping_rss_kb(const void* p) {
  std::ifstream in("/proc/self/smaps");
  std::string line;
  bool inside = false;
  while (std::getline(in, line)) {
    unsigned long lo = 0, hi = 0;
    if (std::sscanf(line.c_str(), "%lx-%lx ", &lo, &hi) == 2) {  // a mapping's first line
      inside = lo <= reinterpret_cast<uintptr_t>(p) && reinterpret_cast<uintptr_t>(p) < hi;
      continue;
    }
    long kb = 0;
    if (inside && std::sscanf(line.c_str(), "Rss: %ld kB", &kb) == 1) return kb;
  }
  return -1;
}

// The mesh at `path` read with FileBytes' step set to one page.
tc::Mesh read_with_small_step(const std::string& path) {
  tc::io::FileBytes::set_step(4096);
  tc::Mesh m = tc::read_mesh(path);
  tc::io::FileBytes::set_step(size_t(16) << 20);
  return m;
}

// The readers give back the file's pages behind them (io::FileBytes): with a step of a few pages
// every gmsh variant reads the same mesh as with the default step, and bytes given back are read
// again from the file when looked at.
TEST(FileBytes, PagesGivenBackAreReadAgainAndTheMeshIsTheSame) {
  tc::test::TempDir dir;
  tc::Mesh m = tc::make_cube_mesh(14);  // 16k tets: a few hundred kB
  m.tet_labels.push_back({"gmsh:physical", std::vector<int32_t>(size_t(m.num_tets()), 3)});
  for (int version : {22, 41})
    for (bool binary : {true, false}) {
      tc::WriteOptions w;
      w.binary = binary;
      w.gmsh_version = version;
      const std::string path = dir.file("m" + std::to_string(version) + (binary ? "b" : "a") + ".msh");
      tc::write_mesh(path, m, w);
      const tc::Mesh whole = tc::read_mesh(path), stepped = read_with_small_step(path);
      EXPECT_EQ(stepped.points, whole.points) << path;
      EXPECT_EQ(stepped.tets, whole.tets) << path;
      EXPECT_EQ(stepped.tets, m.tets) << path;
      ASSERT_EQ(stepped.tet_labels.size(), whole.tet_labels.size()) << path;
      EXPECT_EQ(stepped.tet_labels[0].values, whole.tet_labels[0].values) << path;
    }
  // Medit, ASCII (with and without comments) and binary, and its solution files
  m.vertex_fields.push_back({"x", 1, {}});
  for (int64_t v = 0; v < m.num_vertices(); ++v) m.vertex_fields[0].values.push_back(m.points[size_t(3 * v)]);
  for (const char* name : {"m.mesh", "m.meshb", "m.node"}) {  // (.node: TetGen's .node, .ele, .face)
    const std::string path = dir.file(name);
    tc::write_mesh(path, m);
    const tc::Mesh whole = tc::read_mesh(path), stepped = read_with_small_step(path);
    EXPECT_EQ(stepped.points, whole.points) << path;
    EXPECT_EQ(stepped.tets, m.tets) << path;
    ASSERT_EQ(stepped.vertex_fields.size(), whole.vertex_fields.size()) << path;
    if (!whole.vertex_fields.empty()) {
      EXPECT_EQ(stepped.vertex_fields[0].values, whole.vertex_fields[0].values) << path;
    }
  }
  const std::string commented = dir.file("c.mesh");
  tc::test::write_text(commented, "# a comment\n" + tc::test::read_text(dir.file("m.mesh")));
  EXPECT_EQ(read_with_small_step(commented).tets, m.tets);
  // the bytes themselves
  const std::string path = dir.file("bytes.bin");
  std::string text(size_t(1) << 20, '\0');
  for (size_t i = 0; i < text.size(); ++i) text[i] = char(i * 2654435761u >> 24);
  tc::test::write_text(path, text);
  tc::io::FileBytes::set_step(4096);
  tc::io::FileBytes f(path);
  tc::io::FileBytes::set_step(size_t(16) << 20);
  ASSERT_EQ(f.view().size(), text.size());
  tc::io::BinaryCursor c(f.view(), path);
  c.release_through(&f);
  uint64_t sum = 0, expected = 0;
  while (c.remaining() >= 8) sum += c.get<uint64_t>();
  for (size_t i = 0; i + 8 <= text.size(); i += 8) {
    uint64_t v;
    std::memcpy(&v, text.data() + i, 8);
    expected += v;
  }
  EXPECT_EQ(sum, expected);
  const long rss = mapping_rss_kb(f.view().data());
  EXPECT_GE(rss, 0) << "no mapping found";
  EXPECT_LE(rss, 64) << "kB of the 1 MB file still held after reading it through";
  EXPECT_TRUE(f.view() == std::string_view(text)) << "the pages given back read the same";
}

}  // namespace
