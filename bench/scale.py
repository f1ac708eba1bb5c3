#!/usr/bin/python3
"""Throughput and peak memory at scale: W1 and a 10M+ tet mesh in the same run.

Each mesh goes through `tetcollapse IN OUT --target-factor 2 --stats S.json` in three modes:
`bound` (the CLI's defaults: the boundary error bound, collapse and improvement), `default`
(`--max-boundary-error 0`: the paper's method, no bound; collapse and improvement) and
`collapse` (`--max-boundary-error 0 --no-improve`: the collapse alone), under
`/usr/bin/time -v` for the peak resident set size; the kernels are warm (`devices --warm-up`
and one untimed W1 run first). Times are medians over --runs runs (--large-runs for the large
mesh, which takes a minute and more each). Every output is checked by `tetcollapse check`.
Recorded per mesh and mode: the command, tets in and out, seconds (the CLI's own total, from
reading to writing, and the wall time of the process), seconds per million input tets, peak
RSS and bytes per input tet; then the ratio of the large mesh's per-tet time to W1's.

    /usr/bin/python3 bench/make_large_mesh.py            # once: /work/large/robot_q1.33a0.001.msh
    /usr/bin/python3 bench/scale.py [--runs 3] [--large-runs 1] [--out bench/results/scale.json]

PoCL's device buffers are host memory on a CPU device, so the peak RSS counts them.
"""
import argparse
import json
import os
import platform
import re
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
SHARED = "/work/shared/meshes"
W1 = os.path.join(SHARED, "gen_tetgen_thingi255172_make-robot_514k.msh")
LARGE = "/work/large/robot_q1.33a0.001.msh"


def sh(cmd, **kw):
    return subprocess.run(cmd, cwd=ROOT, text=True, capture_output=True, **kw)


def timed(cmd, env=None):
    """Runs cmd under /usr/bin/time -v; returns (exit code, wall seconds, peak RSS bytes, stderr)."""
    p = sh(["/usr/bin/time", "-v"] + cmd, env=env)
    rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", p.stderr)
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): ([\d:.]+)", p.stderr)
    secs = 0.0
    if wall:
        for part in wall.group(1).split(":"):
            secs = secs * 60 + float(part)
    return p.returncode, secs, int(rss.group(1)) * 1024 if rss else None, p.stderr


def load():
    return round(os.getloadavg()[0], 2)


def one_mesh(args, name, path, mode, runs):
    extra = ([] if mode == "bound" else ["--max-boundary-error", "0"]) + (["--no-improve"] if mode == "collapse" else [])
    out = os.path.join(args.work_dir, "%s_%s.msh" % (name, mode))
    stats = os.path.join(args.work_dir, "%s_%s.json" % (name, mode))
    cmd = [args.tetcollapse, path, out, "--target-factor", "2", "--stats", stats, "-q"] + extra
    rows = []
    for i in range(runs):
        before = load()
        code, wall, rss, err = timed(cmd)
        if code != 0:
            sys.exit("%s failed (exit %d):\n%s" % (" ".join(cmd), code, err[-3000:]))
        with open(stats) as f:
            s = json.load(f)
        rows.append({"seconds_wall": wall, "peak_rss_bytes": rss, "stats": s, "load_before": before})
        print("  %s %s run %d: %.2f s (CLI %.2f s), peak RSS %.0f MB, tets %d -> %d" %
              (name, mode, i + 1, wall, s["seconds_total"], rss / 1e6, s["tets_in"], s["tets_out"]), flush=True)
    # the check on the last run's output
    chk = sh([args.tetcollapse, "check", out, "--json", "-", "--no-quality"])
    try:
        cj = json.loads(chk.stdout)
    except ValueError:
        cj = {}
    s = rows[-1]["stats"]
    med = lambda key: statistics.median(key(r) for r in rows)
    tets_in = s["tets_in"]
    sec = med(lambda r: r["stats"]["seconds_total"])
    rss = med(lambda r: r["peak_rss_bytes"])
    rec = {
        "mesh": os.path.basename(path),
        "mode": mode,
        "command": "tetcollapse %s OUT.msh --target-factor 2 --stats S.json%s" %
                   (os.path.basename(path), "".join(" " + x for x in extra)),
        "runs": runs,
        "vertices_in": s["vertices_in"],
        "tets_in": tets_in,
        "tets_out": s["tets_out"],
        "iterations": len(s["iterations"]),
        "seconds": sec,
        "seconds_wall": med(lambda r: r["seconds_wall"]),
        "seconds_read": med(lambda r: r["stats"]["seconds_read"]),
        "seconds_collapse": med(lambda r: r["stats"]["seconds_collapse"]),
        "seconds_improve": med(lambda r: r["stats"].get("improve", {}).get("seconds", 0.0)),
        "seconds_write": med(lambda r: r["stats"]["seconds_write"]),
        "seconds_per_million_tets": sec / tets_in * 1e6,
        "peak_rss_bytes": rss,
        "bytes_per_input_tet": rss / tets_in,
        "each_run": [{"seconds": r["stats"]["seconds_total"], "seconds_wall": r["seconds_wall"],
                      "peak_rss_bytes": r["peak_rss_bytes"], "load_before": r["load_before"]} for r in rows],
        "check_exit_code": chk.returncode,
        "valid": chk.returncode == 0,
        "device": s["device"],
    }
    print("  %s %s: median %.2f s, %.3f s per M tets, %.0f B/tet, %s" %
          (name, mode, sec, rec["seconds_per_million_tets"], rec["bytes_per_input_tet"],
           "valid" if rec["valid"] else "INVALID (check exit %d)" % chk.returncode), flush=True)
    return rec


MODE_LABELS = {"bound": "defaults (the bound)", "default": "`--max-boundary-error 0`",
               "collapse": "`--max-boundary-error 0 --no-improve`"}


def table(path):
    """Prints the markdown table of a results file (bench/make_tables.py calls it)."""
    with open(path) as f:
        d = json.load(f)
    m = d["meta"]
    print(f"commit {m['commit']}, {m['machine']}, device {m['device']}, load average "
          f"{m['load_before']}-{m['load_after']}; W1 median of {m['runs_w1']} runs, the large mesh "
          f"{m['runs_large']}.\n")
    print("| mesh | mode | tets in | tets out | s | s per M tets | peak MB | bytes per input tet | check |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---|")
    for r in d["runs"]:
        name = "W1" if "514k" in r["mesh"] else f"{r['tets_in'] / 1e6:.1f}M robot"
        mode = MODE_LABELS.get(r["mode"], r["mode"])
        print(f"| {name} | {mode} | {r['tets_in']:,} | {r['tets_out']:,} | {r['seconds']:.2f} | "
              f"{r['seconds_per_million_tets']:.2f} | {r['peak_rss_bytes'] / 1e6:,.0f} | "
              f"{r['bytes_per_input_tet']:.0f} | {'valid' if r['valid'] else 'INVALID'} |")
    print()
    for mode, q in d["ratios"].items():
        label = MODE_LABELS.get(mode, mode)
        print(f"- {label}: time per input tet, large over W1, {q['time_per_tet_large_over_w1']:.2f} (goal at most "
              f"{q['goal_time_ratio_at_most']}); {q['large_bytes_per_input_tet']:.0f} bytes per input tet (goal at "
              f"most {q['goal_bytes_per_tet_at_most']}).")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--tetcollapse", default=os.path.join(ROOT, "build", "tetcollapse"))
    ap.add_argument("--w1", default=W1)
    ap.add_argument("--large", default=LARGE, help="the 10M+ mesh (bench/make_large_mesh.py)")
    ap.add_argument("--runs", type=int, default=3, help="runs per W1 case (median)")
    ap.add_argument("--large-runs", type=int, default=1, help="runs per large-mesh case (median)")
    ap.add_argument("--modes", default="bound,default,collapse",
                    help="bound (the defaults), default (no bound, with the improvement), collapse (no bound, --no-improve)")
    ap.add_argument("--work-dir", default="/work/large/scale_out", help="outputs and stats (large files)")
    ap.add_argument("--out", default=os.path.join(HERE, "results", "scale.json"))
    args = ap.parse_args()
    args.tetcollapse = os.path.abspath(args.tetcollapse)
    os.makedirs(args.work_dir, exist_ok=True)
    for p in (args.w1, args.large):
        if not os.path.exists(p):
            sys.exit("missing %s (the large one: bench/make_large_mesh.py)" % p)

    commit = sh(["git", "rev-parse", "--short", "HEAD"]).stdout.strip()
    dirty = sh(["git", "status", "--porcelain", "--untracked-files=no"]).stdout.strip() != ""
    sh([args.tetcollapse, "devices", "--warm-up"])
    meta = {
        "date": time.strftime("%Y-%m-%d", time.gmtime()),
        "commit": commit + ("+dirty" if dirty else ""),
        "commit_subject": sh(["git", "log", "-1", "--format=%s"]).stdout.strip(),
        "tool": os.path.relpath(args.tetcollapse, ROOT),
        "machine": "%s, %d cores, %.0f GiB" % (platform.machine(), os.cpu_count(),
                                             os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30),
        "load_before": load(),
        "runs_w1": args.runs,
        "runs_large": args.large_runs,
        "time": "seconds: the CLI's seconds_total (read, device set-up, collapse, improvement, write), "
                "median; peak RSS: /usr/bin/time -v, median",
    }
    print("warm-up run (W1, untimed)", flush=True)
    timed([args.tetcollapse, args.w1, os.path.join(args.work_dir, "warm.msh"), "--target-factor", "2", "-q"])
    results = []
    for mode in args.modes.split(","):
        for name, path, runs in (("w1", args.w1, args.runs), ("large", args.large, args.large_runs)):
            results.append(one_mesh(args, name, path, mode, runs))
    ratios = {}
    for mode in args.modes.split(","):
        w1 = next(r for r in results if r["mode"] == mode and r["mesh"] == os.path.basename(args.w1))
        big = next(r for r in results if r["mode"] == mode and r["mesh"] == os.path.basename(args.large))
        ratios[mode] = {
            "time_per_tet_large_over_w1": big["seconds_per_million_tets"] / w1["seconds_per_million_tets"],
            "wall_per_tet_large_over_w1": (big["seconds_wall"] / big["tets_in"]) / (w1["seconds_wall"] / w1["tets_in"]),
            "collapse_per_tet_large_over_w1":
                (big["seconds_collapse"] / big["tets_in"]) / (w1["seconds_collapse"] / w1["tets_in"]),
            "large_bytes_per_input_tet": big["bytes_per_input_tet"],
            "goal_time_ratio_at_most": 1.2,
            "goal_bytes_per_tet_at_most": 300,
        }
        meta["device"] = big["device"]
    meta["load_after"] = load()
    with open(args.out, "w") as f:
        json.dump({"meta": meta, "runs": results, "ratios": ratios}, f, indent=1)
        f.write("\n")
    print("\n%-10s %-9s %10s %9s %8s %9s %9s %7s %s" %
          ("mesh", "mode", "tets in", "tets out", "s", "s/M tets", "peak MB", "B/tet", "check"))
    for r in results:
        print("%-10s %-9s %10d %9d %8.2f %9.3f %9.0f %7.0f %s" %
              (r["mesh"][:10], r["mode"], r["tets_in"], r["tets_out"], r["seconds"], r["seconds_per_million_tets"],
               r["peak_rss_bytes"] / 1e6, r["bytes_per_input_tet"], "valid" if r["valid"] else "INVALID"))
    for mode, q in ratios.items():
        print("%s: per-tet time large / W1 = %.2f (wall %.2f, collapse alone %.2f), large peak %.0f B/tet" %
              (mode, q["time_per_tet_large_over_w1"], q["wall_per_tet_large_over_w1"],
               q["collapse_per_tet_large_over_w1"], q["large_bytes_per_input_tet"]))
    print("wrote", os.path.relpath(args.out, ROOT))
    return 0


if __name__ == "__main__":
    sys.exit(main())
