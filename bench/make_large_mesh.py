#!/usr/bin/python3
"""Generate the 10M+ tet mesh of the scale benchmark (bench/scale.py), deterministically.

The robot surface of W1 (surfaces/thingi255172_MAKE_Robot_V6.stl in the shared meshes) is read,
its STL vertices merged exactly and written as OFF, then tetrahedralized by Debian's TetGen 1.6
with W1's quality bound and a smaller volume constraint (`tetgen -pq1.33a<V>`; W1 is a0.6),
and converted to binary Gmsh 4.1 by `tetcollapse convert`, as W1 is stored. The mesh goes to a
directory outside the repository (default /work/large/; it is not committed).

With the defaults (a0.001) the result is /work/large/robot_q1.33a0.001.msh: 10,748,541 tets and
1,830,478 vertices, a 489 MB file. Cost on the 2-core benchmark machine (TetGen uses one core):
TetGen about 9 minutes (under the load of other builds) with a peak of 1.9 GB resident, the
conversion about 10 s; the intermediate .node/.ele (560 MB) are deleted unless --keep-tetgen.
TetGen is deterministic here: the same counts on every run. Other sizes: a0.03 gives 0.86M
tets, a0.0015 7.5M; W1's a0.6 gives 511,949 (W1 has 514,161: its OFF came from another tool).

    /usr/bin/python3 bench/make_large_mesh.py [--out-dir /work/large] [--volume 0.001]
"""
import argparse
import os
import struct
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
SURFACE = "/work/shared/meshes/surfaces/thingi255172_MAKE_Robot_V6.stl"


def stl_to_off(stl, off):
    """Binary or ASCII STL -> OFF with exactly equal vertices merged (TetGen would otherwise see
    every triangle's corners as separate points)."""
    with open(stl, "rb") as f:
        data = f.read()
    tris = []
    n = struct.unpack_from("<I", data, 80)[0] if len(data) >= 84 else 0
    if len(data) == 84 + 50 * n:
        for i in range(n):
            v = struct.unpack_from("<12f", data, 84 + 50 * i)
            tris.append((v[3:6], v[6:9], v[9:12]))
    else:
        pts = [tuple(float(x) for x in line.split()[1:4])
               for line in data.decode("ascii", "replace").splitlines()
               if line.strip().startswith("vertex")]
        tris = [tuple(pts[i:i + 3]) for i in range(0, len(pts) - 2, 3)]
    index, verts, faces = {}, [], []
    for tri in tris:
        face = []
        for p in tri:
            if p not in index:
                index[p] = len(verts)
                verts.append(p)
            face.append(index[p])
        if len(set(face)) == 3:
            faces.append(face)
    with open(off, "w") as f:
        f.write("OFF\n%d %d 0\n" % (len(verts), len(faces)))
        for p in verts:
            f.write("%r %r %r\n" % p)
        for a, b, c in faces:
            f.write("3 %d %d %d\n" % (a, b, c))
    return len(verts), len(faces)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out-dir", default="/work/large")
    ap.add_argument("--surface", default=SURFACE)
    ap.add_argument("--quality", default="1.33", help="TetGen -q radius-edge bound (W1's: 1.33)")
    ap.add_argument("--volume", default="0.001", help="TetGen -a volume constraint (W1's: 0.6)")
    ap.add_argument("--tetcollapse", default=os.path.join(ROOT, "build", "tetcollapse"))
    ap.add_argument("--name", default=None, help="output file name (default robot_q<Q>a<V>.msh)")
    ap.add_argument("--keep-tetgen", action="store_true", help="keep TetGen's .node/.ele")
    args = ap.parse_args()

    os.makedirs(args.out_dir, exist_ok=True)
    # TetGen reads a trailing ".<digits>" of the input's name as an iteration number: no dots
    base = os.path.join(args.out_dir, "robot")
    out = os.path.join(args.out_dir, args.name or "robot_q%sa%s.msh" % (args.quality, args.volume))
    nv, nf = stl_to_off(args.surface, base + ".off")
    print("surface: %d vertices, %d triangles -> %s.off" % (nv, nf, base), flush=True)
    t0 = time.time()
    # -F: no .face/.edge files (the mesh is tets only, as W1); -Q: quiet.
    cmd = ["tetgen", "-pq%sa%s" % (args.quality, args.volume), "-FQ", base + ".off"]
    print(" ".join(cmd), flush=True)
    subprocess.run(cmd, check=True)
    t1 = time.time()
    print("tetgen: %.0f s" % (t1 - t0), flush=True)
    cmd = [args.tetcollapse, "convert", base + ".1.node", out]
    print(" ".join(cmd), flush=True)
    subprocess.run(cmd, check=True)
    print("convert: %.0f s; %s: %.0f MB" % (time.time() - t1, out, os.path.getsize(out) / 1e6), flush=True)
    if not args.keep_tetgen:
        for ext in (".1.node", ".1.ele", ".1.smesh"):
            if os.path.exists(base + ext):
                os.remove(base + ext)
    return 0


if __name__ == "__main__":
    sys.exit(main())
