#!/usr/bin/python3
"""tetcollapse-mpi against tetcollapse on W1: wall time, tets, validity and peak memory per rank.

    bench/mpi_scale.py [--build DIR] [--mesh M] [--ranks 2,3] [--runs 3] [--factor 2]
                       [--max-boundary-error 0.001] [--out bench/results/mpi_scale.json]
    bench/mpi_scale.py --table bench/results/mpi_scale.json    prints the markdown table
    bench/mpi_scale.py --mesh gen_tetgen_octagonal_pocket_160k.msh --gaussians --max-field-error 0.01 \
                       --out bench/results/mpi_field.json

Runs, one after the other, `runs` times each (the median is reported):
  tetcollapse M OUT --target-factor F --max-boundary-error E --stats S     (one process, one device)
  mpirun -n N tetcollapse-mpi M OUT --target-factor F --max-boundary-error E --stats S
                                                                   (N ranks, a device context each)
and `tetcollapse check OUT` once per configuration. Wall time is the whole command (reading,
writing and, under mpirun, starting the ranks); the peak memory of tetcollapse is its maximum
resident set (wait4), that of each rank the VmHWM tetcollapse-mpi reports in --stats. The goals
measured: with N ranks a valid result within 5% of tetcollapse's tets, and each rank's peak at
most tetcollapse's / N + 20%, also counted above a process's fixed cost (tetcollapse-mpi -n 1 on
two tets: the OpenCL runtime and kernels, which every rank pays).

With --max-field-error E both tools run `--preserve-field F --max-field-error E` instead of the
target (the bound alone decides; --gaussians writes the mesh with field F = "gauss", the
Gaussians of bench/volume_rendering.py, first), and the table adds the field error at the input's
vertices by `tetcollapse check OUT --reference IN` (what the bound bounds: at most E).
"""
import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
W1 = os.path.join(os.path.dirname(ROOT), "shared", "meshes", "gen_tetgen_thingi255172_make-robot_514k.msh")


def run(cmd, env=None):
    """Runs cmd; returns (exit code, wall seconds, max RSS of the process in kB, output)."""
    start = time.monotonic()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=env)
    out = proc.stdout.read().decode(errors="replace")
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    return proc.returncode, time.monotonic() - start, usage.ru_maxrss, out


def mpi_env():
    env = dict(os.environ)
    if os.geteuid() == 0:  # Open MPI refuses root unless told
        env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
        env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    env.setdefault("OMPI_MCA_rmaps_base_oversubscribe", "1")
    return env


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


def measure(name, ranks, cmd_for, tool, runs, tmp, env=None, reference=None):
    """Runs one configuration `runs` times; the record of its median run."""
    walls, tets, peaks, loads, stats = [], [], [], [], None
    out_path = None
    for i in range(runs):
        out_path = os.path.join(tmp, f"{name}.msh")
        stats_path = os.path.join(tmp, f"{name}.json")
        cmd = cmd_for(out_path, stats_path)
        load = os.getloadavg()[0]
        rc, wall, maxrss, log = run(cmd, env)
        if rc != 0:
            sys.exit(f"{' '.join(cmd)} failed ({rc}):\n{log}")
        with open(stats_path) as f:
            stats = json.load(f)
        walls.append(wall)
        loads.append(load)
        tets.append(stats["tets_out"])
        peaks.append(stats.get("peak_rss_kb") or [maxrss])
        print(f"{name} run {i + 1}: {wall:.2f} s, {stats['tets_out']} tets, load {load:.2f}", file=sys.stderr)
    rc, _, _, log = run([tool, "check", out_path] + (["--reference", reference] if reference else []))
    median_wall = statistics.median(walls)
    k = walls.index(min(walls, key=lambda w: abs(w - median_wall)))
    return {
        "name": name,
        "ranks": ranks,
        "command": " ".join(cmd_for("OUT.msh", "STATS.json")),
        "device": stats.get("device"),
        "wall_seconds": walls,
        "wall_seconds_median": median_wall,
        "load_average_before": loads,
        "tool_seconds_total_last": stats.get("seconds_total"),
        "tets_out": tets[k],
        "same_tets_every_run": len(set(tets)) == 1,
        "valid": rc == 0,
        "check": next((line for line in log.splitlines() if "VALID" in line), log.strip()[-300:]),
        "dihedral": next((line for line in log.splitlines() if line.startswith("dihedral angles")), None),
        "field_check": next((line.strip() for line in log.splitlines() if line.strip().startswith("field '")), None),
        "field_error": stats.get("field_error"),
        "peak_rss_kb": peaks[k],
        "rounds": [{key: r[key] for key in ("round", "phase", "tets_before", "tets_after", "interface_vertices",
                                            "seconds_partition", "seconds_scatter", "seconds_coarsen",
                                            "seconds_gather")} for r in stats.get("rounds", [])],
        "rank_seconds_and_tets": [[{"rank": x["rank"], "tets_in": x["tets_in"], "tets_out": x["tets_out"],
                                    "seconds": x["seconds"]} for x in r["ranks"]] for r in stats.get("rounds", [])],
    }


def below_10(c):
    """Tets below 10 degrees, from the checker's line "... tets below 5/10/13 deg: a/b/c"."""
    line = c.get("dihedral") or ""
    return line.rsplit(":", 1)[1].split("/")[1] if "below 5/10/13" in line else "-"


def vertex_max(c):
    """The checker's largest difference at the input's vertices, from its field line ("... at the
    reference's vertices max A (P%)")."""
    line = c.get("field_check") or ""
    return line.rsplit("(", 1)[1].rstrip(")") if "reference's vertices max" in line else "-"


def table(path):
    with open(path) as f:
        res = json.load(f)
    field = res.get("max_field_error")
    how = (f"--preserve-field {res['field']} --max-field-error {field:g}" if field else
           f"--target-factor {res['target_factor']}")
    print(f"`{os.path.basename(res['mesh'])}`{' with the Gaussians' if res.get('gaussians') else ''}, {how} "
          f"--max-boundary-error {res.get('max_boundary_error', 0):g}, median of {res['runs']} runs, "
          f"{res['machine']}, commit {res['commit'][:10]}\n")
    if field:
        print("| command | ranks | wall s (median) | tets | vs tetcollapse | valid | field error at the input's vertices "
              "| peak memory per rank (MB) |")
        print("|---|---:|---:|---:|---:|---|---:|---|")
        for c in res["configurations"]:
            peaks = ", ".join(f"{p / 1024:.0f}" for p in c["peak_rss_kb"])
            print(f"| {c['name']} | {c['ranks']} | {c['wall_seconds_median']:.2f} | {c['tets_out']:,} | "
                  f"{100 * (c['tets_vs_single'] - 1):+.2f}% | {'yes' if c['valid'] else 'NO'} | {vertex_max(c)} | {peaks} |")
        return
    print(f"A process's fixed cost (tetcollapse-mpi -n 1 on two tets): {res['fixed_cost_rss_kb'] / 1024:.0f} MB.\n")
    print("| command | ranks | wall s (median) | tets | vs tetcollapse | valid | tets below 10 deg "
          "| peak memory per rank (MB) | goal: single / ranks + 20% | the same above the fixed cost |")
    print("|---|---:|---:|---:|---:|---|---:|---|---|---|")
    for c in res["configurations"]:
        peaks = ", ".join(f"{p / 1024:.0f}" for p in c["peak_rss_kb"])
        first = c["name"] == "tetcollapse"
        goal = "-" if first else f"{c['memory_goal_kb'] / 1024:.0f} ({'met' if c['memory_goal_met'] else 'not met'})"
        above = "-" if first else (", ".join(f"{p / 1024:.0f}" for p in c["mesh_memory_kb"]) +
                                   f" vs {c['mesh_memory_goal_kb'] / 1024:.0f} "
                                   f"({'met' if c['mesh_memory_goal_met'] else 'not met'})")
        print(f"| {c['name']} | {c['ranks']} | {c['wall_seconds_median']:.2f} | {c['tets_out']:,} | "
              f"{100 * (c['tets_vs_single'] - 1):+.2f}% | {'yes' if c['valid'] else 'NO'} | {below_10(c)} | {peaks} "
              f"| {goal} | {above} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"), help="build folder with tetcollapse and "
                    "tetcollapse-mpi (default: build/)")
    ap.add_argument("--mesh", default=W1)
    ap.add_argument("--ranks", default="2,3")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--factor", type=float, default=2.0)
    ap.add_argument("--max-boundary-error", default="0.001",
                    help="passed to both tools (default: their default in features mode; 0: the paper's method)")
    ap.add_argument("--mpirun", default="mpirun")
    ap.add_argument("--max-field-error", type=float, default=0,
                    help="run both tools with --preserve-field FIELD --max-field-error E instead of the target")
    ap.add_argument("--field", default="gauss", help="the field --max-field-error bounds")
    ap.add_argument("--gaussians", action="store_true",
                    help="give the mesh the field 'gauss' (bench/volume_rendering.py's Gaussians) first")
    ap.add_argument("--out", default=os.path.join(HERE, "results", "mpi_scale.json"))
    ap.add_argument("--table", metavar="JSON", help="print the markdown table of a results file and exit")
    a = ap.parse_args()
    if a.table:
        table(a.table)
        return
    tool = os.path.join(a.build, "tetcollapse")
    mpi_tool = os.path.join(a.build, "tetcollapse-mpi")
    for path in (tool, mpi_tool, a.mesh):
        if not os.path.exists(path):
            sys.exit(f"mpi_scale: {path} not found (build with MPI and METIS, or pass --build / --mesh)")
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "HEAD"], capture_output=True, text=True).stdout.strip()
    dirty = subprocess.run(["git", "-C", ROOT, "status", "--porcelain", "--untracked-files=no"], capture_output=True,
                           text=True).stdout.strip() != ""
    configs = []
    with tempfile.TemporaryDirectory() as tmp:
        f = str(a.factor)
        bound = ["--max-boundary-error", a.max_boundary_error]
        mesh = a.mesh
        if a.gaussians:
            import vtk
            import volume_rendering
            plain, mesh = os.path.join(tmp, "plain.vtu"), os.path.join(tmp, "with_field.vtu")
            subprocess.run([tool, "convert", a.mesh, plain, "-q"], check=True)
            volume_rendering.with_field(vtk, plain, mesh, "gauss", volume_rendering.gaussians)
        how = ["--preserve-field", a.field, "--max-field-error", str(a.max_field_error)] if a.max_field_error else \
            ["--target-factor", f]
        reference = mesh if a.max_field_error else None
        single = measure("tetcollapse", 1, lambda out, st: [tool, mesh, out, *how, *bound, "-q", "--stats", st],
                         tool, a.runs, tmp, reference=reference)
        configs.append(single)
        for n in [int(x) for x in a.ranks.split(",") if x]:
            configs.append(measure(f"tetcollapse-mpi -n {n}", n,
                                   lambda out, st, n=n: [a.mpirun, "--oversubscribe", "-n", str(n), mpi_tool, mesh, out,
                                                         *how, *bound, "-q", "--stats", st],
                                   tool, a.runs, tmp, mpi_env(), reference))
        # What a process costs before any mesh: the OpenCL runtime (PoCL links LLVM), the kernels.
        tiny = os.path.join(ROOT, "meshes", "two_tets.mesh")
        fixed = measure("fixed cost (two_tets.mesh)", 1,
                        lambda out, st: [a.mpirun, "-n", "1", mpi_tool, tiny, out, "-q", "--stats", st], tool, 1, tmp,
                        mpi_env())["peak_rss_kb"][0]
    single_peak = single["peak_rss_kb"][0]
    for c in configs:
        c["tets_vs_single"] = c["tets_out"] / single["tets_out"]
        c["within_5_percent"] = abs(c["tets_vs_single"] - 1) <= 0.05
        c["memory_goal_kb"] = single_peak / c["ranks"] * 1.2
        c["memory_goal_met"] = all(p <= c["memory_goal_kb"] for p in c["peak_rss_kb"])
        # the same goal for what the mesh costs, the fixed cost of a process set aside
        c["mesh_memory_goal_kb"] = (single_peak - fixed) / c["ranks"] * 1.2
        c["mesh_memory_kb"] = [p - fixed for p in c["peak_rss_kb"]]
        c["mesh_memory_goal_met"] = all(p <= c["mesh_memory_goal_kb"] for p in c["mesh_memory_kb"])
    res = {
        "benchmark": "tetcollapse-mpi against tetcollapse, " + os.path.basename(a.mesh),
        "mesh": a.mesh,
        "target_factor": a.factor,
        "max_boundary_error": float(a.max_boundary_error),
        "max_field_error": a.max_field_error,
        "field": a.field if a.max_field_error else None,
        "gaussians": a.gaussians,
        "runs": a.runs,
        "commit": commit + (" (with uncommitted changes)" if dirty else ""),
        "machine": f"{cpu_model()}, {os.cpu_count()} cores",
        "fixed_cost_rss_kb": fixed,
        "configurations": configs,
    }
    os.makedirs(os.path.dirname(a.out), exist_ok=True)
    with open(a.out, "w") as fh:
        json.dump(res, fh, indent=1)
        fh.write("\n")
    table(a.out)


if __name__ == "__main__":
    main()
