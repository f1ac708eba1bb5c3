#!/usr/bin/python3
"""Every shared mesh coarsened to its median edge length, with --check.

    bench/shared_meshes.py [--tetcollapse PATH] [--meshes DIR] [--modes features,strict]
                           [--only SUBSTRING,...] [--out-json F] [--readme F] [--work-dir DIR]

For every volume mesh in DIR (default ../shared/meshes; every extension the CLI reads:
.msh .mesh .meshb .vtk .vtu .node; the sub-folders cad/ and surfaces/ hold STEP files and
surface meshes only and are not read) and every mode, runs

    tetcollapse IN OUT.vtu --target-factor 1 --boundary MODE --max-boundary-error 0 --check --stats S.json --quiet

and then, on the output when one was written, `tetcollapse check OUT.vtu --reference IN --json`
for the numbers --check does not put in the statistics (boundary Hausdorff distance, topology,
output quality). Writes one JSON object per (mesh, mode) to --out-json (default
bench/results/shared_meshes.json) and rewrites the table between <!-- table:shared_meshes -->
and <!-- /table:shared_meshes --> in --readme (default bench/README.md; '' leaves it alone)
with the results (--from-json F: only that, from a results file). bench/make_tables.py writes
the same table from bench/results/shared_meshes.json.
Expected for every mesh that is valid on input: exit 0, check valid, boundary topology
unchanged, and in strict mode a Hausdorff distance of 0. Anything else is listed under the table.
"""
import argparse
import datetime
import json
import os
import platform
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
EXTS = (".msh", ".mesh", ".meshb", ".vtk", ".vtu", ".node")
TABLE = "shared_meshes"  # the name of the README's table markers


def default_tetcollapse():
    for d in ("build", "build-peers", "build-lead"):
        p = os.path.join(ROOT, d, "tetcollapse")
        if os.access(p, os.X_OK):
            return p
    return None


def tail(text, n=400):
    text = text.strip()
    return text[-n:] if len(text) > n else text


def run_one(tc, path, mode, work, timeout):
    name = os.path.basename(path)
    stem = f"{os.path.splitext(name)[0]}_{mode}"
    out = os.path.join(work, stem + ".vtu")
    stats = os.path.join(work, stem + ".stats.json")
    for f in (out, stats):
        if os.path.exists(f):
            os.remove(f)
    cmd = [tc, path, out, "--target-factor", "1", "--boundary", mode, "--max-boundary-error", "0", "--check", "--stats", stats,
           "--quiet"]
    row = {"mesh": name, "mode": mode,
           "command": f"tetcollapse {name} OUT.vtu --target-factor 1 --boundary {mode} --max-boundary-error 0 --check --stats S.json",
           "load_avg_before": round(os.getloadavg()[0], 2)}
    t0 = time.perf_counter()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        row["exit_code"] = p.returncode
        stderr = p.stderr
    except subprocess.TimeoutExpired:
        row["exit_code"] = None
        stderr = f"timed out after {timeout} s"
    row["seconds_wall"] = round(time.perf_counter() - t0, 3)
    row["check_errors"] = [l[len("error: "):] for l in stderr.splitlines() if l.startswith("error: ")]
    row["check_warnings"] = [l[len("warning: "):] for l in stderr.splitlines() if l.startswith("warning: ")]
    if row["exit_code"] not in (0,):
        row["stderr_tail"] = tail(stderr)
    if os.path.exists(stats):
        with open(stats) as f:
            s = json.load(f)
        for k in ("vertices_in", "vertices_out", "tets_in", "tets_out", "tet_reduction", "median_edge_length",
                  "target_length", "seconds_collapse", "seconds_total", "seconds_read", "seconds_write", "device"):
            row[k] = s.get(k)
        row["iterations"] = len(s.get("iterations", []))
        row["check"] = s.get("check")
    if row["exit_code"] == 0 and os.path.exists(out):
        js = os.path.join(work, stem + ".check.json")
        c = subprocess.run([tc, "check", out, "--reference", path, "--json", js, "-q"], capture_output=True, text=True,
                           timeout=timeout)
        if os.path.exists(js):
            with open(js) as f:
                r = json.load(f)
            ref = r.get("reference", {})
            q = r.get("quality", {})
            row.update({
                "recheck_valid": r["valid"],
                "recheck_errors": [f["code"] for f in r["findings"] if f["severity"] == "error"],
                "topology_changed": ref.get("topology_changed"),
                "boundary_components": r["boundary"]["components"],
                "boundary_euler": r["boundary"]["euler_characteristic"],
                "hausdorff": ref.get("hausdorff"),
                "hausdorff_rel": ref.get("hausdorff_rel"),
                "volume_change_rel": ref.get("volume_change_rel"),
                "min_dihedral_deg": q.get("min_dihedral_deg", {}).get("min"),
            })
        else:
            row["recheck_valid"] = None
            row["recheck_errors"] = [f"check exit {c.returncode}: {tail(c.stderr, 200)}"]
        os.remove(out)
    row["load_avg_after"] = round(os.getloadavg()[0], 2)
    return row


def problems(r):
    """Why a row is not the expected result (empty when it is)."""
    why = []
    if any(w.startswith("reference_invalid") for w in r.get("check_warnings", [])):
        why.append("the input is itself invalid (reference_invalid)")
    if r.get("exit_code") != 0:
        why.append(f"exit {r.get('exit_code')}")
    if r.get("check") not in ("valid",):
        why.append(f"--check {r.get('check')}")
    if r.get("recheck_valid") is False:
        why.append("check of the output: " + ", ".join(r.get("recheck_errors", [])))
    if r.get("topology_changed"):
        why.append("boundary topology changed")
    if r["mode"] == "strict" and r.get("hausdorff") not in (None, 0, 0.0):
        why.append(f"strict Hausdorff {r.get('hausdorff'):.3g} != 0")
    return why


def fmt(x, spec):
    return "-" if x is None else format(x, spec)


def table(rows, meta, json_path="bench/results/shared_meshes.json"):
    """The README's table of a results file: where it was recorded, one row per mesh with a
    group of columns per boundary mode, then every run that is not the expected result."""
    modes = list(dict.fromkeys(r["mode"] for r in rows))
    meshes = list(dict.fromkeys(r["mesh"] for r in rows))
    by = {(r["mesh"], r["mode"]): r for r in rows}
    lines = [f"Recorded: `{json_path}`; commit {meta['commit']}, device {meta['device']}, machine "
             f"{meta.get('machine', '?')}; load average {meta['load_min']:.1f}-{meta['load_max']:.1f} during the run.",
             ""]
    head = ["mesh", "tets in"]
    for m in modes:
        head += [f"{m}: tets out (reduction)", "it.", "collapse (total) s", "Hausdorff rel", "--check"]
    head.append("min dihedral in -> " + " / ".join(modes))
    lines.append("| " + " | ".join(head) + " |")
    lines.append("|---|---:|" + "---:|---:|---:|---:|---|" * len(modes) + "---:|")
    for mesh in meshes:
        rs = [by.get((mesh, m)) for m in modes]
        first = next(r for r in rs if r)
        cells = [mesh, fmt(first.get("tets_in"), ",")]
        for r in rs:
            if r is None:
                cells += ["-"] * 5
                continue
            check = r.get("check") or (f"exit {r.get('exit_code')}")
            if r.get("topology_changed"):
                check += ", topology changed"
            red = fmt(None if r.get("tet_reduction") is None else 100 * r["tet_reduction"], ".1f")
            cells += [f"{fmt(r.get('tets_out'), ',')} ({red}%)", fmt(r.get("iterations"), "d"),
                      f"{fmt(r.get('seconds_collapse'), '.2f')} ({fmt(r.get('seconds_total'), '.2f')})",
                      fmt(r.get("hausdorff_rel"), ".2g"), check]
        cells.append(fmt(first.get("min_dihedral_in_deg"), ".2f") + " -> "
                     + " / ".join(fmt(r.get("min_dihedral_deg") if r else None, ".2f") for r in rs))
        lines.append("| " + " | ".join(cells) + " |")
    bad = [(r, problems(r)) for r in rows if problems(r)]
    lines.append("")
    if bad:
        lines.append("Not as expected:")
        lines.append("")
        for r, why in bad:
            errs = "; ".join(r.get("check_errors", []))[:300]
            lines.append(f"- `{r['mesh']}` ({r['mode']}): {', '.join(why)}" + (f". Errors: {errs}" if errs else "") +
                         f". Command: `{r['command']}`")
    else:
        lines.append("Every run: exit 0, output valid, boundary topology unchanged, strict Hausdorff 0.")
    return "\n".join(lines)


def write_readme(readme, rows, meta, json_path):
    sys.path.insert(0, HERE)
    import make_tables
    rel = os.path.relpath(os.path.abspath(json_path), ROOT)
    make_tables.replace_blocks(readme, {TABLE: table(rows, meta, rel)})


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tetcollapse", default=None)
    ap.add_argument("--meshes", default=os.path.join(ROOT, "..", "shared", "meshes"))
    ap.add_argument("--modes", default="features,strict")
    ap.add_argument("--only", default="", help="comma-separated substrings of the file names to run")
    ap.add_argument("--out-json", default=os.path.join(HERE, "results", "shared_meshes.json"))
    ap.add_argument("--readme", default=os.path.join(HERE, "README.md"), help="'' to leave the README alone")
    ap.add_argument("--work-dir", default=None)
    ap.add_argument("--timeout", type=float, default=3600)
    ap.add_argument("--commit", default=None, help="the commit the binary was built from (default: HEAD of the work tree)")
    ap.add_argument("--from-json", default=None, help="run nothing: rewrite the README section from this results file")
    a = ap.parse_args()
    if a.from_json:
        with open(a.from_json) as f:
            res = json.load(f)
        write_readme(a.readme, res["runs"], res["meta"], a.from_json)
        return
    tc = a.tetcollapse or default_tetcollapse()
    if not tc or not os.access(tc, os.X_OK):
        sys.exit("shared_meshes.py: no tetcollapse binary (give --tetcollapse PATH)")
    tc = os.path.abspath(tc)
    if not os.path.isdir(a.meshes):
        sys.exit(f"shared_meshes.py: {a.meshes}: no such folder")
    only = [s for s in a.only.split(",") if s]
    meshes = sorted(os.path.join(a.meshes, f) for f in os.listdir(a.meshes)
                    if f.endswith(EXTS) and os.path.isfile(os.path.join(a.meshes, f))
                    and (not only or any(s in f for s in only)))
    modes = [m for m in a.modes.split(",") if m]
    tmp = None if a.work_dir else tempfile.TemporaryDirectory(prefix="tc_shared_")
    work = a.work_dir or tmp.name
    os.makedirs(work, exist_ok=True)

    # The binary's build time and the commit at the start of the run (the tree is shared by
    # several people: the binary may hold uncommitted work of its build time).
    commit = a.commit or subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True,
                                        text=True).stdout.strip()
    built = datetime.datetime.fromtimestamp(os.path.getmtime(tc), datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    rows = []
    for path in meshes:
        info = subprocess.run([tc, "info", path, "--json"], capture_output=True, text=True, timeout=a.timeout)
        try:
            min_in = json.loads(info.stdout).get("min_dihedral_deg")
        except ValueError:
            min_in = None
        for mode in modes:
            r = run_one(tc, os.path.abspath(path), mode, work, a.timeout)
            r["min_dihedral_in_deg"] = min_in
            rows.append(r)
            why = problems(r)
            print(f"{r['mesh']:45s} {mode:8s} tets {r.get('tets_in')} -> {r.get('tets_out')}  "
                  f"collapse {r.get('seconds_collapse')} s  check {r.get('check')}  H {r.get('hausdorff')}"
                  + (f"  NOT AS EXPECTED: {why}" if why else ""), flush=True)

    loads = [r[k] for r in rows for k in ("load_avg_before", "load_avg_after")]
    device = next((r["device"] for r in rows if r.get("device")), "?")
    meta = {"date": datetime.date.today().isoformat(), "commit": commit, "binary_built": built, "device": device,
            "machine": platform.node(), "load_min": min(loads) if loads else 0, "load_max": max(loads) if loads else 0}
    os.makedirs(os.path.dirname(os.path.abspath(a.out_json)), exist_ok=True)
    with open(a.out_json, "w") as f:
        json.dump({"meta": meta, "runs": rows}, f, indent=1)
        f.write("\n")
    if a.readme:
        write_readme(a.readme, rows, meta, a.out_json)
    if tmp:
        tmp.cleanup()


if __name__ == "__main__":
    main()
