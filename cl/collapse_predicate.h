/* The predicate Q of the collapse (boundary protection by mode), shared by the admissible
 * filter of the parallel pipeline (cl/collapse_admissible.cl) and the sequential CPU method
 * (host/collapse/sequential_mesh.cpp): written once, compiled as OpenCL C and as C++ (names in
 * namespace tc::rules there), like cl/geometry.h. Pure integer logic.
 *
 * The constants here are the ones every kernel uses (cl/collapse_common.h includes this file). */
#ifndef TETCOLLAPSE_COLLAPSE_PREDICATE_H
#define TETCOLLAPSE_COLLAPSE_PREDICATE_H

/* Bits of vflags / eflags. */
#define TCC_BOUNDARY 1u  /* on a face with one tet */
#define TCC_INTERFACE 2u /* on a face between tets of different labels */
#define TCC_RIDGE 4u     /* eflags only: a ridge (feature) edge */

/* Vertex classes (tc::VertexClass) */
#define TCC_INTERIOR 0
#define TCC_FACE 1
#define TCC_RIDGEV 2
#define TCC_CORNER 3

/* Boundary modes (tc::CollapseOptions::Boundary) */
#define TCC_STRICT 0
#define TCC_FEATURES 1
#define TCC_FREE 2

/* Collapse direction of an admissible edge (edge_dir):
 * bit 0 set: the removed vertex is v1 (survivor v0), else the removed vertex is v0;
 * bit 1 set: midpoint placement, else the survivor keeps its position. */
#define TCC_DIR_REMOVE_V1 1u
#define TCC_DIR_MIDPOINT 2u
/* bit 2 set (with bit 1): the user's placement instead of the midpoint (tcc_user_dir in
 * collapse_common.h; never set by tcc_predicate_q) */
#define TCC_DIR_USER 4u
/* Under the boundary error bound, a collapse of S to the midpoint may keep an end point instead
 * where that changes S less (tcc_lazy_decide, SeqMesh::closest_placement): only while the
 * tets it reshapes keep this mean ratio (or what they had), since an end point of a curved face
 * skews its fan more than the midpoint does. */
#define TCC_END_POINT_MIN_QUALITY 0.3

#ifndef __OPENCL_C_VERSION__
namespace tc::rules {
#endif

/* Predicate Q of the edge (a, b), a < b, from the S flags of its end points (fa, fb) and of the
 * edge (fe), the classes of the end points (ca, cb), the mode and the paper's rule; returns the
 * edge_dir bits, or -1 to refuse. */
inline int tcc_predicate_q(int a, int b, unsigned int fa, unsigned int fb, unsigned int fe, int ca, int cb, int mode,
                           int paper_rule) {
  (void)a;
  (void)b;
  const int keep_a = (int)TCC_DIR_REMOVE_V1, keep_b = 0;
  const int sa = fa != 0u, sb = fb != 0u, se = (fe & (TCC_BOUNDARY | TCC_INTERFACE)) != 0u;
  if (mode == TCC_FREE) return (int)TCC_DIR_MIDPOINT | keep_a;
  if (mode == TCC_STRICT) {
    if (sa && sb) return -1;
    if (sa || sb) return paper_rule ? -1 : (sa ? keep_a : keep_b);
    return (int)TCC_DIR_MIDPOINT | keep_a;
  }
  /* features */
  if (sa && sb && !se) return -1;                 /* would pinch two sheets of S together */
  if (paper_rule && (sa || sb) && !se) return -1; /* the paper: no interior edge touching S */
  if (ca == cb) {
    if (ca == TCC_CORNER) return -1;
    if (ca == TCC_RIDGEV && !(fe & TCC_RIDGE)) return -1;
    return (int)TCC_DIR_MIDPOINT | keep_a; /* equal ranks: midpoint, survivor = lower index */
  }
  int removed_class = ca < cb ? ca : cb;
  if (removed_class == TCC_FACE && !se) return -1;
  if (removed_class == TCC_RIDGEV && !(fe & TCC_RIDGE)) return -1;
  return ca > cb ? keep_a : keep_b;
}

/* The link condition's virtual vertex w (collapse_admissible.cl tcc_link_test, SeqMesh::link_ok),
 * joined to every S-face: two simplices through a and b (the end points themselves, or the
 * edges (a, c) and (b, c)) with the S flags k1 and k2, which the collapse merges, need their join
 * (the edge (a, b), or the triangle (a, b, c)) with the flags k12 on S when both are on S; and
 * on each kind of S they share, since the boundary and the interfaces are two surfaces, either
 * of which the merge would pinch (an interface edge joining two points of the boundary: w of
 * the boundary would be in lk(a) and lk(b) but not in lk(ab)). */
inline int tcc_w_join_ok(unsigned int k1, unsigned int k2, unsigned int k12) {
  const unsigned int s = TCC_BOUNDARY | TCC_INTERFACE;
  if ((k1 & s) && (k2 & s) && !(k12 & s)) return 0;
  return (k1 & k2 & s & ~k12) == 0u;
}

#ifndef __OPENCL_C_VERSION__
}  // namespace tc::rules
#endif

#endif /* TETCOLLAPSE_COLLAPSE_PREDICATE_H */
