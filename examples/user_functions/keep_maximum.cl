// A placement that keeps the field's maxima: the survivor goes to the end point with the larger
// first vertex field (and keeps that value), instead of the midpoint with the mean value.
//   tetcollapse IN OUT --placement-cl keep_maximum.cl
// Used where both end points are off the boundary (everywhere with --boundary free). Symmetric
// in its two end points, as a placement should be (which end is p0 is the pipeline's choice).
double3 tc_user_placement(double3 p0, double3 p1, double f0, double f1) {
  return f0 > f1 ? p0 : f1 > f0 ? p1 : 0.5 * (p0 + p1);
}
