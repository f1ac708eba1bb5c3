// The checker's CGAL-facing pieces (exact.cpp, surface.cpp). Only plain types cross this
// interface so that check.cpp compiles without CGAL headers.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace tc::check_detail {

// Exact sign of CGAL::orientation(p0, p1, p2, p3) for every tet whose `skip` entry is 0
// (skip may be empty); sign[t] = +1, -1, 0 (0 for skipped tets too).
void exact_orientation(const std::vector<double>& points, const std::vector<int32_t>& tets,
                       const std::vector<uint8_t>& skip, std::vector<int8_t>& sign);

// A triangle surface whose vertices are not pinched (every vertex one umbrella), so that it
// can be a CGAL halfedge mesh. origin[i] is the vertex of the tet mesh point i came from.
struct Soup {
  std::vector<double> points;      // 3 per point
  std::vector<int32_t> tris;       // 3 per triangle
  std::vector<int64_t> origin;     // per point
};

struct SelfIntersections {
  bool ran = false;
  std::string why_not;                         // when !ran
  bool capped = false;                         // stopped after max_pairs pairs
  std::vector<std::pair<int64_t, int64_t>> pairs;  // intersecting triangles (soup indices)
};
SelfIntersections self_intersections(const Soup& soup, int64_t max_pairs);

struct Hausdorff {
  bool ran = false;
  std::string why_not;
  double a_to_b = 0, b_to_a = 0;
};
// Two-sided Hausdorff distance between the surfaces, each direction within error_bound.
Hausdorff hausdorff(const Soup& a, const Soup& b, double error_bound);

}  // namespace tc::check_detail
