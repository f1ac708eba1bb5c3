#!/usr/bin/python3
"""The first run on a new machine: the default command with empty kernel caches.

    bench/cold_start.py [--tetcollapse PATH] [--out-json bench/results/cold_start.json]

For the bundled bracket (2x median) and W1 (the shared robot 514k, 2x median, --eps-c 0), each
with the default command (the collapse and the improvement phase), one after the other:
  cold            fresh POCL_CACHE_DIR and TETCOLLAPSE_CACHE_DIR (what a new machine, driver
                  or container pays: the OpenCL compiler runs for every kernel used)
  cold, specialised  the same with POCL_WORK_GROUP_SPECIALIZATION=1 (PoCL's default, which
                  tetcollapse turns off: a work-group function per kernel and local size)
  warm            the caches the cold run filled
and `tetcollapse devices --warm-up` into fresh caches, then the bracket warm from them. Wall
times of the whole command.

    bench/cold_start.py --table F.json   prints the markdown table of a results file
"""
import argparse
import json
import os
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
    out = ["| mesh | cold s | cold, PoCL specialising s | warm s | goal (cold) s |", "|---|---:|---:|---:|---:|"]
    for r in doc["rows"]:
        out.append(f"| {r['mesh']} | {r['cold']:.1f} | {r['cold_specialised']:.1f} | {r['warm']:.2f} | {r['goal']} |")
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
    ap.add_argument("--out-json", default=os.path.join(HERE, "results", "cold_start.json"))
    a = ap.parse_args()
    tc = os.path.abspath(a.tetcollapse or peers.default_tetcollapse() or "")
    if not os.access(tc, os.X_OK):
        sys.exit("cold_start.py: no tetcollapse binary (give --tetcollapse PATH)")
    doc = dict(peers.provenance("cold_start.py", tc), rows=[])
    meshes = [("bracket", os.path.join(ROOT, "meshes", "bracket.msh"), [], 5),
              ("W1 (robot 514k)", os.path.join(SHARED, "gen_tetgen_thingi255172_make-robot_514k.msh"),
               ["--eps-c", "0"], 10)]
    with tempfile.TemporaryDirectory(prefix="tc_cold_") as work:
        out = os.path.join(work, "out.msh")
        for name, mesh, extra, goal in meshes:
            if not os.path.exists(mesh):
                print(f"skipped {name}: {mesh} is missing")
                continue
            cmd = [tc, mesh, out, "--target-factor", "2", "-q"] + extra
            times = {}
            for key, spec in (("cold_specialised", "1"), ("cold", "0")):
                d = tempfile.mkdtemp(dir=work)
                caches = {"POCL_CACHE_DIR": os.path.join(d, "pocl"), "TETCOLLAPSE_CACHE_DIR": os.path.join(d, "tc"),
                          "POCL_WORK_GROUP_SPECIALIZATION": spec}
                times[key] = run(cmd, caches)
            times["warm"] = run(cmd, caches)
            row = dict(mesh=name, goal=goal, **times)
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
