// The CPU topology on every shared mesh that tc::read_mesh can read: structural invariants.
// (Separate from test_topology.cpp so that file does not depend on the readers.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "test_support.hpp"
#include "tetcollapse/io.hpp"
#include "tetcollapse/topology.hpp"
#include "topology_checks.hpp"

using namespace tc;

TEST(Topology, SharedMeshesInvariants) {
  TC_SKIP_IF_NO_SHARED();
  int done = 0;
  for (const std::string& path : test::shared_volume_meshes()) {
    Mesh m = read_mesh(path);  // every shared mesh must load (tests/io checks the counts)
    if (m.num_tets() > 120000) continue;  // the large ones are covered by the bench
    SCOPED_TRACE(path);
    Topology t = build_topology(m);
    test::check_invariants(m, t);
    const int64_t V = m.num_vertices();
    // a closed boundary surface: every edge of an outer boundary face has an even, non-zero
    // number of outer boundary faces (two, or four where the surface touches itself)
    for (int32_t e = 0; e < t.num_edges(); ++e) {
      int outer = 0;
      for (int32_t i = t.edge_sfaces_offsets[e]; i < t.edge_sfaces_offsets[e + 1]; ++i)
        outer += t.sface_interface[t.edge_sfaces[i]] == 0;
      ASSERT_EQ(outer % 2, 0) << "edge " << e;
    }
    const TopologySummary s = summarize(m, t);
    EXPECT_GT(s.total_volume, 0);
    EXPECT_EQ(s.face_vertices + s.ridge_vertices + s.corner_vertices + s.interior_vertices, V);
    ++done;
  }
  EXPECT_GT(done, 0) << "no shared mesh checked";
}
