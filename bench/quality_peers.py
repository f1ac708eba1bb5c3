#!/usr/bin/python3
"""Output quality against MMG3D: every shared mesh coarsened to 2x its median edge length.

    bench/quality_peers.py [--tetcollapse PATH] [--reps N] [--meshes a,b] [--factor F]
                           [--out-json bench/results/quality_peers.json]

For each mesh of ../shared/meshes (top level), L = F x the input's median edge length (F = 2),
bench/peers.py runs, in one process each and one after the other on the same machine:
  tetcollapse            tetcollapse M OUT --target-length L         (defaults: collapse + improvement)
  tetcollapse_noimprove  ... --no-improve                            (the collapse alone)
  tetcollapse_bounded    ... --max-boundary-error 0.001               (the default's bound, given)
  tetcollapse_unbounded  ... --max-boundary-error 0                   (no bound: the paper's method)
  mmg3d_hmin             mmg3d_O3 M.mesh -hmin L                     (MMG3D, coarsening only)
  mmg3d_hmin_hausd       ... -hausd 0.001 x the bounding-box diagonal (MMG's default -hausd 0.01 is
                                                                      in mesh units)
and `tetcollapse check` judges every output against the input (validity, dihedral angles,
boundary Hausdorff distance). The input's own quality is recorded with it, since a goal is
relative to it (no more tets below 10 degrees than MMG, or than the input if it had more).

    bench/quality_peers.py --table F.json   prints the markdown table of a results file
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import peers  # noqa: E402

SHARED = os.path.join(os.path.dirname(ROOT), "shared", "meshes")
PEERS = ["tetcollapse", "tetcollapse_noimprove", "tetcollapse_bounded", "tetcollapse_unbounded", "mmg3d_hmin",
         "mmg3d_hmin_hausd"]


def fmt(x, spec):
    return "-" if x is None else format(x, spec)


def table(doc):
    out = ["| mesh | tets in | input min dihedral / < 10 deg | peer | tets out | min dihedral | < 10 deg | "
           "< 13 deg | Hausdorff rel | valid | own s | wall s |",
           "|---|---:|---|---|---:|---:|---:|---:|---:|---|---:|---:|"]
    for m in doc["meshes"]:
        inp = m["input"]
        first = True
        for r in m["rows"]:
            head = (f"| {m['mesh']} | {m['tets_in']} | {fmt(inp.get('min_dihedral_deg'), '.1f')} / "
                    f"{inp.get('tets_below_10_deg')} " if first else "| | | ")
            first = False
            if "skipped_reason" in r:
                out.append(head + f"| {r['peer']} | skipped | | | | | | | |")
                continue
            out.append(head + f"| {r['peer']} | {r.get('tets_out')} | {fmt(r.get('min_dihedral_deg'), '.1f')} | "
                       f"{r.get('tets_below_10_deg')} | {r.get('tets_below_13_deg')} | "
                       f"{fmt(r.get('hausdorff_rel'), '.4f')} | {r.get('valid')} | "
                       f"{fmt(r.get('seconds_algorithm'), '.3f')} | {fmt(r.get('seconds'), '.2f')} |")
    return "\n".join(out)


def main():
    if peers.table_asked(table):
        return
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tetcollapse", default=None)
    ap.add_argument("--reps", type=int, default=1)
    ap.add_argument("--factor", type=float, default=2.0)
    ap.add_argument("--meshes", default=None, help="comma-separated file names (default: every shared mesh)")
    ap.add_argument("--peers", default=",".join(PEERS))
    ap.add_argument("--timeout", type=float, default=600, help="seconds per command (a peer over it is skipped)")
    ap.add_argument("--out-json", default=os.path.join(HERE, "results", "quality_peers.json"))
    a = ap.parse_args()
    tc = peers.tetcollapse_or_exit(a.tetcollapse, "quality_peers.py")
    if not os.path.isdir(SHARED):
        sys.exit(f"quality_peers.py: no shared meshes at {SHARED}")
    names = a.meshes.split(",") if a.meshes else sorted(
        f for f in os.listdir(SHARED) if f.endswith((".msh", ".mesh", ".vtk", ".vtu")))
    doc = dict(peers.provenance("quality_peers.py", tc), factor=a.factor, reps=a.reps, meshes=[])
    for name in names:
        mesh = os.path.join(SHARED, name)
        info = json.loads(subprocess.run([tc, "info", mesh, "--json"], capture_output=True, text=True).stdout)
        L = a.factor * info["edge_length"]["median"]
        with tempfile.TemporaryDirectory(prefix="tc_qp_") as work:
            inp = peers.check_output(tc, mesh, mesh, work, 3600, False)
            js = os.path.join(work, "rows.json")
            subprocess.run([sys.executable, os.path.join(HERE, "peers.py"), "--mesh", mesh, "--target-length",
                            repr(L), "--tetcollapse", tc, "--reps", str(a.reps), "--peers", a.peers,
                            "--out-json", js, "--timeout", str(a.timeout)], check=True)
            with open(js) as f:
                rows = json.load(f)
        doc["meshes"].append({"mesh": name, "tets_in": info["tets"], "target_length": L, "input": inp, "rows": rows})
        os.makedirs(os.path.dirname(os.path.abspath(a.out_json)), exist_ok=True)
        with open(a.out_json, "w") as f:  # after every mesh: a long run that stops keeps what it did
            json.dump(doc, f, indent=1)
            f.write("\n")
    print(table(doc))


if __name__ == "__main__":
    main()
