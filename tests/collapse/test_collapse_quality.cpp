// The quality guard (CollapseOptions::min_quality): by induction over the collapses, the worst
// mean ratio of the output is at least min(worst of the input, min_quality).
#include <gtest/gtest.h>

#include <algorithm>

#include "geometry.h"
#include "test_support.hpp"
#include "tetcollapse/check.hpp"
#include "tetcollapse/collapse.hpp"
#include "tetcollapse/io.hpp"

namespace {

double worst_quality(const tc::Mesh& m) {
  double q = 1.0;
  for (int64_t t = 0; t < m.num_tets(); ++t) {
    auto p = [&](int k) { return tc::geo::tc_point(m.points.data(), m.tets[4 * t + k]); };
    q = std::min(q, tc::geo::tc_tet_quality(p(0), p(1), p(2), p(3)));
  }
  return q;
}

TEST(CollapseQuality, GuardKeepsWorstQualityAndWithoutItSliversAppear) {
  tc::Mesh input = tc::read_mesh(tc::test::project_mesh("bracket.msh"));
  const double q_in = worst_quality(input);
  tc::Context ctx;
  tc::CollapseOptions opt;
  opt.target_factor = 2;
  ASSERT_EQ(opt.min_quality, 0.1);  // the documented default

  tc::Mesh guarded = input;
  tc::CollapseReport r = tc::collapse(guarded, opt, ctx);
  EXPECT_LT(r.tets_out, r.tets_in / 4);  // still a strong reduction
  EXPECT_GE(worst_quality(guarded), std::min(q_in, opt.min_quality));
  tc::CheckOptions co;
  co.hausdorff = false;
  EXPECT_TRUE(tc::check_mesh(guarded, co, &input).valid);

  opt.min_quality = 0;  // the paper: only eps_v
  tc::Mesh unguarded = input;
  tc::CollapseReport r0 = tc::collapse(unguarded, opt, ctx);
  EXPECT_LE(r0.tets_out, r.tets_out);
  EXPECT_LT(worst_quality(unguarded), 0.5 * std::min(q_in, 0.1));
}

}  // namespace
