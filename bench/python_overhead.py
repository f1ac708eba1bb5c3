#!/usr/bin/python3
"""What the Python module adds to the C++ call: tetcollapse.collapse(points, tets, target_factor=2)
on NumPy arrays against tc::coarsen on the same mesh in memory (build/bench/bench_coarsen), both
with the collapse and the improvement phase, after a first call that loaded the programs, medians
of N runs each, one after the other on the same machine.

    bench/python_overhead.py [--build build] [--runs 5] [--out-json bench/results/python_overhead.json]
    bench/python_overhead.py --table F.json   prints the markdown table of a results file
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import peers  # noqa: E402

SHARED = os.path.join(os.path.dirname(ROOT), "shared", "meshes")


def table(doc):
    out = ["| mesh | tets | C++ tc::coarsen s | Python collapse() s | Python / C++ | goal |",
           "|---|---:|---:|---:|---:|---|"]
    for r in doc["rows"]:
        ratio = r["python"] / r["cpp"]
        out.append(f"| {r['mesh']} | {r['tets']:,} | {r['cpp']:.3f} | {r['python']:.3f} | {ratio:.3f} | "
                   f"at most 1.05 ({'met' if ratio <= 1.05 else 'not met'}) |")
    out += ["", f"Medians of {doc['runs']} runs each, after a first call."]
    return "\n".join(out)


def main():
    if peers.table_asked(table):
        return
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--out-json", default=os.path.join(HERE, "results", "python_overhead.json"))
    a = ap.parse_args()
    sys.path.insert(0, os.path.join(a.build, "python"))
    import tetcollapse  # noqa: E402
    doc = dict(peers.provenance("python_overhead.py", os.path.join(a.build, "tetcollapse")), rows=[], runs=a.runs)
    meshes = [("bracket", os.path.join(ROOT, "meshes", "bracket.msh")),
              ("W1 (robot 514k)", os.path.join(SHARED, "gen_tetgen_thingi255172_make-robot_514k.msh"))]
    for name, path in meshes:
        if not os.path.exists(path):
            print(f"skipped {name}: {path} is missing")
            continue
        cpp = json.loads(subprocess.run([os.path.join(a.build, "bench", "bench_coarsen"), path, str(a.runs)],
                                        capture_output=True, text=True, check=True).stdout)
        m = tetcollapse.read(path)
        tetcollapse.collapse(m["points"], m["tets"], target_factor=2)  # the programs loaded
        times = []
        for _ in range(a.runs):
            t0 = time.perf_counter()
            out = tetcollapse.collapse(m["points"], m["tets"], target_factor=2)
            times.append(time.perf_counter() - t0)
        row = dict(mesh=name, tets=len(m["tets"]), cpp=cpp["seconds"], python=statistics.median(times),
                   tets_out_cpp=cpp["tets_out"], tets_out_python=int(out["stats"]["tets_out"]))
        print(row)
        doc["rows"].append(row)
    with open(a.out_json, "w") as f:
        json.dump(doc, f, indent=1)
    print(table(doc))


if __name__ == "__main__":
    main()
