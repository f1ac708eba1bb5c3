#!/usr/bin/python3
"""W1 with and without the improvement phase, and the improvement by where it runs.

    bench/improve_paths.py [--tetcollapse PATH] [--mesh NAME] [--reps N]
                           [--out-json bench/results/improve_paths.json]

On the shared robot mesh (514k tets; default) coarsened to twice its median edge length, runs
--reps times, interleaved:
  - `tetcollapse IN OUT --target-factor 2 --eps-c 0 --max-boundary-error 0 --no-improve` (W1 is
    the paper's method: no boundary error bound) and the same with the
    improvement phase (W1 through the CLI, the quality guard on and two cycles of collapse and
    improvement as by default): the ratio of their own times without file I/O (every cycle's
    collapse and improvement); the same pair with the CLI's defaults otherwise (the boundary
    error bound on: `tetcollapse IN OUT --target-factor 2 --eps-c 0 [--no-improve]`);
  - `tetcollapse improve COARSE OUT` on the coarsened mesh three ways: the device's default
    paths (`TETCOLLAPSE_TUNING` as the device says; on a CPU: relocation on the device, flips on
    the host), `TETCOLLAPSE_TUNING=gpu` (flips found on the device too) and `--method
    sequential` (all on the CPU): the improvement's time and its parts (setup, flips,
    relocation, the collapse step), medians, and the quality it leaves.

    bench/improve_paths.py --table F.json   prints the markdown tables of a results file
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
PATHS = [("device default", {}, []), ("device, GPU tuning", {"TETCOLLAPSE_TUNING": "gpu"}, []),
         ("sequential (CPU)", {}, ["--method", "sequential"])]


def table(doc):
    w = doc["w1"]
    out = ["| W1 (CLI, own s: collapse + improvement) | median s | tets out | below 10 deg | below 13 deg |",
           "|---|---:|---:|---:|---:|"]
    for key, label in (("without", "`--max-boundary-error 0 --no-improve` (the paper's W1)"),
                       ("with", "`--max-boundary-error 0` (with the improvement)")):
        r = w[key]
        out.append(f"| {label} | {r['seconds']:.2f} | {r['tets']} | {r['below_10']} | {r['below_13']} |")
    if "bound_without" in w:
        for key, label in (("bound_without", "`--no-improve` (the bound on, as by default)"),
                           ("bound_with", "the defaults (the bound and the improvement)")):
            r = w[key]
            out.append(f"| {label} | {r['seconds']:.2f} | {r['tets']} | {r['below_10']} | {r['below_13']} |")
    out += ["", f"Ratio with / without: **{w['ratio']:.2f}x** (the goal: 1.5x)" +
            (f"; with the bound on, as by default: {w['bound_ratio']:.2f}x." if "bound_ratio" in w else "."), "",
            "| `improve` on W1's output | median s | setup | flips | relocation | collapse step | passes | "
            "below 10 deg | below 13 deg |", "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in doc["paths"]:
        out.append(f"| {r['path']} | {r['seconds']:.2f} | {r['setup']:.2f} | {r['flips']:.2f} | "
                   f"{r['relocation']:.2f} | {r['collapse_step']:.2f} | {r['passes']} | {r['below_10']} | "
                   f"{r['below_13']} |")
    return "\n".join(out)


def run(cmd, env_extra, stats):
    env = dict(os.environ, **env_extra)
    p = subprocess.run(cmd + ["--stats", stats, "-q"], capture_output=True, text=True, env=env)
    if p.returncode != 0:
        sys.exit(f"improve_paths.py: {' '.join(cmd)} failed ({p.returncode}): {p.stderr.strip()}")
    with open(stats) as f:
        return json.load(f)


def main():
    if peers.table_asked(table):
        return
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tetcollapse", default=None)
    ap.add_argument("--mesh", default="gen_tetgen_thingi255172_make-robot_514k.msh")
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--out-json", default=os.path.join(HERE, "results", "improve_paths.json"))
    a = ap.parse_args()
    tc = peers.tetcollapse_or_exit(a.tetcollapse, "improve_paths.py")
    mesh = os.path.join(SHARED, a.mesh)
    if not os.path.exists(mesh):
        sys.exit(f"improve_paths.py: {a.mesh} is not in {SHARED}")
    doc = dict(peers.provenance("improve_paths.py", tc), mesh=a.mesh, reps=a.reps)
    w1 = {"without": [], "with": [], "bound_without": [], "bound_with": []}
    paths = {name: [] for name, _, _ in PATHS}
    with tempfile.TemporaryDirectory(prefix="tc_ip_") as work:
        coarse, out, js = (os.path.join(work, n) for n in ("coarse.msh", "out.msh", "s.json"))
        base = [tc, mesh, coarse, "--target-factor", "2", "--eps-c", "0", "--max-boundary-error", "0"]  # W1: the paper's
        for _ in range(a.reps):
            w1["without"].append(run(base + ["--no-improve"], {}, js))
            w1["with"].append(run(base[:2] + [out] + base[3:], {}, js))
            w1["bound_without"].append(run([tc, mesh, out] + base[3:-2] + ["--no-improve"], {}, js))
            w1["bound_with"].append(run([tc, mesh, out] + base[3:-2], {}, js))
            for name, env, extra in PATHS:
                paths[name].append(run([tc, "improve", coarse, out] + extra, env, js))

    def own(st):  # every cycle's collapse and improvement (--cycles)
        return (st["seconds_collapse"] + (st["improve"]["seconds"] if "improve" in st else 0) +
                sum(c["seconds_collapse"] + c["seconds_improve"] for c in st.get("later_cycles", [])))

    def quality(st):  # the output's: after the last improvement
        improved = [c["quality_after"] for c in st.get("later_cycles", []) if "quality_after" in c]
        if improved:
            return improved[-1]
        return st["improve"]["quality_after"] if "improve" in st else st["quality_collapsed"]

    doc["w1"] = {}
    for key, runs in w1.items():
        q = quality(runs[-1])
        doc["w1"][key] = {"seconds": statistics.median(own(s) for s in runs), "tets": runs[-1]["tets_out"],
                          "below_10": q["below_10_deg"], "below_13": q["below_13_deg"],
                          "runs": [own(s) for s in runs]}
    doc["w1"]["ratio"] = doc["w1"]["with"]["seconds"] / doc["w1"]["without"]["seconds"]
    doc["w1"]["bound_ratio"] = doc["w1"]["bound_with"]["seconds"] / doc["w1"]["bound_without"]["seconds"]
    doc["paths"] = []
    for name, _, _ in PATHS:
        runs = [s["improve"] for s in paths[name]]

        def med(f):
            return statistics.median(f(r) for r in runs)

        last = runs[-1]
        doc["paths"].append({
            "path": name, "seconds": med(lambda r: r["seconds"]), "setup": med(lambda r: r["seconds_setup"]),
            "flips": med(lambda r: sum(p["seconds_flips"] for p in r["passes"])),
            "relocation": med(lambda r: sum(p["seconds_relocation"] for p in r["passes"])),
            "collapse_step": med(lambda r: sum(p["seconds"] for p in r["passes"] if p["collapsed"])),
            "passes": len(last["passes"]), "below_10": last["quality_after"]["below_10_deg"],
            "below_13": last["quality_after"]["below_13_deg"], "runs": [r["seconds"] for r in runs]})
    with open(a.out_json, "w") as f:
        json.dump(doc, f, indent=1)
    print(table(doc))


if __name__ == "__main__":
    main()
