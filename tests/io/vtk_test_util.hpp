// Helpers shared by test_vtk.cpp and test_vtu.cpp.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <string>

#include "test_support.hpp"
#include "tetcollapse/error.hpp"
#include "tetcollapse/mesh.hpp"

namespace tc::test {

// A small mesh with every kind of attribute and awkward doubles (thirds, denormals,
// -0.0, huge and tiny values), so that a round trip that is not bit-exact shows.
inline Mesh attribute_mesh() {
  Mesh m = cube_tets(2);
  const int64_t nv = m.num_vertices(), nt = m.num_tets();
  for (size_t i = 0; i < m.points.size(); ++i) m.points[i] = m.points[i] / 3.0 + 1e-17 * double(i);
  Labels mat{"material", {}}, part{"part id", {}};
  for (int64_t t = 0; t < nt; ++t) {
    mat.values.push_back(int32_t(t % 3) + 1);
    part.values.push_back(int32_t(-1000000 + 7 * t));
  }
  m.tet_labels = {mat, part};
  Field pressure{"pressure", 1, {}}, vel{"velocity", 3, {}}, metric{"metric", 6, {}};
  for (int64_t v = 0; v < nv; ++v) {
    pressure.values.push_back(1.0 / double(v + 3));
    for (int c = 0; c < 3; ++c) vel.values.push_back(c == 0 ? -0.0 : std::ldexp(1.0, -1060 + int(v)));
    for (int c = 0; c < 6; ++c) metric.values.push_back(1e300 * double(c) - double(v) / 7.0);
  }
  m.vertex_fields = {pressure, vel, metric};
  Field quality{"quality", 1, {}}, grad{"grad", 3, {}}, stress{"stress", 9, {}};
  for (int64_t t = 0; t < nt; ++t) {
    quality.values.push_back(std::sqrt(double(t) + 0.5));
    for (int c = 0; c < 3; ++c) grad.values.push_back(double(t * 3 + c) * 0.1);
    for (int c = 0; c < 9; ++c) stress.values.push_back(std::numeric_limits<double>::min() * double(c + t));
  }
  m.tet_fields = {quality, grad, stress};
  return m;
}

inline std::map<int32_t, int64_t> histogram(const std::vector<int32_t>& v) {
  std::map<int32_t, int64_t> h;
  for (int32_t x : v) ++h[x];
  return h;
}

// Reads `path` with meshio (Debian python3-meshio) and checks the point and tetra counts
// and that `field` is a point-data array. Skips when meshio cannot be imported.
inline void meshio_cross_read(const std::string& path, int64_t points, int64_t tets, const std::string& field) {
  std::string out;
  if (run_command("/usr/bin/python3 -c 'import meshio' 2>&1", &out) != 0)
    GTEST_SKIP() << "meshio cannot be imported by /usr/bin/python3 (" << out << "); cross-read skipped";
  const std::string script =
      "import meshio,sys; m=meshio.read(sys.argv[1]); "
      "print(len(m.points), sum(len(c.data) for c in m.cells if c.type=='tetra'), int(sys.argv[2] in m.point_data))";
  int rc = run_command("/usr/bin/python3 -c \"" + script + "\" '" + path + "' '" + field + "' 2>&1", &out);
  ASSERT_EQ(rc, 0) << out;
  std::string expected = std::to_string(points) + " " + std::to_string(tets) + " 1";
  EXPECT_NE(out.find(expected), std::string::npos) << "meshio printed: " << out << " expected: " << expected;
}

// Runs `f`, which must throw tc::InputError; returns its message ("" when nothing was thrown).
template <class F>
std::string input_error_of(F&& f) {
  return error_of<InputError>(f);
}

}  // namespace tc::test

namespace tc::test {

// Every prefix of a valid file (in steps of `step` bytes) must read or fail with an
// InputError: never crash, never throw anything else. Returns how many prefixes failed.
template <class Read>
int64_t check_truncations(const std::string& full, const std::string& path, size_t step, Read&& read) {
  int64_t failed = 0;
  for (size_t n = 0; n < full.size(); n += step) {
    write_text(path, full.substr(0, n));
    try {
      read(path);
    } catch (const InputError& e) {
      ++failed;
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "multi-line error: " << e.what();
    }
  }
  return failed;
}

}  // namespace tc::test
