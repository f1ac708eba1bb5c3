// VTK XML UnstructuredGrid reader and writer: the shared bracket file, every encoding
// (ascii, base64 with UInt32/UInt64 headers, zlib blocks, appended raw and base64, big
// endian), exact round trips, meshio cross-reads and one test per kind of bad input.
#include <gtest/gtest.h>
#include <zlib.h>

#include <bit>
#include <cstring>

#include "io/io_util.hpp"
#include "test_support.hpp"
#include "tetcollapse/io.hpp"
#include "vtk_test_util.hpp"

namespace {

using tc::test::input_error_of;

std::string write_and_path(const tc::test::TempDir& dir, const std::string& text) {
  std::string p = dir.file("in.vtu");
  tc::test::write_text(p, text);
  return p;
}

tc::Mesh read_text_vtu(const std::string& text, tc::ReadNotes* notes_out = nullptr) {
  tc::test::TempDir dir;
  std::string p = write_and_path(dir, text);
  tc::ReadNotes notes;
  tc::Mesh m = tc::read_vtu(p, notes);
  if (notes_out) *notes_out = notes;
  return m;
}

std::string error_of_text(const std::string& text) {
  tc::test::TempDir dir;
  std::string p = write_and_path(dir, text);
  return input_error_of([&] {
    tc::ReadNotes notes;
    tc::read_vtu(p, notes);
  });
}

template <class T>
std::string bytes_of(const std::vector<T>& v, bool big_endian = false) {
  std::string s(v.size() * sizeof(T), '\0');
  if (!v.empty()) std::memcpy(s.data(), v.data(), s.size());
  if (big_endian != (std::endian::native == std::endian::big))
    for (size_t i = 0; i < v.size(); ++i) std::reverse(s.begin() + i * sizeof(T), s.begin() + (i + 1) * sizeof(T));
  return s;
}

template <class H>
std::string header(std::vector<H> h, bool big_endian = false) { return bytes_of(h, big_endian); }

// A file around the given <Piece> content; `root_attrs` go on <VTKFile>; `appended` is
// placed after "_" in an <AppendedData> of encoding `enc` when not empty.
std::string vtu(const std::string& piece_attrs, const std::string& body, const std::string& root_attrs = "",
                const std::string& appended = "", const std::string& enc = "raw") {
  std::string s = "<?xml version=\"1.0\"?>\n<!-- test file -->\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" " +
                  root_attrs + ">\n<UnstructuredGrid>\n<Piece " + piece_attrs + ">\n" + body +
                  "</Piece>\n</UnstructuredGrid>\n";
  if (!appended.empty() || enc != "raw") s += "<AppendedData encoding=\"" + enc + "\">\n_" + appended + "\n</AppendedData>\n";
  return s + "</VTKFile>\n";
}

const std::string kTetPoints =
    "<Points>\n<DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">0 0 0 1 0 0 0 1 0 0 0 1</DataArray>\n</Points>\n";
const std::string kTetCells =
    "<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 1 2 3</DataArray>\n"
    "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">4</DataArray>\n"
    "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">10</DataArray>\n</Cells>\n";
const std::string kOnePiece = "NumberOfPoints=\"4\" NumberOfCells=\"1\"";

// ------------------------------------------------------------ shared file

TEST(VtuShared, FeaBracketZlib) {
  TC_SKIP_IF_NO_SHARED();
  std::string p = tc::test::shared_mesh("vtkdata_fea_bracket_kiefer_linear.vtu");
  if (p.empty()) GTEST_SKIP() << "vtkdata_fea_bracket_kiefer_linear.vtu is not in the shared meshes";
  tc::ReadNotes notes;
  tc::Mesh m = tc::read_vtu(p, notes);
  EXPECT_EQ(m.num_vertices(), 16468);
  EXPECT_EQ(m.num_tets(), 56786);
  const tc::Field* avg = m.find_vertex_field("von_mises_psi_vertex_avg");
  ASSERT_NE(avg, nullptr);
  EXPECT_EQ(avg->values.size(), 16468u);
  ASSERT_EQ(m.tet_fields.size(), 1u);
  EXPECT_EQ(m.tet_fields[0].name, "von_mises_psi");
  ASSERT_EQ(m.tet_fields[0].values.size(), 56786u);
  auto [lo, hi] = std::minmax_element(m.tet_fields[0].values.begin(), m.tet_fields[0].values.end());
  EXPECT_NEAR(*lo, 0.014, 1e-3);
  EXPECT_NEAR(*hi, 23.27, 1e-2);
  EXPECT_TRUE(m.tet_labels.empty());
}

// ------------------------------------------------------------ encodings

TEST(VtuRead, AsciiMixedCellsLabelsAndFields) {
  std::string body =
      "<PointData>\n<DataArray type=\"Int16\" Name=\"flag\" format=\"ascii\">1 2 3 4 5</DataArray>\n</PointData>\n"
      "<CellData>\n<DataArray type=\"Int32\" Name=\"mat &amp; id\" format=\"ascii\">7 8 9 10</DataArray>\n"
      "<DataArray type=\"Float64\" Name=\"q\" NumberOfComponents=\"2\" format=\"ascii\">1 2 3 4 5 6 7 8</DataArray>\n</CellData>\n"
      "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n"
      "0 0 0 1 0 0 0 1 0 0 0 1 1 1 1\n</DataArray>\n</Points>\n"
      "<Cells>\n<DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">0 1 2 3 1 2 4 0 4 0 1 2 4 0 1 2 3 4</DataArray>\n"
      "<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">4 7 9 18</DataArray>\n"
      "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">10 5 3 24</DataArray>\n</Cells>\n";
  // the quadratic tet (type 24) lists 10 points; its first 4 are the corners
  body.replace(body.find(">0 1 2 3 1 2 4 0 4 0 1 2 4 0 1 2 3 4<"), 37, ">0 1 2 3 1 2 4 0 4 0 1 2 4 0 1 2 3 4 0<");
  body.replace(body.find(">4 7 9 18<"), 10, ">4 7 9 19<");
  tc::ReadNotes notes;
  std::string text = vtu("NumberOfPoints=\"5\" NumberOfCells=\"4\"", body);
  tc::Mesh m = read_text_vtu(text, &notes);
  EXPECT_EQ(m.tets, (std::vector<int32_t>{0, 1, 2, 3, 0, 1, 2, 4}));
  EXPECT_EQ(m.tris, (std::vector<int32_t>{1, 2, 4}));
  EXPECT_EQ(m.edges, (std::vector<int32_t>{0, 4}));
  EXPECT_EQ(notes.reduced_quadratic_tets, 1);
  ASSERT_EQ(m.tet_labels.size(), 1u);
  EXPECT_EQ(m.tet_labels[0].name, "mat & id");
  EXPECT_EQ(m.tet_labels[0].values, (std::vector<int32_t>{7, 10}));
  ASSERT_EQ(m.tet_fields.size(), 1u);
  EXPECT_EQ(m.tet_fields[0].values, (std::vector<double>{1, 2, 7, 8}));
  ASSERT_EQ(m.vertex_fields.size(), 1u);
  EXPECT_EQ(m.vertex_fields[0].values, (std::vector<double>{1, 2, 3, 4, 5}));
}

TEST(VtuRead, Base64BigEndianUInt32Header) {
  auto block = [](const std::string& data) {
    return tc::io::base64_encode(header<uint32_t>({uint32_t(data.size())}, true) + data);
  };
  std::string body =
      "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"binary\">" +
      block(bytes_of<double>({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}, true)) + "</DataArray>\n</Points>\n" +
      "<Cells>\n<DataArray type=\"UInt16\" Name=\"connectivity\" format=\"binary\">" +
      block(bytes_of<uint16_t>({0, 2, 1, 3}, true)) + "</DataArray>\n" +
      "<DataArray type=\"Int32\" Name=\"offsets\" format=\"binary\">" + block(bytes_of<int32_t>({4}, true)) +
      "</DataArray>\n<DataArray type=\"Int8\" Name=\"types\" format=\"binary\">" + block(bytes_of<int8_t>({10}, true)) +
      "</DataArray>\n</Cells>\n";
  tc::Mesh m = read_text_vtu(vtu(kOnePiece, body, "byte_order=\"BigEndian\" header_type=\"UInt32\""));
  EXPECT_EQ(m.points, (std::vector<double>{0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}));
  EXPECT_EQ(m.tets, (std::vector<int32_t>{0, 2, 1, 3}));
}

// zlib blocks as vtkZLibDataCompressor writes them: header [nblocks, block size, last
// block size, compressed sizes...], then the compressed blocks.
template <class H>
std::string zlib_blocks(const std::string& data, size_t block_size) {
  std::vector<H> h;
  std::string body;
  size_t nblocks = (data.size() + block_size - 1) / block_size;
  h.push_back(H(nblocks));
  h.push_back(H(block_size));
  h.push_back(H(data.size() % block_size));
  for (size_t b = 0; b < nblocks; ++b) {
    std::string in = data.substr(b * block_size, block_size);
    uLongf n = compressBound(in.size());
    std::string out(n, '\0');
    compress(reinterpret_cast<Bytef*>(out.data()), &n, reinterpret_cast<const Bytef*>(in.data()), in.size());
    out.resize(n);
    h.push_back(H(n));
    body += out;
  }
  return header(h) + body;
}

TEST(VtuRead, ZlibInlineWithSeparateHeaderAndAppendedRaw) {
  // Points inline (header and data base64-encoded separately, as VTK does), cells appended raw.
  std::string pts = zlib_blocks<uint64_t>(bytes_of<double>({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 2, 2, 2}), 16);
  size_t hbytes = 8 * (3 + 8);
  std::string pts_b64 = tc::io::base64_encode(pts.substr(0, hbytes)) + tc::io::base64_encode(pts.substr(hbytes));
  std::string conn = zlib_blocks<uint64_t>(bytes_of<int64_t>({0, 1, 2, 3, 1, 0, 2, 4}), 24);
  std::string offs = zlib_blocks<uint64_t>(bytes_of<int64_t>({4, 8}), 1 << 15);
  std::string types = zlib_blocks<uint64_t>(bytes_of<uint8_t>({10, 10}), 1 << 15);
  std::string body =
      "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"binary\">\n" + pts_b64 +
      "\n</DataArray>\n</Points>\n<Cells>\n"
      "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"appended\" offset=\"0\"/>\n"
      "<DataArray type=\"Int64\" Name=\"offsets\" format=\"appended\" offset=\"" + std::to_string(conn.size()) + "\"/>\n"
      "<DataArray type=\"UInt8\" Name=\"types\" format=\"appended\" offset=\"" + std::to_string(conn.size() + offs.size()) +
      "\"/>\n</Cells>\n";
  tc::Mesh m = read_text_vtu(vtu("NumberOfPoints=\"5\" NumberOfCells=\"2\"", body,
                                 "byte_order=\"LittleEndian\" header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\"",
                                 conn + offs + types));
  EXPECT_EQ(m.num_vertices(), 5);
  EXPECT_EQ(m.points[12], 2.0);
  EXPECT_EQ(m.tets, (std::vector<int32_t>{0, 1, 2, 3, 1, 0, 2, 4}));
}

TEST(VtuRead, AppendedBase64) {
  std::string a0 = tc::io::base64_encode(header<uint32_t>({48}) + bytes_of<float>({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}));
  std::string a1 = tc::io::base64_encode(header<uint32_t>({16}) + bytes_of<int32_t>({3, 2, 1, 0}));
  std::string body =
      "<Points>\n<DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"appended\" offset=\"0\"/>\n</Points>\n"
      "<Cells>\n<DataArray type=\"Int32\" Name=\"connectivity\" format=\"appended\" offset=\"" + std::to_string(a0.size()) +
      "\"/>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">4</DataArray>\n"
      "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">10</DataArray>\n</Cells>\n";
  tc::Mesh m = read_text_vtu(vtu(kOnePiece, body, "", a0 + a1, "base64"));
  EXPECT_EQ(m.tets, (std::vector<int32_t>{3, 2, 1, 0}));
  EXPECT_EQ(m.points[3], 1.0);
}

TEST(VtuRead, NoTetsGivesEmptyTets) {
  std::string cells = kTetCells;
  cells.replace(cells.find(">10<"), 4, ">12<");
  tc::ReadNotes notes;
  tc::Mesh m = read_text_vtu(vtu(kOnePiece, kTetPoints + cells), &notes);
  EXPECT_EQ(m.num_tets(), 0);
  EXPECT_EQ(notes.skipped_elements, 1);
}

TEST(VtuRead, NoTetsIsReportedByReadMesh) {
  std::string cells = kTetCells;
  cells.replace(cells.find(">10<"), 4, ">12<");
  tc::test::TempDir dir;
  std::string p = write_and_path(dir, vtu(kOnePiece, kTetPoints + cells));
  std::string e = input_error_of([&] { tc::read_mesh(p); });
  EXPECT_NE(e.find("the mesh has no tetrahedra (1 non-tetrahedral elements were skipped)"), std::string::npos) << e;
}

// ------------------------------------------------------------ round trips

void round_trip(tc::WriteOptions::VtuEncoding enc) {
  tc::test::TempDir dir;
  tc::Mesh a = tc::test::attribute_mesh();
  tc::WriteOptions opt;
  opt.vtu_encoding = enc;
  std::string p = dir.file("rt.vtu");
  tc::write_vtu(p, a, opt);
  tc::ReadNotes notes;
  tc::Mesh b = tc::read_vtu(p, notes);
  tc::test::expect_same_mesh(a, b);
  EXPECT_EQ(notes.skipped_elements, 0);
  tc::test::meshio_cross_read(p, a.num_vertices(), a.num_tets(), "pressure");
}

TEST(VtuRoundTrip, AsciiExactAndMeshio) { round_trip(tc::WriteOptions::VtuEncoding::Ascii); }
TEST(VtuRoundTrip, Base64ExactAndMeshio) { round_trip(tc::WriteOptions::VtuEncoding::Base64); }
TEST(VtuRoundTrip, AppendedExactAndMeshio) { round_trip(tc::WriteOptions::VtuEncoding::Appended); }

TEST(VtuRoundTrip, EmptyMeshWritesAndReadsBack) {
  tc::test::TempDir dir;
  tc::Mesh a;
  std::string p = dir.file("e.vtu");
  tc::write_vtu(p, a, tc::WriteOptions{});
  tc::ReadNotes notes;
  tc::Mesh b = tc::read_vtu(p, notes);
  EXPECT_EQ(b.num_vertices(), 0);
  EXPECT_EQ(b.num_tets(), 0);
}

// ------------------------------------------------------------ bad input

TEST(VtuBad, EveryTruncationIsAnInputError) {
  using Enc = tc::WriteOptions::VtuEncoding;
  for (Enc enc : {Enc::Ascii, Enc::Base64, Enc::Appended}) {
    tc::test::TempDir dir;
    tc::WriteOptions opt;
    opt.vtu_encoding = enc;
    tc::write_vtu(dir.file("full.vtu"), tc::test::attribute_mesh(), opt);
    std::string full = tc::test::read_text(dir.file("full.vtu"));
    int64_t failed = tc::test::check_truncations(full, dir.file("cut.vtu"), 5, [](const std::string& p) {
      tc::ReadNotes notes;
      tc::read_vtu(p, notes);
    });
    EXPECT_GT(failed, int64_t(full.size() / 5) / 2) << "encoding " << int(enc);
  }
}

TEST(VtuBad, EmptyFile) { EXPECT_NE(error_of_text("").find("empty file"), std::string::npos); }

TEST(VtuBad, NotVtkXml) {
  std::string e = error_of_text("<?xml version=\"1.0\"?>\n<html></html>\n");
  EXPECT_NE(e.find(":2: not a VTK XML file"), std::string::npos) << e;
}

TEST(VtuBad, OtherDatasetType) {
  std::string e = error_of_text("<VTKFile type=\"PolyData\">\n</VTKFile>\n");
  EXPECT_NE(e.find(":1: VTKFile type 'PolyData' is not supported"), std::string::npos) << e;
}

TEST(VtuBad, UnknownCompressor) {
  std::string e = error_of_text(vtu(kOnePiece, kTetPoints + kTetCells, "compressor=\"vtkLZ4DataCompressor\""));
  EXPECT_NE(e.find("compressor 'vtkLZ4DataCompressor' is not supported"), std::string::npos) << e;
}

TEST(VtuBad, UnterminatedTag) {
  std::string e = error_of_text("<VTKFile type=\"UnstructuredGrid\">\n<Piece NumberOfPoints=\"4\"");
  EXPECT_NE(e.find(":2: unterminated XML tag <Piece>"), std::string::npos) << e;
}

TEST(VtuBad, UnclosedDataArray) {
  std::string text = vtu(kOnePiece, kTetPoints + kTetCells);
  text.erase(text.find("</DataArray>"));
  std::string e = error_of_text(text);
  EXPECT_NE(e.find(":7: <DataArray> '' is not closed"), std::string::npos) << e;
}

TEST(VtuBad, AsciiTooFewValues) {
  std::string pts = kTetPoints;
  pts.replace(pts.find("0 0 0 1 0 0"), 11, "0 0 0 1 0  ");
  std::string e = error_of_text(vtu(kOnePiece, pts + kTetCells));
  EXPECT_NE(e.find(":7: unexpected end of file"), std::string::npos) << e;
}

TEST(VtuBad, AsciiTooManyValues) {
  std::string cells = kTetCells;
  cells.replace(cells.find(">4<"), 3, ">4 8<");
  std::string e = error_of_text(vtu(kOnePiece, kTetPoints + cells));
  EXPECT_NE(e.find(":11: DataArray 'offsets': more than the expected 1 values"), std::string::npos) << e;
}

TEST(VtuBad, HugeCountIsRejectedBeforeAllocation) {
  std::string e = error_of_text(vtu("NumberOfPoints=\"1000000000\" NumberOfCells=\"1\"", kTetPoints + kTetCells));
  EXPECT_NE(e.find("values are more than its text can hold"), std::string::npos) << e;
}

TEST(VtuBad, WrongByteCountInHeader) {
  std::string b = tc::io::base64_encode(header<uint64_t>({40}) + bytes_of<double>({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}));
  std::string body = "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"binary\">" + b +
                     "</DataArray>\n</Points>\n" + kTetCells;
  std::string text = vtu(kOnePiece, body, "header_type=\"UInt64\"");
  size_t at = text.find(b);
  std::string e = error_of_text(text);
  EXPECT_NE(e.find("byte " + std::to_string(at) + ": DataArray '' holds 40 bytes, expected 96"), std::string::npos) << e;
}

TEST(VtuBad, BadBase64) {
  std::string body = "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"binary\">QUJD!!==</DataArray>\n</Points>\n" + kTetCells;
  std::string e = error_of_text(vtu(kOnePiece, body));
  EXPECT_NE(e.find("invalid base64 data"), std::string::npos) << e;
  EXPECT_NE(e.find(": byte "), std::string::npos) << e;
}

TEST(VtuBad, BadZlib) {
  std::string block = header<uint32_t>({1, 96, 0, 10}) + std::string("notzlib!!!");
  std::string body = "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"binary\">" +
                     tc::io::base64_encode(block) + "</DataArray>\n</Points>\n" + kTetCells;
  std::string e = error_of_text(vtu(kOnePiece, body, "compressor=\"vtkZLibDataCompressor\""));
  EXPECT_NE(e.find("DataArray '': compressed block 0 is not valid zlib data of 96 bytes"), std::string::npos) << e;
}

TEST(VtuBad, CompressedSizesPastTheEnd) {
  std::string block = header<uint32_t>({1, 96, 0, 5000}) + std::string("xx");
  std::string body = "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"binary\">" +
                     tc::io::base64_encode(block) + "</DataArray>\n</Points>\n" + kTetCells;
  std::string e = error_of_text(vtu(kOnePiece, body, "compressor=\"vtkZLibDataCompressor\""));
  EXPECT_NE(e.find("compressed block 0 runs past the end of the data"), std::string::npos) << e;
}

TEST(VtuBad, AppendedOffsetPastTheEnd) {
  std::string body = "<Points>\n<DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"appended\" offset=\"999\"/>\n</Points>\n" + kTetCells;
  std::string e = error_of_text(vtu(kOnePiece, body, "", "abcd"));
  EXPECT_NE(e.find(":7: DataArray '': offset 999 is past the end of the appended data"), std::string::npos) << e;
}

TEST(VtuBad, TruncatedAppendedRaw) {
  std::string data = header<uint32_t>({48}) + bytes_of<float>({0, 0, 0, 1, 0, 0, 0});
  std::string body = "<Points>\n<DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"appended\" offset=\"0\"/>\n</Points>\n" + kTetCells;
  std::string text = vtu(kOnePiece, body, "", "X");
  text = text.substr(0, text.find("_X") + 1) + data;  // the file ends inside the data
  std::string e = error_of_text(text);
  EXPECT_NE(e.find("byte " + std::to_string(text.size() - data.size()) + ": DataArray '': 48 bytes run past the end"),
            std::string::npos)
      << e;
}

TEST(VtuBad, AppendedWithoutAppendedData) {
  std::string body = "<Points>\n<DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"appended\" offset=\"0\"/>\n</Points>\n" + kTetCells;
  std::string e = error_of_text(vtu(kOnePiece, body));
  EXPECT_NE(e.find("is appended, but the file has no <AppendedData>"), std::string::npos) << e;
}

TEST(VtuBad, IndexOutOfRange) {
  std::string cells = kTetCells;
  cells.replace(cells.find(">0 1 2 3<"), 9, ">0 1 2 7<");
  std::string e = error_of_text(vtu(kOnePiece, kTetPoints + cells));
  EXPECT_NE(e.find(":10: Cells: cell 0 refers to point 7, but there are 4 points"), std::string::npos) << e;
}

TEST(VtuBad, DecreasingOffsets) {
  std::string cells = kTetCells;
  cells.replace(cells.find(">4<"), 3, ">-4<");
  std::string e = error_of_text(vtu(kOnePiece, kTetPoints + cells));
  EXPECT_NE(e.find(":11: offsets decrease (or are negative) at cell 0"), std::string::npos) << e;
}

TEST(VtuBad, NanCoordinate) {
  std::string pts = kTetPoints;
  pts.replace(pts.find("0 1 0"), 5, "0 nan 0");
  std::string e = error_of_text(vtu(kOnePiece, pts + kTetCells));
  EXPECT_NE(e.find(":7: point 1 has a non-finite coordinate"), std::string::npos) << e;
}

TEST(VtuBad, WrongNumberOfTuples) {
  std::string text = vtu(kOnePiece, kTetPoints + kTetCells +
                                        "<PointData><DataArray type=\"Float64\" Name=\"f\" NumberOfTuples=\"3\" "
                                        "format=\"ascii\">1 2 3</DataArray></PointData>\n");
  std::string e = error_of_text(text);
  EXPECT_NE(e.find(":14: DataArray 'f': NumberOfTuples 3 does not match the expected 4"), std::string::npos) << e;
}

TEST(VtuBad, UnknownType) {
  std::string pts = kTetPoints;
  pts.replace(pts.find("Float32"), 7, "Float16");
  std::string e = error_of_text(vtu(kOnePiece, pts + kTetCells));
  EXPECT_NE(e.find(":7: DataArray '': unknown type 'Float16'"), std::string::npos) << e;
}

TEST(VtuBad, MissingCellsArray) {
  std::string cells = kTetCells;
  cells.erase(cells.find("<DataArray type=\"UInt8\""), cells.find("</Cells>") - cells.find("<DataArray type=\"UInt8\""));
  std::string e = error_of_text(vtu(kOnePiece, kTetPoints + cells));
  EXPECT_NE(e.find(":5: <Cells> lacks the 'types' DataArray"), std::string::npos) << e;
}

}  // namespace
