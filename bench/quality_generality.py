#!/usr/bin/python3
"""Output quality against MMG3D on parts the method was not developed on, against the goals.

    bench/quality_generality.py [--tetcollapse PATH] [--timeout S] [--keep DIR]
                                [--out-json bench/results/quality_generality.json]

bench/quality_peers.py compares tetcollapse with MMG3D on the shared meshes, which the defaults
were measured on while they were chosen. Here gmsh (its Python module, Debian python3-gmsh)
writes parts of other shapes first, from OpenCASCADE solids: a flange (a disc and a hub, a bore
and six bolt holes), a capsule with a groove (a cylinder and two spheres, a torus cut away), a
sphere in a box as two materials, and a tube with a slot (thin walls); one thread and the
Delaunay algorithm, so that the same meshes come back each time. Each is then coarsened to
twice its median edge length L, one after the other on the same machine, by bench/peers.py:

    tetcollapse IN OUT --target-length L                        (defaults: bound, collapse, improvement)
    mmg3d_O3 IN.mesh -hmin L -hausd H                            (H = 0.001 x the bounding-box diagonal)
    mmg3d_O3 IN.mesh -hmin L                                     (the goals' reference run)

and every output judged by `tetcollapse check OUT --reference IN`. Below the table, the goals
that do not hold for each part's tetcollapse row: tets below 10 degrees no more than MMG
-hmin's (or the input's), smallest angle at least MMG -hmin's minus 0.5 degree (or the
input's), own time at most a fifth of MMG -hmin's; boundary distance within the bound, tets at
most 1.1x and own time at most a fifth of MMG -hmin -hausd's.

    bench/quality_generality.py --table F.json   prints the markdown table of a results file
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import peers  # noqa: E402
import quality_peers  # noqa: E402

PEERS = "tetcollapse,mmg3d_hmin_hausd,mmg3d_hmin"


def flange(occ):
    disc = occ.addCylinder(0, 0, 0, 0, 0, 2, 10)
    hub = occ.addCylinder(0, 0, 2, 0, 0, 6, 4)
    body = occ.fuse([(3, disc)], [(3, hub)])[0]
    holes = [occ.addCylinder(7 * math.cos(a), 7 * math.sin(a), -1, 0, 0, 4, 1)
             for a in (i * math.pi / 3 for i in range(6))]
    bore = occ.addCylinder(0, 0, -1, 0, 0, 10, 2.5)
    occ.cut(body, [(3, h) for h in holes] + [(3, bore)])


def capsule(occ):
    body = occ.addCylinder(0, 0, -4, 0, 0, 8, 4)
    ends = [occ.addSphere(0, 0, 4, 4), occ.addSphere(0, 0, -4, 4)]
    whole = occ.fuse([(3, body)], [(3, e) for e in ends])[0]
    occ.cut(whole, [(3, occ.addTorus(0, 0, 0, 4.2, 1.0))])


def sphere_in_box(occ):
    box = occ.addBox(-6, -6, -6, 12, 12, 12)
    occ.fragment([(3, box)], [(3, occ.addSphere(0, 0, 0, 4))])


def slotted_tube(occ):
    outer = occ.addCylinder(0, 0, 0, 0, 0, 12, 3)
    inner = occ.addCylinder(0, 0, -1, 0, 0, 14, 2.4)
    tube = occ.cut([(3, outer)], [(3, inner)])[0]
    occ.cut(tube, [(3, occ.addBox(-0.6, 0, 3, 1.2, 4, 6))])


# (name, solid, size): sizes for 80-200k tets
PARTS = (("flange", flange, 0.35), ("capsule", capsule, 0.3), ("sphere_in_box", sphere_in_box, 0.45),
         ("slotted_tube", slotted_tube, 0.16))


def write_part(name, solid, size, path):
    import gmsh
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.model.add(name)
        solid(gmsh.model.occ)
        gmsh.model.occ.synchronize()
        if name == "sphere_in_box":  # two materials: a physical group per volume
            for i, (_, tag) in enumerate(gmsh.model.getEntities(3)):
                gmsh.model.addPhysicalGroup(3, [tag], i + 1)
        gmsh.option.setNumber("Mesh.MeshSizeMax", size)
        gmsh.option.setNumber("Mesh.MeshSizeMin", 0.5 * size)
        gmsh.option.setNumber("Mesh.Algorithm3D", 1)
        gmsh.model.mesh.generate(3)
        gmsh.write(path)
    finally:
        gmsh.finalize()


def goals(mesh):
    """Which goals hold for the tetcollapse row of one mesh (None: a peer's row is missing)."""
    rows = {r["peer"]: r for r in mesh["rows"] if "skipped_reason" not in r}
    tc, hmin, hausd = rows.get("tetcollapse"), rows.get("mmg3d_hmin"), rows.get("mmg3d_hmin_hausd")
    inp = mesh["input"]
    out = {}
    if tc and hmin:
        out["below_10"] = tc["tets_below_10_deg"] <= max(hmin["tets_below_10_deg"], inp["tets_below_10_deg"])
        out["min_angle"] = tc["min_dihedral_deg"] >= min(hmin["min_dihedral_deg"] - 0.5, inp["min_dihedral_deg"])
        out["time_hmin"] = tc["seconds_algorithm"] <= hmin["seconds_algorithm"] / 5
    if tc:
        out["bound"] = tc["hausdorff_rel"] <= 0.001 * (1 + 1e-9)
    if tc and hausd:
        out["tets_hausd"] = tc["tets_out"] <= 1.1 * hausd["tets_out"]
        out["time_hausd"] = tc["seconds_algorithm"] <= hausd["seconds_algorithm"] / 5
    return out


def table(doc):
    """quality_peers.py's table, then the goals each part's tetcollapse row does not meet."""
    missed = [f"- {m['mesh']}: {', '.join(k for k, ok in m['goals'].items() if not ok) or 'none'}"
              for m in doc["meshes"]]
    return quality_peers.table(doc) + "\n\nGoals not met by tetcollapse:\n\n" + "\n".join(missed)


def main():
    if peers.table_asked(table):
        return
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tetcollapse", default=None)
    ap.add_argument("--timeout", type=float, default=600, help="seconds per command (a peer over it is skipped)")
    ap.add_argument("--keep", default=None, help="write the parts' meshes into this directory and keep them")
    ap.add_argument("--out-json", default=os.path.join(HERE, "results", "quality_generality.json"))
    a = ap.parse_args()
    tc = peers.tetcollapse_or_exit(a.tetcollapse, "quality_generality.py")
    try:
        import gmsh  # noqa: F401
    except ImportError:
        sys.exit("quality_generality.py: needs gmsh's Python module (Debian python3-gmsh; scripts/setup.sh --with-tools)")
    with tempfile.TemporaryDirectory(prefix="tc_qg_") as tmp:
        where = a.keep or tmp
        os.makedirs(where, exist_ok=True)
        paths = []
        for name, solid, size in PARTS:
            path = os.path.join(where, f"{name}.msh")
            write_part(name, solid, size, path)
            paths.append(path)
            print(f"wrote {path}", flush=True)
        js = os.path.join(tmp, "rows.json")
        # (quality_peers.py joins a name to the shared directory: an absolute path stays itself)
        subprocess.run([sys.executable, os.path.join(HERE, "quality_peers.py"), "--tetcollapse", tc, "--timeout",
                        str(a.timeout), "--peers", PEERS, "--meshes", ",".join(paths), "--out-json", js], check=True)
        with open(js) as f:
            measured = json.load(f)
    doc = dict(peers.provenance("quality_generality.py", tc), factor=measured["factor"], meshes=measured["meshes"])
    for m in doc["meshes"]:
        m["mesh"] = os.path.splitext(os.path.basename(m["mesh"]))[0]
        m["goals"] = goals(m)
    os.makedirs(os.path.dirname(os.path.abspath(a.out_json)), exist_ok=True)
    with open(a.out_json, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    print(table(doc))


if __name__ == "__main__":
    main()
