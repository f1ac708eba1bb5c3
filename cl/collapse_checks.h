/* The link condition and the volume test (with the quality guard) of an edge collapse, written
 * once and compiled as OpenCL C (the selections' tests, cl/collapse_select.h) and as C++ (the
 * sequential method, host/collapse/sequential_mesh.cpp; names in namespace tc::geo there, as
 * cl/geometry.h), so that both sides reach the same verdicts by the same steps. The checks are
 * described at the top of cl/collapse_admissible.cl.
 *
 * They read the star of the edge through a small access layer, which the includer defines
 * before including this file (the device over the CSR arrays of an iteration, the host over the
 * dynamic mesh's rings):
 *   TCS_LINK_PARAMS, TCS_LINK_ARGS  what the link test's functions read of the mesh, as
 *                                   parameters and as the matching arguments
 *   TCS_VOL_PARAMS, TCS_VOL_ARGS    the same for the volume test
 *   TCS_RING_BEGIN(x), TCS_RING_END(x), TCS_RING_TET(i)
 *                                   ring(x), the tets containing x: TCS_RING_TET(i) for
 *                                   TCS_RING_BEGIN(x) <= i < TCS_RING_END(x)
 *   TCS_DEAD(t)                     tet t is removed and passed over (the matching selection's
 *                                   live tests, cl/collapse_select.h; 0 elsewhere)
 *   TCS_TET(t)                      the 4 vertices of tet t (a TCS_GLOBAL const int*)
 *   TCS_TETS                        all of them, 4 per tet (for TCS_Q4)
 *   TCS_ACROSS(t, f)                the tet across the face of t opposite local vertex f (-1: none,
 *                                   -2: several, as tet_nbr in cl/collapse_common.h)
 *   TCS_USE_LABELS, TCS_LABEL(t)    whether labels make interfaces, and the label of t
 *   TCS_SEDGE_SKIP(c)               the S-edges (a, c), (b, c) of check (ii) need not be looked at
 *                                   (c is off S)
 *   TCS_SEDGE(x, c, e)              the S kinds of the edge (x, c), e its edge id where the caller
 *                                   gathered one (tcc_link_holds)
 *   TCS_POINT(v)                    the position of v
 *   TCS_OLD_QUALITY(t, p0, p1, p2, p3)  tc_tet_quality of tet t = (p0, p1, p2, p3) as it is
 *                                   (or a value kept of it)
 *   TCS_FIELD_EPS, TCS_FIELD(v)     the field check's threshold (0: off) and the first vertex
 *                                   field's value at v (read only when the threshold is > 0)
 * The common neighbours of the edge are gathered by the caller (tcc_link_holds): the device
 * merges the sorted neighbour lists it has, the host marks the vertices of the rings (it keeps no
 * sorted lists). The device's live gatherings (cl/collapse_select.h) stay there: the host's rings
 * hold no removed tets, and tcc_live_common refuses an N(a) longer than TCC_MAX_LINK, which the
 * other two gatherings do not. */
#ifndef TETCOLLAPSE_COLLAPSE_CHECKS_H
#define TETCOLLAPSE_COLLAPSE_CHECKS_H

#include "collapse_predicate.h"
#include "geometry.h"

#ifdef __OPENCL_C_VERSION__
#define TCS_GLOBAL __global
/* a tet's vertices as one load */
typedef int4 tcs_q4;
#define TCS_Q4(t) vload4((t), TCS_TETS)
#define TCS_Q4_HAS(q, y) any((q) == (int4)(y))
#else
#include <cstddef>
namespace tc::geo {
using rules::tcc_w_join_ok;
#define TCS_GLOBAL
struct tcs_q4 {
  int x, y, z, w;
};
inline tcs_q4 tcs_q4_load(const int* tets, int t) {
  const int* q = tets + 4 * size_t(t);
  return {q[0], q[1], q[2], q[3]};
}
#define TCS_Q4(t) tcs_q4_load(TCS_TETS, (t))
#define TCS_Q4_HAS(q, y) (((q).x == (y)) | ((q).y == (y)) | ((q).z == (y)) | ((q).w == (y)))
/* the verdicts of cl/collapse_common.h (collapse_detail::Reason on the host) */
#define TCC_OK 0
#define TCC_REFUSED_LINK 3
#define TCC_REFUSED_VOLUME 4
#define TCC_REFUSED_QUALITY 6
#endif

/* The link test's lists (the common neighbours, the edges of lk(ab)) hold at most this many
 * entries; a longer list refuses the edge (conservative; never reached on real meshes). */
#ifndef TCC_MAX_LINK
#define TCC_MAX_LINK 96
#endif
/* Tets per chunk of the volume loop: on CPUs (CPU devices: TCC_PREFETCH; the host) many, so
 * that the gathers overlap; elsewhere few (private arrays indexed at run time cost GPUs scratch
 * memory). */
#ifndef TCC_VOL_CHUNK
#if defined(TCC_PREFETCH) || !defined(__OPENCL_C_VERSION__)
#define TCC_VOL_CHUNK 32
#else
#define TCC_VOL_CHUNK 4
#endif
#endif

/* --- the volume test --- */

/* The field check's search: when the tet c holds x better than the best so far (a larger
 * smallest barycentric coordinate), it becomes the best, and *at the field f interpolated at x. */
TC_FN void tcc_field_in_tet(const tc_d3* c, const double* f, tc_d3 x, double* best, double* at) {
  double l[4];
  tc_barycentric(c[0], c[1], c[2], c[3], x, l);
  const double m = fmin(fmin(l[0], l[1]), fmin(l[2], l[3]));
  if (m > *best) {
    *best = m;
    *at = l[0] * f[0] + l[1] * f[1] + l[2] * f[2] + l[3] * f[3];
  }
}

/* The volume test and the quality guard of the collapse of (a, b) in which the survivor goes to
 * p (the vertex that moves there is a, b or both): TCC_OK, TCC_REFUSED_VOLUME or
 * TCC_REFUSED_QUALITY. Every tet of ring(a) U ring(b) that survives (holds one end point only)
 * must keep a volume of at least eps_v with its end point at p; with the quality guard
 * (q_min > 0), the worst mean ratio among the tets that change shape may not fall below
 * min(its value before the collapse, q_min): a collapse never makes a good neighbourhood bad,
 * nor a bad one worse. With the field check (TCS_FIELD_EPS > 0; TCS_FIELD(v) the first vertex
 * field, both defined by the includer): an end point that moves may not find the new piecewise
 * linear field at its old place off its value by more than TCS_FIELD_EPS (TCC_REFUSED_QUALITY:
 * docs/algorithm.md, the field check). */
TC_FN int tcc_volume_verdict(TCS_VOL_PARAMS, int a, int b, tc_d3 p, double eps_v, double q_min) {
  tc_d3 pa = TCS_POINT(a), pb = TCS_POINT(b);
  double q_old = 1.0, q_new = 1.0;
  /* The field check (TCS_FIELD_EPS > 0): the survivor's value interpolated along the edge at the
   * placement's parameter, as the collapse sets it; for each end point that moves, the new tet
   * that holds its old place best (largest smallest barycentric coordinate) and the new field's
   * value there. */
  const double f_eps = TCS_FIELD_EPS;
  double f_a = 0.0, f_b = 0.0, f_p = 0.0, best_a = -INFINITY, best_b = -INFINITY, at_a = 0.0, at_b = 0.0;
  if (f_eps > 0.0) {
    f_a = TCS_FIELD(a);
    f_b = TCS_FIELD(b);
    tc_d3 e = pb - pa;
    double ee = dot(e, e), t = ee > 0.0 ? dot(p - pa, e) / ee : 0.0;
    t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    f_p = f_a + (f_b - f_a) * t;
  }
  /* Two passes with the field check: the volumes and the quality guard first, then, only for a
   * collapse they admit, the field at the end points' old places (most tests are refused by the
   * first, and the search for the tets that hold those places costs more than the volumes). The
   * same tets in the same order: the same verdicts. */
  const int passes = f_eps > 0.0 ? 2 : 1;
  for (int pass = 0; pass < passes; ++pass) {
    for (int side = 0; side < 2; ++side) {
      int x = side == 0 ? a : b, y = side == 0 ? b : a;
      tc_d3 px = side == 0 ? pa : pb;
      if (px.x == p.x && px.y == p.y && px.z == p.z) continue; /* x does not move: its tets keep their shape */
      /* In chunks, two loops: first the vertices of the tets (independent loads, so that the
       * processor has many cache misses in flight; branch-free), then their volumes. One loop
       * doing both waited for each tet's vertices in turn. */
      for (unsigned int i0 = TCS_RING_BEGIN(x), iend = TCS_RING_END(x); i0 < iend; i0 += TCC_VOL_CHUNK) {
        tcs_q4 qs[TCC_VOL_CHUNK];
        int ts[TCC_VOL_CHUNK];
        unsigned int m = 0, i1 = iend - i0 < TCC_VOL_CHUNK ? iend : i0 + TCC_VOL_CHUNK;
        for (unsigned int i = i0; i < i1; ++i) {
          int t = TCS_RING_TET(i);
          tcs_q4 q = TCS_Q4(t);
          qs[m] = q;
          ts[m] = t;
          m += (TCS_Q4_HAS(q, y) | TCS_DEAD(t)) ? 0u : 1u; /* else removed by this collapse or an earlier one */
        }
        for (unsigned int j = 0; j < m; ++j) {
          tcs_q4 q = qs[j];
          tc_d3 c[4];
          c[0] = q.x == x ? p : TCS_POINT(q.x);
          c[1] = q.y == x ? p : TCS_POINT(q.y);
          c[2] = q.z == x ? p : TCS_POINT(q.z);
          c[3] = q.w == x ? p : TCS_POINT(q.w);
          if (pass == 1) {
            const double f[4] = {q.x == x ? f_p : TCS_FIELD(q.x), q.y == x ? f_p : TCS_FIELD(q.y),
                                 q.z == x ? f_p : TCS_FIELD(q.z), q.w == x ? f_p : TCS_FIELD(q.w)};
            if (pa.x != p.x || pa.y != p.y || pa.z != p.z) tcc_field_in_tet(c, f, pa, &best_a, &at_a);
            if (pb.x != p.x || pb.y != p.y || pb.z != p.z) tcc_field_in_tet(c, f, pb, &best_b, &at_b);
            continue;
          }
          double vol = tc_tet_volume(c[0], c[1], c[2], c[3]);
          if (!(vol >= eps_v)) return TCC_REFUSED_VOLUME;
#ifdef TCC_USER_PLACEMENT
          if (!(vol < INFINITY)) return TCC_REFUSED_VOLUME; /* a finite placement far enough overflows */
#endif
          if (q_min > 0.0) {
            double qn = tc_tet_quality_v(c[0], c[1], c[2], c[3], vol);
            double qo = TCS_OLD_QUALITY(ts[j], q.x == x ? px : c[0], q.y == x ? px : c[1], q.z == x ? px : c[2],
                                        q.w == x ? px : c[3]);
            q_new = qn < q_new ? qn : q_new;
            q_old = qo < q_old ? qo : q_old;
          }
        }
      }
    }
    if (pass == 0 && q_min > 0.0 && q_new < (q_old < q_min ? q_old : q_min)) return TCC_REFUSED_QUALITY;
  }
  if (f_eps > 0.0 && ((best_a > -INFINITY && !(fabs(at_a - f_a) <= f_eps)) ||
                          (best_b > -INFINITY && !(fabs(at_b - f_b) <= f_eps))))
    return TCC_REFUSED_QUALITY;
  return TCC_OK;
}

/* --- the link condition --- */

TC_FN int tcc_in(const int* list, int n, int x) {
  for (int i = 0; i < n; ++i)
    if (list[i] == x) return 1;
  return 0;
}

/* x in v[0..8) (pads of -1 never match a vertex): eight compares, no branch. The link test's
 * small sets are kept so when they fit: a lookup by loop exits at a data-dependent place, and
 * those mispredicted exits were a large part of a passing test (bench_admissible). */
#define TCC_ANY8(v, x)                                                                                     \
  (((x) == (v)[0]) | ((x) == (v)[1]) | ((x) == (v)[2]) | ((x) == (v)[3]) | ((x) == (v)[4]) | ((x) == (v)[5]) | \
   ((x) == (v)[6]) | ((x) == (v)[7]))

/* v[0..8): list[0..n), then -1 (for TCC_ANY8) */
TC_FN void tcc_pad8(const int* list, int n, int* v) {
  for (int k = 0; k < 8; ++k) v[k] = k < n ? list[k] : -1;
}

/* Is x a vertex of lk(ab)? pc, pd: its np edges; p8, d8: the same padded to 8 with -1 (used when
 * np <= 8, for TCC_ANY8). */
TC_FN int tcc_in_lk(int x, const int* pc, const int* pd, int np, const int* p8, const int* d8) {
  return np <= 8 ? (TCC_ANY8(p8, x) | TCC_ANY8(d8, x)) : (tcc_in(pc, np, x) || tcc_in(pd, np, x));
}

/* Local index (0..3) of x in the tet q, or -1. */
TC_FN int tcc_qlocal(TCS_GLOBAL const int* q, int x) {
  return q[0] == x ? 0 : q[1] == x ? 1 : q[2] == x ? 2 : q[3] == x ? 3 : -1;
}
TC_FN int tcc_qhas(TCS_GLOBAL const int* q, int x) { return q[0] == x || q[1] == x || q[2] == x || q[3] == x; }

/* The S kind of the face of tet t opposite local vertex f (0: off S): boundary when no tet or
 * several are across it (as tcc_owned_sface), interface when the tet across has another label. */
TC_FN unsigned int tcc_face_kind(TCS_LINK_PARAMS, int t, int f) {
  int o = TCS_ACROSS(t, f);
  if (o < 0) return TCC_BOUNDARY;
  if (TCS_USE_LABELS && TCS_LABEL(t) != TCS_LABEL(o)) return TCC_INTERFACE;
  return 0u;
}

/* Does some tet of ring(x) contain y and z (and w when w >= 0)? */
TC_FN int tcc_ring_has(TCS_LINK_PARAMS, int x, int y, int z, int w) {
  for (unsigned int i = TCS_RING_BEGIN(x); i < TCS_RING_END(x); ++i) {
    int t = TCS_RING_TET(i);
    if (TCS_DEAD(t)) continue;
    TCS_GLOBAL const int* q = TCS_TET(t);
    if (tcc_qhas(q, y) && tcc_qhas(q, z) && (w < 0 || tcc_qhas(q, w))) return 1;
  }
  return 0;
}

/* Is the triangle (x, y, z) an S-face (boundary or interface)? From the tets of ring(x) that hold
 * it: none, not a triangle of the mesh; one or more than two, boundary; two of different labels,
 * interface. */
TC_FN unsigned int tcc_tri_kind(TCS_LINK_PARAMS, int x, int y, int z) {
  int n = 0, t0 = -1, t1 = -1;
  for (unsigned int i = TCS_RING_BEGIN(x); i < TCS_RING_END(x); ++i) {
    int u = TCS_RING_TET(i);
    if (TCS_DEAD(u)) continue;
    TCS_GLOBAL const int* q = TCS_TET(u);
    if (tcc_qhas(q, y) && tcc_qhas(q, z)) {
      if (n == 0) t0 = u;
      else if (n == 1) t1 = u;
      ++n;
    }
  }
  if (n == 0) return 0u; /* not a triangle of the mesh */
  if (n != 2) return TCC_BOUNDARY;
  if (TCS_USE_LABELS && TCS_LABEL(t0) != TCS_LABEL(t1)) return TCC_INTERFACE;
  return 0u;
}

/* The S kinds of the edge (x, c) (0 when it is no S-edge) from the faces through it of the tets
 * of ring(x), for a star whose edge flags are not at hand (TCS_SEDGE). */
TC_FN unsigned int tcc_ring_sedge(TCS_LINK_PARAMS, int x, int c) {
  unsigned int flags = 0;
  for (unsigned int i = TCS_RING_BEGIN(x); i < TCS_RING_END(x); ++i) {
    int t = TCS_RING_TET(i);
    if (TCS_DEAD(t)) continue;
    TCS_GLOBAL const int* q = TCS_TET(t);
    int lc = tcc_qlocal(q, c);
    if (lc < 0) continue;
    int lx = tcc_qlocal(q, x);
    for (int f = 0; f < 4; ++f) {
      if (f == lx || f == lc) continue; /* the two faces through x and c */
      flags |= tcc_face_kind(TCS_LINK_ARGS, t, f);
    }
  }
  return flags;
}

/* lk(ab) as edges (pc[k], pd[k]), one per tet (a, b, pc[k], pd[k]) of ring(a): returns their
 * number np, or -1 when there are more than TCC_MAX_LINK. */
TC_FN int tcc_link_edges(TCS_LINK_PARAMS, int a, int b, int* pc, int* pd) {
  int np = 0;
  for (unsigned int i = TCS_RING_BEGIN(a); i < TCS_RING_END(a); ++i) {
    int t = TCS_RING_TET(i);
    TCS_GLOBAL const int* q = TCS_TET(t);
    if (TCS_DEAD(t) || !tcc_qhas(q, b)) continue;
    if (np == TCC_MAX_LINK) return -1;
    int o[2], no = 0;
    for (int k = 0; k < 4; ++k)
      if (q[k] != a && q[k] != b) o[no++] = q[k];
    pc[np] = o[0];
    pd[np] = o[1];
    ++np;
  }
  return np;
}

/* The link condition of the edge (a, b), a < b, with the S flags fa, fb of a and b and fe of the
 * edge: 1 when it holds. cn: N(a) n N(b) (ncn <= TCC_MAX_LINK vertices; cea[k], ceb[k] the edges
 * (a, cn[k]) and (b, cn[k]) for TCS_SEDGE, where the caller has them); pc, pd: the np edges of
 * lk(ab) (tcc_link_edges, np <= TCC_MAX_LINK), p8, d8: the same padded to 8 (tcc_pad8). */
TC_FN int tcc_link_holds(TCS_LINK_PARAMS, int a, int b, unsigned int fa, unsigned int fb, unsigned int fe,
                         const int* cn, const int* cea, const int* ceb, int ncn, const int* pc, const int* pd, int np,
                         const int* p8, const int* d8) {
  (void)cea;
  (void)ceb;
  /* cn padded to 8 when it fits (the usual case), for TCC_ANY8 */
  int c8[8];
  const int small = ncn <= 8 && np <= 8;
  tcc_pad8(cn, ncn, c8);
#define TCC_IN_CN(x) (small ? TCC_ANY8(c8, x) : tcc_in(cn, ncn, (x)))
  int ok = 1;
  const unsigned int smask = TCC_BOUNDARY | TCC_INTERFACE;
  /* (iii) with w, inside the tets (a,b,c,d) of the edge: no S-faces (a,c,d) and (b,c,d) (the
   * triangle (c,d,w) would be in lk(a) and lk(b) but not in lk(ab); e.g. a lone tet, which the
   * collapse would flatten away). An S-face has S vertices only. */
  if ((fa & smask) && (fb & smask))
    for (unsigned int i = TCS_RING_BEGIN(a); i < TCS_RING_END(a) && ok; ++i) {
      int t = TCS_RING_TET(i);
      TCS_GLOBAL const int* q = TCS_TET(t);
      int la = tcc_qlocal(q, a), lb = tcc_qlocal(q, b);
      if (lb < 0 || TCS_DEAD(t)) continue;
      /* the faces (a,c,d) and (b,c,d), opposite b and a */
      int acd = tcc_face_kind(TCS_LINK_ARGS, t, lb) != 0u, bcd = tcc_face_kind(TCS_LINK_ARGS, t, la) != 0u;
      if (acd && bcd) ok = 0;
    }
  /* (i) vertices, and w */
  if (small) {
    for (int k = 0; k < 8; ++k) ok &= (c8[k] < 0) | TCC_ANY8(p8, c8[k]) | TCC_ANY8(d8, c8[k]);
  } else {
    for (int k = 0; k < ncn && ok; ++k)
      if (!tcc_in_lk(cn[k], pc, pd, np, p8, d8)) ok = 0;
  }
  if (ok && !tcc_w_join_ok(fa, fb, fe)) ok = 0;
  /* (ii) with w: S-edges (a,c) and (b,c) need the S-face (a,b,c), of the kinds they share
   * (tcc_w_join_ok); an S-edge has both end points on S, so only when a and b are */
  if ((fa & smask) && (fb & smask))
    for (int k = 0; k < ncn && ok; ++k) {
      int c = cn[k];
      if (TCS_SEDGE_SKIP(c)) continue;
      unsigned int fac = TCS_SEDGE(a, c, cea[k]), fbc = TCS_SEDGE(b, c, ceb[k]);
      if ((fac & smask) && (fbc & smask) && !tcc_w_join_ok(fac, fbc, tcc_tri_kind(TCS_LINK_ARGS, a, b, c))) ok = 0;
    }
  /* (ii) triangles and (iii) tets and S-faces, from the tets of ring(a) without b */
  for (unsigned int i = TCS_RING_BEGIN(a); i < TCS_RING_END(a) && ok; ++i) {
    int t = TCS_RING_TET(i);
    const tcs_q4 q4 = TCS_Q4(t);
    if ((q4.x == b) | (q4.y == b) | (q4.z == b) | (q4.w == b) || TCS_DEAD(t)) continue;
    TCS_GLOBAL const int* q = TCS_TET(t);
    /* the three vertices other than a, in the tet's order, without branches */
    const int la = q4.x == a ? 0 : q4.y == a ? 1 : q4.z == a ? 2 : 3;
    const int o[3] = {la == 0 ? q4.y : q4.x, la <= 1 ? q4.z : q4.y, la <= 2 ? q4.w : q4.z};
    const int in0 = TCC_IN_CN(o[0]), in1 = TCC_IN_CN(o[1]), in2 = TCC_IN_CN(o[2]);
    if (in0 + in1 + in2 < 2) continue; /* most tets: nothing below applies (no pair in cn) */
    if (in0 && in1 && in2 && tcc_ring_has(TCS_LINK_ARGS, b, o[0], o[1], o[2])) {
      ok = 0; /* tets (a,c,d,e) and (b,c,d,e) */
      break;
    }
    const int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
    const int inside[3] = {in0, in1, in2};
    for (int k = 0; k < 3 && ok; ++k) {
      if (!inside[pairs[k][0]] || !inside[pairs[k][1]]) continue;
      int c = o[pairs[k][0]], d = o[pairs[k][1]];
      int in_lk = 0;
      if (small)
        for (int m = 0; m < 8; ++m) in_lk |= ((p8[m] == c) & (d8[m] == d)) | ((p8[m] == d) & (d8[m] == c));
      else
        for (int m = 0; m < np; ++m)
          if ((pc[m] == c && pd[m] == d) || (pc[m] == d && pd[m] == c)) in_lk = 1;
      if (!in_lk) {
        /* (ii) triangles (a,c,d) and (b,c,d) need the tet (a,b,c,d) */
        if (tcc_ring_has(TCS_LINK_ARGS, b, c, d, -1)) ok = 0;
        continue;
      }
      /* (c,d) in lk(ab): (b,c,d) is a face of the tet (a,b,c,d). (iii) no S-faces (a,c,d) and
       * (b,c,d); an S-face has S vertices only. (a,c,d) is the face of t opposite its fourth
       * vertex z. */
      if (!(fa & smask) || !(fb & smask)) continue;
      int z = 0;
      while (q[z] == a || q[z] == c || q[z] == d) ++z;
      if (tcc_face_kind(TCS_LINK_ARGS, t, z) && tcc_tri_kind(TCS_LINK_ARGS, b, c, d)) ok = 0;
    }
  }
#undef TCC_IN_CN
  return ok;
}

#ifndef __OPENCL_C_VERSION__
}  // namespace tc::geo
#endif

#endif /* TETCOLLAPSE_COLLAPSE_CHECKS_H */
