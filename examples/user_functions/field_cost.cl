// A cost for scalar data (the paper's volume-rendering use): the edge length, weighted up where
// the first vertex field changes along the edge, so that coarsening goes first where the field
// is flat.  tetcollapse IN OUT --cost-cl field_cost.cl --target-length L
// (p0, p1: the end points; f0, f1: the first vertex field at them, 0 without fields.)
double tc_user_cost(double3 p0, double3 p1, double f0, double f1) {
  return length(p1 - p0) * (1.0 + 10.0 * fabs(f1 - f0));
}
