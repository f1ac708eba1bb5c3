#!/usr/bin/python3
"""The paper's Fig. 11 experiment: a mesh full of slivers, improved.

    bench/improve_slivers.py [--tetcollapse PATH] [--meshes a,b] [--reps N]
                             [--out-json bench/results/improve_slivers.json]

Runs `tetcollapse improve M OUT --check --stats S` on meshes made by TetGen without a quality
bound (default: the shared robot meshes, 283k and 514k tets, minimum dihedral angle 0.01
degrees) and records, per mesh: the tets below 10 and 13 degrees before and after, the share of
the tets below 13 degrees removed (of all, and of those the boundary does not pin: none of
their vertices may move), the smallest dihedral angle, the passes, the wall time of the
improvement (median of --reps runs) and the checker's verdict.

    bench/improve_slivers.py --table F.json   prints the markdown table of a results file
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import peers  # noqa: E402

SHARED = os.path.join(os.path.dirname(ROOT), "shared", "meshes")
DEFAULT = ["gen_tetgen_thingi255172_make-robot_283k.msh", "gen_tetgen_thingi255172_make-robot_514k.msh"]


def table(doc):
    out = ["| mesh | tets | below 13 deg before -> after | removed | removed, not pinned | below 10 deg | "
           "min dihedral | passes | improve s | valid |", "|---|---:|---|---:|---:|---|---|---:|---:|---|"]
    for r in doc["rows"]:
        out.append(f"| {r['mesh']} | {r['tets_in']} | {r['below_13_before']} -> {r['below_13_after']} | "
                   f"{100 * r['removed_share']:.1f}% | {100 * r['removed_share_unpinned']:.1f}% | "
                   f"{r['below_10_before']} -> {r['below_10_after']} | {r['min_dihedral_before']:.2f} -> "
                   f"{r['min_dihedral_after']:.2f} | {r['passes']} | {r['seconds_improve']:.2f} | {r['check']} |")
    return "\n".join(out)


def main():
    if peers.table_asked(table):
        return
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tetcollapse", default=None)
    ap.add_argument("--meshes", default=",".join(DEFAULT))
    ap.add_argument("--reps", type=int, default=1)
    ap.add_argument("--out-json", default=os.path.join(HERE, "results", "improve_slivers.json"))
    a = ap.parse_args()
    tc = peers.tetcollapse_or_exit(a.tetcollapse, "improve_slivers.py")
    doc = dict(peers.provenance("improve_slivers.py", tc), reps=a.reps, rows=[])
    for name in a.meshes.split(","):
        mesh = os.path.join(SHARED, name)
        if not os.path.exists(mesh):
            print(f"skipped {name}: not in {SHARED}")
            continue
        times, st = [], None
        with tempfile.TemporaryDirectory(prefix="tc_sl_") as work:
            for _ in range(a.reps):
                out, js = os.path.join(work, "out.msh"), os.path.join(work, "s.json")
                p = subprocess.run([tc, "improve", mesh, out, "--check", "--stats", js, "-q"], capture_output=True,
                                   text=True)
                with open(js) as f:
                    st = json.load(f)
                st["exit_code"] = p.returncode
                times.append(st["improve"]["seconds"])
        imp = st["improve"]
        b, q = imp["quality_before"], imp["quality_after"]
        unpinned_before = b["below_13_deg"] - imp["pinned_below_13_before"]
        unpinned_after = q["below_13_deg"] - imp["pinned_below_13_after"]
        doc["rows"].append({
            "mesh": name, "tets_in": b["tets"], "tets_out": q["tets"],
            "below_13_before": b["below_13_deg"], "below_13_after": q["below_13_deg"],
            "below_10_before": b["below_10_deg"], "below_10_after": q["below_10_deg"],
            "removed_share": 1 - q["below_13_deg"] / max(1, b["below_13_deg"]),
            "removed_share_unpinned": 1 - max(0, unpinned_after) / max(1, unpinned_before),
            "min_dihedral_before": b["min_dihedral_deg"], "min_dihedral_after": q["min_dihedral_deg"],
            "passes": len(imp["passes"]), "seconds_improve": statistics.median(times), "seconds_runs": times,
            "check": st.get("check"), "exit_code": st["exit_code"], "load_avg": os.getloadavg()[0]})
        print(table({"rows": doc["rows"][-1:]}).splitlines()[-1], flush=True)
    os.makedirs(os.path.dirname(os.path.abspath(a.out_json)), exist_ok=True)
    with open(a.out_json, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
