// Inputs that are themselves bad, as the coarsening CLI meets them (README "Bad input meshes").
// Each case is built in code from the Kuhn cube grid, written as Medit text, and run through
// `tetcollapse IN OUT --check`; the test asserts the documented exit code and message, or a
// valid output. Invalid inputs are not repaired: the run writes the output and --check names
// the input's defect (exit 1, with a reference_invalid warning), so a user learns why.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>
#include <string>

#include "tetcollapse/io.hpp"
#include "tetcollapse/mesh.hpp"
#include "test_support.hpp"

namespace {

using tc::test::run_command;

std::string cli() { return std::string("'") + TC_CLI + "'"; }
std::string q(const std::string& s) { return "'" + s + "'"; }

void write_medit(const std::string& path, const tc::Mesh& m) {
  tc::WriteOptions opt;
  opt.binary = false;
  tc::write_mesh(path, m, opt);  // writes the tets as they are (no reorientation)
}

// The n^3 Kuhn cube grid, scaled by s and moved by (dx, dy, dz).
tc::Mesh cube_at(int n, double dx, double dy, double dz, double s = 1.0) {
  tc::Mesh m = tc::test::cube_tets(n);
  for (int64_t v = 0; v < m.num_vertices(); ++v) {
    m.points[3 * v] = m.points[3 * v] * s + dx;
    m.points[3 * v + 1] = m.points[3 * v + 1] * s + dy;
    m.points[3 * v + 2] = m.points[3 * v + 2] * s + dz;
  }
  return m;
}

// Appends b to a; with `merge`, vertices of b at exactly the position of a vertex of a are
// shared (so the two bodies are glued where they touch), otherwise every vertex is new.
tc::Mesh join(const tc::Mesh& a, const tc::Mesh& b, bool merge) {
  tc::Mesh m = a;
  std::map<std::array<double, 3>, int32_t> at;
  if (merge)
    for (int64_t v = 0; v < a.num_vertices(); ++v) at[a.point(v)] = int32_t(v);
  std::vector<int32_t> index(b.num_vertices());
  for (int64_t v = 0; v < b.num_vertices(); ++v) {
    auto it = at.find(b.point(v));
    if (merge && it != at.end()) {
      index[v] = it->second;
    } else {
      index[v] = int32_t(m.num_vertices());
      for (double c : b.point(v)) m.points.push_back(c);
    }
  }
  for (int32_t v : b.tets) m.tets.push_back(index[v]);
  return m;
}

void flip(tc::Mesh& m, int64_t t) { std::swap(m.tets[4 * t + 2], m.tets[4 * t + 3]); }

struct CliRun {
  int code = -1;
  std::string out;
};

CliRun coarsen(const std::string& in, const std::string& extra = "") {
  tc::test::TempDir dir;
  CliRun r;
  r.code = run_command(cli() + " " + q(in) + " " + q(dir.file("out.mesh")) + " --check " + extra, &r.out);
  return r;
}

// A number after "key": in the --json output of `check` (enough for these flat keys).
double json_number(const std::string& json, const std::string& key) {
  auto p = json.find("\"" + key + "\":");
  if (p == std::string::npos) return -1;
  return std::stod(json.substr(p + key.size() + 3));
}

#define EXPECT_HAS(text, part) EXPECT_NE((text).find(part), std::string::npos) << "no '" << (part) << "' in:\n" << (text)

TEST(BadMeshes, MixedOrientationIsRefusedUnlessFixOrientation) {
  tc::test::TempDir dir;
  tc::Mesh m = cube_at(3, 0, 0, 0);
  flip(m, 5);
  flip(m, 40);
  std::string in = dir.file("mixed.mesh");
  write_medit(in, m);

  CliRun r = coarsen(in);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_HAS(r.out, "mixed.mesh");
  EXPECT_HAS(r.out, "mixed tet orientation: 160 positive, 2 negative");
  EXPECT_HAS(r.out, "--fix-orientation");

  CliRun fixed = coarsen(in, "--fix-orientation");
  EXPECT_EQ(fixed.code, 0) << fixed.out;
  EXPECT_HAS(fixed.out, "flipped 2 negatively oriented tets");
  EXPECT_HAS(fixed.out, "check: valid");
}

TEST(BadMeshes, ConsistentlyNegativeMeshIsFlippedWithANote) {
  tc::test::TempDir dir;
  tc::Mesh m = cube_at(3, 0, 0, 0);
  for (int64_t t = 0; t < m.num_tets(); ++t) flip(m, t);
  std::string in = dir.file("negative.mesh");
  write_medit(in, m);
  CliRun r = coarsen(in);
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_HAS(r.out, "all 162 tets were negatively oriented; flipped");
  EXPECT_HAS(r.out, "check: valid");
}

// `check` reads what it can parse and reports the defects as findings (exit 1, the offender
// named); the coarsening command still refuses such an input (exit 2, file and line).
TEST(BadMeshes, CheckReportsWhatTheOtherCommandsRefuse) {
  tc::test::TempDir dir;
  const std::string head = "MeshVersionFormatted 2\nDimension 3\nVertices\n5\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\n";
  struct Case {
    const char* name;
    std::string text;
    const char* finding;
  };
  const Case cases[] = {
      {"mixed.mesh", head + "1 1 1 0\nTetrahedra\n2\n1 2 3 4 1\n2 4 3 5 1\nEnd\n", "inverted_tet"},
      {"nan.mesh", head + "nan 1 1 0\nTetrahedra\n2\n1 2 3 4 1\n2 4 3 5 1\nEnd\n", "non_finite_coordinate"},
      {"index.mesh", head + "1 1 1 0\nTetrahedra\n2\n1 2 3 4 1\n2 4 3 9 1\nEnd\n", "index_out_of_range"},
      {"nan.vtk",
       "# vtk DataFile Version 3.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 double\n0 0 0 1 0 0 0 1 0 nan 0 1\n"
       "CELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n",
       "non_finite_coordinate"},
  };
  for (const Case& c : cases) {
    const std::string in = dir.file(c.name);
    tc::test::write_text(in, c.text);
    std::string out;
    EXPECT_EQ(run_command(cli() + " check " + q(in), &out), 1) << c.name << ": " << out;
    EXPECT_HAS(out, c.finding);
    EXPECT_EQ(run_command(cli() + " " + q(in) + " " + q(dir.file("out.mesh")), &out), 2) << c.name << ": " << out;
  }
  const std::string junk = dir.file("junk.mesh");
  tc::test::write_text(junk, "MeshVersionFormatted 2\nDimension 3\nVertices\nthree\n");
  std::string out;
  EXPECT_EQ(run_command(cli() + " check " + q(junk), &out), 2) << "an unparsable file: " << out;
}

TEST(BadMeshes, NonManifoldEdgeInputIsCoarsenedAndReportedInvalid) {
  // Two cubes touching along one edge: the boundary has an edge in four triangles.
  tc::test::TempDir dir;
  std::string in = dir.file("edge.mesh");
  write_medit(in, join(cube_at(2, 0, 0, 0), cube_at(2, 1, 1, 0), /*merge=*/true));
  std::string out;
  EXPECT_EQ(run_command(cli() + " check " + q(in), &out), 1) << out;
  EXPECT_HAS(out, "boundary_nonmanifold_edge");

  CliRun r = coarsen(in);
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_HAS(r.out, "boundary_nonmanifold_edge");
  EXPECT_HAS(r.out, "reference_invalid");  // the defect was in the input
}

TEST(BadMeshes, NonManifoldVertexInputGivesAValidOutput) {
  // Two cubes touching at one corner: a pinched boundary vertex (a warning, not an error).
  tc::test::TempDir dir;
  std::string in = dir.file("vertex.mesh");
  write_medit(in, join(cube_at(3, 0, 0, 0), cube_at(3, 1, 1, 1), /*merge=*/true));
  CliRun r = coarsen(in);
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_HAS(r.out, "check: valid, boundary topology unchanged");
}

TEST(BadMeshes, DuplicateVerticesAreKeptAndReportedInvalid) {
  // Two cubes side by side whose common face is stored twice (a seam).
  tc::test::TempDir dir;
  std::string in = dir.file("seam.mesh");
  write_medit(in, join(cube_at(2, 0, 0, 0), cube_at(2, 1, 0, 0), /*merge=*/false));
  CliRun r = coarsen(in);
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_HAS(r.out, "duplicate_vertices: 9 pairs");
  EXPECT_HAS(r.out, "reference_invalid");
}

TEST(BadMeshes, ZeroVolumeTetIsKeptWithANoteAndReportedInvalid) {
  // Two square pyramids glued through a flat tet on their common square (conforming faces).
  tc::test::TempDir dir;
  tc::Mesh m;
  m.points = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, 0.5, 1, 0.5, 0.5, -1};
  m.tets = {0, 1, 2, 4, 0, 2, 3, 4, 0, 1, 3, 5, 1, 2, 3, 5, 0, 1, 2, 3};
  // Orient the four real tets positively (the flat one has no orientation).
  for (int64_t t = 0; t < 4; ++t) {
    auto p = [&](int i) { return m.point(m.tets[4 * t + i]); };
    auto a = p(0), b = p(1), c = p(2), d = p(3);
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]},
           w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
    double det = u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
    if (det < 0) flip(m, t);
  }
  std::string in = dir.file("flat.mesh");
  write_medit(in, m);
  CliRun r = coarsen(in);
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_HAS(r.out, "1 tets have exactly zero volume");
  EXPECT_HAS(r.out, "flat_tet: 1 tets with zero volume");
  EXPECT_HAS(r.out, "reference_invalid");
}

TEST(BadMeshes, TetRepeatingAVertexIsRefused) {
  tc::test::TempDir dir;
  tc::Mesh m = cube_at(2, 0, 0, 0);
  m.tets.insert(m.tets.end(), {0, 1, 1, 26});
  std::string in = dir.file("repeat.mesh");
  write_medit(in, m);
  CliRun r = coarsen(in);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_HAS(r.out, "tet 48 repeats vertex 1");
}

TEST(BadMeshes, DuplicateTetIsReportedInvalid) {
  tc::test::TempDir dir;
  tc::Mesh m = cube_at(2, 0, 0, 0);
  m.tets.insert(m.tets.end(), m.tets.begin(), m.tets.begin() + 4);
  std::string in = dir.file("twice.mesh");
  write_medit(in, m);
  CliRun r = coarsen(in);
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_HAS(r.out, "duplicate_tet: 1 pairs of tets on the same four vertices");
}

TEST(BadMeshes, SeveralComponentsAreCoarsenedSeparately) {
  tc::test::TempDir dir;
  std::string in = dir.file("two.mesh");
  std::string out_mesh = dir.file("out.mesh");
  write_medit(in, join(cube_at(3, 0, 0, 0), cube_at(3, 3, 0, 0, 2.0), /*merge=*/false));
  std::string out;
  ASSERT_EQ(run_command(cli() + " " + q(in) + " " + q(out_mesh) + " --check -q", &out), 0) << out;
  ASSERT_EQ(run_command(cli() + " check " + q(out_mesh) + " --reference " + q(in) + " --json -", &out), 0) << out;
  EXPECT_HAS(out, "\"components\":2");
  double tets = json_number(out, "tets");
  EXPECT_GT(tets, 0);
  EXPECT_LT(tets, 2 * 162);  // something was collapsed
}

TEST(BadMeshes, UnreferencedVertexIsCarriedWithAWarning) {
  tc::test::TempDir dir;
  tc::Mesh m = cube_at(3, 0, 0, 0);
  for (double c : {5.0, 5.0, 5.0}) m.points.push_back(c);
  std::string in = dir.file("stray.mesh");
  write_medit(in, m);
  CliRun r = coarsen(in);
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_HAS(r.out, "check: valid");
}

}  // namespace
