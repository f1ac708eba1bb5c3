#!/usr/bin/python3
"""The Python module on the bundled bracket: NumPy arrays in and out, a field carried, the
result checked and written. Run from the repository after building:

    PYTHONPATH=build/python /usr/bin/python3 examples/coarsen.py [OUT.vtu]
"""
import os
import sys

import numpy as np
import tetcollapse

here = os.path.dirname(os.path.abspath(__file__))
mesh = tetcollapse.read(os.path.join(here, "..", "meshes", "bracket.msh"))
points, tets = mesh["points"], mesh["tets"]
print(f"input: {len(points)} vertices, {len(tets)} tets")

# a vertex field travels with the mesh: each output vertex gets the input's value at its place
temperature = 20 + 5 * points[:, 2]
out = tetcollapse.collapse(points, tets, target_factor=2, vertex_fields={"temperature": temperature})
s = out["stats"]
print(f"output: {s['vertices_out']} vertices, {s['tets_out']} tets in {s['seconds_collapse']:.2f} s "
      f"(+ {s['seconds_improve']:.2f} s improvement) on {s['device']}")
print(f"smallest dihedral angle {s['quality']['min_dihedral_deg']:.1f} degrees, "
      f"{s['quality']['below_10_deg']} tets below 10")
t = out["vertex_fields"]["temperature"]
gap = np.abs(t - (20 + 5 * out["points"][:, 2]))
# (a linear field stays exact inside the input; a vertex the coarsening moved a little outside,
# on a curved face, takes the value of the input's nearest point)
print(f"temperature: exact at {np.mean(gap < 1e-9):.1%} of the vertices, off by at most {gap.max():.2g} elsewhere")
print(f"valid: {tetcollapse.check(out['points'], out['tets'])['valid']}")
if len(sys.argv) > 1:
    tetcollapse.write(sys.argv[1], out["points"], out["tets"], vertex_fields=out["vertex_fields"])
    print(f"wrote {sys.argv[1]}")
