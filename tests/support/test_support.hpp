// Helpers shared by the test executables.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "tetcollapse/mesh.hpp"

namespace tc::test {

// ../shared/meshes beside the project, or "" when absent (tests then GTEST_SKIP with a message).
std::string shared_meshes_dir();
// Full path of a shared mesh, or "" when the folder or the file is absent.
std::string shared_mesh(const std::string& name);
// Every volume mesh file of ../shared/meshes (not .sol, not surfaces/ or cad/).
std::vector<std::string> shared_volume_meshes();
// meshes/ of this project.
std::string project_mesh(const std::string& name);

// A fresh temporary folder, removed when the object dies.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// Sets an environment variable for the lifetime of the object (the previous value comes back).
class EnvVar {
 public:
  EnvVar(const char* name, const std::string& value);
  ~EnvVar();

 private:
  const char* name_;
  bool had_old_ = false;
  std::string old_;
};

void write_text(const std::string& path, const std::string& text);
std::string read_text(const std::string& path);

// The same doubles bit for bit (NaN and -0 included), and as many.
bool same_bits(const std::vector<double>& a, const std::vector<double>& b);
// Two meshes are the same bit for bit: points, tets (their vertex order too), every label array
// and every tet and vertex field with their names (gtest expectations; `what` goes into their
// messages).
void expect_same_mesh(const Mesh& a, const Mesh& b, const std::string& what = "");

// Small meshes built in code.
Mesh single_tet();             // the unit right-corner tet, positively oriented
Mesh cube_tets(int n);         // [0,1]^3 split into n^3 cubes of 6 tets each (Kuhn), labels none
Mesh slab(int n);              // the bottom layer of cube_tets(n): one tet thick, every vertex on the boundary
Mesh two_materials(int n);     // cube_tets(n) with labels 1 below z = 0.5 and 2 above (an interface plane)
Mesh ball(int n);              // cube_tets(n) in [-1, 1]^3, pushed out to the unit ball (x -> x |x|_inf / |x|_2)
// cube_tets(n) in [-1, 1]^3 pushed out radially onto a cylinder of radius 1 and height 2 whose two
// rims are rounded by fillets of radius `fillet` (a smooth surface: flat caps, a cylinder, two
// toroidal bands).
Mesh filleted_cylinder(int n, double fillet);
// A solid torus of radii R = 2 (the ring) and 1 (the tube): a ring of `ring` x n x n cells of 6
// tets each (Kuhn), closed around, its square cross-section pushed out onto the disc as ball()'s.
Mesh torus(int n, int ring);
// cube_tets(n) labelled ("material") by the side of the plane coordinate `axis` = 0.5 each tet's
// centroid lies on: `below` or `above`
Mesh split_materials(int n, int axis, int32_t below, int32_t above);
// The tets t of m with keep(t), in order, with only their vertices (renumbered in order of use).
Mesh sub_mesh(const Mesh& m, const std::function<bool(int64_t)>& keep);
// cube_tets(n) notched at its corner (1, 1, 1): the tets whose centroid lies in [1 - 1/n, 1]^3
// taken out (a detail of the boundary an n-th of the side, three concave ridges, corners).
Mesh notched_cube(int n);
// m closed by a cone: a new last vertex at (x, y, z) joined by a tet to every boundary face (each
// tet made positively oriented, whatever it overlaps; labelled as the tet it closes; m's fields,
// triangles and edges are dropped). No boundary is left: the new vertex plays the virtual vertex
// of the link condition as a real one.
Mesh cone_boundary(const Mesh& m, double x, double y, double z);

// Adaptive marking tests: a vertex mask selecting the vertices with x < x_max; the positions
// of the others (which no collapse may move or remove) go to *unselected.
using Point3 = std::tuple<double, double, double>;
std::vector<uint8_t> mask_x_below(const Mesh& m, double x_max, std::set<Point3>* unselected);
// The vertex positions of a mesh.
std::set<Point3> vertex_positions(const Mesh& m);
// How many of the tets t of `in` with which(t) `out` has too, with the same four vertex
// positions bit for bit (in any order): {found, asked}.
std::pair<int64_t, int64_t> tets_kept(const Mesh& in, const Mesh& out, const std::function<bool(int64_t)>& which);
// bracket.msh with a primary label "material" of 7 where a tet's centroid has x below the mean
// vertex x and 9 elsewhere (a plane interface); its other labels and fields dropped.
Mesh two_material_bracket();
// Options that keep a run to part of `in` (two_material_bracket() as read back), each with the
// tets of `in` it must leave as they are: --region box:0,0,0,2,2,1.3 (the tets with every
// vertex at x > 2) and --labels 7 (the tets labelled 9). `in` must outlive the tests.
std::vector<std::pair<std::string, std::function<bool(int64_t)>>> restricted_runs(const Mesh& in);
// The faces of the feature surface S (tc::build_topology) as sorted vertex triples, and the
// indices of the triangles of m.tris that are not among them.
std::set<std::array<int32_t, 3>> sface_keys(const Mesh& m);
std::vector<size_t> triangles_off_surface(const Mesh& m);

// Runs a shell command, returns its exit code; its stdout+stderr go into *output.
int run_command(const std::string& cmd, std::string* output);

// Runs `f`, which must throw E; returns its message ("" when nothing was thrown).
template <class E, class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  return "";
}

}  // namespace tc::test

#define TC_SKIP_IF_NO_SHARED()                                                                       \
  do {                                                                                               \
    if (tc::test::shared_meshes_dir().empty())                                                       \
      GTEST_SKIP() << "../shared/meshes is not present beside the project; shared-mesh test skipped"; \
  } while (0)
