// Medit .mesh / .meshb / .sol / .solb reading and writing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <sstream>

#include "io/io_util.hpp"
#include "tetcollapse/io.hpp"
#include "test_support.hpp"

using namespace tc;
using tc::test::same_bits;
using tc::test::TempDir;
using tc::test::write_text;

namespace {

Mesh read(const std::string& path, ReadNotes* notes_out = nullptr, bool sol = true) {
  ReadNotes notes;
  Mesh m = read_medit(path, notes, sol);
  if (notes_out) *notes_out = notes;
  return m;
}

// The message of the InputError that reading `path` throws ("" when none is thrown).
std::string read_error(const std::string& path) {
  try {
    read(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// A mesh with every attribute the writers carry: awkward coordinates (full precision,
// tiny, huge, negative zero), labels, tagged triangles and edges, fields of 1, 3, 6 and 2
// components (the last is written as 2 scalar solutions) and a tet field.
Mesh rich_mesh() {
  Mesh m = tc::test::cube_tets(3);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (double& x : m.points) x = x + 1e-3 * u(rng);
  m.points[0] = -0.0;
  m.points[1] = 1e-300;
  m.points[2] = 0.1 + 0.2;
  m.points[3] = 1.0 + 1e-6 * M_PI;
  m.points[4] = 123456789.123456789;
  Labels l{"medit:ref", {}};
  for (int64_t t = 0; t < m.num_tets(); ++t) l.values.push_back(int32_t(t % 3 + 1 - (t == 5 ? 10 : 0)));
  m.tet_labels.push_back(l);
  m.tris = {0, 1, 4, 1, 5, 4};
  m.tri_tags = {7, -2};
  m.edges = {0, 1, 1, 2, 2, 3};
  m.edge_tags = {1, 2, 3};
  const int64_t nv = m.num_vertices(), nt = m.num_tets();
  for (int comps : {1, 3, 6, 2}) {
    Field f{std::string("f").append(std::to_string(comps)), comps, {}};
    for (int64_t i = 0; i < nv * comps; ++i) f.values.push_back(u(rng) * std::pow(10.0, double(i % 7) - 3));
    m.vertex_fields.push_back(f);
  }
  Field tf{"tf", 1, {}};
  for (int64_t i = 0; i < nt; ++i) tf.values.push_back(u(rng));
  m.tet_fields.push_back(tf);
  return m;
}

// Fields as written: 1/3/6/9 components kept, others split into scalar components.
std::vector<Field> as_solutions(const std::vector<Field>& fields, int64_t n) {
  std::vector<Field> out;
  for (const Field& f : fields) {
    if (f.components == 1 || f.components == 3 || f.components == 6 || f.components == 9) {
      out.push_back(f);
      continue;
    }
    for (int c = 0; c < f.components; ++c) {
      Field s{f.name, 1, {}};
      for (int64_t i = 0; i < n; ++i) s.values.push_back(f.values[size_t(i * f.components + c)]);
      out.push_back(s);
    }
  }
  return out;
}

void expect_same_fields(const std::vector<Field>& expected, const std::vector<Field>& got) {
  ASSERT_EQ(expected.size(), got.size());
  for (size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].name, "sol" + std::to_string(i)) << "names are sol0, sol1, ...";
    EXPECT_EQ(expected[i].components, got[i].components) << "field " << i;
    EXPECT_TRUE(same_bits(expected[i].values, got[i].values)) << "field " << i;
  }
}

void expect_round_trip(const Mesh& m, const Mesh& r) {
  EXPECT_TRUE(same_bits(m.points, r.points)) << "points differ";
  EXPECT_EQ(m.tets, r.tets);
  ASSERT_EQ(r.tet_labels.size(), 1u);
  EXPECT_EQ(r.tet_labels[0].name, "medit:ref");
  EXPECT_EQ(r.tet_labels[0].values, m.tet_labels[0].values);
  EXPECT_EQ(m.tris, r.tris);
  EXPECT_EQ(m.tri_tags, r.tri_tags);
  EXPECT_EQ(m.edges, r.edges);
  EXPECT_EQ(m.edge_tags, r.edge_tags);
}

struct SharedCase {
  const char* name;
  int64_t vertices, tets, tris, edges;
};
const SharedCase kShared[] = {
    {"libigl_octopus-low.mesh", 452, 1140, 898, 0},
    {"libigl_hand.mesh", 7234, 29998, 9556, 0},
    {"mmg_torus.mesh", 4351, 20067, 2954, 94},
    {"mmg_tinyBoxt.mesh", 11866, 63434, 5056, 233},
};

}  // namespace

// ------------------------------------------------------------------ shared meshes

TEST(Medit, SharedMeshesHaveTheCountsOfSources) {
  TC_SKIP_IF_NO_SHARED();
  for (const SharedCase& c : kShared) {
    std::string p = tc::test::shared_mesh(c.name);
    if (p.empty()) GTEST_SKIP() << c.name << " is missing from ../shared/meshes";
    Mesh m = read(p);
    EXPECT_EQ(m.num_vertices(), c.vertices) << c.name;
    EXPECT_EQ(m.num_tets(), c.tets) << c.name;
    EXPECT_EQ(m.num_tris(), c.tris) << c.name;
    EXPECT_EQ(int64_t(m.edges.size() / 2), c.edges) << c.name;
    EXPECT_EQ(m.tri_tags.size(), size_t(c.tris));
    ASSERT_NE(m.find_labels("medit:ref"), nullptr) << c.name;
    EXPECT_NO_THROW(validate_structure(m, p));
  }
}

TEST(Medit, TinyBoxtHasTwoSubdomains) {
  TC_SKIP_IF_NO_SHARED();
  std::string p = tc::test::shared_mesh("mmg_tinyBoxt.mesh");
  if (p.empty()) GTEST_SKIP() << "mmg_tinyBoxt.mesh missing";
  ReadNotes notes;
  Mesh m = read(p, &notes);
  const Labels* l = m.find_labels("medit:ref");
  ASSERT_NE(l, nullptr);
  int64_t n2 = std::count(l->values.begin(), l->values.end(), 2);
  int64_t n3 = std::count(l->values.begin(), l->values.end(), 3);
  EXPECT_EQ(n2, 62116);
  EXPECT_EQ(n3, 1318);
  EXPECT_EQ(n2 + n3, m.num_tets());
  // The feature keywords are read and noted, not silently dropped.
  std::string all;
  for (auto& n : notes.notes) all += n + "\n";
  for (const char* kw : {"Corners", "RequiredVertices", "Ridges", "Normals", "Tangents"})
    EXPECT_NE(all.find(kw), std::string::npos) << kw << " not noted in:\n" << all;
  EXPECT_EQ(notes.skipped_elements, 0);
  // The .sol beside it: one vector field.
  ASSERT_EQ(m.vertex_fields.size(), 1u);
  EXPECT_EQ(m.vertex_fields[0].name, "sol0");
  EXPECT_EQ(m.vertex_fields[0].components, 3);
  EXPECT_EQ(m.vertex_fields[0].values.size(), size_t(3 * m.num_vertices()));
  double vmax = 0;
  for (double v : m.vertex_fields[0].values) vmax = std::max(vmax, std::abs(v));
  EXPECT_NEAR(vmax, 0.3, 1e-6);  // SOURCES.md: max 0.3
}

TEST(Medit, TorusSolHasTensorAndVector) {
  TC_SKIP_IF_NO_SHARED();
  std::string p = tc::test::shared_mesh("mmg_torus.mesh");
  if (p.empty()) GTEST_SKIP() << "mmg_torus.mesh missing";
  Mesh m = read(p);
  ASSERT_EQ(m.vertex_fields.size(), 2u);
  EXPECT_EQ(m.vertex_fields[0].components, 6);
  EXPECT_EQ(m.vertex_fields[1].components, 3);
  EXPECT_EQ(m.vertex_fields[0].name, "sol0");
  EXPECT_EQ(m.vertex_fields[1].name, "sol1");
  // First line of torus.sol: "32.5918  0 25 0 0 25 32.5918 1.5 1.3"
  EXPECT_EQ(m.vertex_fields[0].values[0], 32.5918);
  EXPECT_EQ(m.vertex_fields[0].values[2], 25.0);
  EXPECT_EQ(m.vertex_fields[1].values[0], 32.5918);
  EXPECT_EQ(m.vertex_fields[1].values[2], 1.3);
  Mesh no_sol = read(p, nullptr, false);
  EXPECT_TRUE(no_sol.vertex_fields.empty());
}

TEST(Medit, SharedTorusRoundTripsThroughMeshAndMeshb) {
  TC_SKIP_IF_NO_SHARED();
  std::string p = tc::test::shared_mesh("mmg_torus.mesh");
  if (p.empty()) GTEST_SKIP() << "mmg_torus.mesh missing";
  Mesh m = read(p);
  TempDir dir;
  for (const char* name : {"t.mesh", "t.meshb"}) {
    write_medit(dir.file(name), m, {});
    Mesh r = read(dir.file(name));
    expect_round_trip(m, r);
    expect_same_fields(m.vertex_fields, r.vertex_fields);
  }
}

// ------------------------------------------------------------------ round trips

TEST(Medit, AsciiRoundTripIsExact) {
  Mesh m = rich_mesh();
  TempDir dir;
  write_medit(dir.file("a.mesh"), m, {});
  EXPECT_TRUE(std::filesystem::exists(dir.file("a.sol")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("a.meshb")));
  Mesh r = read(dir.file("a.mesh"));
  expect_round_trip(m, r);
  expect_same_fields(as_solutions(m.vertex_fields, m.num_vertices()), r.vertex_fields);
  ASSERT_EQ(r.tet_fields.size(), 1u);
  EXPECT_EQ(r.tet_fields[0].name, "sol5");  // numbered after the 5 vertex solutions
  EXPECT_TRUE(same_bits(m.tet_fields[0].values, r.tet_fields[0].values));
}

TEST(Medit, BinaryRoundTripIsExact) {
  Mesh m = rich_mesh();
  TempDir dir;
  WriteOptions o;
  write_medit(dir.file("b.meshb"), m, o);
  EXPECT_TRUE(std::filesystem::exists(dir.file("b.solb")));
  std::string bytes = tc::test::read_text(dir.file("b.meshb"));
  int32_t head[2];
  std::memcpy(head, bytes.data(), 8);
  EXPECT_EQ(head[0], 1);
  EXPECT_EQ(head[1], 2);  // version 2: doubles, 32-bit integers and positions
  Mesh r = read(dir.file("b.meshb"));
  expect_round_trip(m, r);
  expect_same_fields(as_solutions(m.vertex_fields, m.num_vertices()), r.vertex_fields);
  ASSERT_EQ(r.tet_fields.size(), 1u);
  EXPECT_TRUE(same_bits(m.tet_fields[0].values, r.tet_fields[0].values));
}

TEST(Medit, WriterWithoutFieldsRemovesAStaleSol) {
  Mesh m = rich_mesh();
  TempDir dir;
  write_medit(dir.file("s.mesh"), m, {});
  ASSERT_TRUE(std::filesystem::exists(dir.file("s.sol")));
  Mesh bare = tc::test::single_tet();
  write_medit(dir.file("s.mesh"), bare, {});
  EXPECT_FALSE(std::filesystem::exists(dir.file("s.sol")));
  Mesh r = read(dir.file("s.mesh"));  // would fail on the stale .sol's vertex count
  EXPECT_EQ(r.num_tets(), 1);
  EXPECT_EQ(r.tet_labels[0].values, std::vector<int32_t>{0});  // no labels: ref 0
}

TEST(Medit, WriterRefusesAFieldOfTheWrongSize) {
  Mesh m = tc::test::single_tet();
  m.vertex_fields.push_back({"bad", 1, {1.0, 2.0}});
  TempDir dir;
  EXPECT_THROW(write_medit(dir.file("w.mesh"), m, {}), OutputError);
  EXPECT_FALSE(std::filesystem::exists(dir.file("w.mesh")));
}

// ------------------------------------------------------------------ hand-made binary files

namespace {

// A minimal libMeshb writer for the tests, independent of the one under test: the
// single tet, in any version 1-4 and either byte order.
std::string handmade_meshb(int version, bool swap) {
  std::string out;
  auto put = [&](const void* p, size_t n) {
    std::string b(static_cast<const char*>(p), n);
    if (swap) std::reverse(b.begin(), b.end());
    out += b;
  };
  auto i32 = [&](int32_t v) { put(&v, 4); };
  auto i64 = [&](int64_t v) { put(&v, 8); };
  auto integer = [&](int64_t v) { version == 4 ? i64(v) : i32(int32_t(v)); };
  auto real = [&](double v) {
    if (version == 1) {
      float f = float(v);
      put(&f, 4);
    } else {
      put(&v, 8);
    }
  };
  std::vector<size_t> next_slots;
  auto keyword = [&](int32_t code) {
    // Patch the previous keyword's next position to here.
    if (!next_slots.empty()) {
      size_t at = next_slots.back();
      std::string saved = out;
      out.resize(at);
      version >= 3 ? i64(int64_t(saved.size())) : i32(int32_t(saved.size()));
      out += saved.substr(out.size());
    }
    i32(code);
    next_slots.push_back(out.size());
    version >= 3 ? i64(0) : i32(0);
  };
  auto count = [&](int64_t n) { version == 4 ? i64(n) : i32(int32_t(n)); };
  i32(1);
  i32(version);
  keyword(3);
  i32(3);
  keyword(4);
  count(4);
  const double pts[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (auto& p : pts) {
    for (double x : p) real(x);
    integer(0);
  }
  keyword(999);  // unknown keyword: skipped through its next position
  i32(12345);
  keyword(8);
  count(1);
  for (int v : {1, 2, 3, 4}) integer(v);
  integer(42);
  keyword(54);
  return out;
}

}  // namespace

TEST(Medit, ReadsEveryBinaryVersionInBothByteOrders) {
  TempDir dir;
  for (int version = 1; version <= 4; ++version)
    for (bool swap : {false, true}) {
      std::string p = dir.file("v" + std::to_string(version) + (swap ? "s" : "") + ".meshb");
      write_text(p, handmade_meshb(version, swap));
      ReadNotes notes;
      Mesh m;
      ASSERT_NO_THROW(m = read(p, &notes)) << p << ": " << read_error(p);
      EXPECT_EQ(m.points, tc::test::single_tet().points) << p;
      EXPECT_EQ(m.tets, (std::vector<int32_t>{0, 1, 2, 3})) << p;
      ASSERT_EQ(m.tet_labels.size(), 1u);
      EXPECT_EQ(m.tet_labels[0].values, std::vector<int32_t>{42});
      bool noted = false;
      for (auto& n : notes.notes) noted |= n.find("999") != std::string::npos;
      EXPECT_TRUE(noted) << "unknown keyword 999 not noted";
    }
}

// ------------------------------------------------------------------ ASCII details

TEST(Medit, CommentsCaseAndSkippedElements) {
  TempDir dir;
  std::string p = dir.file("c.mesh");
  write_text(p,
             "# a comment line\n"
             "meshversionformatted 1 # trailing comment\n"
             "DIMENSION\n3\n"
             "Vertices\n5\n"
             "0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 3\n1 1 1 0\n"
             "Corners 1 1\n"
             "Hexahedra\n1\n1 2 3 4 5 1 2 3 0\n"
             "Tetrahedra\n1\n1 2 3 4 9\n"
             "TetrahedraP2\n1\n2 3 4 5 1 1 1 1 1 1 8\n"
             "BoundingBox 0 0 0 1 1 1\n"
             "MyOwnKeyword 3\n1 2 3\n"
             "End\n");
  ReadNotes notes;
  Mesh m = read(p, &notes);
  EXPECT_EQ(m.num_vertices(), 5);
  EXPECT_EQ(m.tets, (std::vector<int32_t>{0, 1, 2, 3, 1, 2, 3, 4}));
  EXPECT_EQ(m.tet_labels[0].values, (std::vector<int32_t>{9, 8}));
  EXPECT_EQ(notes.skipped_elements, 1);
  EXPECT_EQ(notes.reduced_quadratic_tets, 1);
  std::string all;
  for (auto& n : notes.notes) all += n + "\n";
  EXPECT_NE(all.find("MyOwnKeyword"), std::string::npos) << all;
  EXPECT_NE(all.find("Corners"), std::string::npos) << all;
  EXPECT_NE(all.find("non-zero Medit reference"), std::string::npos) << all;
}

TEST(Medit, NoTetrahedraGivesAnEmptyMesh) {
  TempDir dir;
  std::string p = dir.file("n.mesh");
  write_text(p, "MeshVersionFormatted 1\nDimension 3\nVertices\n3\n0 0 0 0\n1 0 0 0\n0 1 0 0\nTriangles\n1\n1 2 3 5\nEnd\n");
  Mesh m = read(p);
  EXPECT_EQ(m.num_tets(), 0);
  EXPECT_EQ(m.num_tris(), 1);
}

// ------------------------------------------------------------------ bad input

namespace {

const char* kHead = "MeshVersionFormatted 1\nDimension 3\nVertices\n4\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\n";  // lines 1-8

// Writes `text` to a fresh .mesh and checks the error names the file, the line and the reason.
void expect_error(const std::string& text, int line, const std::string& reason) {
  TempDir dir;
  std::string p = dir.file("bad.mesh");
  write_text(p, text);
  std::string msg = read_error(p);
  EXPECT_NE(msg.find(p + ":" + std::to_string(line) + ":"), std::string::npos) << "message: " << msg;
  EXPECT_NE(msg.find(reason), std::string::npos) << "message: " << msg;
}

}  // namespace

TEST(MeditBad, ZeroBasedIndex) {
  expect_error(std::string(kHead) + "Tetrahedra\n1\n0 1 2 3 1\nEnd\n", 11,
               "index 0 where Medit indices are one-based");
}

TEST(MeditBad, IndexOutOfRange) {
  expect_error(std::string(kHead) + "Tetrahedra\n2\n1 2 3 4 1\n1 2 3 5 1\nEnd\n", 12,
               "vertex index 5 is out of range (the file has 4 vertices)");
}

TEST(MeditBad, NegativeIndex) {
  expect_error(std::string(kHead) + "Triangles\n1\n1 -2 3 1\nEnd\n", 11, "negative vertex index -2");
}

TEST(MeditBad, IndexOutOfRangeBeforeVertices) {
  expect_error("MeshVersionFormatted 1\nDimension 3\nTetrahedra\n1\n1 2 3 9 1\n"
               "Vertices\n4\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\nEnd\n",
               3, "Tetrahedra: vertex index 9 is out of range");
}

TEST(MeditBad, TruncatedFile) {
  expect_error(std::string(kHead) + "Tetrahedra\n2\n1 2 3 4 1\n1 2", 12, "unexpected end of file");
}

TEST(MeditBad, CountLargerThanTheFile) {
  expect_error(std::string(kHead) + "Tetrahedra\n1000000\n1 2 3 4 1\nEnd\n", 10,
               "Tetrahedra count 1000000 is more than the rest of the file can hold");
}

TEST(MeditBad, HugeVertexCount) {
  expect_error("MeshVersionFormatted 1\nDimension 3\nVertices\n99999999999999\n0 0 0 0\n", 4,
               "vertex count 99999999999999 is more than the rest of the file can hold");
}

TEST(MeditBad, NegativeCount) {
  expect_error(std::string(kHead) + "Triangles\n-3\n", 10, "negative Triangles count: -3");
}

TEST(MeditBad, NanCoordinate) {
  expect_error("MeshVersionFormatted 1\nDimension 3\nVertices\n2\n0 0 0 0\n1 nan 0 0\n", 6,
               "non-finite vertex coordinate");
}

TEST(MeditBad, InfCoordinate) {
  expect_error("MeshVersionFormatted 1\nDimension 3\nVertices\n2\n0 0 0 0\n1 0 inf 0\n", 6,
               "non-finite vertex coordinate");
}

TEST(MeditBad, NotANumber) {
  expect_error(std::string(kHead) + "Tetrahedra\n1\n1 2 x3 4 1\n", 11, "expected an integer, found 'x3'");
}

TEST(MeditBad, TwoDimensional) {
  expect_error("MeshVersionFormatted 1\n\nDimension 2\n", 3, "Dimension 2: only 3D meshes are supported");
}

TEST(MeditBad, NumberWhereAKeywordBelongs) {
  expect_error(std::string(kHead) + "17 Tetrahedra\n", 9, "expected a Medit keyword, found '17'");
}

TEST(MeditBad, NoVertices) {
  expect_error("MeshVersionFormatted 1\nDimension 3\nEnd\n", 3, "no Vertices section");
}

TEST(MeditBad, EmptyFile) {
  TempDir dir;
  std::string p = dir.file("empty.mesh");
  write_text(p, "");
  std::string msg = read_error(p);
  EXPECT_NE(msg.find(p + ": empty file"), std::string::npos) << msg;
}

TEST(MeditBad, MissingFile) {
  TempDir dir;
  std::string msg = read_error(dir.file("none.mesh"));
  EXPECT_NE(msg.find("none.mesh: cannot open"), std::string::npos) << msg;
}

TEST(MeditBad, SolVertexCountMismatchNamesTheSolFile) {
  TempDir dir;
  std::string p = dir.file("m.mesh"), s = dir.file("m.sol");
  write_text(p, std::string(kHead) + "Tetrahedra\n1\n1 2 3 4 1\nEnd\n");
  write_text(s, "MeshVersionFormatted 1\nDimension 3\nSolAtVertices\n3\n1 1\n1\n2\n3\nEnd\n");
  std::string msg = read_error(p);
  EXPECT_NE(msg.find(s + ":4:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("SolAtVertices has 3 entries but the mesh has 4 vertices"), std::string::npos) << msg;
}

TEST(MeditBad, SolUnknownTypeAndTruncation) {
  TempDir dir;
  std::string p = dir.file("m.mesh"), s = dir.file("m.sol");
  write_text(p, std::string(kHead) + "Tetrahedra\n1\n1 2 3 4 1\nEnd\n");
  write_text(s, "MeshVersionFormatted 1\nDimension 3\nSolAtVertices\n4\n1 7\n");
  std::string msg = read_error(p);
  EXPECT_NE(msg.find(s + ":5: unknown solution type 7"), std::string::npos) << msg;
  write_text(s, "MeshVersionFormatted 1\nDimension 3\nSolAtVertices\n4\n1 2\n1.5 2.5 3.5\n4.5 5.5 6.5\n7.5 8.5 9.5\n");
  msg = read_error(p);
  EXPECT_NE(msg.find(s + ":9: unexpected end of file"), std::string::npos) << msg;
  write_text(s, "MeshVersionFormatted 1\nDimension 3\nSolAtVertices\n4\n1 2\n1 2 3\n4 5 6\n");
  msg = read_error(p);
  EXPECT_NE(msg.find(s + ":5: solution count 4 is more than the rest of the file can hold"), std::string::npos) << msg;
}

namespace {

std::string binary_error(const std::string& bytes) {
  TempDir dir;
  std::string p = dir.file("bad.meshb");
  write_text(p, bytes);
  std::string msg = read_error(p);
  EXPECT_NE(msg.find(p + ": byte "), std::string::npos) << msg;
  return msg;
}

}  // namespace

TEST(MeditBadBinary, TruncatedAnywhere) {
  std::string good = handmade_meshb(2, false);
  for (size_t cut : {good.size() - 30, good.size() / 2, size_t(20)}) {
    std::string msg = binary_error(good.substr(0, cut));
    EXPECT_TRUE(msg.find("end of the file") != std::string::npos || msg.find("outside the file") != std::string::npos ||
                msg.find("unexpected end of file") != std::string::npos)
        << "cut at " << cut << ": " << msg;
  }
}

TEST(MeditBadBinary, BadVersion) {
  std::string b = handmade_meshb(2, false);
  int32_t v = 7;
  std::memcpy(&b[4], &v, 4);
  std::string msg = binary_error(b);
  EXPECT_NE(msg.find("byte 4: unsupported Medit binary version 7"), std::string::npos) << msg;
}

TEST(MeditBadBinary, HugeCount) {
  std::string b = handmade_meshb(2, false);
  // Vertices count sits after: code(4) version(4) | 3 next dim (12) | 4 next (8).
  int32_t n = 2000000000;
  std::memcpy(&b[28], &n, 4);
  std::string msg = binary_error(b);
  EXPECT_NE(msg.find("vertex count 2000000000 runs past the end of the file"), std::string::npos) << msg;
}

TEST(MeditBadBinary, BackwardNextPosition) {
  std::string b = handmade_meshb(2, false);
  int32_t back = 8;
  std::memcpy(&b[12], &back, 4);  // the Dimension keyword's next position points backwards
  std::string msg = binary_error(b);
  EXPECT_NE(msg.find("byte 8: keyword 3: next-keyword position 8"), std::string::npos) << msg;
}

TEST(MeditBadBinary, ZeroIndex) {
  std::string b = handmade_meshb(2, false);
  // The tet's first index: find the int32 sequence 1 2 3 4 42 from the end.
  size_t at = b.size() - 8 - 20;  // before the End keyword (code + 32-bit position)
  int32_t first;
  std::memcpy(&first, &b[at], 4);
  ASSERT_EQ(first, 1);
  int32_t zero = 0;
  std::memcpy(&b[at], &zero, 4);
  std::string msg = binary_error(b);
  EXPECT_NE(msg.find("byte " + std::to_string(at) + ": index 0 where Medit indices are one-based"), std::string::npos) << msg;
}

TEST(MeditBadBinary, NanCoordinate) {
  std::string b = handmade_meshb(2, false);
  double nan = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(&b[32 + 8], &nan, 8);  // the first vertex's y
  std::string msg = binary_error(b);
  EXPECT_NE(msg.find("byte 40: non-finite vertex coordinate"), std::string::npos) << msg;
}

// ------------------------------------------------------------------ meshio cross-read

namespace {

bool have_meshio() {
  std::string out;
  return tc::test::run_command("/usr/bin/python3 -c 'import meshio'", &out) == 0;
}

// meshio reads `path` as Medit; it must see our vertex and tet counts, the same tets
// (sum of zero-based indices) and the same coordinates (sum, to rounding).
void expect_meshio_reads(const std::string& path, const Mesh& m) {
  std::string out;
  int rc = tc::test::run_command(
      "/usr/bin/python3 -c \"import meshio; m=meshio.read('" + path +
          "', file_format='medit'); t=[c.data for c in m.cells if c.type=='tetra']; "
          "print(len(m.points), sum(len(x) for x in t), sum(int(x.sum()) for x in t), repr(float(m.points.sum())))\"",
      &out);
  ASSERT_EQ(rc, 0) << out;
  int64_t index_sum = 0;
  for (int32_t v : m.tets) index_sum += v;
  double coord_sum = 0;
  for (double x : m.points) coord_sum += x;
  std::istringstream in(out);
  int64_t nv = -1, nt = -1, isum = -1;
  double csum = 0;
  in >> nv >> nt >> isum >> csum;
  EXPECT_EQ(nv, m.num_vertices()) << out;
  EXPECT_EQ(nt, m.num_tets()) << out;
  EXPECT_EQ(isum, index_sum) << out;
  EXPECT_NEAR(csum, coord_sum, 1e-9 * std::abs(coord_sum)) << out;
}

}  // namespace

TEST(Medit, MeshioReadsOurAsciiMesh) {
  if (!have_meshio()) GTEST_SKIP() << "/usr/bin/python3 with meshio is not available";
  Mesh m = rich_mesh();
  m.points[4] = 1.25;  // keep the coordinate sum well conditioned
  TempDir dir;
  write_medit(dir.file("x.mesh"), m, {});
  expect_meshio_reads(dir.file("x.mesh"), m);
}

TEST(Medit, MeshioReadsOurBinaryMesh) {
  if (!have_meshio()) GTEST_SKIP() << "/usr/bin/python3 with meshio is not available";
  Mesh m = rich_mesh();
  m.points[4] = 1.25;
  TempDir dir;
  write_medit(dir.file("x.meshb"), m, {});
  expect_meshio_reads(dir.file("x.meshb"), m);
}
