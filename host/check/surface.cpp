// Boundary-surface checks that need CGAL Polygon Mesh Processing: self-intersection and
// the Hausdorff distance. The soups come from check.cpp with pinched vertices already split,
// so each one is a valid halfedge mesh (edge-manifold, consistently oriented).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/distance.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <algorithm>
#include <future>
#include <thread>

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
  // Both directions at once, each in parts: the distance from a surface is the largest from its
  // parts (each within the error bound of its own, so their largest is of the whole). A part is
  // its triangles, each with corners of its own (a part of a surface may pinch where the whole
  // does not); every task reads meshes of its own, since CGAL may add a property map to a mesh it
  // reads. Each task gives the same value whatever the thread that runs it. (CGAL's parallel tag
  // would need TBB and METIS.)
  // (at most kMaxParts per direction: each part holds a copy of the other surface)
  constexpr size_t kMaxParts = 4;
  const size_t threads = std::min<size_t>(kMaxParts, std::max(1u, std::thread::hardware_concurrency()));
  const auto from_parts = [&](const Soup& from, const SM& to) {
    const size_t nf = from.tris.size() / 3, parts = std::min(threads, std::max<size_t>(1, nf / 1024));
    std::vector<std::future<double>> tasks;
    for (size_t k = 0; k < parts; ++k)
      tasks.push_back(std::async(std::launch::async, [&from, target = to, error_bound, f0 = nf * k / parts,
                                                      f1 = nf * (k + 1) / parts] {
        SM part;
        part.reserve(SM::size_type(3 * (f1 - f0)), SM::size_type(3 * (f1 - f0)), SM::size_type(f1 - f0));
        for (size_t f = f0; f < f1; ++f) {
          SM::Vertex_index v[3];
          for (int c = 0; c < 3; ++c) {
            const size_t p = size_t(from.tris[3 * f + size_t(c)]);
            v[c] = part.add_vertex(K::Point_3(from.points[3 * p], from.points[3 * p + 1], from.points[3 * p + 2]));
          }
          part.add_face(v[0], v[1], v[2]);
        }
        return PMP::bounded_error_Hausdorff_distance<CGAL::Sequential_tag>(part, target, error_bound);
      }));
    return tasks;
  };
  auto ab = from_parts(a, mb), ba = from_parts(b, ma);
  const auto largest = [](std::vector<std::future<double>>& tasks) {
    double d = 0;
    for (auto& t : tasks) d = std::max(d, t.get());
    return d;
  };
  r.a_to_b = largest(ab);
  r.b_to_a = largest(ba);
  r.ran = true;
  return r;
}

}  // namespace tc::check_detail
