// The boundary error bound measured (surface_distance.hpp).
#include "collapse/surface_distance.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <thread>

#include "topology/topology_detail.hpp"

namespace tc::surface_distance {

using geo::dot;

namespace {

double point_segment_dist2(tc_d3 p, tc_d3 a, tc_d3 b) {
  const tc_d3 ab = b - a;
  const double l2 = dot(ab, ab);
  const double s = l2 > 0 ? std::clamp(dot(p - a, ab) / l2, 0.0, 1.0) : 0.0;
  const tc_d3 d = p - (a + ab * s);
  return dot(d, d);
}

// The closest point of a triangle (Ericson, Real-Time Collision Detection, 5.1.5); NaN for a
// triangle of no area (its divisions 0 / 0).
double point_triangle_dist2_ericson(tc_d3 p, const Tri& t) {
  const tc_d3 a = t[0], b = t[1], c = t[2];
  const tc_d3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  tc_d3 q;
  if (d1 <= 0 && d2 <= 0) {
    q = a;
  } else {
    const tc_d3 bp = p - b;
    const double d3 = dot(ab, bp), d4 = dot(ac, bp);
    const double vc = d1 * d4 - d3 * d2;
    if (d3 >= 0 && d4 <= d3) {
      q = b;
    } else if (vc <= 0 && d1 >= 0 && d3 <= 0) {
      q = a + ab * std::clamp(d1 / (d1 - d3), 0.0, 1.0);
    } else {
      const tc_d3 cp = p - c;
      const double d5 = dot(ab, cp), d6 = dot(ac, cp);
      const double vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
      if (d6 >= 0 && d5 <= d6) {
        q = c;
      } else if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        q = a + ac * std::clamp(d2 / (d2 - d6), 0.0, 1.0);
      } else if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        q = b + (c - b) * std::clamp((d4 - d3) / ((d4 - d3) + (d5 - d6)), 0.0, 1.0);
      } else {
        // (clamped into the triangle: a point of it, so never nearer than the triangle is)
        const double den = 1 / (va + vb + vc);
        double v = std::max(0.0, vb * den), w = std::max(0.0, vc * den);
        if (v + w > 1) {
          const double sum = v + w;
          v /= sum;
          w /= sum;
        }
        q = a + ab * v + ac * w;
      }
    }
  }
  const tc_d3 d = p - q;
  return dot(d, d);
}

}  // namespace

// A triangle of no area is the union of its edges.
double point_triangle_dist2(tc_d3 p, const Tri& t) {
  const double d = point_triangle_dist2_ericson(p, t);
  if (std::isfinite(d)) return d;
  return std::min({point_segment_dist2(p, t[0], t[1]), point_segment_dist2(p, t[1], t[2]),
                   point_segment_dist2(p, t[2], t[0])});
}

void box_of(const Tri& t, tc_d3& lo, tc_d3& hi) {
  lo = hi = t[0];
  for (int k = 1; k < 3; ++k) {
    lo = {std::min(lo.x, t[k].x), std::min(lo.y, t[k].y), std::min(lo.z, t[k].z)};
    hi = {std::max(hi.x, t[k].x), std::max(hi.y, t[k].y), std::max(hi.z, t[k].z)};
  }
}

namespace {

// The squared distance from p to the box [lo, hi]: at most p's to anything in the box.
double box_dist2(tc_d3 p, tc_d3 lo, tc_d3 hi) {
  const double dx = std::max({lo.x - p.x, 0.0, p.x - hi.x}), dy = std::max({lo.y - p.y, 0.0, p.y - hi.y}),
               dz = std::max({lo.z - p.z, 0.0, p.z - hi.z});
  return dx * dx + dy * dy + dz * dz;
}

tc_d3 centroid_of(const Tri& t) { return (t[0] + t[1] + t[2]) * (1.0 / 3); }

// A triangle's name whatever the order of its corners (a hash of their bits, never 0): a hint
// only, every use of it checks the distances again.
uint64_t tri_key(const Tri& t) {
  std::array<tc_d3, 3> c = t;
  const auto less = [](const tc_d3& a, const tc_d3& b) {
    return a.x < b.x || (a.x == b.x && (a.y < b.y || (a.y == b.y && a.z < b.z)));
  };
  std::sort(c.begin(), c.end(), less);
  uint64_t h = 0x9e3779b97f4a7c15ull;
  for (const tc_d3& p : c)
    for (double x : {p.x, p.y, p.z}) {
      uint64_t b;
      std::memcpy(&b, &x, sizeof b);
      h ^= b + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    }
  return h ? h : 1;
}

bool boxes_apart(tc_d3 alo, tc_d3 ahi, tc_d3 blo, tc_d3 bhi, double pad) {
  return alo.x > bhi.x + pad || ahi.x < blo.x - pad || alo.y > bhi.y + pad || ahi.y < blo.y - pad ||
         alo.z > bhi.z + pad || ahi.z < blo.z - pad;
}

}  // namespace

// A surface's vertices (triangle corners equal to the bit), the triangles around each, and per
// vertex, computed when first asked (from any thread), its fan as wedges (Pieces::fan_holds).
class Fans {
 public:
  explicit Fans(const std::vector<Tri>& tris);

  struct Fan {
    tc_d3 o, n;                     // the vertex, the axis (the fan's mean normal)
    double radius;                  // of the ball around o that holds the fan
    const int32_t *tri, *from;      // per wedge, in turn around n: its triangle, its first edge's end
    int32_t k;                      // wedges; 0: the fan is not one turn around any axis tried
  };
  // the fan of v
  Fan fan(int32_t v) const;
  const std::array<int32_t, 3>& tri_verts(size_t t) const { return tri_verts_[t]; }
  tc_d3 vertex(int32_t v) const { return verts_[size_t(v)]; }

 private:
  bool compute(int32_t v, tc_d3& n, double& radius, int32_t* tri, int32_t* from) const;
  const std::vector<Tri>& t_;
  std::vector<tc_d3> verts_;
  std::vector<std::array<int32_t, 3>> tri_verts_;  // per triangle
  std::vector<int32_t> off_, tris_;                // per vertex: tris_[off_[v] .. off_[v + 1])
  // per vertex: 0 not yet computed, 1 being computed, 2 a fan, 3 none
  std::unique_ptr<std::atomic<uint8_t>[]> state_;
  mutable std::vector<tc_d3> axis_;
  mutable std::vector<double> radius_;
  mutable std::vector<int32_t> wedge_tri_, wedge_from_;  // per fan entry, in turn
};

namespace {

// The branch and bound of within(), each point's distance to each feature computed once: a
// piece shares its corners with its parent and its siblings, and a feature that fails at one
// corner needs no other.
class Pieces {
 public:
  // set by another thread when the verdict is known: every piece then fails at once
  const std::atomic<bool>* stop = nullptr;

  // Boxes and centroids computed once for an array of triangles the features point into
  // (feature i's at index feats[i] - base), instead of at each reset.
  struct Known {
    const Tri* base;
    const tc_d3 *lo, *hi, *centroid;
  };

  // fans: the fans of the surface the features point into (fan_cover), or null
  void reset(const std::vector<const Tri*>& feats, double e2, const std::function<bool(const Tri&)>* relevant,
             const Fans* fans = nullptr, const Tri* fans_base = nullptr, const Known* known = nullptr) {
    feats_ = &feats;
    fans_ = fans;
    fans_base_ = fans_base;
    e2_ = e2;
    e_ = std::sqrt(e2);
    relevant_ = relevant;
    centroids_.resize(feats.size());
    lo_.resize(feats.size());
    hi_.resize(feats.size());
    for (size_t f = 0; f < feats.size(); ++f) {
      if (known) {
        const size_t i = size_t(feats[f] - known->base);
        centroids_[f] = known->centroid[i];
        lo_[f] = known->lo[i];
        hi_[f] = known->hi[i];
      } else {
        centroids_[f] = centroid_of(*feats[f]);
        box_of(*feats[f], lo_[f], hi_[f]);
      }
    }
  }

  // The feature that held the whole triangle of the last within() (every point within e of
  // it), or -1 when none did alone.
  int32_t whole() const { return whole_; }

  bool within(const Tri& P, int depth) {
    pts_.clear();
    dist_.clear();
    whole_ = -1;
    top_ = depth;
    const std::array<int32_t, 3> c = {add(P[0]), add(P[1]), add(P[2])};
    if (levels_.size() < size_t(depth) + 1) levels_.resize(size_t(depth) + 1);
    std::vector<int32_t>& all = levels_[size_t(depth)].all;
    all.resize(feats_->size());
    for (size_t f = 0; f < all.size(); ++f) all[f] = int32_t(f);
    return piece(c, all, depth);
  }

 private:
  struct Level {
    std::vector<std::pair<double, int32_t>> order;
    std::vector<int32_t> near, all;
  };

  int32_t add(tc_d3 p) {
    pts_.push_back(p);
    dist_.resize(dist_.size() + feats_->size(), -1.0);
    return int32_t(pts_.size() - 1);
  }
  // The squared distance of point p to feature f, or, when the feature's box is farther than e,
  // that box's: every use compares it with e2, and both are then above it.
  double d2(int32_t p, int32_t f) {
    double& d = dist_[size_t(p) * feats_->size() + size_t(f)];
    if (d < 0) {
      const tc_d3 q = pts_[size_t(p)];
      const double box = box_dist2(q, lo_[size_t(f)], hi_[size_t(f)]);
      d = box > e2_ ? box : point_triangle_dist2(q, *(*feats_)[size_t(f)]);
    }
    return d;
  }

  bool holds(const std::array<int32_t, 3>& c, int32_t f) {
    return d2(c[0], f) <= e2_ && d2(c[1], f) <= e2_ && d2(c[2], f) <= e2_;
  }

  bool piece(std::array<int32_t, 3> c, const std::vector<int32_t>& feats, int depth) {
    if (stop && stop->load(std::memory_order_relaxed)) return false;
    const Tri P = {pts_[size_t(c[0])], pts_[size_t(c[1])], pts_[size_t(c[2])]};
    Level& L = levels_[size_t(depth)];
    // the features nearest the piece first: the one that certifies it is then found at once
    const tc_d3 m = (P[0] + P[1] + P[2]) * (1.0 / 3);
    L.order.clear();
    std::pair<double, int32_t> nearest{INFINITY, -1};  // (as std::min_element over L.order)
    for (int32_t f : feats) {
      const tc_d3 d = m - centroids_[size_t(f)];
      const std::pair<double, int32_t> key{dot(d, d), f};
      L.order.push_back(key);
      if (nearest.second < 0 || key < nearest) nearest = key;
    }
    // most pieces are certified by the nearest: the order of the others only when it fails
    if (nearest.second >= 0 && holds(c, nearest.second)) {
      if (depth == top_) whole_ = nearest.second;
      return true;
    }
    // (the nearest in order, for two_cover and fan_cover; any feature that holds certifies)
    std::partial_sort(L.order.begin(), L.order.begin() + ptrdiff_t(std::min(kNearest, L.order.size())),
                      L.order.end());
    for (const auto& [key, f] : L.order)
      if (holds(c, f)) {
        if (depth == top_) whole_ = f;
        return true;
      }
    if (two_cover(c, L.order)) return true;
    if (depth == top_ && !relevant_ && overlay_holds(c)) return true;
    // (whether the piece matters at all only now: most pieces are certified before)
    if (relevant_ && !(*relevant_)(P)) return true;
    // (the fans of a check's own triangles, which the reference's pieces are measured against,
    // only for a piece longer than kSideFanMin x e: a shorter one splits down at less cost)
    if ((!relevant_ || longer_than(P, kSideFanMin * e_)) && fan_cover(c, L.order)) return true;
    if (depth == 0) return false;
    if (!relevant_)  // a corner farther than e from every feature: no split can help
      for (int32_t k : c) {
        double dmin = INFINITY;
        for (int32_t f : feats) dmin = std::min(dmin, d2(k, f));
        if (dmin > e2_) return false;
      }
    tc_d3 lo, hi;
    box_of(P, lo, hi);
    L.near.clear();  // the features within reach of the piece (the nearest first)
    for (const auto& [key, f] : L.order)
      if (!boxes_apart(lo_[size_t(f)], hi_[size_t(f)], lo, hi, e_)) L.near.push_back(f);
    const size_t keep = pts_.size();
    const int32_t m01 = add((P[0] + P[1]) * 0.5), m12 = add((P[1] + P[2]) * 0.5), m20 = add((P[2] + P[0]) * 0.5);
    const std::array<int32_t, 3> kids[4] = {{c[0], m01, m20}, {m01, c[1], m12}, {m20, m12, c[2]}, {m01, m12, m20}};
    bool ok = true;
    for (const auto& k : kids)
      if (!(ok = piece(k, L.near, depth - 1))) break;
    pts_.resize(keep);
    dist_.resize(keep * feats_->size());
    return ok;
  }

  // Whether two features with a common edge hold the piece between them: cut by the plane
  // through that edge that bisects their angle, each part (convex) lies within e of its own
  // feature where its corners do. A piece across an edge of the features is then certified
  // whole instead of being split down to the edge. (Any plane would do for the proof; rounding
  // moves the cut points by far less than the margin of change_ok.)
  static constexpr size_t kNearest = 6;  // the features two_cover tries, nearest first

  bool two_cover(const std::array<int32_t, 3>& c, const std::vector<std::pair<double, int32_t>>& order) {
    int32_t f[kNearest];
    int mask[kNearest];
    size_t n = 0;
    for (size_t i = 0; i < order.size() && i < kNearest; ++i) {
      const int32_t g = order[i].second;
      int m = 0;
      for (int k = 0; k < 3; ++k)
        if (d2(c[size_t(k)], g) <= e2_) m |= 1 << k;
      if (m) {
        f[n] = g;
        mask[n++] = m;
      }
    }
    for (size_t i = 0; i < n; ++i)
      for (size_t j = i + 1; j < n; ++j)
        if ((mask[i] | mask[j]) == 7 && cut_holds(c, f[i], f[j])) return true;
    return false;
  }

  static constexpr double kSideFanMin = 8;
  static bool longer_than(const Tri& P, double l) {
    for (int i = 0; i < 3; ++i) {
      const tc_d3 d = P[size_t(i)] - P[size_t((i + 1) % 3)];
      if (dot(d, d) > l * l) return true;
    }
    return false;
  }

  bool cut_holds(const std::array<int32_t, 3>& c, int32_t f1, int32_t f2) {
    const Tri &t1 = *(*feats_)[size_t(f1)], &t2 = *(*feats_)[size_t(f2)];
    int s1[2], s2[2], shared = 0;  // the common corners' places in t1 and t2
    for (int a = 0; a < 3 && shared < 3; ++a)
      for (int b = 0; b < 3; ++b)
        if (t1[size_t(a)].x == t2[size_t(b)].x && t1[size_t(a)].y == t2[size_t(b)].y &&
            t1[size_t(a)].z == t2[size_t(b)].z) {
          if (shared < 2) {
            s1[shared] = a;
            s2[shared] = b;
          }
          ++shared;
          break;
        }
    if (shared != 2) return false;
    const tc_d3 a = t1[size_t(s1[0])], b = t1[size_t(s1[1])];
    const tc_d3 o1 = t1[size_t(3 - s1[0] - s1[1])], o2 = t2[size_t(3 - s2[0] - s2[1])];
    const tc_d3 d = b - a;
    const double dd = dot(d, d);
    if (!(dd > 0)) return false;
    auto across = [&](tc_d3 o) {  // the unit direction from the edge to o, across the edge
      const tc_d3 w = (o - a) - d * (dot(o - a, d) / dd);
      const double l = std::sqrt(dot(w, w));
      return l > 0 ? w * (1 / l) : tc_d3{0, 0, 0};
    };
    const tc_d3 nrm = across(o1) - across(o2);  // t1's side positive
    if (!(dot(nrm, nrm) > 1e-12)) return false;
    tc_d3 p[3];
    double h[3];
    for (int k = 0; k < 3; ++k) {
      p[k] = pts_[size_t(c[size_t(k)])];
      h[k] = dot(nrm, p[k] - a);
      if (h[k] >= 0 && d2(c[size_t(k)], f1) > e2_) return false;
      if (h[k] <= 0 && d2(c[size_t(k)], f2) > e2_) return false;
    }
    for (int k = 0; k < 3; ++k) {  // the cut points, in both parts
      const int l = (k + 1) % 3;
      if (!((h[k] > 0 && h[l] < 0) || (h[k] < 0 && h[l] > 0))) continue;
      const tc_d3 x = p[k] + (p[l] - p[k]) * (h[k] / (h[k] - h[l]));
      if (point_triangle_dist2(x, t1) > e2_ || point_triangle_dist2(x, t2) > e2_) return false;
    }
    return true;
  }

  // Whether the triangles around a vertex of the nearest feature hold the piece between them,
  // as two_cover does for two across an edge: the half-planes from the axis through the vertex
  // along the fan's mean normal to each of its edges cut space into wedges, one per triangle,
  // each convex (less than half a turn), together all of it; the piece's part in a wedge (a
  // convex polygon) lies within e of the wedge's triangle where that polygon's corners do. A
  // piece over a vertex of the features is then certified whole instead of split down to the
  // size of e around it. Only against a surface whose fans are known (the reference, or a
  // check's new and surrounding triangles, whose fans at the patch's rim are not whole); a fan
  // that does not wind once around its normal (a sharp corner, a fold, a rim) is not tried.
  bool fan_cover(const std::array<int32_t, 3>& c, const std::vector<std::pair<double, int32_t>>& order) {
    if (!fans_ || order.empty()) return false;
    const size_t t = size_t((*feats_)[size_t(order[0].second)] - fans_base_);  // the nearest feature
    const tc_d3 P[3] = {pts_[size_t(c[0])], pts_[size_t(c[1])], pts_[size_t(c[2])]};
    for (int32_t v : fans_->tri_verts(t))
      if (fan_holds(P, fans_->fan(v))) return true;
    return false;
  }

  bool fan_holds(const tc_d3 (&P)[3], const Fans::Fan& f) {
    if (f.k == 0) return false;
    const double r2 = (f.radius + e_) * (f.radius + e_);  // (a corner beyond: not within e of the fan)
    for (const tc_d3& p : P)
      if (dot(p - f.o, p - f.o) > r2) return false;
    // wedge i: (x - o).(n x (from_i - o)) >= 0 and (x - o).(n x (from_i+1 - o)) <= 0
    const auto side = [&](int32_t i) { return geo::cross(f.n, fan_vertex(f.from[i % f.k]) - f.o); };
    tc_d3 next = side(0);
    for (int32_t i = 0; i < f.k; ++i) {
      const tc_d3 ms = next;
      next = side(i + 1);
      tc_d3 a[kPoly] = {P[0], P[1], P[2]};
      int na = 3;
      for (const tc_d3& m : {ms, next * -1.0})
        if ((na = clip(a, na, [&](tc_d3 x) { return dot(x - f.o, m); })) < 0) return false;
      const Tri& t = fans_base_[f.tri[i]];
      for (int j = 0; j < na; ++j)
        if (point_triangle_dist2(a[j], t) > e2_) return false;
    }
    return true;
  }
  tc_d3 fan_vertex(int32_t u) const { return fans_->vertex(u); }

  // Sutherland-Hodgman: polygon a[0..n) replaced by its part where h (a signed distance to a
  // plane) is >= 0; returns its corners, or -1 where they might not fit in kPoly (not certified
  // rather than overrun). Each clip adds a point per edge that changes side: a triangle clipped
  // by two planes keeps at most 5 corners, by three at most 6, more only where rounding
  // alternates the corners' sides (a polygon nearly in the plane), within 8.
  static constexpr int kPoly = 8;
  template <class H>
  static int clip(tc_d3 (&a)[kPoly], int n, const H& h) {
    tc_d3 r[kPoly];
    int m = 0;
    for (int j = 0; j < n; ++j) {
      if (m + 2 > kPoly) return -1;
      const tc_d3 p = a[j], q = a[(j + 1) % n];
      const double hp = h(p), hq = h(q);
      if (hp >= 0) r[m++] = p;
      if ((hp > 0 && hq < 0) || (hp < 0 && hq > 0)) r[m++] = p + (q - p) * (hp / (hp - hq));
    }
    std::copy(r, r + m, a);
    return m;
  }

  // Whether the features seen from the piece cut it into cells, each within e of its own
  // feature: the features projected onto the piece's plane that keep their orientation (the
  // surface facing the piece's way) are clipped to it, and each cell, convex, lies within e of
  // its feature where its corners do. They cover the piece when none of their free edges (an
  // edge not shared, in opposite directions, by two of them) crosses the piece: the number of
  // features over a point is then the same over all of it, and their cells' areas add up to
  // the piece's once. A new triangle over many small ones of the features is then certified in
  // one step instead of being split down to their size. Only where the features are triangles
  // of the surface whose vertices are known (fans_: corners equal to the bit share a vertex).
  // (Either way round: the piece's corners in the order given, or, where no feature then faces
  // it, in the other.)
  bool overlay_holds(const std::array<int32_t, 3>& c) {
    if (!fans_) return false;
    const Overlay o = overlay(c);
    return o == Overlay::Held || (o == Overlay::Bare && overlay({c[0], c[2], c[1]}) == Overlay::Held);
  }
  enum class Overlay { Held, Failed, Bare };  // Bare: no feature faces the piece's way over it
  Overlay overlay(const std::array<int32_t, 3>& c) {
    const tc_d3 A = pts_[size_t(c[0])], B = pts_[size_t(c[1])], C = pts_[size_t(c[2])];
    const tc_d3 nn = geo::cross(B - A, C - A);
    const double ab = std::sqrt(dot(B - A, B - A));
    if (!(dot(nn, nn) > 0) || !(ab > 0)) return Overlay::Failed;
    const tc_d3 u = (B - A) * (1 / ab), w = geo::normalize(geo::cross(nn, u));
    // (in the piece's plane: x along u, y along w, z 0)
    const auto to2 = [&](tc_d3 p) { return tc_d3{dot(p - A, u), dot(p - A, w), 0}; };
    const auto cross2 = [](tc_d3 o, tc_d3 a, tc_d3 b) { return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x); };
    const tc_d3 T[3] = {{0, 0, 0}, {ab, 0, 0}, to2(C)};  // counterclockwise: C lies on w's side
    const double area = 0.5 * cross2(T[0], T[1], T[2]);
    // the piece's sides as half-planes: inside when side(k, p) >= 0
    double len[3];
    for (int k = 0; k < 3; ++k) {
      const tc_d3 a = T[k], b = T[(k + 1) % 3];
      len[k] = std::hypot(b.x - a.x, b.y - a.y);
    }
    // A free edge may cross into the piece by less than tol from its rim: the points of that
    // band lie within tol / sin(half the corner's angle) of the rest, which the margin of
    // change_ok (1e-9 e) covers with room for the rounding of the distances.
    double s = 1;  // the smallest sin of half a corner's angle
    for (int k = 0; k < 3; ++k) {
      const tc_d3 o = T[k], a = T[(k + 1) % 3], b = T[(k + 2) % 3];
      const double c = ((a.x - o.x) * (b.x - o.x) + (a.y - o.y) * (b.y - o.y)) / (len[k] * len[(k + 2) % 3]);
      s = std::min(s, std::sqrt(std::max(0.0, 0.5 * (1 - c))));
    }
    const double tol = kOverlayTol * s * e_, perimeter = len[0] + len[1] + len[2];
    if (!(area > 0) || !(tol > 0) || !(tol * perimeter * double(feats_->size()) < 0.1 * area)) return Overlay::Failed;
    const auto side = [&](int k, tc_d3 p) { return cross2(T[k], T[(k + 1) % 3], p) / len[k]; };
    edges_.clear();
    double covered = 0;
    for (size_t f = 0; f < feats_->size(); ++f) {
      const Tri& F = *(*feats_)[f];
      tc_d3 poly[kPoly] = {to2(F[0]), to2(F[1]), to2(F[2])};
      if (!(cross2(poly[0], poly[1], poly[2]) > 0)) continue;  // turned away, or seen edge-on
      int n = 3;
      for (int k = 0; k < 3 && n > 0; ++k)
        if ((n = clip(poly, n, [&](tc_d3 x) { return side(k, x); })) < 0) return Overlay::Failed;
      double a = 0;
      for (int j = 1; j + 1 < n; ++j) a += 0.5 * cross2(poly[0], poly[j], poly[j + 1]);
      if (!(a > 0)) continue;  // not over the piece
      for (int j = 0; j < n; ++j)
        if (point_triangle_dist2(A + u * poly[j].x + w * poly[j].y, F) > e2_) return Overlay::Failed;
      covered += a;
      const std::array<int32_t, 3>& v = fans_->tri_verts(size_t((*feats_)[f] - fans_base_));
      for (int k = 0; k < 3; ++k) {
        const int32_t a = v[size_t(k)], b = v[size_t((k + 1) % 3)];
        edges_.push_back({a, b, int32_t(f), k, uint64_t(uint32_t(std::min(a, b))) << 32 | uint32_t(std::max(a, b))});
      }
    }
    if (!(covered > 0.25 * area)) return edges_.empty() ? Overlay::Bare : Overlay::Failed;
    if (!(covered > 0.75 * area && covered < 1.25 * area)) return Overlay::Failed;
    // the free edges: those not met once each way
    std::sort(edges_.begin(), edges_.end(), [](const Edge& x, const Edge& y) { return x.key < y.key; });
    for (size_t i = 0; i < edges_.size();) {
      size_t j = i + 1;
      while (j < edges_.size() && edges_[j].key == edges_[i].key) ++j;
      const bool shared = j - i == 2 && edges_[i].a == edges_[i + 1].b;
      for (size_t k = i; k < j && !shared; ++k) {
        const Tri& F = *(*feats_)[size_t(edges_[k].f)];
        if (crosses(to2(F[size_t(edges_[k].k)]), to2(F[size_t((edges_[k].k + 1) % 3)]), side, tol))
          return Overlay::Failed;
      }
      i = j;
    }
    return Overlay::Held;
  }

  // Whether the segment pq has a part inside the piece by more than tol from its rim.
  template <class Side>
  static bool crosses(const auto& p, const auto& q, const Side& side, double tol) {
    double t0 = 0, t1 = 1;
    for (int k = 0; k < 3; ++k) {
      const double hp = side(k, p) - tol, hq = side(k, q) - tol;
      if (hp < 0 && hq < 0) return false;
      if (hp < 0) t0 = std::max(t0, hp / (hp - hq));
      else if (hq < 0) t1 = std::min(t1, hp / (hp - hq));
    }
    return t0 < t1;
  }
  static constexpr double kOverlayTol = 1e-10;  // the band along the rim, a share of e (times s)
  struct Edge {
    int32_t a, b, f, k;  // from a to b, side k of feature f
    uint64_t key;        // the smaller end, then the larger: the same both ways
  };
  std::vector<Edge> edges_;

  const std::vector<const Tri*>* feats_ = nullptr;
  const Fans* fans_ = nullptr;
  const Tri* fans_base_ = nullptr;
  double e2_ = 0, e_ = 0;
  int top_ = 0;        // the depth within() started at
  int32_t whole_ = -1;  // whole()
  const std::function<bool(const Tri&)>* relevant_ = nullptr;
  std::vector<tc_d3> centroids_, lo_, hi_;  // per feature
  std::vector<tc_d3> pts_;                  // the corners of the pieces on the way down
  std::vector<double> dist_;                // per point and feature, -1 until computed
  std::vector<Level> levels_;               // per depth, scratch
};

}  // namespace

bool within(const Tri& P, const std::vector<const Tri*>& feats, double e2, int depth,
            const std::function<bool(const Tri&)>* relevant, const ReferenceSurface* surface) {
  Pieces pieces;
  const bool fans = surface && surface->fans();
  pieces.reset(feats, e2, relevant, fans ? surface->fans() : nullptr, fans ? &surface->tri(0) : nullptr);
  return pieces.within(P, depth);
}

namespace {
int64_t cell_key(int64_t i, int64_t j, int64_t k) { return (i * 2097152 + j) * 2097152 + k; }

// TETCOLLAPSE_RECORD_CHECKS=FILE: the process's first reference surface and every change_ok
// against it are written to FILE (kRecordMagic, the triangles, then per check olds, news, around,
// e and reach), which bench/bench_measured_check replays: the check timed alone, without the
// rest of a run's noise. Only the first surface: a later one (a second cycle) is the same.
std::FILE* g_record = nullptr;
std::atomic<const ReferenceSurface*> g_recorded{nullptr};
bool g_record_taken = false;  // (once per process)
std::mutex g_record_mutex;

void record_tris(std::FILE* f, const std::vector<Tri>& t) {
  const uint64_t n = t.size();
  std::fwrite(&n, sizeof n, 1, f);
  std::fwrite(t.data(), sizeof(Tri), t.size(), f);
}
}  // namespace

Fans::Fans(const std::vector<Tri>& t) : t_(t) {
  struct Corner {
    tc_d3 p;
    int32_t at;  // 3 x triangle + corner
  };
  std::vector<Corner> c(3 * t.size());
  for (size_t i = 0; i < c.size(); ++i) c[i] = {t[i / 3][i % 3], int32_t(i)};
  const auto less = [](const Corner& a, const Corner& b) {
    return a.p.x != b.p.x ? a.p.x < b.p.x : a.p.y != b.p.y ? a.p.y < b.p.y : a.p.z < b.p.z;
  };
  std::sort(c.begin(), c.end(), less);
  tri_verts_.resize(t.size());
  std::vector<int32_t> corner_vertex(c.size()), corner_tri(c.size());
  for (size_t i = 0; i < c.size(); ++i) {
    if (i == 0 || less(c[i - 1], c[i])) verts_.push_back(c[i].p);
    corner_vertex[size_t(c[i].at)] = tri_verts_[size_t(c[i].at / 3)][size_t(c[i].at % 3)] = int32_t(verts_.size() - 1);
    corner_tri[size_t(c[i].at)] = c[i].at / 3;
  }
  topology_detail::build_csr(int32_t(verts_.size()), corner_vertex, corner_tri, off_, tris_);
  state_ = std::make_unique<std::atomic<uint8_t>[]>(verts_.size());
  for (size_t v = 0; v < verts_.size(); ++v) state_[v] = 0;
  axis_.resize(verts_.size());
  radius_.resize(verts_.size());
  wedge_tri_.resize(tris_.size());
  wedge_from_.resize(tris_.size());
}

// The first thread to ask computes and keeps the fan; another that asks meanwhile computes its
// own copy.
Fans::Fan Fans::fan(int32_t v) const {
  std::atomic<uint8_t>& s = state_[size_t(v)];
  uint8_t st = s.load(std::memory_order_acquire);
  const size_t b = size_t(off_[size_t(v)]), k = size_t(off_[size_t(v) + 1]) - b;
  if (st == 0 && s.compare_exchange_strong(st, 1, std::memory_order_acq_rel)) {
    const bool ok = compute(v, axis_[size_t(v)], radius_[size_t(v)], &wedge_tri_[b], &wedge_from_[b]);
    s.store(ok ? 2 : 3, std::memory_order_release);
    st = ok ? 2 : 3;
  }
  if (st == 2) return {verts_[size_t(v)], axis_[size_t(v)], radius_[size_t(v)], &wedge_tri_[b], &wedge_from_[b], int32_t(k)};
  Fan f{verts_[size_t(v)], {0, 0, 0}, 0, nullptr, nullptr, 0};
  if (st == 1) {
    thread_local std::vector<int32_t> tri, from;
    tri.resize(k);
    from.resize(k);
    if (compute(v, f.n, f.radius, tri.data(), from.data())) {
      f.tri = tri.data();
      f.from = from.data();
      f.k = int32_t(k);
    }
  }
  return f;
}

// The axis: the mean of the triangles' unit normals, turned to agree with the first; the fan is
// one turn around it when every triangle spans less than half a turn seen along it, each starts
// where the one before ends, and the spans add up to one turn.
bool Fans::compute(int32_t v, tc_d3& n, double& radius, int32_t* tri, int32_t* from) const {
  constexpr int kMaxFan = 32;
  const int32_t b = off_[size_t(v)], k = off_[size_t(v) + 1] - b;
  if (k < 3 || k > kMaxFan) return false;
  const tc_d3 o = verts_[size_t(v)];
  n = {0, 0, 0};
  tc_d3 n0{0, 0, 0};
  radius = 0;
  for (int32_t i = 0; i < k; ++i) {
    const Tri& t = t_[size_t(tris_[size_t(b + i)])];
    tc_d3 m = geo::cross(t[1] - t[0], t[2] - t[0]);
    const double l = geo::length(m);
    if (!(l > 0)) return false;
    m = m * (1 / l);
    if (i == 0) n0 = m;
    n = n + (dot(m, n0) < 0 ? m * -1.0 : m);
    for (const tc_d3& p : t) radius = std::max(radius, geo::length(p - o));
  }
  const double nl = geo::length(n);
  if (!(nl > 0)) return false;
  n = n * (1 / nl);
  const tc_d3 e1 = geo::normalize(geo::cross(n, std::fabs(n.x) < 0.9 ? tc_d3{1, 0, 0} : tc_d3{0, 1, 0}));
  const tc_d3 e2 = geo::cross(n, e1);
  const auto angle = [&](int32_t u) {
    const tc_d3 d = verts_[size_t(u)] - o;
    return std::atan2(dot(d, e2), dot(d, e1));
  };
  struct Wedge {
    int32_t tri, from, to;
    double angle, span;
  } w[kMaxFan];
  constexpr double kTurn = 2 * M_PI;
  double total = 0;
  for (int32_t i = 0; i < k; ++i) {
    const int32_t t = tris_[size_t(b + i)];
    int32_t other[2], m = 0;
    for (int32_t u : tri_verts_[size_t(t)])
      if (u != v && m < 2) other[m++] = u;
    if (m != 2) return false;
    const double a0 = angle(other[0]), a1 = angle(other[1]);
    double span = a1 - a0;
    if (span < 0) span += kTurn;
    w[i] = span <= M_PI ? Wedge{t, other[0], other[1], a0, span} : Wedge{t, other[1], other[0], a1, kTurn - span};
    if (!(w[i].span > 1e-9 && w[i].span < M_PI - 1e-9)) return false;
    total += w[i].span;
  }
  if (!(std::fabs(total - kTurn) < 1e-6)) return false;
  std::sort(w, w + k, [](const Wedge& x, const Wedge& y) { return x.angle < y.angle; });
  for (int32_t i = 0; i < k; ++i) {
    if (w[i].to != w[(i + 1) % k].from) return false;
    tri[i] = w[i].tri;
    from[i] = w[i].from;
  }
  return true;
}

ReferenceSurface::ReferenceSurface(const std::vector<double>& triangles) {
  tris_.resize(triangles.size() / 9);
  double total = 0;
  for (size_t i = 0; i < tris_.size(); ++i) {
    for (size_t k = 0; k < 3; ++k)
      tris_[i][k] = {triangles[9 * i + 3 * k], triangles[9 * i + 3 * k + 1], triangles[9 * i + 3 * k + 2]};
    total += geo::length(tris_[i][1] - tris_[i][0]);
  }
  if (tris_.empty()) return;
  fans_ = std::make_unique<Fans>(tris_);
  cell_ = 2 * total / double(tris_.size());
  if (!(cell_ > 0)) cell_ = 1;
  origin_ = tris_[0][0];
  seen_.assign(tris_.size(), 0);
  lo_.resize(tris_.size());
  hi_.resize(tris_.size());
  centroids_.resize(tris_.size());
  for (size_t i = 0; i < tris_.size(); ++i) centroids_[i] = centroid_of(tris_[i]);
  holder_.assign(tris_.size(), 0);
  const auto c = [&](double x, double o) { return int64_t(std::floor((x - o) / cell_)); };
  for (int32_t i = 0; i < int32_t(tris_.size()); ++i) {
    tc_d3& lo = lo_[size_t(i)];
    tc_d3& hi = hi_[size_t(i)];
    box_of(tris_[size_t(i)], lo, hi);
    for (int64_t a = c(lo.x, origin_.x); a <= c(hi.x, origin_.x); ++a)
      for (int64_t b = c(lo.y, origin_.y); b <= c(hi.y, origin_.y); ++b)
        for (int64_t d = c(lo.z, origin_.z); d <= c(hi.z, origin_.z); ++d) cells_[cell_key(a, b, d)].push_back(i);
  }
  if (const char* path = std::getenv("TETCOLLAPSE_RECORD_CHECKS"); path && *path) {
    std::lock_guard<std::mutex> lock(g_record_mutex);
    if (!g_record_taken && (g_record = std::fopen(path, "wb"))) {
      g_record_taken = true;
      g_recorded = this;
      std::fwrite(kRecordMagic, 1, sizeof kRecordMagic, g_record);
      record_tris(g_record, tris_);
    }
  }
}

void ReferenceSurface::query(tc_d3 lo, tc_d3 hi, std::vector<int32_t>& out) const {
  out.clear();
  if (tris_.empty()) return;
  if (++stamp_ == 0) {
    std::fill(seen_.begin(), seen_.end(), 0);
    stamp_ = 1;
  }
  const auto c = [&](double x, double o) { return int64_t(std::floor((x - o) / cell_)); };
  for (int64_t a = c(lo.x, origin_.x); a <= c(hi.x, origin_.x); ++a)
    for (int64_t b = c(lo.y, origin_.y); b <= c(hi.y, origin_.y); ++b)
      for (int64_t d = c(lo.z, origin_.z); d <= c(hi.z, origin_.z); ++d) {
        const auto it = cells_.find(cell_key(a, b, d));
        if (it == cells_.end()) continue;
        for (int32_t i : it->second) {
          if (seen_[size_t(i)] == stamp_) continue;
          seen_[size_t(i)] = stamp_;
          if (!boxes_apart(lo_[size_t(i)], hi_[size_t(i)], lo, hi, 0)) out.push_back(i);
        }
      }
}

// A second thread for change_ok's pieces, woken per check: a check measures a few thousand
// distances, too few for a thread of its own each time, and the collapse's host tail, which
// makes these checks one after another, leaves the other core idle.
class ReferenceSurface::Helper {
 public:
  Helper() : thread_([this] { loop(); }) {}
  ~Helper() {
    {
      std::lock_guard<std::mutex> l(m_);
      quit_ = true;
    }
    cv_.notify_all();
    thread_.join();
  }
  // f on the helper and on the caller's thread; returns when both are done
  void both(const std::function<void()>& f) {
    {
      std::lock_guard<std::mutex> l(m_);
      task_ = &f;
      ++posted_;
    }
    cv_.notify_all();
    f();
    std::unique_lock<std::mutex> l(m_);
    cv_.wait(l, [&] { return finished_ == posted_; });
  }

 private:
  void loop() {
    uint64_t seen = 0;
    std::unique_lock<std::mutex> l(m_);
    for (;;) {
      cv_.wait(l, [&] { return quit_ || posted_ != seen; });
      if (quit_) return;
      seen = posted_;
      const std::function<void()>* f = task_;
      l.unlock();
      (*f)();
      l.lock();
      finished_ = seen;
      cv_.notify_all();
    }
  }
  std::mutex m_;
  std::condition_variable cv_;
  const std::function<void()>* task_ = nullptr;
  uint64_t posted_ = 0, finished_ = 0;
  bool quit_ = false;
  std::thread thread_;  // (last: started once the members above exist)
};

bool read_recorded_checks(const char* path, std::vector<double>& reference, std::vector<RecordedCheck>& checks) {
  std::FILE* f = std::fopen(path, "rb");
  if (!f) return false;
  auto tris = [&](std::vector<Tri>& out) {
    uint64_t n = 0;
    if (std::fread(&n, sizeof n, 1, f) != 1 || n > (uint64_t(1) << 32)) return false;
    out.resize(size_t(n));
    return std::fread(out.data(), sizeof(Tri), out.size(), f) == out.size();
  };
  char magic[sizeof kRecordMagic];
  std::vector<Tri> ref;
  const bool ok = std::fread(magic, 1, sizeof magic, f) == sizeof magic &&
                  std::equal(magic, magic + sizeof magic, kRecordMagic) && tris(ref);
  checks.clear();
  for (RecordedCheck c; ok && tris(c.olds) && tris(c.news) && tris(c.around) &&
                        std::fread(&c.e, sizeof c.e, 1, f) == 1 && std::fread(&c.reach, sizeof c.reach, 1, f) == 1;)
    checks.push_back(c);
  std::fclose(f);
  reference.clear();
  for (const Tri& t : ref)
    for (const tc_d3& p : t) reference.insert(reference.end(), {p.x, p.y, p.z});
  return ok;
}

ReferenceSurface::~ReferenceSurface() {
  std::lock_guard<std::mutex> lock(g_record_mutex);
  if (g_recorded == this) {
    std::fclose(g_record);
    g_record = nullptr;
    g_recorded = nullptr;
  }
}

bool ReferenceSurface::change_ok(const std::vector<Tri>& olds, const std::vector<Tri>& news,
                                 const std::vector<Tri>& around, double e, double reach) const {
  if (g_recorded.load(std::memory_order_relaxed) == this) {
    std::lock_guard<std::mutex> lock(g_record_mutex);
    for (const auto* set : {&olds, &news, &around}) record_tris(g_record, *set);
    std::fwrite(&e, sizeof e, 1, g_record);
    std::fwrite(&reach, sizeof reach, 1, g_record);
  }
  if (olds.empty() && news.empty()) return true;
  // (a margin for the rounding of the distances, far below any bound asked for)
  e *= 1 - 1e-9;
  const double e2 = e * e;
  std::vector<int32_t> ids;
  // every point of a new triangle within e of this surface (the triangles in its box grown
  // by e are all that can be that near); first a quick look at a few points of each, which
  // finds most refusals
  std::vector<std::vector<const Tri*>> near(news.size());
  for (size_t j = 0; j < news.size(); ++j) {
    const Tri& t = news[j];
    tc_d3 lo, hi;
    box_of(t, lo, hi);
    query(lo - tc_d3{e, e, e}, hi + tc_d3{e, e, e}, ids);
    for (int32_t i : ids) near[j].push_back(&tris_[size_t(i)]);
    const tc_d3 probes[4] = {t[0], (t[0] + t[1] + t[2]) * (1.0 / 3), (t[0] + t[1]) * 0.5, (t[0] + t[2]) * 0.5};
    for (const tc_d3& q : probes) {  // (a probe needs one triangle within e, nothing nearer)
      bool found = false;
      for (size_t i = 0; i < ids.size() && !found; ++i) {
        const size_t f = size_t(ids[i]);
        found = box_dist2(q, lo_[f], hi_[f]) <= e2 && point_triangle_dist2(q, tris_[f]) <= e2;
      }
      if (!found) return false;
    }
  }
  // every point of this surface within reach of an old triangle within e of the new S: the
  // pieces farther from every old triangle keep the S point they were within reach of
  tc_d3 lo, hi;
  box_of(olds.empty() ? news[0] : olds[0], lo, hi);
  for (const auto* set : {&olds, &news})
    for (const Tri& t : *set) {
      tc_d3 l, h;
      box_of(t, l, h);
      lo = {std::min(lo.x, l.x), std::min(lo.y, l.y), std::min(lo.z, l.z)};
      hi = {std::max(hi.x, h.x), std::max(hi.y, h.y), std::max(hi.z, h.z)};
    }
  query(lo - tc_d3{reach, reach, reach}, hi + tc_d3{reach, reach, reach}, ids);
  const std::function<bool(const Tri&)> relevant = [&](const Tri& p) {
    const tc_d3 c = (p[0] + p[1] + p[2]) * (1.0 / 3);
    double r = 0, d2 = INFINITY;
    for (const tc_d3& v : p) r = std::max(r, geo::length(v - c));
    for (const Tri& t : olds) d2 = std::min(d2, point_triangle_dist2(c, t));
    return std::sqrt(d2) - r <= reach;
  };
  // The pieces, the new triangles' first, taken in turn by each thread: the verdict is that
  // all hold, whichever thread measures which.
  std::vector<Tri> sides;  // the new triangles and those around, with their boxes and centroids
  sides.insert(sides.end(), news.begin(), news.end());
  sides.insert(sides.end(), around.begin(), around.end());
  std::vector<tc_d3> side_lo(sides.size()), side_hi(sides.size()), side_c(sides.size());
  for (size_t f = 0; f < sides.size(); ++f) {
    box_of(sides[f], side_lo[f], side_hi[f]);
    side_c[f] = centroid_of(sides[f]);
  }
  const Pieces::Known known_sides{sides.data(), side_lo.data(), side_hi.data(), side_c.data()};
  // The fans of the new and surrounding triangles, for the reference's pieces over one of their
  // vertices (a fan the patch holds whole: one at its rim is not one turn, and is not tried).
  const Fans side_fans(sides);
  std::vector<uint64_t> side_key(sides.size());
  for (size_t f = 0; f < sides.size(); ++f) side_key[f] = tri_key(sides[f]);
  const Pieces::Known known_tris{tris_.data(), lo_.data(), hi_.data(), centroids_.data()};
  const size_t jobs = news.size() + ids.size();
  std::atomic<size_t> next{0};
  std::atomic<bool> failed{false};
  const std::function<void()> work = [&] {
    // (each thread's scratch kept from check to check: a check is too small to allocate its own)
    thread_local Pieces pieces;
    thread_local std::vector<const Tri*> feats;
    pieces.stop = &failed;
    // (the jobs in chunks: one atomic per job bounced its cache line between the threads)
    for (size_t k0 = next.fetch_add(kJobChunk); k0 < jobs && !failed.load(std::memory_order_relaxed);
         k0 = next.fetch_add(kJobChunk))
      for (size_t k = k0, k1 = std::min(jobs, k0 + kJobChunk); k < k1 && !failed.load(std::memory_order_relaxed); ++k) {
        bool ok;
        if (k < news.size()) {
          pieces.reset(near[k], e2, nullptr, fans_.get(), tris_.data(), &known_tris);  // (near: triangles of tris_)
          ok = pieces.within(news[k], kDepth);
        } else {
          const size_t r = size_t(ids[k - news.size()]);
          const Tri& t = tris_[r];
          // The S triangle that held all of t in an earlier check, if it is still there: the
          // nearest-first search would find it too (it is within e of t's box), so trying it
          // first gives the same verdict (the reference's triangles are measured again in
          // check after check, and many keep the triangle that held them).
          if (const uint64_t h = holder_[r]) {
            const auto at = std::find(side_key.begin(), side_key.end(), h);
            if (at != side_key.end()) {
              const Tri& s = sides[size_t(at - side_key.begin())];
              if (point_triangle_dist2(t[0], s) <= e2 && point_triangle_dist2(t[1], s) <= e2 &&
                  point_triangle_dist2(t[2], s) <= e2)
                continue;
            }
          }
          feats.clear();
          for (size_t f = 0; f < sides.size(); ++f)
            if (!boxes_apart(side_lo[f], side_hi[f], lo_[r], hi_[r], e)) feats.push_back(&sides[f]);
          pieces.reset(feats, e2, &relevant, &side_fans, sides.data(), &known_sides);
          ok = pieces.within(t, kDepth);
          if (ok && pieces.whole() >= 0) holder_[r] = side_key[size_t(feats[size_t(pieces.whole())] - sides.data())];
        }
        if (!ok) failed = true;
      }
  };
  // (the core count once: the library reads it from the system at each call)
  static const bool two_cores = std::thread::hardware_concurrency() > 1;
  if (jobs >= kTwoThreadJobs && two_cores) {
    if (!helper_) helper_ = std::make_unique<Helper>();
    helper_->both(work);
  } else {
    work();
  }
  return !failed;
}

}  // namespace tc::surface_distance
