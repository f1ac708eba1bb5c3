// A predicate: coarsen only below the plane z = 0.5 (both end points); the rest of the mesh
// keeps its vertices.  tetcollapse IN OUT --predicate-cl below_plane.cl
// Returns 0 to refuse the edge (on top of the built-in checks).
int tc_user_predicate(double3 p0, double3 p1, double f0, double f1) {
  return p0.z < 0.5 && p1.z < 0.5;
}
