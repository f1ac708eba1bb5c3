// Every volume mesh in ../shared/meshes loads through tc::read_mesh, with the vertex and tet
// counts that ../shared/meshes/SOURCES.md lists for it (parsed from its tables).
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <sstream>

#include "test_support.hpp"
#include "tetcollapse/io.hpp"

namespace {

struct Expected {
  int64_t vertices = -1, tets = -1;
};

std::string trim(std::string s) {
  auto b = s.find_first_not_of(" \t*`");
  auto e = s.find_last_not_of(" \t*`");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

std::vector<std::string> cells_of(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  std::string cell;
  std::getline(ss, cell, '|');  // before the first bar
  while (std::getline(ss, cell, '|')) cells.push_back(trim(cell));
  return cells;
}

int64_t parse_count(const std::string& s) {
  std::string digits;
  for (char c : s)
    if (std::isdigit(static_cast<unsigned char>(c))) digits += c;
    else if (c != ',') return -1;
  return digits.empty() ? -1 : std::stoll(digits);
}

// file name -> counts, from every table of SOURCES.md that has #vertices and #tets columns.
std::map<std::string, Expected> parse_sources(const std::string& text) {
  std::map<std::string, Expected> out;
  std::stringstream in(text);
  std::string line;
  int col_v = -1, col_t = -1;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] != '|') {
      col_v = col_t = -1;
      continue;
    }
    auto cells = cells_of(line);
    bool header = false;
    for (size_t i = 0; i < cells.size(); ++i) {
      if (cells[i] == "#vertices") { col_v = int(i); header = true; }
      if (cells[i] == "#tets") { col_t = int(i); header = true; }
    }
    if (header || col_v < 0 || col_t < 0 || int(cells.size()) <= std::max(col_v, col_t)) continue;
    std::string name = cells[0];
    auto plus = name.find(" + ");
    if (plus != std::string::npos) name = name.substr(0, plus);
    Expected e{parse_count(cells[col_v]), parse_count(cells[col_t])};
    if (e.vertices >= 0 && e.tets >= 0) out[name] = e;
  }
  return out;
}

TEST(SharedMeshes, EveryVolumeMeshLoadsWithTheCountsOfSourcesMd) {
  TC_SKIP_IF_NO_SHARED();
  std::string sources = tc::test::read_text(tc::test::shared_meshes_dir() + "/SOURCES.md");
  ASSERT_FALSE(sources.empty()) << "SOURCES.md missing";
  auto expected = parse_sources(sources);
  ASSERT_GE(expected.size(), 20u) << "could not parse the tables of SOURCES.md";
  auto files = tc::test::shared_volume_meshes();
  ASSERT_FALSE(files.empty());
  for (const auto& path : files) {
    std::string name = std::filesystem::path(path).filename().string();
    SCOPED_TRACE(name);
    auto it = expected.find(name);
    ASSERT_NE(it, expected.end()) << name << " is not listed in SOURCES.md";
    tc::ReadNotes notes;
    tc::Mesh m;
    ASSERT_NO_THROW(m = tc::read_mesh(path, {}, &notes));
    EXPECT_EQ(m.num_vertices(), it->second.vertices);
    EXPECT_EQ(m.num_tets(), it->second.tets);
  }
}

}  // namespace
