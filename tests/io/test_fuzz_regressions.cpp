// Inputs found by the libFuzzer harnesses (tests/fuzz/, scripts/fuzz.sh) that once crashed
// a reader or tripped a sanitizer, replayed exactly as the fuzzer ran them: each file of
// tests/data/fuzz/<harness>/ is split into the reader's files by the same code as in the
// harness (tests/fuzz/fuzz_input.hpp) and must be refused with tc::InputError.
// Also checks that the committed seed corpora read, so the corpora stay valid inputs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <filesystem>
#include <string>
#include <vector>

#include "../fuzz/fuzz_input.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using tc::Format;

namespace {

struct Harness {
  const char* name;
  Format format;
};
const Harness kHarnesses[] = {{"gmsh", Format::Gmsh},
                              {"medit", Format::Medit},
                              {"vtk", Format::Vtk},
                              {"vtu", Format::Vtu},
                              {"tetgen", Format::TetGen}};

std::vector<fs::path> files_in(const fs::path& dir) {
  std::vector<fs::path> out;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file() && e.path().filename().string()[0] != '.' && e.path().extension() != ".md")
      out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

std::string describe(const fs::path& p) { return p.parent_path().filename().string() + "/" + p.filename().string(); }

}  // namespace

TEST(FuzzRegressions, EveryCrasherIsRefusedWithInputError) {
  const fs::path root = fs::path(TC_SOURCE_DIR) / "tests" / "data" / "fuzz";
  int replayed = 0;
  for (const Harness& h : kHarnesses)
    for (const fs::path& file : files_in(root / h.name)) {
      SCOPED_TRACE(describe(file));
      tc::test::TempDir dir;
      const std::string path = tc::fuzz::materialize(dir.path(), h.format, tc::test::read_text(file.string()));
      try {
        tc::fuzz::read_input(path, h.format);
        ADD_FAILURE() << describe(file) << " was read as a mesh; expected tc::InputError";
      } catch (const tc::InputError& e) {
        // The message is one line that names the file the reader opened.
        const std::string what = e.what();
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
        EXPECT_NE(what.find(dir.path().string()), std::string::npos) << what;
      }
      ++replayed;
    }
  // the crashers are the project's own data (committed with it): none replayed means they are lost
  ASSERT_GT(replayed, 0) << "no crashers found in " << root << " (see bench/fuzzing.md)";
  RecordProperty("replayed", replayed);
}

// The seeds are valid meshes of their format; a seed that stops reading means the
// corpora (or the split convention of fuzz_input.hpp) went stale.
TEST(FuzzRegressions, SeedCorporaRead) {
  const fs::path root = fs::path(TC_SOURCE_DIR) / "tests" / "fuzz" / "seeds";
  for (const Harness& h : kHarnesses) {
    const std::vector<fs::path> seeds = files_in(root / h.name);
    EXPECT_GE(seeds.size(), 2u) << h.name;
    for (const fs::path& file : seeds) {
      SCOPED_TRACE(describe(file));
      tc::test::TempDir dir;
      const std::string path = tc::fuzz::materialize(dir.path(), h.format, tc::test::read_text(file.string()));
      try {
        const tc::Mesh m = tc::fuzz::read_input(path, h.format);
        EXPECT_GT(m.num_tets(), 0);
      } catch (const tc::InputError& e) {
        ADD_FAILURE() << e.what();
      }
    }
  }
}

// The split convention itself: a part separator makes the next file; an absent optional
// part is an absent file (so a stale x.sol from an earlier input is not read).
TEST(FuzzRegressions, PartsBecomeFiles) {
  tc::test::TempDir dir;
  const std::string sep(tc::fuzz::kPartSeparator);
  tc::fuzz::materialize(dir.path(), Format::Medit, "mesh" + sep + "sol");
  EXPECT_EQ(tc::test::read_text(dir.file("x.mesh")), "mesh");
  EXPECT_EQ(tc::test::read_text(dir.file("x.sol")), "sol");
  tc::fuzz::materialize(dir.path(), Format::Medit, "only mesh");
  EXPECT_FALSE(fs::exists(dir.file("x.sol")));
  // TetGen: the last part keeps any further separators (they are bytes of x.face).
  tc::fuzz::materialize(dir.path(), Format::TetGen, "n" + sep + "e" + sep + "f" + sep + "g");
  EXPECT_EQ(tc::test::read_text(dir.file("x.face")), "f" + sep + "g");
  // A Medit mesh whose .sol part is cut short is refused, naming the .sol file.
  const std::string mesh = tc::test::read_text((fs::path(TC_SOURCE_DIR) / "meshes" / "tet.mesh").string());
  const std::string path = tc::fuzz::materialize(dir.path(), Format::Medit, mesh + sep + "MeshVersionFormatted 2\nDimension 3\nSolAtVertices\n4\n1 1\n0.5\n");
  try {
    tc::fuzz::read_input(path, Format::Medit);
    ADD_FAILURE() << "a truncated .sol was accepted";
  } catch (const tc::InputError& e) {
    EXPECT_EQ(e.file(), dir.file("x.sol"));
  }
}

// Found by fuzz_vtk (tests/data/fuzz/vtk/float-offsets-*): integer data stored as floats
// was cast to int64 unchecked, undefined for 1e300 or NaN (UBSan) and silently truncated for
// 4.5. Now such a value is refused, in VTK legacy BINARY and in VTU alike.
namespace {
std::string be_doubles(std::initializer_list<double> values) {
  std::string out;
  for (double v : values) {
    unsigned char b[8];
    std::memcpy(b, &v, 8);
    for (int i = 7; i >= 0; --i) out += static_cast<char>(b[i]);
  }
  return out;
}
std::string be_int64s(std::initializer_list<int64_t> values) {
  std::string out;
  for (int64_t v : values)
    for (int i = 7; i >= 0; --i) out += static_cast<char>((static_cast<uint64_t>(v) >> (8 * i)) & 0xff);
  return out;
}
std::string vtk_with_offsets(double last_offset) {
  return "# vtk DataFile Version 5.1\nfloat offsets\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 double\n" +
         be_doubles({0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1}) + "\nCELLS 2 4\nOFFSETS double\n" + be_doubles({0, last_offset}) +
         "\nCONNECTIVITY vtktypeint64\n" + be_int64s({0, 1, 2, 3}) + "\nCELL_TYPES 1\n" + std::string("\0\0\0\x0a", 4) + "\n";
}
}  // namespace

TEST(FuzzRegressions, VtkFloatOffsetsMustBeIntegers) {
  tc::test::TempDir dir;
  // Integral floats are integer data like any other.
  const std::string ok = tc::fuzz::materialize(dir.path(), Format::Vtk, vtk_with_offsets(4.0));
  EXPECT_EQ(tc::fuzz::read_input(ok, Format::Vtk).num_tets(), 1);
  for (double bad : {4.5, 1e300, std::numeric_limits<double>::quiet_NaN(), -0x1p64}) {
    SCOPED_TRACE(bad);
    const std::string path = tc::fuzz::materialize(dir.path(), Format::Vtk, vtk_with_offsets(bad));
    try {
      tc::fuzz::read_input(path, Format::Vtk);
      ADD_FAILURE() << "offset " << bad << " was accepted";
    } catch (const tc::InputError& e) {
      EXPECT_NE(e.reason().find("OFFSETS: value 2 is not an integer"), std::string::npos) << e.what();
      EXPECT_GE(e.byte_offset(), 0) << e.what();
    }
  }
}

TEST(FuzzRegressions, VtuFloatConnectivityMustBeIntegers) {
  auto vtu = [](const std::string& conn) {
    return "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\">\n"
           "<UnstructuredGrid><Piece NumberOfPoints=\"4\" NumberOfCells=\"1\">\n"
           "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">0 0 0 1 0 0 0 1 0 0 0 1</DataArray></Points>\n"
           "<Cells><DataArray type=\"Float64\" Name=\"connectivity\" format=\"binary\">" + conn + "</DataArray>\n"
           "<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">4</DataArray>\n"
           "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">10</DataArray></Cells>\n"
           "</Piece></UnstructuredGrid></VTKFile>\n";
  };
  // Base64 of a UInt32 byte count (32) and four little-endian doubles.
  auto encoded = [](double last) {
    std::string raw(4, '\0');
    raw[0] = 32;
    for (double v : {0.0, 1.0, 2.0, last}) raw.append(reinterpret_cast<const char*>(&v), 8);
    static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < raw.size(); i += 3) {
      uint32_t n = uint8_t(raw[i]) << 16;
      if (i + 1 < raw.size()) n |= uint8_t(raw[i + 1]) << 8;
      if (i + 2 < raw.size()) n |= uint8_t(raw[i + 2]);
      out += k[(n >> 18) & 63];
      out += k[(n >> 12) & 63];
      out += i + 1 < raw.size() ? k[(n >> 6) & 63] : '=';
      out += i + 2 < raw.size() ? k[n & 63] : '=';
    }
    return out;
  };
  tc::test::TempDir dir;
  const std::string ok = tc::fuzz::materialize(dir.path(), Format::Vtu, vtu(encoded(3.0)));
  EXPECT_EQ(tc::fuzz::read_input(ok, Format::Vtu).num_tets(), 1);
  for (double bad : {2.5, 1e300}) {
    SCOPED_TRACE(bad);
    const std::string path = tc::fuzz::materialize(dir.path(), Format::Vtu, vtu(encoded(bad)));
    try {
      tc::fuzz::read_input(path, Format::Vtu);
      ADD_FAILURE() << "connectivity " << bad << " was accepted";
    } catch (const tc::InputError& e) {
      EXPECT_NE(e.reason().find("value 4 is not an integer"), std::string::npos) << e.what();
    }
  }
}
