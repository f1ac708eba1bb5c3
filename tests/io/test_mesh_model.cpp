// The mesh model: orientation normalisation, structural validation, format dispatch, atomic
// writing.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <random>

#include "io/io_util.hpp"
#include "test_support.hpp"
#include "tetcollapse/io.hpp"

namespace {

using tc::test::cube_tets;
using tc::test::single_tet;

void flip(tc::Mesh& m, int64_t t) { std::swap(m.tets[4 * t + 2], m.tets[4 * t + 3]); }

TEST(Orientation, PositiveMeshIsUntouched) {
  tc::Mesh m = cube_tets(2);
  tc::Mesh before = m;
  auto r = tc::normalize_orientation(m, tc::OrientationPolicy::Refuse);
  EXPECT_EQ(r.positive, m.num_tets());
  EXPECT_EQ(r.negative, 0);
  EXPECT_FALSE(r.flipped_all);
  EXPECT_EQ(m.tets, before.tets);
}

TEST(Orientation, ConsistentlyNegativeMeshIsFlipped) {
  tc::Mesh m = cube_tets(2);
  for (int64_t t = 0; t < m.num_tets(); ++t) flip(m, t);
  auto r = tc::normalize_orientation(m, tc::OrientationPolicy::Refuse);
  EXPECT_TRUE(r.flipped_all);
  EXPECT_EQ(r.flipped, m.num_tets());
  auto again = tc::normalize_orientation(m, tc::OrientationPolicy::Refuse);
  EXPECT_EQ(again.positive, m.num_tets());
}

TEST(Orientation, MixedIsRefusedWithCountsOrFixed) {
  tc::Mesh m = cube_tets(2);
  flip(m, 3);
  flip(m, 7);
  try {
    tc::Mesh copy = m;
    tc::normalize_orientation(copy, tc::OrientationPolicy::Refuse);
    FAIL() << "mixed orientation accepted";
  } catch (const tc::InputError& e) {
    std::string w = e.what();
    EXPECT_NE(w.find("46 positive, 2 negative"), std::string::npos) << w;
    EXPECT_NE(w.find("--fix-orientation"), std::string::npos) << w;
  }
  auto r = tc::normalize_orientation(m, tc::OrientationPolicy::Fix);
  EXPECT_EQ(r.flipped, 2);
  EXPECT_EQ(tc::normalize_orientation(m, tc::OrientationPolicy::Refuse).negative, 0);
}

TEST(Orientation, SignIsExactForNearlyFlatTets) {
  // Points d on (or next to) the plane of a, b, c, with coordinates that do not subtract
  // exactly: the floating-point determinant is then noise, and only an exact sign is
  // consistent under permutations (odd: opposite sign, even: the same sign).
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int zero = 0;
  for (int i = 0; i < 2000; ++i) {
    double a[3], b[3], c[3], d[3];
    for (int k = 0; k < 3; ++k) {
      a[k] = u(rng) + 0.1;
      b[k] = u(rng) * 1e3;
      c[k] = u(rng) * 1e-3;
    }
    double s = u(rng), t = u(rng);
    for (int k = 0; k < 3; ++k) d[k] = a[k] + s * (b[k] - a[k]) + t * (c[k] - a[k]);
    if (i % 2) d[i % 3] = std::nextafter(d[i % 3], 10.0);
    auto sign_of = [&](std::array<int32_t, 4> order) {
      tc::Mesh m;
      m.points = {a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2], d[0], d[1], d[2]};
      m.tets.assign(order.begin(), order.end());
      auto r = tc::normalize_orientation(m, tc::OrientationPolicy::Refuse);
      return r.positive ? 1 : r.negative ? -1 : 0;
    };
    int s0 = sign_of({0, 1, 2, 3});
    EXPECT_EQ(sign_of({1, 0, 2, 3}), -s0) << i;
    EXPECT_EQ(sign_of({1, 2, 0, 3}), s0) << i;
    EXPECT_EQ(sign_of({3, 2, 1, 0}), s0) << i;
    EXPECT_EQ(sign_of({0, 1, 3, 2}), -s0) << i;
    zero += s0 == 0;
  }
  // Exactly flat: four points of the plane z = 0.
  tc::Mesh flat;
  flat.points = {0.1, 0.2, 0, 0.7, 0.3, 0, 0.3, 0.9, 0, 0.5, 0.5, 0};
  flat.tets = {0, 1, 2, 3};
  EXPECT_EQ(tc::normalize_orientation(flat, tc::OrientationPolicy::Refuse).degenerate, 1);
  (void)zero;
}

TEST(Structure, ValidationNamesTheProblem) {
  auto expect_error = [](const tc::Mesh& m, const std::string& part) {
    try {
      tc::validate_structure(m, "x.mesh");
      FAIL() << "accepted; expected: " << part;
    } catch (const tc::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).rfind("x.mesh: ", 0), 0u) << e.what();
    }
  };
  tc::Mesh m = single_tet();
  EXPECT_NO_THROW(tc::validate_structure(m, "x.mesh"));
  tc::Mesh nan = m;
  nan.points[4] = std::numeric_limits<double>::quiet_NaN();
  expect_error(nan, "vertex 2 has a non-finite coordinate");
  tc::Mesh inf = m;
  inf.points[0] = std::numeric_limits<double>::infinity();
  expect_error(inf, "vertex 1 has a non-finite coordinate");
  tc::Mesh out = m;
  out.tets[3] = 4;
  expect_error(out, "tet 1 refers to vertex 5, outside 1..4");
  tc::Mesh none;
  none.points = m.points;
  expect_error(none, "no tetrahedra");
  tc::Mesh lab = m;
  lab.tet_labels.push_back({"mat", {1, 2}});
  expect_error(lab, "label 'mat' has 2 values for 1 tets");
  tc::Mesh field = m;
  field.vertex_fields.push_back({"f", 3, std::vector<double>(4, 0.0)});
  expect_error(field, "vertex field 'f' has 4 values for 4 vertices");
}

TEST(Formats, ChosenByExtensionAndNamedInErrors) {
  EXPECT_EQ(tc::format_from_name("a/b.MSH"), tc::Format::Gmsh);
  EXPECT_EQ(tc::format_from_name("a.meshb"), tc::Format::Medit);
  EXPECT_EQ(tc::format_from_name("a.vtu"), tc::Format::Vtu);
  EXPECT_EQ(tc::format_from_name("a.ele"), tc::Format::TetGen);
  EXPECT_THROW(tc::format_from_name("a.stl"), tc::InputError);
  EXPECT_THROW(tc::format_from_name("noext"), tc::InputError);
  EXPECT_EQ(tc::parse_format("vtk"), tc::Format::Vtk);
  tc::test::TempDir dir;
  EXPECT_THROW(tc::write_mesh(dir.file("x.stl"), single_tet()), tc::OutputError);
}

TEST(Formats, NegativeInputIsFlippedWithANote) {
  tc::test::TempDir dir;
  std::string p = dir.file("neg.mesh");
  tc::test::write_text(p, "MeshVersionFormatted 2\nDimension 3\nVertices\n4\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\n"
                          "Tetrahedra\n1\n1 2 4 3 0\nEnd\n");
  tc::ReadNotes notes;
  tc::OrientationReport orient;
  tc::Mesh m = tc::read_mesh(p, {}, &notes, &orient);
  EXPECT_TRUE(orient.flipped_all);
  ASSERT_FALSE(notes.notes.empty());
  EXPECT_NE(notes.notes.back().find("negatively oriented; flipped"), std::string::npos);
  EXPECT_EQ(m.tets, (std::vector<int32_t>{0, 1, 2, 3}));
}

TEST(Formats, ReadMeshReportsAMeshWithoutTets) {
  tc::test::TempDir dir;
  std::string p = dir.file("empty.mesh");
  tc::test::write_text(p, "MeshVersionFormatted 2\nDimension 3\nVertices\n3\n0 0 0 0\n1 0 0 0\n0 1 0 0\n"
                          "Triangles\n1\n1 2 3 0\nEnd\n");
  try {
    tc::read_mesh(p);
    FAIL();
  } catch (const tc::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("empty.mesh: the mesh has no tetrahedra"), std::string::npos) << e.what();
  }
}

TEST(AtomicFile, UncommittedWriteLeavesNothingAndCommitReplaces) {
  tc::test::TempDir dir;
  std::string target = dir.file("out.txt");
  tc::test::write_text(target, "old");
  {
    tc::io::AtomicFile f(target);
    f.stream() << "half";
    // destroyed without commit: as if the writer failed half way
  }
  EXPECT_EQ(tc::test::read_text(target), "old");
  int files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir.path())) {
    (void)e;
    ++files;
  }
  EXPECT_EQ(files, 1);
  {
    tc::io::AtomicFile f(target);
    f.stream() << "new";
    f.commit();
  }
  EXPECT_EQ(tc::test::read_text(target), "new");
  EXPECT_THROW(tc::io::AtomicFile(dir.file("missing/x.txt")), tc::OutputError);
}

TEST(TestSupport, KuhnCubeIsPositivelyOriented) {
  tc::Mesh m = cube_tets(3);
  EXPECT_EQ(m.num_tets(), 6 * 27);
  auto r = tc::normalize_orientation(m, tc::OrientationPolicy::Refuse);
  EXPECT_EQ(r.positive, m.num_tets());
}

}  // namespace
