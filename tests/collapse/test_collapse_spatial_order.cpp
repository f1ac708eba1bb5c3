// The spatial order of the device run (host/collapse/spatial_order.*, CollapseTuning::spatial_order):
// a permutation that brings the ends of edges close in index, and with it the result no longer
// depends on how the input happens to be numbered.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <numeric>
#include <random>
#include <set>
#include <vector>

#include "collapse/spatial_order.hpp"
#include "collapse/stages.hpp"
#include "tetcollapse/check.hpp"
#include "tetcollapse/collapse.hpp"
#include "test_support.hpp"

using namespace tc;
using namespace tc::collapse_detail;

namespace {

// The mesh with its vertices and tets renumbered at random (a vertex field and a tet label
// travel along).
Mesh shuffled(const Mesh& in, unsigned seed) {
  std::mt19937 rng(seed);
  const int64_t nv = in.num_vertices(), nt = in.num_tets();
  std::vector<int32_t> vp(nv), tp(nt);  // new -> old
  std::iota(vp.begin(), vp.end(), 0);
  std::iota(tp.begin(), tp.end(), 0);
  std::shuffle(vp.begin(), vp.end(), rng);
  std::shuffle(tp.begin(), tp.end(), rng);
  std::vector<int32_t> vnew(nv);
  for (int64_t i = 0; i < nv; ++i) vnew[vp[i]] = int32_t(i);
  Mesh m;
  for (int64_t i = 0; i < nv; ++i)
    for (int c = 0; c < 3; ++c) m.points.push_back(in.points[3 * vp[i] + c]);
  Labels l{"material", {}};
  for (int64_t j = 0; j < nt; ++j) {
    for (int k = 0; k < 4; ++k) m.tets.push_back(vnew[in.tets[4 * tp[j] + k]]);
    l.values.push_back(in.tet_labels.empty() ? 1 : in.tet_labels[0].values[tp[j]]);
  }
  m.tet_labels.push_back(l);
  Field f{"x", 1, {}};
  for (int64_t i = 0; i < nv; ++i) f.values.push_back(m.points[3 * i]);
  m.vertex_fields.push_back(f);
  return m;
}

// The tets as sets of corner positions, with their labels (numbering-free).
std::multiset<std::pair<std::array<std::array<double, 3>, 4>, int32_t>> geometric_tets(const Mesh& m) {
  std::multiset<std::pair<std::array<std::array<double, 3>, 4>, int32_t>> s;
  for (int64_t t = 0; t < m.num_tets(); ++t) {
    std::array<std::array<double, 3>, 4> q;
    for (int k = 0; k < 4; ++k)
      for (int c = 0; c < 3; ++c) q[k][c] = m.points[3 * m.tets[4 * t + k] + c];
    std::sort(q.begin(), q.end());
    s.insert({q, m.tet_labels.empty() ? 0 : m.tet_labels[0].values[t]});
  }
  return s;
}

double median_index_gap(const std::vector<int32_t>& tets, const std::vector<int32_t>* vertex_new) {
  std::vector<int64_t> gap;
  for (size_t t = 0; t + 3 < tets.size(); t += 4)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        int64_t a = tets[t + i], b = tets[t + j];
        if (vertex_new) a = (*vertex_new)[a], b = (*vertex_new)[b];
        gap.push_back(std::llabs(a - b));
      }
  std::nth_element(gap.begin(), gap.begin() + gap.size() / 2, gap.end());
  return double(gap[gap.size() / 2]);
}

}  // namespace

TEST(SpatialOrder, IsAPermutationThatKeepsEdgeEndsClose) {
  const Mesh m = shuffled(test::cube_tets(8), 1);
  const SpatialOrder o = spatial_order(m);
  const size_t nv = size_t(m.num_vertices()), nt = size_t(m.num_tets());
  ASSERT_EQ(o.vertex_old.size(), nv);
  ASSERT_EQ(o.vertex_new.size(), nv);
  ASSERT_EQ(o.tet_old.size(), nt);
  for (size_t i = 0; i < nv; ++i) EXPECT_EQ(o.vertex_new[size_t(o.vertex_old[i])], int32_t(i));
  std::vector<int32_t> t = o.tet_old;
  std::sort(t.begin(), t.end());
  for (size_t i = 0; i < nt; ++i) ASSERT_EQ(t[i], int32_t(i));
  // tets by their smallest new vertex; tets holds them in that order, renumbered
  ASSERT_EQ(o.tets.size(), 4 * nt);
  int32_t prev = -1;
  for (size_t j = 0; j < nt; ++j) {
    int32_t lo = INT32_MAX;
    for (int k = 0; k < 4; ++k) {
      lo = std::min(lo, o.vertex_new[size_t(m.tets[4 * size_t(o.tet_old[j]) + k])]);
      ASSERT_EQ(o.tets[4 * j + k], o.vertex_new[size_t(m.tets[4 * size_t(o.tet_old[j]) + k])]) << "tet " << j;
    }
    EXPECT_GE(lo, prev) << "tet " << j;
    prev = lo;
  }
  // the ends of an edge: far apart in the shuffled numbering, close after
  const double before = median_index_gap(m.tets, nullptr), after = median_index_gap(m.tets, &o.vertex_new);
  EXPECT_LT(after * 10, before) << "median |a - b| over edges: " << before << " -> " << after;
}

TEST(SpatialOrder, ResultDoesNotDependOnTheInputNumbering) {
  Context ctx;
  Mesh base = test::cube_tets(6);
  Labels l{"material", {}};
  for (int64_t t = 0; t < base.num_tets(); ++t) l.values.push_back(base.points[3 * base.tets[4 * t]] < 0.5 ? 1 : 2);
  base.tet_labels.push_back(l);
  CollapseOptions o;
  o.target_factor = 2;
  std::multiset<std::pair<std::array<std::array<double, 3>, 4>, int32_t>> first;
  for (unsigned seed : {1u, 2u, 3u}) {
    Mesh m = shuffled(base, seed);
    const Mesh in = m;
    CollapseReport r = collapse(m, o, ctx);
    EXPECT_LT(r.tets_out, r.tets_in / 2);
    CheckOptions co;
    co.quality = false;
    co.hausdorff = false;
    CheckReport c = check_mesh(m, co, &in);
    EXPECT_TRUE(c.valid) << check_report_text(c);
    // the vertex field followed its vertices (x of a survivor; midpoints average it)
    for (int64_t v = 0; v < m.num_vertices(); ++v) EXPECT_NEAR(m.vertex_fields[0].values[v], m.points[3 * v], 1e-12);
    auto g = geometric_tets(m);
    if (seed == 1u) first = g;
    else EXPECT_TRUE(g == first) << "seed " << seed << ": " << g.size() << " tets vs " << first.size();
  }
}

TEST(SpatialOrder, OffKeepsTheInputNumberingAndStaysValid) {
  Context ctx;
  const Mesh in = shuffled(test::cube_tets(8), 4);
  CollapseOptions o;
  o.target_factor = 1.5;
  o.boundary = CollapseOptions::Strict;  // boundary vertices never move: many survive unmoved
  Mesh on = in, off = in;
  CollapseReport r_on = collapse(on, o, ctx);
  o.tuning.spatial_order = false;
  CollapseReport r_off = collapse(off, o, ctx);
  CheckOptions co;
  co.quality = false;
  co.hausdorff = false;
  for (const Mesh* m : {&on, &off}) {
    CheckReport c = check_mesh(*m, co, &in);
    EXPECT_TRUE(c.valid) << check_report_text(c);
  }
  EXPECT_LT(r_on.tets_out, r_on.tets_in);
  EXPECT_LT(r_off.tets_out, r_off.tets_in);
  // Without the order the compaction keeps the input's relative order: the vertices that
  // never moved come out in input order. With it they follow the curve instead.
  auto input_indices_of_unmoved = [&](const Mesh& m) {
    std::vector<int64_t> idx;
    for (int64_t v = 0; v < m.num_vertices(); ++v)
      for (int64_t u = 0; u < in.num_vertices(); ++u)
        if (in.points[3 * u] == m.points[3 * v] && in.points[3 * u + 1] == m.points[3 * v + 1] &&
            in.points[3 * u + 2] == m.points[3 * v + 2]) {
          idx.push_back(u);
          break;
        }
    return idx;
  };
  const std::vector<int64_t> a = input_indices_of_unmoved(off), b = input_indices_of_unmoved(on);
  ASSERT_GT(a.size(), 20u);
  ASSERT_GT(b.size(), 20u);
  EXPECT_TRUE(std::is_sorted(a.begin(), a.end()));
  EXPECT_FALSE(std::is_sorted(b.begin(), b.end()));
}
