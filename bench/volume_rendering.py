#!/usr/bin/python3
"""Coarsening for direct volume rendering (the paper's Section 4.5), measured.

    bench/volume_rendering.py [--tetcollapse PATH] [--out-json bench/results/volume_rendering.json]
                              [--no-render] [--images DIR]

Data sets: shared meshes carrying an analytic field written here (a sum of three Gaussians, a
smooth field spanning tens of vertices, on the pocket and on the robot of W1; the
Marschner-Lobb signal, the standard volume-rendering test, with its 6 cycles, which a mesh of
this size does not resolve), and the shared `vtkdata_post_pressure.vtk` with its own field.
Each is coarsened by

    tetcollapse IN OUT --preserve-field F [--field-tolerance T] --boundary B --no-improve (features mode: with
    the default boundary error bound, and without it, --max-boundary-error 0, as "no bound")

at T = 0.02 (the paper) in `features` and `free` modes, with `--field-check 0` (the paper's cost
alone: "paper cost" rows) and `--average-fields` (the survivor's value the average of the edge's
ends) as the befores, and the pocket's Gaussians over a sweep of T; and with the field error
bound in place of T (`--max-field-error E`, E = 0.01: the "E" column). The robot (514k tets) in
`features` mode only.
Recorded per run: vertices and tets in and out, the tool's time without I/O, the volume kept,
and `tetcollapse check OUT --reference IN`'s field error (largest and RMS difference of the two
piecewise linear fields at every input vertex and 100,000 random points, as a share of the
field's range; "vertex max" at the input's vertices alone, what the bound bounds). W1-sized data is timed against W1's own coarsening in the same run. With VTK
(Debian python3-vtk9) and Xvfb, the input and the output are rendered
by VTK's unstructured-grid ray casting with one camera and transfer function, and the PSNR and
SSIM of the output's image against the input's are recorded (images in --images).

    bench/volume_rendering.py --table F.json   prints the markdown table of a results file
"""
import argparse
import json
import math
import statistics
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import peers  # noqa: E402

SHARED = os.path.join(os.path.dirname(ROOT), "shared", "meshes")
BOUND = 0.01  # --max-field-error


def table(doc):
    out = ["| data | field | mode | T | vertices in -> out | fewer vertices | tets out | volume kept | "
           "field RMS | field max | vertex max | PSNR dB | SSIM | own s |",
           "|---|---|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in doc["rows"]:
        f = lambda x, spec: "-" if x is None else format(x, spec)  # noqa: E731
        t = f"E {r['E']}" if r.get("E") else r["T"]
        out.append(f"| {r['data']} | {r['field']} | {r['mode']} | {t} | {r['vertices_in']} -> "
                   f"{r['vertices_out']} | {100 * r['vertex_reduction']:.1f}% | {r['tets_out']} | "
                   f"{100 * r['volume_kept']:.2f}% | {100 * r['rms_rel']:.3f}% | {100 * r['max_rel']:.2f}% | "
                   f"{f(r.get('max_vertex_rel') and 100 * r['max_vertex_rel'], '.3f')}{'' if r.get('max_vertex_rel') is None else '%'} | "
                   f"{f(r.get('psnr'), '.1f')} | {f(r.get('ssim'), '.3f')} | {r['seconds']:.2f} |")
    w = doc.get("w1_sized")
    if w:
        out += ["", f"W1-sized data (the robot, {w['tets']:,} tets, with the Gaussians, T = 0.02, features): "
                    f"{w['vertices_in']:,} -> {w['vertices_out']:,} vertices in {w['seconds_preserve_field']:.2f} s"
                    + (f" ({w['seconds_preserve_field_no_bound']:.2f} s without the boundary error bound, "
                       f"--max-boundary-error 0, as W1's)" if "seconds_preserve_field_no_bound" in w else "")
                    + f", against {w['seconds_w1']:.2f} s for W1's coarsening in the same run (medians of 3)."]
    return "\n".join(out)


def gaussians(p, lo, hi):
    """Three round Gaussians of width a tenth of the box's diagonal, at fixed places in the box
    (round: on a thin part, widths relative to each side would vary across a few edges)."""
    sigma = 0.1 * math.dist(lo, hi)
    centres = [(0.3, 0.3, 0.5), (0.7, 0.6, 0.4), (0.5, 0.8, 0.7)]
    return sum(math.exp(-sum((p[c] - lo[c] - m[c] * (hi[c] - lo[c])) ** 2 for c in range(3)) / (2 * sigma ** 2))
               for m in centres)


def marschner_lobb(p, lo, hi):
    x, y, z = (2 * (p[c] - lo[c]) / (hi[c] - lo[c]) - 1 for c in range(3))
    alpha, fm = 0.25, 6.0
    rho = math.cos(2 * math.pi * fm * math.cos(math.pi * math.sqrt(x * x + y * y) / 2))
    return (1 - math.sin(math.pi * z / 2) + alpha * (1 + rho)) / (2 * (1 + alpha))


def with_field(vtk, src, dst, name, fn):
    """Writes src (any format tetcollapse reads, converted to .vtu) with the point field `name`."""
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(src)
    r.Update()
    g = r.GetOutput()
    pts = g.GetPoints()
    lo = [min(pts.GetPoint(i)[c] for i in range(pts.GetNumberOfPoints())) for c in range(3)]
    hi = [max(pts.GetPoint(i)[c] for i in range(pts.GetNumberOfPoints())) for c in range(3)]
    arr = vtk.vtkDoubleArray()
    arr.SetName(name)
    for i in range(pts.GetNumberOfPoints()):
        arr.InsertNextValue(fn(pts.GetPoint(i), lo, hi))
    g.GetPointData().AddArray(arr)
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetFileName(dst)
    w.SetInputData(g)
    w.Write()


def vtk_or_exit(script):
    """VTK's Python module, which writes the fields and renders; exits with a message without it."""
    try:
        import vtk
    except ImportError:
        sys.exit(f"{script}: needs VTK's Python module (Debian python3-vtk9; scripts/setup.sh --with-tools)")
    return vtk


def judged(tc, vtu, out, stats, field):
    """What a run with --preserve-field is judged by: its stats (vertices, tets, time) and
    `tetcollapse check OUT --reference IN` (volume kept, field RMS and max, max at the input's
    vertices); with the check's reference report, for what a caller adds."""
    c = subprocess.run([tc, "check", out, "--reference", vtu, "--json", "-", "-q"], capture_output=True, text=True)
    ref = json.loads(c.stdout)["reference"]
    fe = next(x for x in ref["fields"] if x["name"] == field)
    return {"vertices_in": stats["vertices_in"], "vertices_out": stats["vertices_out"],
            "vertex_reduction": 1 - stats["vertices_out"] / stats["vertices_in"], "tets_out": stats["tets_out"],
            "volume_kept": 1 + ref["volume_change_rel"], "rms_rel": fe["rms_rel"], "max_rel": fe["max_rel"],
            "max_vertex_rel": fe["max_vertex_rel"], "seconds": stats["seconds_collapse"]}, ref


def main():
    if peers.table_asked(table):
        return
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tetcollapse", default=None)
    ap.add_argument("--out-json", default=os.path.join(HERE, "results", "volume_rendering.json"))
    ap.add_argument("--no-render", action="store_true")
    ap.add_argument("--images", default=os.path.join(HERE, "plots", "volume_rendering"))
    a = ap.parse_args()
    tc = peers.tetcollapse_or_exit(a.tetcollapse, "volume_rendering.py")
    vtk = vtk_or_exit("volume_rendering.py")
    doc = dict(peers.provenance("volume_rendering.py", tc), rows=[])
    render = None
    if not a.no_render:
        sys.path.insert(0, os.path.join(ROOT, "scripts"))
        import render_dvr  # noqa: E402
        render = render_dvr
        os.makedirs(a.images, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="tc_vr_") as work:
        data = []
        for mesh, field, fn in (("gen_tetgen_octagonal_pocket_160k.msh", "gauss", gaussians),
                                ("gen_tetgen_thingi255172_make-robot_514k.msh", "gauss", gaussians),
                                ("gen_tetgen_octagonal_pocket_160k.msh", "ml", marschner_lobb),
                                ("vtkdata_post_pressure.vtk", "Pressure", None)):
            src = os.path.join(SHARED, mesh)
            if not os.path.exists(src):
                print(f"skipped {mesh}: not in {SHARED}")
                continue
            vtu = os.path.join(work, f"{os.path.splitext(mesh)[0]}_{field}.vtu")
            subprocess.run([tc, "convert", src, vtu, "-q"], check=True)
            if fn:
                with_field(vtk, vtu, vtu, field, fn)
            data.append((mesh, field, vtu))
        # (mesh, field, vtu, mode, T or None for the bound, variant: "", "paper cost", "averaged",
        # "no bound": features mode without the default boundary error bound)
        runs = []
        for mesh, field, vtu in data:
            robot = "robot" in mesh
            sweep = [0.01, 0.02, 0.05] if field == "gauss" and not robot else [0.02]
            for mode in ("features",) if robot else ("features", "free"):
                for t in sweep:
                    runs.append((mesh, field, vtu, mode, t, ""))
                runs.append((mesh, field, vtu, mode, 0.02, "paper cost"))
                if mode == "features":
                    runs.append((mesh, field, vtu, mode, 0.02, "no bound"))
                if not robot:
                    runs.append((mesh, field, vtu, mode, 0.02, "averaged"))
                if field != "ml":  # (the bound on an unresolved signal keeps nearly everything)
                    runs.append((mesh, field, vtu, mode, None, ""))
        for mesh, field, vtu, mode, t, variant in runs:
            out = os.path.join(work, "out.vtu")
            stats = os.path.join(work, "s.json")
            cmd = [tc, vtu, out, "--preserve-field", field, "--boundary", mode, "--no-improve", "--stats", stats,
                   "-q"] + {"": [], "paper cost": ["--field-check", "0"], "averaged": ["--average-fields"],
                            "no bound": ["--max-boundary-error", "0"]}[variant]
            cmd += ["--field-tolerance", str(t)] if t is not None else ["--max-field-error", str(BOUND)]
            p = subprocess.run(cmd, capture_output=True, text=True)
            if p.returncode != 0:
                print(f"failed: {' '.join(cmd)}: {p.stderr.strip()}")
                continue
            with open(stats) as f:
                st = json.load(f)
            row = {"data": os.path.splitext(mesh)[0].replace("gen_tetgen_", ""), "field": field,
                   "mode": mode + (", " + variant if variant else ""), "T": t}
            row.update(judged(tc, vtu, out, st, field)[0])
            if t is None:
                row["E"] = BOUND
            if render and (t == 0.02 or t is None):
                tag = ("robot_" if "robot" in mesh else "") + f"{field}_{mode}" + ("_bound" if t is None else "")
                m = render.compare(vtu, out, field, None if variant else os.path.join(a.images, f"{tag}.png"))
                row.update(psnr=m["psnr"], ssim=m["ssim"])
            print(row)
            doc["rows"].append(row)
        # W1-sized data in the same run: the robot (514k tets) with the Gaussians, coarsened with
        # --preserve-field, with the boundary error bound (the default) and without it, against W1's
        # own coarsening (2x median, --eps-c 0, no bound), medians of 3
        robot = os.path.join(SHARED, "gen_tetgen_thingi255172_make-robot_514k.msh")
        robot_vtu = [vtu for mesh, field, vtu in data if "robot" in mesh]
        if robot_vtu:
            vtu = robot_vtu[0]  # written above
            out, stats = os.path.join(work, "out.vtu"), os.path.join(work, "s.json")
            times = {"preserve_field": [], "preserve_field_no_bound": [], "w1": []}
            for _ in range(3):
                for key, cmd in (("preserve_field", [tc, vtu, out, "--preserve-field", "gauss", "--no-improve"]),
                                 ("preserve_field_no_bound", [tc, vtu, out, "--preserve-field", "gauss", "--no-improve",
                                                              "--max-boundary-error", "0"]),
                                 ("w1", [tc, robot, out, "--target-factor", "2", "--eps-c", "0", "--max-boundary-error", "0",
                                         "--no-improve"])):
                    subprocess.run(cmd + ["--stats", stats, "-q"], check=True)
                    with open(stats) as f:
                        st = json.load(f)
                    times[key].append(st["seconds_collapse"])
                    if key == "preserve_field":
                        vertices = (st["vertices_in"], st["vertices_out"])
            doc["w1_sized"] = {"tets": 514161, "vertices_in": vertices[0], "vertices_out": vertices[1],
                               "seconds_preserve_field": statistics.median(times["preserve_field"]),
                               "seconds_preserve_field_no_bound": statistics.median(times["preserve_field_no_bound"]),
                               "seconds_w1": statistics.median(times["w1"])}
    with open(a.out_json, "w") as f:
        json.dump(doc, f, indent=1)
    print(table(doc))


if __name__ == "__main__":
    main()
