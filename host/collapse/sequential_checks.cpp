// The admissible checks of the sequential method's dynamic mesh (SeqMesh::check, predicate,
// link_and_volume): Q, then the link and volume tests of cl/collapse_checks.h, the device's own,
// over the mesh's rings (see sequential_mesh.hpp).
#include <algorithm>

#include "collapse/sequential_mesh.hpp"
#include "collapse/stages.hpp"  // collapse_detail::Reason
#include "collapse_predicate.h"

// The star the link and volume tests of cl/collapse_checks.h read: the rings as they are now
// (a removed tet is in no ring, so none is passed over), the kept tet neighbours, the current
// flags, with the S-edges and the qualities before computed from them.
#define TCS_LINK_PARAMS const ::tc::sequential_detail::SeqStar& s
#define TCS_LINK_ARGS s
#define TCS_VOL_PARAMS const ::tc::sequential_detail::SeqStar& s
#define TCS_VOL_ARGS s
#define TCS_RING_BEGIN(x) s.roff[x]
#define TCS_RING_END(x) (s.roff[x] + s.rlen[x])
#define TCS_RING_TET(i) s.pool[i]
#define TCS_DEAD(t) 0
#define TCS_TET(t) (s.tets + 4 * size_t(t))
#define TCS_TETS s.tets
#define TCS_ACROSS(t, f) s.nbr[4 * size_t(t) + size_t(f)]
#define TCS_USE_LABELS (s.labels != nullptr)
#define TCS_LABEL(t) s.labels[t]
#define TCS_SEDGE_SKIP(c) !(s.vflags[c] & (TCC_BOUNDARY | TCC_INTERFACE))
#define TCS_SEDGE(x, c, e) tcc_ring_sedge(s, (x), (c))
#define TCS_POINT(v) tc_point(s.pts, (v))
#define TCS_OLD_QUALITY(t, p0, p1, p2, p3) ((void)(t), tc_tet_quality(p0, p1, p2, p3))
#define TCS_FIELD_EPS s.field_eps
#define TCS_FIELD(v) s.field[size_t(v) * s.field_stride]
#include "collapse_checks.h"  // the link and volume tests, the device's own

namespace tc::sequential_detail {

using namespace collapse_detail;
using geo::tc_d3;

static_assert(TCC_OK == kOk && TCC_REFUSED_LINK == kRefusedLink && TCC_REFUSED_VOLUME == kRefusedVolume &&
              TCC_REFUSED_QUALITY == kRefusedQuality);

int SeqMesh::predicate(int32_t a, int32_t b, uint8_t& fe) {
  fe = edge_flags(a, b);
  return rules::tcc_predicate_q(a, b, vflags_[a], vflags_[b], fe, vclass_[a], vclass_[b], p_.mode,
                                p_.paper_rule ? 1 : 0);
}

Verdict SeqMesh::check(int32_t a, int32_t b) {
  if (a > b) std::swap(a, b);
  Verdict v;
  uint8_t fe = 0;
  const int dir = predicate(a, b, fe);
  if (dir < 0) {
    v.reason = kRefusedQ;
    return v;
  }
  v.reason = link_and_volume(a, b, fe, dir);
  if (v.reason == kOk) v.dir = uint8_t(dir);
  return v;
}

tc_d3 SeqMesh::placement(int32_t a, int32_t b, unsigned dir) const {
  tc_d3 p0 = point(a), p1 = point(b);
  if (dir & TCC_DIR_MIDPOINT) {
    tc_d3 p;
    if (free_placement_ && free_placement_(std::min(a, b), std::max(a, b), &p)) return p;
    return (p0 + p1) * 0.5;
  }
  return (dir & TCC_DIR_REMOVE_V1) ? p0 : p1;
}

// tcc_link_and_volume, over the current rings (a < b): the volume and quality test first.
uint8_t SeqMesh::link_and_volume(int32_t a, int32_t b, uint8_t fe, int dir) {
  const uint8_t r = volume_and_quality(a, b, dir, p_.min_quality);
  if (r != kOk) return r;
  return link_ok(a, b, fe) ? kOk : kRefusedLink;
}

bool SeqMesh::admissible(int32_t a, int32_t b, uint8_t fe, int dir) { return link_and_volume(a, b, fe, dir) == kOk; }

SeqStar SeqMesh::star() const {
  return {pool_.data(), roff_.data(), rlen_.data(), tets_->data(), nbr_.data(), labels_ ? labels_->data() : nullptr,
          vflags_.data(), points_->data(), p_.field_eps > 0 ? mesh_.vertex_fields[0].values.data() : nullptr,
          p_.field_eps > 0 ? size_t(mesh_.vertex_fields[0].components) : 0, p_.field_eps};
}

// The link condition (a < b): cl/collapse_checks.h's, over the common neighbours gathered here
// from marks on the rings (the device merges its sorted neighbour lists instead, which this
// dynamic mesh does not keep). True when it holds.
bool SeqMesh::link_ok(int32_t a, int32_t b, uint8_t fe) {
  // N(a) marked sA; the common neighbours cn = N(a) n N(b), each once, re-marked sC
  const uint32_t sA = next_stamp(), sC = next_stamp();
  const int32_t* ra = ring(a);
  const int32_t* rb = ring(b);
  for (uint32_t i = 0; i < rlen_[a]; ++i) {
    const int32_t* q = tet(ra[i]);
    for (int k = 0; k < 4; ++k)
      if (q[k] != a) mark_[q[k]] = sA;
  }
  cn_.clear();
  for (uint32_t i = 0; i < rlen_[b]; ++i) {
    const int32_t* q = tet(rb[i]);
    for (int k = 0; k < 4; ++k) {
      int32_t u = q[k];
      if (u != b && mark_[u] == sA) {
        mark_[u] = sC;
        cn_.push_back(u);
      }
    }
  }
  if (cn_.size() > TCC_MAX_LINK) return false;
  const SeqStar s = star();
  int pc[TCC_MAX_LINK], pd[TCC_MAX_LINK], p8[8], d8[8];
  const int np = geo::tcc_link_edges(s, a, b, pc, pd);
  if (np < 0) return false;
  geo::tcc_pad8(pc, np, p8);
  geo::tcc_pad8(pd, np, d8);
  return geo::tcc_link_holds(s, a, b, vflags_[a], vflags_[b], fe, cn_.data(), nullptr, nullptr, int(cn_.size()), pc,
                             pd, np, p8, d8) != 0;
}

// The volumes (and the quality guard) after the tentative collapse: cl/collapse_checks.h's.
uint8_t SeqMesh::volume_and_quality(int32_t a, int32_t b, int dir, double q_min) const {
  return uint8_t(geo::tcc_volume_verdict(star(), a, b, placement(a, b, unsigned(dir)), p_.eps_v, q_min));
}

bool SeqMesh::keeps_shape(int32_t a, int32_t b, int dir, double q) const {
  return volume_and_quality(a, b, dir, std::max(p_.min_quality, q)) == kOk;
}

}  // namespace tc::sequential_detail
