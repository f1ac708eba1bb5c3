// Exact orientation of tets with CGAL's filtered predicates (Epick): the interval filter
// decides almost every tet in double precision; exact arithmetic only for near-flat ones.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include "check/check_cgal.hpp"

namespace tc::check_detail {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;

void exact_orientation(const std::vector<double>& points, const std::vector<int32_t>& tets,
                       const std::vector<uint8_t>& skip, std::vector<int8_t>& sign) {
  const size_t nt = tets.size() / 4;
  sign.assign(nt, 0);
  auto P = [&](int32_t v) { return K::Point_3(points[3 * size_t(v)], points[3 * size_t(v) + 1], points[3 * size_t(v) + 2]); };
  K::Orientation_3 orient = K().orientation_3_object();
  for (size_t t = 0; t < nt; ++t) {
    if (!skip.empty() && skip[t]) continue;
    const int32_t* v = &tets[4 * t];
    // CGAL::orientation(p, q, r, s) is the sign of det[q-p, r-p, s-p]: POSITIVE when s is
    // on the side of plane (p, q, r) that (q-p)x(r-p) points to, as geo::tc_orient3d.
    CGAL::Orientation o = orient(P(v[0]), P(v[1]), P(v[2]), P(v[3]));
    sign[t] = o == CGAL::POSITIVE ? 1 : o == CGAL::NEGATIVE ? -1 : 0;
  }
}

}  // namespace tc::check_detail
