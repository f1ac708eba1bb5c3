// Inputs found by the libFuzzer harnesses (tests/fuzz/, scripts/fuzz.sh) that once crashed
// a reader or tripped a sanitizer, replayed exactly as the fuzzer ran them: each file of
// tests/data/fuzz/<harness>/ is split into the reader's files by the same code as in the
// harness (tests/fuzz/fuzz_input.hpp) and must be refused with tc::InputError.
// Also checks that the committed seed corpora read, so the corpora stay valid inputs.
#include <gtest/gtest.h>

#include <algorithm>
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
  if (replayed == 0) GTEST_SKIP() << "no crashers in tests/data/fuzz/";
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
