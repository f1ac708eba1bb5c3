#!/usr/bin/python3
"""The first run on a new machine: the default command with empty kernel caches.

    bench/cold_start.py [--tetcollapse PATH] [--baseline PATH] [--runs N]
                        [--out-json bench/results/cold_start.json]

For the bundled bracket (2x median) and W1 (the shared robot 514k, 2x median, --eps-c 0), each
with the default command (the collapse and the improvement phase), medians of N runs (default 3):
  cold            fresh POCL_CACHE_DIR and TETCOLLAPSE_CACHE_DIR for each run (what a new machine,
                  driver or container pays: the OpenCL compiler runs for every program used)
  baseline        the same with another binary (--baseline: the previous commit's), in the same run
  cold, specialised  one run with POCL_WORK_GROUP_SPECIALIZATION=1 (PoCL's default, which
                  tetcollapse turns off: a work-group function per kernel and local size)
  warm            the caches a cold run filled
and `tetcollapse devices --warm-up` into fresh caches, then the bracket warm from them. Wall
times of the whole command.

    bench/cold_start.py --table F.json   prints the markdown table of a results file
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import peers  # noqa: E402

SHARED = os.path.join(os.path.dirname(ROOT), "shared", "meshes")


def table(doc):
    base = doc.get("baseline")
    head = "| mesh | cold s | " + (f"cold s, {base} | cold vs baseline | " if base else "") + \
        "cold, PoCL specialising s | warm s | goal (cold) s |"
    out = [head, "|---|" + "---:|" * (head.count("|") - 2)]
    for r in doc["rows"]:
        cells = [r["mesh"], f"{r['cold']:.1f}"]
        if base:
            cells += [f"{r['cold_baseline']:.1f}", f"{r['cold'] / r['cold_baseline']:.2f}x"]
        cells += [f"{r['cold_specialised']:.1f}", f"{r['warm']:.2f}", f"{r['goal']} ({'met' if r['cold'] <= r['goal'] else 'not met'})"]
        out.append("| " + " | ".join(cells) + " |")
    n = doc.get("runs", 1)
    out += ["", f"Cold and warm: medians of {n} runs, each cold run with empty caches; PoCL specialising: one run."]
    w = doc.get("warm_up")
    if w:
        out += ["", f"`tetcollapse devices --warm-up` into empty caches: {w['seconds']:.1f} s; the bracket "
                    f"after it: {w['bracket_after']:.2f} s."]
    return "\n".join(out)


def run(cmd, env_extra):
    env = dict(os.environ, **env_extra)
    t0 = time.monotonic()
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if p.returncode != 0:
        sys.exit(f"cold_start.py: {' '.join(cmd)} failed: {p.stderr.strip()[-300:]}")
    return time.monotonic() - t0


def main():
    if peers.table_asked(table):
        return
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tetcollapse", default=None)
    ap.add_argument("--baseline", default=None, help="another tetcollapse binary, measured cold in the same run")
    ap.add_argument("--baseline-label", default=None, help="what the baseline is (default: its path)")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--out-json", default=os.path.join(HERE, "results", "cold_start.json"))
    a = ap.parse_args()
    tc = peers.tetcollapse_or_exit(a.tetcollapse, "cold_start.py")
    doc = dict(peers.provenance("cold_start.py", tc), rows=[], runs=a.runs)
    if a.baseline:
        doc["baseline"] = a.baseline_label or a.baseline
    meshes = [("bracket", os.path.join(ROOT, "meshes", "bracket.msh"), [], 5),
              ("W1 (robot 514k)", os.path.join(SHARED, "gen_tetgen_thingi255172_make-robot_514k.msh"),
               ["--eps-c", "0"], 10)]
    with tempfile.TemporaryDirectory(prefix="tc_cold_") as work:
        out = os.path.join(work, "out.msh")

        def cold(binary, cmd_tail, spec="0"):
            d = tempfile.mkdtemp(dir=work)
            caches = {"POCL_CACHE_DIR": os.path.join(d, "pocl"), "TETCOLLAPSE_CACHE_DIR": os.path.join(d, "tc"),
                      "POCL_WORK_GROUP_SPECIALIZATION": spec}
            return run([binary] + cmd_tail, caches), caches

        for name, mesh, extra, goal in meshes:
            if not os.path.exists(mesh):
                print(f"skipped {name}: {mesh} is missing")
                continue
            tail = [mesh, out, "--target-factor", "2", "-q"] + extra
            colds, bases, warms = [], [], []
            for _ in range(a.runs):  # interleaved, so that the load of the machine falls on both
                t, caches = cold(tc, tail)
                colds.append(t)
                warms.append(run([tc] + tail, caches))
                if a.baseline:
                    bases.append(cold(a.baseline, tail)[0])
            row = dict(mesh=name, goal=goal, cold=statistics.median(colds), warm=statistics.median(warms),
                       cold_runs=colds, cold_specialised=cold(tc, tail, "1")[0])
            if a.baseline:
                row.update(cold_baseline=statistics.median(bases), cold_baseline_runs=bases)
            print(row)
            doc["rows"].append(row)
        d = tempfile.mkdtemp(dir=work)
        caches = {"POCL_CACHE_DIR": os.path.join(d, "pocl"), "TETCOLLAPSE_CACHE_DIR": os.path.join(d, "tc")}
        w = run([tc, "devices", "--warm-up"], caches)
        after = run([tc, meshes[0][1], out, "--target-factor", "2", "-q"], caches)
        doc["warm_up"] = {"seconds": w, "bracket_after": after}
    with open(a.out_json, "w") as f:
        json.dump(doc, f, indent=1)
    print(table(doc))


if __name__ == "__main__":
    main()
