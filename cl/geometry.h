/* Geometry shared by the OpenCL kernels and the C++ host.
 *
 * Written once, compiled twice: as OpenCL C (embedded with the kernels) and as C++ (host
 * paths, reference implementations, tests), so both sides compute the same numbers.
 * Only scalar double arithmetic and the vector helpers below are used here; in C++ the
 * names live in namespace tc::geo.
 */
#ifndef TETCOLLAPSE_GEOMETRY_H
#define TETCOLLAPSE_GEOMETRY_H

#ifdef __OPENCL_C_VERSION__
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#define TC_FN inline
#define TC_D3(x, y, z) ((double3)((x), (y), (z)))
typedef double3 tc_d3;
#else
#include <cmath>
namespace tc::geo {
#define TC_FN inline
struct tc_d3 {
  double x, y, z;
};
inline tc_d3 operator+(tc_d3 a, tc_d3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline tc_d3 operator-(tc_d3 a, tc_d3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline tc_d3 operator*(tc_d3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
inline tc_d3 operator*(double s, tc_d3 a) { return {a.x * s, a.y * s, a.z * s}; }
inline tc_d3 operator/(tc_d3 a, double s) { return {a.x / s, a.y / s, a.z / s}; }
inline double dot(tc_d3 a, tc_d3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline tc_d3 cross(tc_d3 a, tc_d3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double length(tc_d3 a) { return std::sqrt(dot(a, a)); }
inline tc_d3 normalize(tc_d3 a) {
  double l = length(a);
  return l > 0 ? a / l : a;
}
using std::acos;
using std::fabs;
using std::sqrt;
#define TC_D3(x, y, z) (tc::geo::tc_d3{(x), (y), (z)})
#endif

/* Point i of a packed xyz array. */
TC_FN tc_d3 tc_point(const
#ifdef __OPENCL_C_VERSION__
                     __global
#endif
                     double* p,
                     int i) {
  return TC_D3(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
}

/* Six times the signed volume of (a, b, c, d): positive when d is on the side of the
 * triangle (a, b, c) its normal (b-a)x(c-a) points to, i.e. the right-hand rule used by
 * Gmsh, Medit and VTK for positively oriented tets. */
TC_FN double tc_orient3d(tc_d3 a, tc_d3 b, tc_d3 c, tc_d3 d) {
  return dot(cross(b - a, c - a), d - a);
}

TC_FN double tc_tet_volume(tc_d3 a, tc_d3 b, tc_d3 c, tc_d3 d) { return tc_orient3d(a, b, c, d) / 6.0; }

/* The barycentric coordinates of p in the tet (c0, c1, c2, c3): the point location of the
 * fields, on the host (TetLocator) and on the device (bvh.cl), with the same operations. */
TC_FN void tc_barycentric(tc_d3 c0, tc_d3 c1, tc_d3 c2, tc_d3 c3, tc_d3 p, double* b) {
  const double v = tc_orient3d(c0, c1, c2, c3);
  b[0] = tc_orient3d(p, c1, c2, c3) / v;
  b[1] = tc_orient3d(c0, p, c2, c3) / v;
  b[2] = tc_orient3d(c0, c1, p, c3) / v;
  b[3] = 1.0 - b[0] - b[1] - b[2];
}

/* Error bound of the floating-point tc_orient3d relative to its "permanent"
 * (Shewchuk's o3derrboundA): when |det| > bound, the sign is exact. */
TC_FN double tc_orient3d_errbound(tc_d3 a, tc_d3 b, tc_d3 c, tc_d3 d) {
  tc_d3 ba = b - a, ca = c - a, da = d - a;
  double perm = (fabs(ba.y * ca.z) + fabs(ba.z * ca.y)) * fabs(da.x) +
                (fabs(ba.z * ca.x) + fabs(ba.x * ca.z)) * fabs(da.y) +
                (fabs(ba.x * ca.y) + fabs(ba.y * ca.x)) * fabs(da.z);
  const double eps = 1.1102230246251565e-16; /* 2^-53 */
  return (7.0 + 56.0 * eps) * eps * perm * 2.0; /* x2: the differences are rounded too */
}

/* Unnormalised normal of triangle (a, b, c); its length is twice the area. */
TC_FN tc_d3 tc_triangle_normal(tc_d3 a, tc_d3 b, tc_d3 c) { return cross(b - a, c - a); }

/* Faces of a positively oriented tet (v0, v1, v2, v3), each listed so that its normal
 * points out of the tet. Face i is opposite vertex i. */
#ifdef __OPENCL_C_VERSION__
__constant int TC_TET_FACES[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
__constant int TC_TET_EDGES[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
#else
constexpr int TC_TET_FACES[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
constexpr int TC_TET_EDGES[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
#endif

/* Interior dihedral angle (radians) at edge (a, b) of tet (a, b, c, d). */
TC_FN double tc_dihedral_angle(tc_d3 a, tc_d3 b, tc_d3 c, tc_d3 d) {
  tc_d3 e = b - a;
  tc_d3 n1 = cross(e, c - a); /* normal of face (a, b, c) */
  tc_d3 n2 = cross(e, d - a); /* normal of face (a, b, d) */
  double l1 = length(n1), l2 = length(n2);
  if (l1 <= 0.0 || l2 <= 0.0) return 0.0;
  double cosang = dot(n1, n2) / (l1 * l2);
  if (cosang > 1.0) cosang = 1.0;
  if (cosang < -1.0) cosang = -1.0;
  return acos(cosang);
}

/* Smallest of the six interior dihedral angles (radians). */
TC_FN double tc_min_dihedral(tc_d3 p0, tc_d3 p1, tc_d3 p2, tc_d3 p3) {
  double m = tc_dihedral_angle(p0, p1, p2, p3);
  double t;
  t = tc_dihedral_angle(p0, p2, p1, p3); m = t < m ? t : m;
  t = tc_dihedral_angle(p0, p3, p1, p2); m = t < m ? t : m;
  t = tc_dihedral_angle(p1, p2, p0, p3); m = t < m ? t : m;
  t = tc_dihedral_angle(p1, p3, p0, p2); m = t < m ? t : m;
  t = tc_dihedral_angle(p2, p3, p0, p1); m = t < m ? t : m;
  return m;
}

/* Largest of the six interior dihedral angles (radians). */
TC_FN double tc_max_dihedral(tc_d3 p0, tc_d3 p1, tc_d3 p2, tc_d3 p3) {
  double m = tc_dihedral_angle(p0, p1, p2, p3);
  double t;
  t = tc_dihedral_angle(p0, p2, p1, p3); m = t > m ? t : m;
  t = tc_dihedral_angle(p0, p3, p1, p2); m = t > m ? t : m;
  t = tc_dihedral_angle(p1, p2, p0, p3); m = t > m ? t : m;
  t = tc_dihedral_angle(p1, p3, p0, p2); m = t > m ? t : m;
  t = tc_dihedral_angle(p2, p3, p0, p1); m = t > m ? t : m;
  return m;
}

/* Mean-ratio style quality 6*sqrt(2)*V / l_rms^3: 1 for a regular tet, -> 0 for slivers,
 * negative when inverted (the "qmin" of ../shared/meshes/SOURCES.md). tc_tet_quality_v takes
 * the volume tc_tet_volume(p0, p1, p2, p3) already at hand (the same bits). */
TC_FN double tc_tet_quality_v(tc_d3 p0, tc_d3 p1, tc_d3 p2, tc_d3 p3, double volume) {
  double s = dot(p1 - p0, p1 - p0) + dot(p2 - p0, p2 - p0) + dot(p3 - p0, p3 - p0) +
             dot(p2 - p1, p2 - p1) + dot(p3 - p1, p3 - p1) + dot(p3 - p2, p3 - p2);
  double lrms = sqrt(s / 6.0);
  if (lrms <= 0.0) return 0.0;
  return 6.0 * sqrt(2.0) * volume / (lrms * lrms * lrms);
}
TC_FN double tc_tet_quality(tc_d3 p0, tc_d3 p1, tc_d3 p2, tc_d3 p3) {
  return tc_tet_quality_v(p0, p1, p2, p3, tc_tet_volume(p0, p1, p2, p3));
}

/* Smallest sine of the six interior dihedral angles, signed by the volume: 1 at most, small for
 * a tet with a dihedral angle near 0 or 180 degrees, negative when inverted. The improvement's
 * measure (Klingner and Shewchuk's "minimum sine"): it penalises both kinds of sliver, and the
 * sine of the angle at edge (i, j) is 3 V |e_ij| / (2 A_k A_l) with A_k, A_l the two faces
 * through the edge, so no arc cosine is taken. */
TC_FN double tc_tet_min_sine(tc_d3 p0, tc_d3 p1, tc_d3 p2, tc_d3 p3) {
  double v = tc_tet_volume(p0, p1, p2, p3);
  /* twice the areas of the faces opposite each vertex */
  double a0 = length(cross(p2 - p1, p3 - p1)), a1 = length(cross(p2 - p0, p3 - p0));
  double a2 = length(cross(p1 - p0, p3 - p0)), a3 = length(cross(p1 - p0, p2 - p0));
  if (a0 <= 0.0 || a1 <= 0.0 || a2 <= 0.0 || a3 <= 0.0) return 0.0;
  /* edge (i, j) lies on the faces opposite the other two vertices; with doubled areas the
   * sine is 6 V |e| / (a_k a_l) */
  double s = length(p1 - p0) / (a2 * a3), t;
  t = length(p2 - p0) / (a1 * a3); s = t < s ? t : s;
  t = length(p3 - p0) / (a1 * a2); s = t < s ? t : s;
  t = length(p2 - p1) / (a0 * a3); s = t < s ? t : s;
  t = length(p3 - p1) / (a0 * a2); s = t < s ? t : s;
  t = length(p3 - p2) / (a0 * a1); s = t < s ? t : s;
  return 6.0 * v * s;
}

/* Cosine of the smallest interior dihedral angle (the largest cosine of the six): the angle at
 * edge (i, j) is pi minus the angle between the outward normals of the two faces through it. */
TC_FN double tc_tet_max_dihedral_cos(tc_d3 p0, tc_d3 p1, tc_d3 p2, tc_d3 p3) {
  /* outward normals of the faces opposite each vertex (TC_TET_FACES order) */
  tc_d3 n0 = normalize(cross(p2 - p1, p3 - p1)), n1 = normalize(cross(p3 - p0, p2 - p0));
  tc_d3 n2 = normalize(cross(p1 - p0, p3 - p0)), n3 = normalize(cross(p2 - p0, p1 - p0));
  double c = -dot(n2, n3), t;
  t = -dot(n1, n3); c = t > c ? t : c;
  t = -dot(n1, n2); c = t > c ? t : c;
  t = -dot(n0, n3); c = t > c ? t : c;
  t = -dot(n0, n2); c = t > c ? t : c;
  t = -dot(n0, n1); c = t > c ? t : c;
  return c;
}

#ifndef __OPENCL_C_VERSION__
}  // namespace tc::geo
#endif

#endif /* TETCOLLAPSE_GEOMETRY_H */
