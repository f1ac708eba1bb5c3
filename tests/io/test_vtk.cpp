// VTK legacy reader and writer: shared real files, every version and layout, exact round
// trips, meshio cross-reads and one test per kind of bad input.
#include <gtest/gtest.h>

#include <bit>
#include <cstring>

#include "test_support.hpp"
#include "tetcollapse/io.hpp"
#include "vtk_test_util.hpp"

namespace {

using tc::test::input_error_of;

tc::Mesh read_text_vtk(const tc::test::TempDir& dir, const std::string& text, tc::ReadNotes* notes_out = nullptr) {
  std::string p = dir.file("in.vtk");
  tc::test::write_text(p, text);
  tc::ReadNotes notes;
  tc::Mesh m = tc::read_vtk(p, notes);
  if (notes_out) *notes_out = notes;
  return m;
}

std::string error_of_text(const std::string& text) {
  tc::test::TempDir dir;
  std::string p = dir.file("bad.vtk");
  tc::test::write_text(p, text);
  return input_error_of([&] {
    tc::ReadNotes notes;
    tc::read_vtk(p, notes);
  });
}

const std::string kHead = "# vtk DataFile Version 4.2\ntest\nASCII\nDATASET UNSTRUCTURED_GRID\n";
const std::string kOneTet = "POINTS 4 double\n0 0 0\n1 0 0\n0 1 0\n0 0 1\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n";

// Big-endian bytes, as VTK legacy BINARY stores them.
template <class T>
std::string be(std::initializer_list<T> vals) {
  std::string s;
  for (T v : vals) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if constexpr (std::endian::native == std::endian::little) std::reverse(b, b + sizeof(T));
    s.append(b, sizeof(T));
  }
  return s;
}

// ------------------------------------------------------------ shared files

TEST(VtkShared, PostPressureBinary30) {
  TC_SKIP_IF_NO_SHARED();
  std::string p = tc::test::shared_mesh("vtkdata_post_pressure.vtk");
  if (p.empty()) GTEST_SKIP() << "vtkdata_post_pressure.vtk is not in the shared meshes";
  tc::ReadNotes notes;
  tc::Mesh m = tc::read_vtk(p, notes);
  EXPECT_EQ(m.num_vertices(), 2288);
  EXPECT_EQ(m.num_tets(), 8750);
  const tc::Field* f = m.find_vertex_field("Pressure");
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->components, 1);
  ASSERT_EQ(f->values.size(), 2288u);
  auto [lo, hi] = std::minmax_element(f->values.begin(), f->values.end());
  EXPECT_NEAR(*lo, 0.355, 1e-3);
  EXPECT_NEAR(*hi, 1.641, 1e-3);
}

TEST(VtkShared, MultiMaterialCylinderAscii42) {
  TC_SKIP_IF_NO_SHARED();
  std::string p = tc::test::shared_mesh("sfepy_multi_material_cylinder_plate.vtk");
  if (p.empty()) GTEST_SKIP() << "sfepy_multi_material_cylinder_plate.vtk is not in the shared meshes";
  tc::ReadNotes notes;
  tc::Mesh m = tc::read_vtk(p, notes);
  EXPECT_EQ(m.num_vertices(), 2101);
  EXPECT_EQ(m.num_tets(), 10440);
  const tc::Labels* mat = m.find_labels("mat_id");
  ASSERT_NE(mat, nullptr);
  EXPECT_EQ(tc::test::histogram(mat->values), (std::map<int32_t, int64_t>{{1, 4092}, {2, 84}, {3, 6138}, {4, 126}}));
  const tc::Field* g = m.find_vertex_field("node_groups");
  ASSERT_NE(g, nullptr);
  ASSERT_EQ(g->values.size(), 2101u);
  EXPECT_EQ(*std::min_element(g->values.begin(), g->values.end()), 1.0);
  EXPECT_EQ(*std::max_element(g->values.begin(), g->values.end()), 25.0);
}

TEST(VtkShared, PiezoAscii26) {
  TC_SKIP_IF_NO_SHARED();
  std::string p = tc::test::shared_mesh("sfepy_piezo_mesh_micro.vtk");
  if (p.empty()) GTEST_SKIP() << "sfepy_piezo_mesh_micro.vtk is not in the shared meshes";
  tc::ReadNotes notes;
  tc::Mesh m = tc::read_vtk(p, notes);
  EXPECT_EQ(m.num_vertices(), 8918);
  EXPECT_EQ(m.num_tets(), 42744);
  const tc::Labels* mat = m.find_labels("mat_id");
  ASSERT_NE(mat, nullptr);
  ASSERT_EQ(mat->values.size(), 42744u);
  std::vector<int64_t> counts;
  for (auto [label, n] : tc::test::histogram(mat->values)) counts.push_back(n);
  std::sort(counts.begin(), counts.end());
  EXPECT_EQ(counts, (std::vector<int64_t>{3284, 3284, 36176}));
}

// ------------------------------------------------------------ layouts and element types

TEST(VtkRead, Version20AsciiMinimal) {
  tc::test::TempDir dir;
  std::string text = kHead + kOneTet;
  text.replace(text.find("4.2"), 3, "2.0");
  tc::Mesh m = read_text_vtk(dir, text);
  EXPECT_EQ(m.num_vertices(), 4);
  EXPECT_EQ(m.tets, (std::vector<int32_t>{0, 1, 2, 3}));
}

TEST(VtkRead, Version51OffsetsConnectivityAscii) {
  tc::test::TempDir dir;
  std::string text =
      "# vtk DataFile Version 5.1\nv51\nASCII\nDATASET UNSTRUCTURED_GRID\n"
      "POINTS 5 float\n0 0 0 1 0 0 0 1 0 0 0 1 1 1 1\n"
      "METADATA\nINFORMATION 0\n\n"
      "CELLS 3 7\nOFFSETS vtktypeint64\n0 4 7\nCONNECTIVITY vtktypeint64\n0 1 2 3 1 2 4\n"
      "CELL_TYPES 2\n10\n5\n"
      "CELL_DATA 2\nSCALARS mat int 1\nLOOKUP_TABLE default\n7 8\n";
  tc::Mesh m = read_text_vtk(dir, text);
  EXPECT_EQ(m.tets, (std::vector<int32_t>{0, 1, 2, 3}));
  EXPECT_EQ(m.tris, (std::vector<int32_t>{1, 2, 4}));
  ASSERT_EQ(m.tet_labels.size(), 1u);
  EXPECT_EQ(m.tet_labels[0].values, (std::vector<int32_t>{7}));  // the triangle's 8 is not a tet value
}

TEST(VtkRead, Version51Binary) {
  tc::test::TempDir dir;
  std::string text = "# vtk DataFile Version 5.1\nb\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 double\n";
  text += be<double>({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1});
  text += "\nCELLS 2 4\nOFFSETS vtktypeint64\n" + be<int64_t>({0, 4});
  text += "\nCONNECTIVITY vtktypeint64\n" + be<int64_t>({0, 1, 3, 2});
  text += "\nCELL_TYPES 1\n" + be<int32_t>({10});
  text += "\nPOINT_DATA 4\nSCALARS s unsigned_char 2\nLOOKUP_TABLE default\n" + std::string("\x01\x02\x03\x04\x05\x06\x07\xff", 8);
  text += "\n";
  tc::Mesh m = read_text_vtk(dir, text);
  EXPECT_EQ(m.tets, (std::vector<int32_t>{0, 1, 3, 2}));
  ASSERT_EQ(m.vertex_fields.size(), 1u);
  EXPECT_EQ(m.vertex_fields[0].components, 2);
  EXPECT_EQ(m.vertex_fields[0].values, (std::vector<double>{1, 2, 3, 4, 5, 6, 7, 255}));
}

TEST(VtkRead, QuadraticTetsTrianglesLinesAndSkippedCells) {
  tc::test::TempDir dir;
  std::string text = kHead + "POINTS 10 double\n";
  for (int i = 0; i < 10; ++i) text += std::to_string(i % 2) + " " + std::to_string(i / 4) + " " + std::to_string(i) + "\n";
  text +=
      "CELLS 5 29\n10 0 1 2 3 4 5 6 7 8 9\n3 4 5 6\n2 7 8\n5 0 1 2 3 4\n4 0 1 2 3\n"
      "CELL_TYPES 5\n24 5 3 12 10\n"
      "CELL_DATA 5\nFIELD FieldData 2\nregion 1 5 long\n1 2 3 4 5\nheat 1 5 float\n0.5 1 2 3 4.25\n";
  // cell 3 says type 12 (hexahedron) with 5 points: skipped, not checked for its shape
  tc::ReadNotes notes;
  tc::Mesh m = read_text_vtk(dir, text, &notes);
  EXPECT_EQ(m.tets, (std::vector<int32_t>{0, 1, 2, 3, 0, 1, 2, 3}));
  EXPECT_EQ(m.tris, (std::vector<int32_t>{4, 5, 6}));
  EXPECT_EQ(m.tri_tags, (std::vector<int32_t>{0}));
  EXPECT_EQ(m.edges, (std::vector<int32_t>{7, 8}));
  EXPECT_EQ(notes.reduced_quadratic_tets, 1);
  EXPECT_EQ(notes.skipped_elements, 1);
  ASSERT_NE(m.find_labels("region"), nullptr);
  EXPECT_EQ(m.find_labels("region")->values, (std::vector<int32_t>{1, 5}));
  ASSERT_EQ(m.tet_fields.size(), 1u);
  EXPECT_EQ(m.tet_fields[0].values, (std::vector<double>{0.5, 4.25}));
}

TEST(VtkRead, PointDataScalarsVectorsAndIntegerFields) {
  tc::test::TempDir dir;
  std::string text = kHead + kOneTet +
                     "POINT_DATA 4\nSCALARS temp%20C float\n1.5 2.5 3.5 4.5\n"
                     "VECTORS v double\n1 2 3 4 5 6 7 8 9 10 11 12\n"
                     "FIELD FieldData 1\nids 1 4 int\n-1 0 1 2\nMETADATA\nINFORMATION 1\nNAME x LOCATION y\nDATA 1\n\n"
                     "SCALARS pair short 2\nLOOKUP_TABLE default\n1 2 3 4 5 6 7 8\n";
  tc::Mesh m = read_text_vtk(dir, text);
  ASSERT_EQ(m.vertex_fields.size(), 4u);
  EXPECT_EQ(m.vertex_fields[0].name, "temp C");
  EXPECT_EQ(m.vertex_fields[0].values, (std::vector<double>{1.5, 2.5, 3.5, 4.5}));
  EXPECT_EQ(m.vertex_fields[1].components, 3);
  EXPECT_EQ(m.vertex_fields[2].name, "ids");
  EXPECT_EQ(m.vertex_fields[2].values, (std::vector<double>{-1, 0, 1, 2}));
  EXPECT_EQ(m.vertex_fields[3].components, 2);
  EXPECT_EQ(m.vertex_fields[3].values.size(), 8u);
}

TEST(VtkRead, NoTetsGivesEmptyTets) {
  tc::test::TempDir dir;
  tc::ReadNotes notes;
  tc::Mesh m = read_text_vtk(dir, kHead + "POINTS 4 double\n0 0 0 1 0 0 0 1 0 0 0 1\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n9\n", &notes);
  EXPECT_EQ(m.num_tets(), 0);
  EXPECT_EQ(notes.skipped_elements, 1);
}

TEST(VtkRead, NoTetsIsReportedByReadMesh) {
  tc::test::TempDir dir;
  std::string p = dir.file("notets.vtk");
  tc::test::write_text(p, kHead + "POINTS 4 double\n0 0 0 1 0 0 0 1 0 0 0 1\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n9\n");
  std::string e = input_error_of([&] { tc::read_mesh(p); });
  EXPECT_NE(e.find("the mesh has no tetrahedra (1 non-tetrahedral elements were skipped)"), std::string::npos) << e;
}

// ------------------------------------------------------------ round trips

void round_trip(bool binary) {
  tc::test::TempDir dir;
  tc::Mesh a = tc::test::attribute_mesh();
  tc::WriteOptions opt;
  opt.binary = binary;
  std::string p = dir.file("rt.vtk");
  tc::write_vtk(p, a, opt);
  EXPECT_EQ(tc::test::read_text(p).substr(0, 26), "# vtk DataFile Version 4.2");
  tc::ReadNotes notes;
  tc::Mesh b = tc::read_vtk(p, notes);
  tc::test::expect_same_mesh(a, b);
  EXPECT_EQ(notes.skipped_elements, 0);
}

TEST(VtkRoundTrip, AsciiExact) { round_trip(false); }
TEST(VtkRoundTrip, BinaryExact) { round_trip(true); }

TEST(VtkRoundTrip, NamesWithSpacesSurvive) {
  tc::test::TempDir dir;
  tc::Mesh a = tc::test::single_tet();
  a.tet_labels.push_back({"my label", {42}});
  std::string p = dir.file("n.vtk");
  tc::write_vtk(p, a, tc::WriteOptions{});
  tc::ReadNotes notes;
  tc::Mesh b = tc::read_vtk(p, notes);
  ASSERT_EQ(b.tet_labels.size(), 1u);
  EXPECT_EQ(b.tet_labels[0].name, "my label");
  EXPECT_EQ(b.tet_labels[0].values, (std::vector<int32_t>{42}));
}

void meshio_check(bool binary) {
  tc::test::TempDir dir;
  tc::Mesh a = tc::test::attribute_mesh();
  tc::WriteOptions opt;
  opt.binary = binary;
  std::string p = dir.file("x.vtk");
  tc::write_vtk(p, a, opt);
  tc::test::meshio_cross_read(p, a.num_vertices(), a.num_tets(), "pressure");
}

TEST(VtkMeshio, ReadsOurAscii) { meshio_check(false); }
TEST(VtkMeshio, ReadsOurBinary) { meshio_check(true); }

// ------------------------------------------------------------ bad input

TEST(VtkBad, EveryTruncationIsAnInputError) {
  for (bool binary : {false, true}) {
    tc::test::TempDir dir;
    tc::Mesh a = tc::test::attribute_mesh();
    tc::WriteOptions opt;
    opt.binary = binary;
    tc::write_vtk(dir.file("full.vtk"), a, opt);
    std::string full = tc::test::read_text(dir.file("full.vtk"));
    int64_t failed = tc::test::check_truncations(full, dir.file("cut.vtk"), 7, [](const std::string& p) {
      tc::ReadNotes notes;
      tc::read_vtk(p, notes);
    });
    // A cut inside the last value of a block (before the next keyword) leaves a shorter but
    // well-formed file; there are 7 blocks, each with a value of at most 24 characters.
    EXPECT_GE(failed, int64_t(full.size() / 7) - 7 * 4) << (binary ? "binary" : "ascii");
  }
}

TEST(VtkBad, EmptyFile) { EXPECT_NE(error_of_text("").find("empty file"), std::string::npos); }

TEST(VtkBad, NotVtk) {
  std::string e = error_of_text("hello\nworld\n");
  EXPECT_NE(e.find(":1: not a VTK legacy file"), std::string::npos) << e;
}

TEST(VtkBad, UnknownVersion) {
  std::string e = error_of_text("# vtk DataFile Version 6.3\nx\nASCII\nDATASET UNSTRUCTURED_GRID\n");
  EXPECT_NE(e.find("unsupported VTK legacy version '6.3'"), std::string::npos) << e;
}

TEST(VtkBad, OtherDatasetType) {
  std::string e = error_of_text("# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\nPOINTS 0 float\n");
  EXPECT_NE(e.find(":4: DATASET POLYDATA is not supported"), std::string::npos) << e;
}

TEST(VtkBad, NeitherAsciiNorBinary) {
  std::string e = error_of_text("# vtk DataFile Version 3.0\nx\nTEXT\nDATASET UNSTRUCTURED_GRID\n");
  EXPECT_NE(e.find(":3: expected ASCII or BINARY"), std::string::npos) << e;
}

TEST(VtkBad, TruncatedAsciiPoints) {
  std::string e = error_of_text(kHead + "POINTS 4 double\n0 0 0\n1 0 0\n0 1");
  EXPECT_NE(e.find("POINTS: 12 values are more than the rest of the file can hold"), std::string::npos) << e;
}

TEST(VtkBad, TruncatedAsciiCells) {
  // the count fits in the bytes left (padding), but the values end early
  std::string e = error_of_text(kHead + "POINTS 4 double\n0 0 0 1 0 0 0 1 0 0 0 1\nCELLS 2 10\n4 0 1 2 3\n4 0 1" +
                                std::string(40, ' '));
  EXPECT_NE(e.find(":9: unexpected end of file"), std::string::npos) << e;
  std::string e2 = error_of_text(kHead + "POINTS 4 double\n0 0 0 1 0 0 0 1 0 0 0 1\nCELLS 200 1000\n4 0 1 2 3\n");
  EXPECT_NE(e2.find(":7: CELLS: 1000 values are more than the rest of the file can hold"), std::string::npos) << e2;
}

TEST(VtkBad, TruncatedBinary) {
  std::string text = "# vtk DataFile Version 3.0\nb\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 double\n";
  const size_t data_start = text.size();
  text += be<double>({0, 0, 0, 1, 0, 0, 0});  // 7 of 12 values
  std::string e = error_of_text(text);
  EXPECT_NE(e.find("byte " + std::to_string(data_start) + ": POINTS: 12 values of 8 bytes run past the end"),
            std::string::npos)
      << e;
}

TEST(VtkBad, HugeCountIsRejectedBeforeAllocation) {
  std::string e = error_of_text(kHead + "POINTS 2000000000 double\n0 0 0\n");
  EXPECT_NE(e.find("more than the rest of the file can hold"), std::string::npos) << e;
}

TEST(VtkBad, CellsSizeMismatch) {
  std::string e = error_of_text(kHead + "POINTS 4 double\n0 0 0 1 0 0 0 1 0 0 0 1\nCELLS 1 6\n4 0 1 2 3 3\nCELL_TYPES 1\n10\n");
  EXPECT_NE(e.find(":7: CELLS size is 6, but the 1 cells use 5 values"), std::string::npos) << e;
}

TEST(VtkBad, CellCountRunsPastList) {
  std::string e = error_of_text(kHead + "POINTS 4 double\n0 0 0 1 0 0 0 1 0 0 0 1\nCELLS 1 5\n9 0 1 2 3\nCELL_TYPES 1\n10\n");
  EXPECT_NE(e.find("cell 0 has 9 points, which runs past the CELLS list size 5"), std::string::npos) << e;
}

TEST(VtkBad, CellTypesCountMismatch) {
  std::string e = error_of_text(kHead + "POINTS 4 double\n0 0 0 1 0 0 0 1 0 0 0 1\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 2\n10 10\n");
  EXPECT_NE(e.find(":9: CELL_TYPES has 2 entries, but CELLS has 1 cells"), std::string::npos) << e;
}

TEST(VtkBad, IndexOutOfRange) {
  std::string e = error_of_text(kHead + "POINTS 4 double\n0 0 0 1 0 0 0 1 0 0 0 1\nCELLS 1 5\n4 0 1 2 4\nCELL_TYPES 1\n10\n");
  EXPECT_NE(e.find(":7: CELLS: cell 0 refers to point 4, but there are 4 points"), std::string::npos) << e;
}

TEST(VtkBad, NegativeIndex) {
  std::string e = error_of_text(kHead + "POINTS 4 double\n0 0 0 1 0 0 0 1 0 0 0 1\nCELLS 1 5\n4 0 -1 2 3\nCELL_TYPES 1\n10\n");
  EXPECT_NE(e.find("cell 0 refers to point -1"), std::string::npos) << e;
}

TEST(VtkBad, TetWithWrongPointCount) {
  std::string e = error_of_text(kHead + "POINTS 4 double\n0 0 0 1 0 0 0 1 0 0 0 1\nCELLS 1 4\n3 0 1 2\nCELL_TYPES 1\n10\n");
  EXPECT_NE(e.find("cell 0 (tetrahedron) has 3 points, expected 4"), std::string::npos) << e;
}

TEST(VtkBad, NanCoordinate) {
  std::string e = error_of_text(kHead + "POINTS 4 double\n0 0 0\n1 0 nan\n0 1 0\n0 0 1\n" + kOneTet.substr(kOneTet.find("CELLS")));
  EXPECT_NE(e.find(":5: point 1 has a non-finite coordinate"), std::string::npos) << e;
}

TEST(VtkBad, InfCoordinateBinary) {
  std::string text = "# vtk DataFile Version 3.0\nb\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS 1 float\n";
  text += be<float>({0, std::numeric_limits<float>::infinity(), 0}) + "\n";
  std::string e = error_of_text(text);
  EXPECT_NE(e.find("byte "), std::string::npos) << e;
  EXPECT_NE(e.find("point 0 has a non-finite coordinate"), std::string::npos) << e;
}

TEST(VtkBad, PointDataCountMismatch) {
  std::string e = error_of_text(kHead + kOneTet + "POINT_DATA 5\nSCALARS s float\n1 2 3 4 5\n");
  EXPECT_NE(e.find(":14: POINT_DATA 5 does not match the number of points 4"), std::string::npos) << e;
}

TEST(VtkBad, CellDataCountMismatch) {
  std::string e = error_of_text(kHead + kOneTet + "CELL_DATA 3\nSCALARS s int\n1 2 3\n");
  EXPECT_NE(e.find(":14: CELL_DATA 3 does not match the number of cells 1"), std::string::npos) << e;
}

TEST(VtkBad, UnknownDataType) {
  std::string e = error_of_text(kHead + "POINTS 4 quad\n");
  EXPECT_NE(e.find(":5: POINTS: unknown data type 'quad'"), std::string::npos) << e;
}

TEST(VtkBad, BadNumber) {
  std::string e = error_of_text(kHead + "POINTS 4 double\n0 0 0 1 0 x 0 1 0 0 0 1\n");
  EXPECT_NE(e.find(":6: expected a number, found 'x'"), std::string::npos) << e;
}

TEST(VtkBad, UnknownKeyword) {
  std::string e = error_of_text(kHead + kOneTet + "BLOCKS 3\n");
  EXPECT_NE(e.find(":14: unknown keyword 'BLOCKS'"), std::string::npos) << e;
}

TEST(VtkBad, NoPoints) {
  std::string e = error_of_text(kHead);
  EXPECT_NE(e.find("no POINTS section"), std::string::npos) << e;
}

TEST(VtkBad, Offsets51NotMatchingConnectivity) {
  std::string e = error_of_text(
      "# vtk DataFile Version 5.1\nv\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 float\n0 0 0 1 0 0 0 1 0 0 0 1\n"
      "CELLS 2 4\nOFFSETS vtktypeint64\n0 5\nCONNECTIVITY vtktypeint64\n0 1 2 3\nCELL_TYPES 1\n10\n");
  EXPECT_NE(e.find(":7: the last offset is 5, but CONNECTIVITY has 4 values"), std::string::npos) << e;
}

}  // namespace
