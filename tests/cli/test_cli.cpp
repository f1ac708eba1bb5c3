// The command line as a user meets it: exit codes, messages, --help, --json keys.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iterator>
#include <set>
#include <string>

#include "test_support.hpp"
#include "tetcollapse/io.hpp"

namespace {

using tc::test::run_command;

std::string cli() { return std::string("'") + TC_CLI + "'"; }
std::string q(const std::string& s) { return "'" + s + "'"; }
// How many files and folders are in a folder (a failed write must leave none behind).
int entries(const std::filesystem::path& dir) {
  return int(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()));
}

TEST(Cli, VersionAndHelp) {
  std::string out;
  EXPECT_EQ(run_command(cli() + " --version", &out), 0);
  EXPECT_NE(out.find("tetcollapse " TETCOLLAPSE_VERSION), std::string::npos) << out;
  EXPECT_EQ(run_command(cli() + " --help", &out), 0);
  for (const char* sub : {"info", "convert", "devices", "features"}) EXPECT_NE(out.find(sub), std::string::npos) << sub;
  EXPECT_NE(out.find("Exit codes"), std::string::npos);
  EXPECT_EQ(run_command(cli() + " info --help", &out), 0);
  EXPECT_NE(out.find("--json"), std::string::npos) << out;
  EXPECT_EQ(run_command(cli() + " convert --help", &out), 0);
  EXPECT_NE(out.find("--ascii"), std::string::npos) << out;
}

TEST(Cli, UsageErrorsExitWithTwo) {
  std::string out;
  EXPECT_EQ(run_command(cli(), &out), 2);
  EXPECT_EQ(run_command(cli() + " frobnicate", &out), 2);
  EXPECT_EQ(run_command(cli() + " info", &out), 2);  // MESH missing
  EXPECT_NE(out.find("MESH"), std::string::npos) << out;
}

TEST(Cli, InfoJsonHasTheDocumentedKeys) {
  std::string out;
  ASSERT_EQ(run_command(cli() + " info --json " + q(tc::test::project_mesh("tet.mesh")), &out), 0) << out;
  for (const char* key : {"\"vertices\":4", "\"tets\":1", "\"edges\":6", "\"boundary_faces\":4", "\"edge_length\":{",
                          "\"min\":1", "\"max\":1.4142135623730951", "\"volume\":0.16666666666666666",
                          "\"min_dihedral_deg\":", "\"face_vertices\":0", "\"corner_vertices\":4",
                          "\"ridge_edges\":6"})
    EXPECT_NE(out.find(key), std::string::npos) << key << " not in " << out;
}

TEST(Cli, InfoReportsLabelsOfTwoMaterials) {
  std::string out;
  ASSERT_EQ(run_command(cli() + " info --json " + q(tc::test::project_mesh("two_tets.mesh")), &out), 0) << out;
  EXPECT_NE(out.find("\"medit:ref\":{\"1\":1,\"2\":1}"), std::string::npos) << out;
  EXPECT_NE(out.find("\"interface_faces\":1"), std::string::npos) << out;
}

TEST(Cli, BadInputNamesFileAndLineAndExitsWithTwo) {
  tc::test::TempDir dir;
  std::string out;
  EXPECT_EQ(run_command(cli() + " info " + q(dir.file("missing.msh")), &out), 2);
  EXPECT_NE(out.find("missing.msh"), std::string::npos) << out;

  std::string bad = dir.file("bad.mesh");
  tc::test::write_text(bad, "MeshVersionFormatted 2\nDimension 3\nVertices\n4\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\n"
                            "Tetrahedra\n1\n1 2 3 9 1\nEnd\n");
  EXPECT_EQ(run_command(cli() + " info " + q(bad), &out), 2);
  EXPECT_NE(out.find("bad.mesh:"), std::string::npos) << out;
  EXPECT_NE(out.find("9"), std::string::npos) << out;

  std::string unknown = dir.file("mesh.xyz");
  tc::test::write_text(unknown, "hello");
  EXPECT_EQ(run_command(cli() + " info " + q(unknown), &out), 2);
  EXPECT_NE(out.find("unknown file extension"), std::string::npos) << out;
}

TEST(Cli, ConvertRoundTripsAndNeverLeavesHalfFiles) {
  tc::test::TempDir dir;
  std::string out;
  std::string vtu = dir.file("tet.vtu");
  ASSERT_EQ(run_command(cli() + " convert " + q(tc::test::project_mesh("two_tets.mesh")) + " " + q(vtu), &out), 0) << out;
  ASSERT_EQ(run_command(cli() + " info --json " + q(vtu), &out), 0) << out;
  EXPECT_NE(out.find("\"tets\":2"), std::string::npos) << out;
  // A target folder that does not exist: exit 4, nothing written.
  std::string nowhere = dir.file("no/such/folder/out.msh");
  EXPECT_EQ(run_command(cli() + " convert " + q(tc::test::project_mesh("tet.mesh")) + " " + q(nowhere), &out), 4);
  EXPECT_FALSE(std::filesystem::exists(nowhere));
  // Failed conversion leaves no temporary files in the folder.
  EXPECT_EQ(entries(dir.path()), 1);  // tet.vtu only
}

// An output that cannot be written is refused before the input is read (a long run must not end
// in it): with an input that does not exist either, the error names the output, exit 4 (or 2
// for an unknown --out-format), and nothing is written.
TEST(Cli, UnwritableOutputIsRefusedBeforeTheWork) {
  tc::test::TempDir dir;
  const std::string missing = q(dir.file("missing.mesh")), tet = q(tc::test::project_mesh("tet.mesh"));
  const std::string nowhere = dir.file("no/such/folder/out.vtu");
  struct Case {
    std::string args, expect;
    int code;
  };
  const Case cases[] = {
      {missing + " " + q(nowhere), "no/such/folder' does not exist", 4},
      {missing + " " + q(dir.file("out.xyz")), "unknown file extension '.xyz'", 4},
      {missing + " " + q(dir.file("out.vtu")) + " --stats " + q(dir.file("no/s.json")), "no' does not exist", 4},
      {missing + " " + q(dir.file("out.vtu")) + " --out-format foo", "unknown mesh format", 2},
      {"convert " + missing + " " + q(nowhere), "no/such/folder' does not exist", 4},
      {"features " + missing + " " + q(nowhere), "no/such/folder' does not exist", 4},
      {"check " + missing + " --json " + q(dir.file("no/r.json")), "no' does not exist", 4},
  };
  for (const Case& c : cases) {
    std::string out;
    EXPECT_EQ(run_command(cli() + " " + c.args, &out), c.code) << c.args << "\n" << out;
    EXPECT_NE(out.find(c.expect), std::string::npos) << c.args << "\n" << out;
    EXPECT_EQ(out.find("missing.mesh"), std::string::npos) << "the input was read first: " << out;
  }
  // the same output with a real input: refused before the collapse (no device line, no
  // iteration), nothing written
  std::string out;
  EXPECT_EQ(run_command(cli() + " " + tet + " " + q(dir.file("out.xyz")), &out), 4) << out;
  EXPECT_EQ(out.find("device:"), std::string::npos) << out;
  EXPECT_EQ(out.find("iteration"), std::string::npos) << out;
  EXPECT_EQ(entries(dir.path()), 0);
}

TEST(Cli, DefaultMeshInfo) {
  std::string out;
  ASSERT_EQ(run_command(cli() + " info --json " + q(tc::test::project_mesh("bracket.msh")), &out), 0) << out;
  EXPECT_NE(out.find("\"tets\":23925"), std::string::npos) << out;
  EXPECT_NE(out.find("\"vertices\":5580"), std::string::npos) << out;
}

}  // namespace

namespace {

TEST(Cli, CheckExitCodesAndJson) {
  tc::test::TempDir dir;
  std::string out;
  std::string json = dir.file("report.json");
  ASSERT_EQ(run_command(cli() + " check " + q(tc::test::project_mesh("two_tets.mesh")) + " --json " + q(json), &out), 0)
      << out;
  std::string report = tc::test::read_text(json);
  EXPECT_NE(report.find("\"valid\":true"), std::string::npos) << report;
  // Two tets on the same side of their shared face: they overlap, the face has the same
  // orientation in both; read_mesh accepts it (both positive), the checker must not.
  std::string bad = dir.file("overlap.mesh");
  tc::test::write_text(bad, "MeshVersionFormatted 2\nDimension 3\nVertices\n5\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\n"
                            "0.1 0.1 2 0\nTetrahedra\n2\n1 2 3 4 1\n1 2 3 5 1\nEnd\n");
  EXPECT_EQ(run_command(cli() + " check " + q(bad), &out), 1) << out;
  EXPECT_NE(out.find("face_same_orientation"), std::string::npos) << out;
}

}  // namespace

namespace {

TEST(Cli, CoarsenWritesAValidMeshAndStats) {
  tc::test::TempDir dir;
  std::string out;
  std::string result = dir.file("coarse.vtu"), stats = dir.file("stats.json");
  ASSERT_EQ(run_command(cli() + " " + q(tc::test::project_mesh("bracket.msh")) + " " + q(result) +
                            " --target-factor 1.5 --max-iterations 4 --check --stats " + q(stats),
                        &out),
            0)
      << out;
  EXPECT_NE(out.find("iteration   1:"), std::string::npos) << out;  // progress lines on stderr
  EXPECT_NE(out.find("check: valid"), std::string::npos) << out;
  std::string s = tc::test::read_text(stats);
  for (const char* key : {"\"tets_in\":23925", "\"vertices_in\":5580", "\"tets_out\":", "\"vertices_out\":",
                          "\"device\":", "\"seconds_total\":", "\"seconds_collapse\":", "\"iterations\":[{",
                          "\"collapsed\":", "\"seconds_select\":", "\"refused_by_guard\":", "\"check\":\"valid\""})
    EXPECT_NE(s.find(key), std::string::npos) << key << " not in " << s;
  ASSERT_EQ(run_command(cli() + " check -q " + q(result), &out), 0) << out;
  EXPECT_NE(s.find("\"spatial_order\":true"), std::string::npos) << s;
  // the input's numbering kept on the device: still valid, and said so in the statistics
  ASSERT_EQ(run_command(cli() + " " + q(tc::test::project_mesh("bracket.msh")) + " " + q(result) +
                            " --target-factor 1.5 --max-iterations 4 --no-spatial-order --check -q --stats " + q(stats),
                        &out),
            0)
      << out;
  EXPECT_NE(tc::test::read_text(stats).find("\"spatial_order\":false"), std::string::npos);
  // the host tail: its iterations marked in the progress lines and the statistics (the greedy
  // selection's tail is a long one; the matching selection's dies out fast, on the device)
  ASSERT_EQ(run_command(cli() + " " + q(tc::test::project_mesh("bracket.msh")) + " " + q(result) +
                            " --target-factor 2 --conflicts greedy --host-tail 0.05 --check --stats " + q(stats),
                        &out),
            0)
      << out;
  EXPECT_NE(out.find("(host tail)"), std::string::npos) << out;
  EXPECT_NE(tc::test::read_text(stats).find("\"on_host\":true"), std::string::npos);
  EXPECT_NE(tc::test::read_text(stats).find("\"on_host\":false"), std::string::npos);
  ASSERT_EQ(run_command(cli() + " " + q(tc::test::project_mesh("bracket.msh")) + " " + q(result) +
                            " --target-factor 2 --host-tail 0 -q --stats " + q(stats),
                        &out),
            0)
      << out;
  EXPECT_EQ(tc::test::read_text(stats).find("\"on_host\":true"), std::string::npos);
  EXPECT_NE(run_command(cli() + " " + q(tc::test::project_mesh("bracket.msh")) + " " + q(result) + " --host-tail 2",
                        &out),
            0);
  // Quiet mode prints nothing on success.
  ASSERT_EQ(run_command(cli() + " -q " + q(tc::test::project_mesh("tet.mesh")) + " " + q(dir.file("t.mesh")), &out), 0);
  EXPECT_TRUE(out.empty()) << out;
}

// TETCOLLAPSE_PROFILE_KERNELS=1: the per-kernel table on stderr at the end, with the stages'
// kernels in it, and the same output mesh as without it (the waits change no decision).
// The boundary error bound: the sequential method keeps it (the checker measures the bracket's
// boundary within it), the parallel method takes it, the other modes refuse it.
TEST(Cli, MaxBoundaryErrorHoldsAndIsRefusedWhereItCannot) {
  tc::test::TempDir dir;
  std::string out;
  const std::string in = q(tc::test::project_mesh("bracket.msh")), result = dir.file("b.msh"),
                    stats = dir.file("s.json");
  ASSERT_EQ(run_command(cli() + " " + in + " " + q(result) + " --target-factor 2 --method sequential " +
                            "--max-boundary-error 0.002 --check -q --stats " + q(stats),
                        &out),
            0)
      << out;
  EXPECT_NE(tc::test::read_text(stats).find("\"boundary_error_bound\":"), std::string::npos);
  EXPECT_NE(tc::test::read_text(stats).find("\"refused_by_bound\":"), std::string::npos);
  ASSERT_EQ(run_command(cli() + " check " + q(result) + " --reference " + in + " --json -", &out), 0) << out;
  const size_t at = out.find("\"hausdorff_rel\":");
  ASSERT_NE(at, std::string::npos) << out;
  EXPECT_LE(std::stod(out.substr(at + 16)), 0.002) << out.substr(at, 40);
  EXPECT_EQ(run_command(cli() + " " + in + " " + q(result) + " --max-boundary-error 0.002 -q", &out), 0) << out;
  EXPECT_EQ(run_command(cli() + " " + in + " " + q(result) + " --method sequential --boundary free " +
                            "--max-boundary-error 0.002",
                        &out),
            2);
  EXPECT_NE(out.find("--boundary features"), std::string::npos) << out;
}

// --no-merge-features: a notch an eighth of a cube's side, under a bound larger than it, merges by
// default and stays with the flag (tetcollapse and tetcollapse-mpi take the same flag).
TEST(Cli, NoMergeFeaturesKeepsADetailSmallerThanTheBound) {
  tc::test::TempDir dir;
  tc::write_mesh(dir.file("in.vtu"), tc::test::notched_cube(8));
  std::string out;
  int64_t tets[2];
  for (bool keep : {false, true}) {
    ASSERT_EQ(run_command(cli() + " " + q(dir.file("in.vtu")) + " " + q(dir.file("o.vtu")) +
                              " --target-factor 2 --no-improve --max-boundary-error 0.08 -q" +
                              (keep ? " --no-merge-features" : ""),
                          &out),
              0)
        << out;
    tets[keep] = tc::read_mesh(dir.file("o.vtu")).num_tets();
  }
  EXPECT_LT(tets[0], tets[1]) << "the notch merges unless --no-merge-features";
}

// --region and --labels: the tets with no vertex in the region (or of the labels left out) come
// out as they went in, bit for bit, improvement phase included; the rest coarsens. A bad region
// or labels on a mesh without any: exit 2, naming the option.
TEST(Cli, RegionAndLabelsLeaveTheRestAsItWas) {
  tc::test::TempDir dir;
  tc::write_mesh(dir.file("in.vtu"), tc::test::two_material_bracket());
  const tc::Mesh in = tc::read_mesh(dir.file("in.vtu"));
  std::string out;
  for (const auto& [opts, untouched] : tc::test::restricted_runs(in)) {
    ASSERT_EQ(run_command(cli() + " " + q(dir.file("in.vtu")) + " " + q(dir.file("o.vtu")) + " --target-factor 2 -q " +
                              opts,
                          &out),
              0)
        << out;
    const tc::Mesh o = tc::read_mesh(dir.file("o.vtu"));
    const auto [kept, asked] = tc::test::tets_kept(in, o, untouched);
    EXPECT_GT(asked, in.num_tets() / 10) << opts;
    EXPECT_EQ(kept, asked) << opts << ": tets outside changed";
    EXPECT_LT(o.num_tets() - asked, (in.num_tets() - asked) / 2) << opts << ": the rest did not coarsen";
  }
  EXPECT_EQ(run_command(cli() + " " + q(dir.file("in.vtu")) + " " + q(dir.file("x.vtu")) + " --region cube:1", &out), 2);
  EXPECT_NE(out.find("--region"), std::string::npos) << out;
  tc::write_mesh(dir.file("nolabels.vtu"), tc::test::cube_tets(2));
  EXPECT_EQ(run_command(cli() + " " + q(dir.file("nolabels.vtu")) + " " + q(dir.file("x.vtu")) + " --labels 1", &out), 2);
  EXPECT_NE(out.find("no labels"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir.file("x.vtu")));
}

// A first run (empty kernel caches) says that it compiles, then each program as it is done, up to
// all of them, each program once (the run's boundary error bound builds one variant of the
// programs that test it; the vertex field's values from the input sort and scan after the
// collapse, with the scan the collapse used); a second run from the caches says nothing of it.
TEST(Cli, AFirstRunShowsTheCompileProgress) {
  tc::test::TempDir dir;
  std::string out;
  tc::Mesh in = tc::read_mesh(tc::test::project_mesh("bracket.msh"));
  tc::Field f{"x", 1, {}};
  for (int64_t v = 0; v < in.num_vertices(); ++v) f.values.push_back(in.points[3 * size_t(v)]);
  in.vertex_fields.push_back(f);
  tc::write_mesh(dir.file("in.vtu"), in);
  const std::string env = "POCL_CACHE_DIR=" + q(dir.file("pocl")) + " TETCOLLAPSE_CACHE_DIR=" + q(dir.file("tc")) + " ";
  const std::string cmd = env + cli() + " " + q(dir.file("in.vtu")) + " " + q(dir.file("o.vtu")) + " --target-factor 2";
  ASSERT_EQ(run_command(cmd, &out), 0) << out;
  EXPECT_NE(out.find("compiling kernels for "), std::string::npos) << out;
  const size_t first = out.find("  compiled 1 of ");
  ASSERT_NE(first, std::string::npos) << out;
  const int total = std::atoi(out.c_str() + first + std::string("  compiled 1 of ").size());
  EXPECT_GT(total, 1);
  EXPECT_NE(out.find("  compiled " + std::to_string(total) + " of " + std::to_string(total) + " programs"),
            std::string::npos)
      << out;
  std::set<std::string> programs;
  for (size_t at = out.find("programs ("); at != std::string::npos; at = out.find("programs (", at + 1)) {
    const size_t open = at + std::string("programs (").size();
    EXPECT_TRUE(programs.insert(out.substr(open, out.find(')', open) - open)).second)
        << "a program compiled twice: " << out;
  }
  EXPECT_EQ(programs.size(), size_t(total)) << out;
  ASSERT_EQ(run_command(cmd, &out), 0) << out;
  EXPECT_EQ(out.find("compil"), std::string::npos) << out;
}

// The boundary error bound by default in features mode (0.001 x the diagonal, 4.657 on the
// bracket), none in strict mode or with 0; given with strict, refused.
TEST(Cli, ABoundaryErrorBoundByDefaultInFeaturesMode) {
  tc::test::TempDir dir;
  std::string out;
  const std::string stats = dir.file("s.json");
  const auto bound = [&](const std::string& opts) {
    EXPECT_EQ(run_command(cli() + " " + q(tc::test::project_mesh("bracket.msh")) + " " + q(dir.file("o.msh")) +
                              " --target-factor 2 -q --stats " + q(stats) + " " + opts,
                          &out),
              0)
        << opts << "\n" << out;
    const std::string s = tc::test::read_text(stats);
    const size_t at = s.find("\"boundary_error_bound\":");
    return at == std::string::npos ? -1.0 : std::atof(s.c_str() + at + 23);
  };
  EXPECT_NEAR(bound(""), 0.001 * std::sqrt(4.0 * 4 + 2 * 2 + 1.3 * 1.3), 1e-12);
  EXPECT_EQ(bound("--max-boundary-error 0"), 0.0);
  EXPECT_EQ(bound("--boundary strict"), 0.0);
  EXPECT_NEAR(bound("--max-boundary-error-abs 0.01"), 0.01, 1e-15);
  EXPECT_EQ(run_command(cli() + " " + q(tc::test::project_mesh("bracket.msh")) + " " + q(dir.file("o.msh")) +
                            " --boundary strict --max-boundary-error 0.001",
                        &out),
            2)
      << out;
}

TEST(Cli, KernelProfileTableAndTheSameResult) {
  tc::test::TempDir dir;
  std::string out;
  const std::string in = q(tc::test::project_mesh("bracket.msh")), a = dir.file("a.vtu"), b = dir.file("b.vtu");
  // (the matching selection's kernels: without the default boundary error bound, which selects greedily)
  ASSERT_EQ(run_command("TETCOLLAPSE_PROFILE_KERNELS=1 " + cli() + " " + in + " " + q(a) + " -q --max-boundary-error 0", &out),
            0)
      << out;
  EXPECT_NE(out.find("kernel profile (TETCOLLAPSE_PROFILE_KERNELS)"), std::string::npos) << out;
  for (const char* k : {"match_decide", "match_apply", "conn_ring_sort_and_gather", "cost_and_mark", "sguard_surface"})
    EXPECT_NE(out.find(std::string("\n  ") + k + " "), std::string::npos) << k << " not in " << out;
  ASSERT_EQ(run_command(cli() + " " + in + " " + q(b) + " -q --max-boundary-error 0", &out), 0) << out;
  EXPECT_TRUE(out.empty()) << out;  // off by default: quiet stays quiet
  EXPECT_EQ(tc::test::read_text(a), tc::test::read_text(b));
}

}  // namespace

namespace {

TEST(Cli, UserPlacementAndPredicateFiles) {
  tc::test::TempDir dir;
  std::string out;
  const std::string in = q(tc::test::project_mesh("bracket.msh")), result = q(dir.file("o.vtu")),
                    stats = q(dir.file("s.json"));
  const std::string none = dir.file("none.cl"), keep = dir.file("keep.cl"), bad = dir.file("bad.cl");
  tc::test::write_text(none, "int tc_user_predicate(double3 p0, double3 p1, double f0, double f1) { return 0; }\n");
  tc::test::write_text(keep, "double3 tc_user_placement(double3 p0, double3 p1, double f0, double f1) { return p0; }\n");
  tc::test::write_text(bad, "double3 tc_user_placement(double3 p0) { return nonsense; }\n");
  // a predicate refusing every edge: nothing collapses
  ASSERT_EQ(run_command(cli() + " " + in + " " + result + " -q --predicate-cl " + q(none) + " --stats " + stats, &out), 0)
      << out;
  EXPECT_NE(tc::test::read_text(dir.file("s.json")).find("\"tets_out\":23925"), std::string::npos);
  // a placement (strict mode: only interior edges take it): valid, coarser, and every vertex at
  // an input vertex's place, where the midpoint makes new places
  const std::set<tc::test::Point3> places = tc::test::vertex_positions(tc::read_mesh(tc::test::project_mesh("bracket.msh")));
  auto new_places = [&]() {
    int n = 0;
    for (const tc::test::Point3& p : tc::test::vertex_positions(tc::read_mesh(dir.file("o.vtu")))) n += !places.count(p);
    return n;
  };
  ASSERT_EQ(run_command(cli() + " " + in + " " + result + " -q --check --boundary strict", &out), 0) << out;
  EXPECT_GT(new_places(), 0);
  ASSERT_EQ(run_command(cli() + " " + in + " " + result + " -q --check --boundary strict --placement-cl " + q(keep) +
                            " --stats " + stats,
                        &out),
            0)
      << out;
  EXPECT_EQ(tc::test::read_text(dir.file("s.json")).find("\"tets_out\":23925"), std::string::npos);
  EXPECT_EQ(new_places(), 0);
  // a missing file names it (usage error); a source that does not compile is a device error
  EXPECT_EQ(run_command(cli() + " " + in + " " + result + " --placement-cl " + q(dir.file("absent.cl")), &out), 2);
  EXPECT_NE(out.find("absent.cl"), std::string::npos) << out;
  EXPECT_EQ(run_command(cli() + " " + in + " " + result + " --placement-cl " + q(bad), &out), 3) << out;
  EXPECT_NE(out.find("bad.cl:1:"), std::string::npos) << out;  // the compiler's messages name the file and line
  // OpenCL C needs the parallel method
  EXPECT_EQ(run_command(cli() + " " + in + " " + result + " --method sequential --predicate-cl " + q(none), &out), 2);
  EXPECT_NE(out.find("--predicate-cl"), std::string::npos) << out;
}

TEST(Cli, TheExampleUserFunctionsDoWhatTheySay) {
  // examples/user_functions/*.cl on a cube with the field f = x^2: each run is valid and differs
  // from the run without it as the example says.
  tc::test::TempDir dir;
  std::string out;
  tc::Mesh m = tc::test::cube_tets(4);
  tc::Field f{"f", 1, {}};
  for (int64_t v = 0; v < m.num_vertices(); ++v) f.values.push_back(m.points[3 * v] * m.points[3 * v]);
  m.vertex_fields.push_back(f);
  const std::string in = dir.file("cube.vtu"), result = dir.file("o.vtu");
  tc::write_mesh(in, m);
  const std::string ex = std::string(TC_SOURCE_DIR) + "/examples/user_functions/";
  const std::string run = cli() + " " + q(in) + " " + q(result) + " -q --check ";
  auto tets_after = [&](const std::string& options) {
    EXPECT_EQ(run_command(run + options, &out), 0) << options << ": " << out;
    return tc::read_mesh(result).num_tets();
  };
  // the cost: the length weighted up where f changes, so fewer edges are short enough
  const int64_t plain = tets_after("--target-length 0.3");
  EXPECT_LT(plain, m.num_tets());
  EXPECT_GT(tets_after("--cost-cl " + q(ex + "field_cost.cl") + " --target-length 0.3"), plain);

  // the placement: every survivor keeps the larger value of f with its place (or the midpoint
  // between equal values), so f = x^2 still holds at every vertex; the midpoint breaks it
  auto x2_holds = [&](const tc::Mesh& r) {
    int broken = 0;
    for (int64_t v = 0; v < r.num_vertices(); ++v)
      broken += r.vertex_fields.at(0).values[size_t(v)] != r.points[3 * v] * r.points[3 * v];
    return broken == 0;
  };
  EXPECT_LT(tets_after("--boundary free --min-quality 0"), m.num_tets());
  EXPECT_FALSE(x2_holds(tc::read_mesh(result)));
  EXPECT_LT(tets_after("--placement-cl " + q(ex + "keep_maximum.cl") + " --boundary free --min-quality 0"),
            m.num_tets());
  EXPECT_TRUE(x2_holds(tc::read_mesh(result)));

  // the predicate: every vertex at z >= 0.5 stays
  EXPECT_LT(tets_after("--predicate-cl " + q(ex + "below_plane.cl") + " --target-length 0.5"), m.num_tets());
  const std::set<tc::test::Point3> after = tc::test::vertex_positions(tc::read_mesh(result));
  for (const tc::test::Point3& p : tc::test::vertex_positions(m))
    if (std::get<2>(p) >= 0.5) {
      EXPECT_TRUE(after.count(p)) << "z " << std::get<2>(p);
    }
}

TEST(Cli, DeviceErrorsExitWithThree) {
  tc::test::TempDir dir;
  std::string out;
  EXPECT_EQ(run_command(cli() + " " + q(tc::test::project_mesh("tet.mesh")) + " " + q(dir.file("o.mesh")) +
                            " --device no-such-device-xyz",
                        &out),
            3)
      << out;
  EXPECT_NE(out.find("no-such-device-xyz"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir.file("o.mesh")));
  // The environment variable is used when --device is absent.
  EXPECT_EQ(run_command("TETCOLLAPSE_DEVICE=no-such-device-xyz " + cli() + " " + q(tc::test::project_mesh("tet.mesh")) +
                            " " + q(dir.file("o.mesh")),
                        &out),
            3)
      << out;
  EXPECT_EQ(run_command(cli() + " devices --json", &out), 0) << out;
  EXPECT_NE(out.find("\"fp64\":true"), std::string::npos) << out;
}

// A mesh whose estimated device memory exceeds the device's global memory is refused before the
// collapse starts, with both sizes (the device's memory lowered by TETCOLLAPSE_TEST_GLOBAL_MEM).
TEST(Cli, AMeshTooLargeForTheDeviceIsRefusedWithTheSizes) {
  tc::test::TempDir dir;
  std::string out;
  const std::string mesh = q(tc::test::project_mesh("bracket.msh"));
  EXPECT_EQ(run_command("TETCOLLAPSE_TEST_GLOBAL_MEM=3000000 " + cli() + " " + mesh + " " + q(dir.file("o.msh")), &out), 3)
      << out;
  EXPECT_NE(out.find("too large for device"), std::string::npos) << out;
  EXPECT_NE(out.find("MiB of device memory, and the device has 2 MiB (CL_DEVICE_GLOBAL_MEM_SIZE)"), std::string::npos)
      << out;
  EXPECT_EQ(out.find("iteration"), std::string::npos) << out;  // before any work
  EXPECT_FALSE(std::filesystem::exists(dir.file("o.msh")));
  // the sequential method needs no device memory; a device with enough runs it
  EXPECT_EQ(run_command("TETCOLLAPSE_TEST_GLOBAL_MEM=3000000 " + cli() + " " + mesh + " " + q(dir.file("s.msh")) +
                            " --method sequential --no-improve -q",
                        &out),
            0)
      << out;
  EXPECT_EQ(run_command("TETCOLLAPSE_TEST_GLOBAL_MEM=1000000000 " + cli() + " " + mesh + " " + q(dir.file("p.msh")) +
                            " --no-improve -q",
                        &out),
            0)
      << out;
  EXPECT_EQ(run_command("TETCOLLAPSE_TEST_GLOBAL_MEM=lots " + cli() + " " + mesh + " " + q(dir.file("x.msh")), &out), 3)
      << out;
}

TEST(Cli, FeaturesWritesTheClassificationAsFields) {
  tc::test::TempDir dir;
  std::string out, vtu = dir.file("features.vtu");
  ASSERT_EQ(run_command(cli() + " features " + q(tc::test::project_mesh("bracket.msh")) + " " + q(vtu), &out), 0)
      << out;
  EXPECT_NE(out.find("2320 face, 408 ridge, 571 corner vertices, 432 ridge edges"), std::string::npos) << out;
  std::string text = tc::test::read_text(vtu);
  EXPECT_NE(text.find("Name=\"vertex_class\""), std::string::npos);
  EXPECT_NE(text.find("Name=\"on_surface\""), std::string::npos);
  // The same counts as info --json reports.
  ASSERT_EQ(run_command(cli() + " info --json " + q(tc::test::project_mesh("bracket.msh")), &out), 0);
  EXPECT_NE(out.find("\"face_vertices\":2320,\"ridge_vertices\":408,\"corner_vertices\":571,\"ridge_edges\":432"),
            std::string::npos)
      << out;
}

}  // namespace
