// Boundary-surface checks that need CGAL Polygon Mesh Processing: self-intersection and
// the Hausdorff distance. The soups come from check.cpp with pinched vertices already split,
// so each one is a valid halfedge mesh (edge-manifold, consistently oriented).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/distance.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <future>

#include "check/check_cgal.hpp"

namespace tc::check_detail {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using SM = CGAL::Surface_mesh<K::Point_3>;
namespace PMP = CGAL::Polygon_mesh_processing;

// Face i of the result is triangle i of the soup (faces are added in order, none removed).
bool build(const Soup& soup, SM& sm, std::string& why_not) {
  const size_t np = soup.points.size() / 3, nf = soup.tris.size() / 3;
  sm.reserve(SM::size_type(np), SM::size_type(3 * nf / 2 + 3), SM::size_type(nf));
  for (size_t i = 0; i < np; ++i) sm.add_vertex(K::Point_3(soup.points[3 * i], soup.points[3 * i + 1], soup.points[3 * i + 2]));
  for (size_t f = 0; f < nf; ++f) {
    SM::Vertex_index a(SM::size_type(soup.tris[3 * f])), b(SM::size_type(soup.tris[3 * f + 1])),
        c(SM::size_type(soup.tris[3 * f + 2]));
    if (sm.add_face(a, b, c) == SM::null_face()) {
      why_not = "boundary triangle " + std::to_string(f) + " cannot join a halfedge mesh (non-manifold surface)";
      return false;
    }
  }
  return true;
}

struct Enough {};  // thrown by the output iterator once max_pairs pairs are collected

struct PairCollector {
  using iterator_category = std::output_iterator_tag;
  using value_type = void;
  using difference_type = std::ptrdiff_t;
  using pointer = void;
  using reference = void;
  SelfIntersections* out;
  int64_t max_pairs;
  PairCollector& operator*() { return *this; }
  PairCollector& operator++() { return *this; }
  PairCollector operator++(int) { return *this; }
  PairCollector& operator=(const std::pair<SM::Face_index, SM::Face_index>& p) {
    out->pairs.emplace_back(int64_t(p.first.idx()), int64_t(p.second.idx()));
    if (int64_t(out->pairs.size()) >= max_pairs) throw Enough{};
    return *this;
  }
};

}  // namespace

SelfIntersections self_intersections(const Soup& soup, int64_t max_pairs) {
  SelfIntersections r;
  if (soup.tris.empty()) {
    r.ran = true;
    return r;
  }
  SM sm;
  if (!build(soup, sm, r.why_not)) return r;
  r.ran = true;
  try {
    PMP::self_intersections(sm, PairCollector{&r, std::max<int64_t>(1, max_pairs)});
  } catch (const Enough&) {
    r.capped = true;
  }
  return r;
}

Hausdorff hausdorff(const Soup& a, const Soup& b, double error_bound) {
  Hausdorff r;
  if (a.tris.empty() || b.tris.empty()) {
    r.why_not = "a boundary surface is empty";
    return r;
  }
  SM ma, mb;
  if (!build(a, ma, r.why_not) || !build(b, mb, r.why_not)) return r;
  // The two directions at once, each on meshes of its own: CGAL may add a property map to a mesh
  // it reads. (Its parallel tag would need TBB; two threads need nothing, and the directions
  // cost about the same.)
  auto other = std::async(std::launch::async, [&, ma2 = ma, mb2 = mb] {
    return PMP::bounded_error_Hausdorff_distance<CGAL::Sequential_tag>(mb2, ma2, error_bound);
  });
  r.a_to_b = PMP::bounded_error_Hausdorff_distance<CGAL::Sequential_tag>(ma, mb, error_bound);
  r.b_to_a = other.get();
  r.ran = true;
  return r;
}

}  // namespace tc::check_detail
