// The CI sample of the robustness campaign (scripts/robustness.py): every mesh of
// meshes/corpus/ (a fixed subset of the corpus made by scripts/make_corpus.py, one per line in
// meshes/corpus/README.md) is coarsened to its median edge length through the CLI
//   1. with the default boundary protection and --check: exit 0 and "check": "valid";
//   2. with --boundary strict and --check, then `tetcollapse check OUT --reference IN --json -`:
//      valid, and the two-sided boundary Hausdorff distance is exactly 0.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "test_support.hpp"

namespace {

namespace fs = std::filesystem;
using tc::test::run_command;

std::string cli() { return std::string("'") + TC_CLI + "'"; }
std::string q(const std::string& s) { return "'" + s + "'"; }

std::string corpus_dir() { return std::string(TC_PROJECT_MESHES) + "/corpus"; }

std::vector<std::string> sample_meshes() {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(corpus_dir(), ec))
    if (e.path().extension() == ".msh") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

// The text after "key": in a JSON document (first occurrence; keys here are unique).
std::string json_value(const std::string& json, const std::string& key) {
  std::string k = "\"" + key + "\":";
  auto p = json.find(k);
  if (p == std::string::npos) return "";
  p += k.size();
  auto end = json.find_first_of(",}", p);
  return json.substr(p, end - p);
}

TEST(RobustnessSample, TheSampleIsThere) {
  // The sample is committed; losing it would silently turn this suite into nothing.
  EXPECT_GE(sample_meshes().size(), 15u) << "meshes/corpus/ should hold the committed CI sample";
}

class Sample : public ::testing::TestWithParam<std::string> {};

TEST_P(Sample, CoarsensToAValidMeshAndStrictKeepsTheBoundary) {
  tc::test::TempDir dir;
  const std::string in = corpus_dir() + "/" + GetParam() + ".msh";
  const std::string out = dir.file("out.msh"), stats = dir.file("stats.json");
  const std::string coarsen = cli() + " " + q(in) + " " + q(out) + " --target-factor 1 --check -q --stats " + q(stats);
  std::string log;

  ASSERT_EQ(run_command(coarsen, &log), 0) << log;
  std::string s = tc::test::read_text(stats);
  EXPECT_EQ(json_value(s, "check"), "\"valid\"") << s.substr(0, 600);
  double tets_in = std::stod(json_value(s, "tets_in")), tets_out = std::stod(json_value(s, "tets_out"));
  EXPECT_GT(tets_out, 0);
  EXPECT_LE(tets_out, tets_in);

  ASSERT_EQ(run_command(coarsen + " --boundary strict", &log), 0) << log;
  s = tc::test::read_text(stats);
  EXPECT_EQ(json_value(s, "check"), "\"valid\"") << s.substr(0, 600);
  std::string report;
  ASSERT_EQ(run_command(cli() + " check " + q(out) + " --reference " + q(in) + " --json - -q 2>/dev/null", &report), 0)
      << report.substr(0, 2000);
  EXPECT_EQ(json_value(report, "hausdorff_computed"), "true") << report.substr(0, 2000);
  const std::string h = json_value(report, "hausdorff");
  ASSERT_FALSE(h.empty()) << report.substr(0, 2000);
  EXPECT_EQ(std::stod(h), 0.0) << "strict boundary moved the surface of " << GetParam();
  EXPECT_EQ(json_value(report, "topology_changed"), "false");
}

INSTANTIATE_TEST_SUITE_P(Corpus, Sample, ::testing::ValuesIn(sample_meshes()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(Sample);

}  // namespace
