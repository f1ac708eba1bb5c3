// TetGen .node / .ele / .face reading and writing.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "geometry.h"
#include "tetcollapse/io.hpp"
#include "test_support.hpp"

using namespace tc;
using tc::test::same_bits;
using tc::test::TempDir;
using tc::test::write_text;

namespace {

Mesh read(const std::string& path, ReadNotes* notes_out = nullptr) {
  ReadNotes notes;
  Mesh m = read_tetgen(path, notes);
  if (notes_out) *notes_out = notes;
  return m;
}

std::string read_error(const std::string& path) {
  try {
    read(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

double orient(const Mesh& m, int64_t t) {
  const int32_t* v = &m.tets[size_t(4 * t)];
  auto p = [&](int i) { return geo::tc_point(m.points.data(), v[i]); };
  return geo::tc_orient3d(p(0), p(1), p(2), p(3));
}

bool have_tetgen() {
  std::string out;
  return tc::test::run_command("command -v tetgen", &out) == 0;
}

// A closed cube surface as OFF without comments (TetGen 1.5.0 aborts on OFF comments).
const char* kCubeOff =
    "OFF\n8 12 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
    "3 0 2 1\n3 0 3 2\n3 4 5 6\n3 4 6 7\n3 0 1 5\n3 0 5 4\n3 1 2 6\n3 1 6 5\n3 2 3 7\n3 2 7 6\n3 3 0 4\n3 3 4 7\n";

// Everything the writer carries: awkward coordinates, two label arrays, tagged
// triangles, vertex fields of 1 and 3 components, a non-integer tet field.
Mesh rich_mesh() {
  Mesh m = tc::test::cube_tets(3);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (double& x : m.points) x += 1e-3 * u(rng);
  m.points[0] = -0.0;
  m.points[1] = 1e-310;  // subnormal
  m.points[2] = 0.1 + 0.2;
  Labels region{"gmsh:physical", {}}, other{"part", {}};
  for (int64_t t = 0; t < m.num_tets(); ++t) {
    region.values.push_back(int32_t(t % 4) - 1);
    other.values.push_back(int32_t(t * 7));
  }
  m.tet_labels = {region, other};
  m.tris = {0, 1, 4, 1, 5, 4};
  m.tri_tags = {3, -8};
  Field s{"s", 1, {}}, v{"v", 3, {}}, tf{"tf", 1, {}};
  for (int64_t i = 0; i < m.num_vertices(); ++i) {
    s.values.push_back(u(rng));
    for (int c = 0; c < 3; ++c) v.values.push_back(u(rng) * 1e5);
  }
  for (int64_t t = 0; t < m.num_tets(); ++t) tf.values.push_back(0.5 + u(rng));
  m.vertex_fields = {s, v};
  m.tet_fields = {tf};
  return m;
}

}  // namespace

// ------------------------------------------------------------------ real TetGen output

TEST(TetGen, ReadsTetGenOutputAndItsOrientationIsPositive) {
  if (!have_tetgen()) GTEST_SKIP() << "the tetgen program is not installed";
  TempDir dir;
  write_text(dir.file("cube.off"), kCubeOff);
  std::string out;
  ASSERT_EQ(tc::test::run_command("cd " + dir.path().string() + " && tetgen -pq1.5a0.01AQ cube.off", &out), 0) << out;
  for (const char* name : {"cube.1.node", "cube.1.ele", "cube.1"}) {
    ReadNotes notes;
    Mesh m = read(dir.file(name), &notes);
    // Counts from the headers TetGen wrote.
    std::string ele = tc::test::read_text(dir.file("cube.1.ele"));
    std::string node = tc::test::read_text(dir.file("cube.1.node"));
    EXPECT_EQ(m.num_tets(), std::stoll(ele));
    EXPECT_EQ(m.num_vertices(), std::stoll(node));
    EXPECT_GT(m.num_tets(), 6);
    EXPECT_NO_THROW(validate_structure(m, name));
    // -A: one region attribute, integral -> label.
    const Labels* region = m.find_labels("tetgen:region");
    ASSERT_NE(region, nullptr);
    EXPECT_EQ(region->values.size(), size_t(m.num_tets()));
    // .face: 12 cube triangles refined, all on the boundary; markers read.
    EXPECT_GE(m.num_tris(), 12);
    EXPECT_EQ(m.tri_tags.size(), size_t(m.num_tris()));
    // TetGen writes every tet positively oriented in our convention.
    for (int64_t t = 0; t < m.num_tets(); ++t) ASSERT_GT(orient(m, t), 0) << "tet " << t;
  }
}

TEST(TetGen, TetGenReadsOurFilesWithoutReorderingTets) {
  if (!have_tetgen()) GTEST_SKIP() << "the tetgen program is not installed";
  Mesh m = tc::test::cube_tets(2);
  m.tet_labels = {{"r", std::vector<int32_t>(size_t(m.num_tets()), 5)}};
  TempDir dir;
  write_tetgen(dir.file("ours.node"), m, {});
  std::string out;
  // -r: reconstruct the given mesh and write it again as ours.1.*
  ASSERT_EQ(tc::test::run_command("cd " + dir.path().string() + " && tetgen -rQ ours", &out), 0) << out;
  Mesh back = read(dir.file("ours.1.ele"));
  EXPECT_EQ(back.points, m.points);
  EXPECT_EQ(back.tets, m.tets) << "TetGen reordered our tets: the orientation convention differs";
  ASSERT_NE(back.find_labels("tetgen:region"), nullptr);
  EXPECT_EQ(back.find_labels("tetgen:region")->values, m.tet_labels[0].values);
}

// ------------------------------------------------------------------ round trip

TEST(TetGen, RoundTripIsExact) {
  Mesh m = rich_mesh();
  TempDir dir;
  write_tetgen(dir.file("r.ele"), m, {});
  for (const char* f : {"r.node", "r.ele", "r.face"}) EXPECT_TRUE(std::filesystem::exists(dir.file(f))) << f;
  Mesh r = read(dir.file("r.node"));
  EXPECT_TRUE(same_bits(m.points, r.points));
  EXPECT_EQ(m.tets, r.tets);
  EXPECT_EQ(m.tris, r.tris);
  EXPECT_EQ(m.tri_tags, r.tri_tags);
  ASSERT_EQ(r.tet_labels.size(), 2u);
  EXPECT_EQ(r.tet_labels[0].name, "tetgen:region");
  EXPECT_EQ(r.tet_labels[0].values, m.tet_labels[0].values);
  EXPECT_EQ(r.tet_labels[1].name, "tetgen:attr1");
  EXPECT_EQ(r.tet_labels[1].values, m.tet_labels[1].values);
  ASSERT_EQ(r.tet_fields.size(), 1u);
  EXPECT_EQ(r.tet_fields[0].name, "tetgen:attr2");
  EXPECT_TRUE(same_bits(r.tet_fields[0].values, m.tet_fields[0].values));
  // Vertex fields come back as one scalar attribute per component.
  ASSERT_EQ(r.vertex_fields.size(), 4u);
  EXPECT_EQ(r.vertex_fields[0].name, "tetgen:attr0");
  EXPECT_TRUE(same_bits(r.vertex_fields[0].values, m.vertex_fields[0].values));
  for (int c = 0; c < 3; ++c) {
    std::vector<double> comp;
    for (int64_t i = 0; i < m.num_vertices(); ++i) comp.push_back(m.vertex_fields[1].values[size_t(3 * i + c)]);
    EXPECT_TRUE(same_bits(r.vertex_fields[size_t(1 + c)].values, comp)) << "component " << c;
  }
}

TEST(TetGen, WriterWithoutTrianglesRemovesAStaleFace) {
  TempDir dir;
  write_tetgen(dir.file("f.node"), rich_mesh(), {});
  ASSERT_TRUE(std::filesystem::exists(dir.file("f.face")));
  write_tetgen(dir.file("f.node"), tc::test::single_tet(), {});
  EXPECT_FALSE(std::filesystem::exists(dir.file("f.face")));
  Mesh r = read(dir.file("f.node"));
  EXPECT_EQ(r.num_tets(), 1);
  EXPECT_EQ(r.num_tris(), 0);
}

// ------------------------------------------------------------------ hand-written files

TEST(TetGen, ZeroBasedWithCommentsTet10AndRealAttributes) {
  TempDir dir;
  write_text(dir.file("h.node"),
             "# nodes\n"
             "10 3 0 1  # header\n"
             "0 0 0 0 0\n1 1 0 0 2\n2 0 1 0 0\n3 0 0 1 0\n"
             "4 0.5 0 0 0\n5 0.5 0.5 0 0\n6 0 0.5 0 0\n7 0 0 0.5 0\n8 0.5 0 0.5 0\n9 0 0.5 0.5 0\n");
  write_text(dir.file("h.ele"), "1 10 2\n0  0 1 2 3 4 5 6 7 8 9  -4 0.25 extra columns ignored\n# end\n");
  ReadNotes notes;
  Mesh m = read(dir.file("h.ele"), &notes);
  EXPECT_EQ(m.num_vertices(), 10);
  EXPECT_EQ(m.tets, (std::vector<int32_t>{0, 1, 2, 3}));
  EXPECT_EQ(notes.reduced_quadratic_tets, 1);
  ASSERT_EQ(m.tet_labels.size(), 1u);
  EXPECT_EQ(m.tet_labels[0].name, "tetgen:region");
  EXPECT_EQ(m.tet_labels[0].values, std::vector<int32_t>{-4});
  ASSERT_EQ(m.tet_fields.size(), 1u);
  EXPECT_EQ(m.tet_fields[0].name, "tetgen:attr1");
  EXPECT_EQ(m.tet_fields[0].values, std::vector<double>{0.25});
  EXPECT_TRUE(m.vertex_fields.empty());
  bool noted = false;
  for (auto& n : notes.notes) noted |= n.find("boundary marker") != std::string::npos;
  EXPECT_TRUE(noted);
}

TEST(TetGen, NoTetrahedraGivesAnEmptyMesh) {
  TempDir dir;
  write_text(dir.file("e.node"), "3 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n");
  write_text(dir.file("e.ele"), "0 4 0\n");
  Mesh m = read(dir.file("e.node"));
  EXPECT_EQ(m.num_vertices(), 3);
  EXPECT_EQ(m.num_tets(), 0);
}

// ------------------------------------------------------------------ bad input

namespace {

const char* kNode = "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n";

// Writes node and ele text and checks that reading names `bad_file`, `line` and `reason`.
void expect_error(const std::string& node, const std::string& ele, const char* bad_file, int line,
                  const std::string& reason, const std::string& face = "") {
  TempDir dir;
  write_text(dir.file("x.node"), node);
  write_text(dir.file("x.ele"), ele);
  if (!face.empty()) write_text(dir.file("x.face"), face);
  std::string msg = read_error(dir.file("x.node"));
  std::string where = dir.file(bad_file) + (line > 0 ? ":" + std::to_string(line) : std::string()) + ":";
  EXPECT_NE(msg.find(where), std::string::npos) << "expected " << where << " in: " << msg;
  EXPECT_NE(msg.find(reason), std::string::npos) << "message: " << msg;
}

}  // namespace

TEST(TetGenBad, ZeroIndexInOneBasedMesh) {
  expect_error(kNode, "1 4 0\n1 0 1 2 3\n", "x.ele", 2, "index 0 where the .node file numbers its nodes from 1");
}

TEST(TetGenBad, IndexOutOfRange) {
  expect_error(kNode, "2 4 0\n1 1 2 3 4\n2 1 2 3 5\n", "x.ele", 3,
               "node index 5 is out of range (the .node file has nodes 1 to 4)");
}

TEST(TetGenBad, FaceIndexOutOfRange) {
  expect_error(kNode, "1 4 0\n1 1 2 3 4\n", "x.face", 3, "node index 9 is out of range", "2 1\n1 1 2 3 0\n2 1 2 9 0\n");
}

TEST(TetGenBad, TruncatedNodeFile) {
  expect_error("4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0\n", "1 4 0\n1 1 2 3 4\n", "x.node", 5,
               "line ends early: expected node coordinate");
}

TEST(TetGenBad, TruncatedEleFile) {
  expect_error(kNode, "3 4 0\n1 1 2 3 4\n2 1 2 3 4\n", "x.ele", 4, "unexpected end of file (expected element 3 of 3)");
}

TEST(TetGenBad, CountLargerThanTheFile) {
  expect_error(kNode, "500000 4 0\n1 1 2 3 4\n", "x.ele", 1,
               "element count 500000 is more than the rest of the file can hold");
  expect_error("99999999999 3 0 0\n1 0 0 0\n", "", "x.node", 1, "node count 99999999999 is more than the rest");
}

TEST(TetGenBad, CountSmallerThanTheFile) {
  expect_error(kNode, "1 4 0\n1 1 2 3 4\n2 1 2 3 4\n", "x.ele", 3,
               "more data after the last element (the header says 1)");
}

TEST(TetGenBad, NodeOutOfSequence) {
  expect_error("3 3 0 0\n1 0 0 0\n2 1 0 0\n4 0 1 0\n", "0 4 0\n", "x.node", 4,
               "node index 4 out of sequence (expected 3)");
}

TEST(TetGenBad, FirstIndexNotZeroOrOne) {
  expect_error("1 3 0 0\n5 0 0 0\n", "0 4 0\n", "x.node", 2, "first node index 5 is not 0 or 1");
}

TEST(TetGenBad, NanCoordinate) {
  expect_error("2 3 0 0\n1 0 0 0\n2 nan 0 0\n", "0 4 0\n", "x.node", 3, "non-finite node coordinate");
}

TEST(TetGenBad, InfAttribute) {
  expect_error("1 3 1 0\n1 0 0 0 -inf\n", "0 4 0\n", "x.node", 2, "non-finite node attribute");
}

TEST(TetGenBad, TwoDimensional) {
  expect_error("1 2 0 0\n1 0 0\n", "0 4 0\n", "x.node", 1, "dimension 2: only 3D meshes are supported");
}

TEST(TetGenBad, FiveNodesPerTet) {
  expect_error(kNode, "1 5 0\n1 1 2 3 4 1\n", "x.ele", 1, "nodes per tetrahedron 5 is not 4 or 10");
}

TEST(TetGenBad, NegativeCount) {
  expect_error(kNode, "-1 4 0\n", "x.ele", 1, "negative element count: -1");
}

TEST(TetGenBad, NotANumber) {
  expect_error(kNode, "1 4 0\n1 1 2 three 4\n", "x.ele", 2, "expected an integer, found 'three'");
}

TEST(TetGenBad, EmptyNodeFile) {
  expect_error("", "1 4 0\n1 1 2 3 4\n", "x.node", 1, "unexpected end of file (expected the .node header)");
}

TEST(TetGenBad, EmptyEleFile) {
  expect_error(kNode, "", "x.ele", 1, "unexpected end of file (expected the .ele header)");
}

TEST(TetGenBad, MissingEleFile) {
  TempDir dir;
  write_text(dir.file("y.node"), kNode);
  std::string msg = read_error(dir.file("y.node"));
  EXPECT_NE(msg.find(dir.file("y.ele") + ": cannot open"), std::string::npos) << msg;
}
