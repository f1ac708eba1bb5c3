// The boundary error bound measured (CollapseOptions::boundary_reference): where the bound
// carried per vertex refuses a change of S, the change is measured against the input's S
// itself. A certified upper bound of a directed Hausdorff distance by branch and bound: the
// distance to one triangle is convex, so over a piece of a triangle it is largest at the
// piece's corners; the smallest such largest value over the triangles near the piece bounds the
// distance to their union from above, the largest distance of a corner to them from below, and
// a piece between the two is split in four. No library does this check (CGAL's
// Polygon_mesh_processing::bounded_error_Hausdorff_distance answers for whole meshes, not for
// one local change tested thousands of times), hence our own.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <unordered_map>
#include <vector>

#include "geometry.h"

namespace tc::surface_distance {

using geo::tc_d3;
using Tri = std::array<tc_d3, 3>;

double point_triangle_dist2(tc_d3 p, const Tri& t);
void box_of(const Tri& t, tc_d3& lo, tc_d3& hi);

class ReferenceSurface;

// Whether every point of `piece` lies within sqrt(e2) of the union of `features` (certified:
// false also when `depth` splits run out). With `relevant`, a piece it declines needs no check,
// and the features need not be all the surface near the piece, so a corner beyond them is no
// proof of a failure: the piece is split instead. With `surface`, whose triangles the features
// are, the triangles around a vertex of theirs may hold a piece together (the fan cover).
bool within(const Tri& piece, const std::vector<const Tri*>& features, double e2, int depth,
            const std::function<bool(const Tri&)>* relevant = nullptr, const ReferenceSurface* surface = nullptr);

// The first bytes of a file of checks recorded with TETCOLLAPSE_RECORD_CHECKS (surface_distance.cpp).
inline constexpr char kRecordMagic[8] = {'t', 'c', 'c', 'h', 'e', 'c', 'k', '1'};

// One recorded ReferenceSurface::change_ok: its arguments.
struct RecordedCheck {
  std::vector<Tri> olds, news, around;
  double e = 0, reach = 0;
};
// Reads such a file: the reference's triangles (9 coordinates each, as ReferenceSurface takes
// them) and the checks; false when it is not one.
bool read_recorded_checks(const char* path, std::vector<double>& reference, std::vector<RecordedCheck>& checks);

// The input's S (triangles, 9 coordinates each) in a uniform grid of cells of twice its mean
// edge length.
class ReferenceSurface {
 public:
  explicit ReferenceSurface(const std::vector<double>& triangles);
  ~ReferenceSurface();
  size_t size() const { return tris_.size(); }
  const Tri& tri(int32_t i) const { return tris_[size_t(i)]; }
  const class Fans* fans() const { return fans_.get(); }
  // The triangles whose boxes meet [lo, hi], into out.
  void query(tc_d3 lo, tc_d3 hi, std::vector<int32_t>& out) const;

  // Whether S, changed from `olds` to `news` (the S triangles around them, `around`, staying),
  // stays within e of this surface both ways, when every point of this surface was within
  // `reach` (>= e) of S before: every point of the new triangles within e of this surface, and
  // every point of this surface within `reach` of the old triangles (the only points whose
  // nearest S may be gone) within e of the new ones or those around. Conservative: false
  // when it cannot tell. One check at a time; a large one measures on two threads.
  bool change_ok(const std::vector<Tri>& olds, const std::vector<Tri>& news, const std::vector<Tri>& around, double e,
                 double reach) const;

 private:
  class Helper;
  static constexpr int kDepth = 8;          // splits of a piece: 4^8 pieces at most
  static constexpr size_t kTwoThreadJobs = 8;  // triangles measured from which a check takes two threads
  static constexpr size_t kJobChunk = 4;       // triangles a thread takes at a time
  std::vector<Tri> tris_;
  std::vector<tc_d3> lo_, hi_, centroids_;  // per triangle: its box and centroid
  std::unique_ptr<class Fans> fans_;  // the triangles around each vertex (surface_distance.cpp)
  std::unordered_map<int64_t, std::vector<int32_t>> cells_;
  double cell_ = 1;
  tc_d3 origin_{0, 0, 0};
  mutable std::vector<uint32_t> seen_;
  mutable uint32_t stamp_ = 0;
  mutable std::unique_ptr<Helper> helper_;  // the second thread, from the first check that takes it
  // per triangle: tri_key of the S triangle that held all of it in the last check that measured
  // it (0: none), tried first the next time (change_ok)
  mutable std::vector<uint64_t> holder_;
};

}  // namespace tc::surface_distance
