#!/usr/bin/python3
"""The robustness campaign: coarsen every corpus mesh to its median edge length with
every method and check every output; any invalid output (or crash) fails the run.

    scripts/robustness.py [--corpus build/corpus] [--cli build/tetcollapse] [--methods parallel,...]
                          [--sample N] [--jobs J] [--out bench/robustness]

Per mesh and method, two runs of the CLI:
  1. IN OUT --target-factor 1 --check --stats S        (default boundary protection: features)
  2. the same with --boundary strict.
After each, `tetcollapse check OUT --reference IN --json -` measures the two-sided boundary
Hausdorff distance: exactly 0 for strict, at most the run's boundary error bound (its stats'
boundary_error_bound, plus the checker's error bound) for features.
A run is valid when the CLI exits 0 with "check": "valid" and the Hausdorff distance is as above.
Results: OUT/results.json and OUT/README.md (summary first). Failing inputs and outputs are
copied to OUT/../robustness-failures/ (not committed) and listed. Exit 1 when anything failed.

Methods are a parameter: `parallel` (the default pipeline: the matching selection), `greedy`
(--conflicts greedy), `two-pass`, `sequential` (--method sequential) and `atomic-min`
(--conflicts atomic-min). A method whose option the CLI rejects is skipped
with a note, so the script runs before the baselines exist.
"""
import argparse
import concurrent.futures
import datetime
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, ".."))

METHOD_ARGS = {
    "parallel": [],
    "greedy": ["--conflicts", "greedy"],
    "sequential": ["--method", "sequential"],
    "atomic-min": ["--conflicts", "atomic-min"],
    "two-pass": ["--conflicts", "two-pass"],
}
TIMEOUT_S = 900


def run(cmd, timeout=TIMEOUT_S):
    t0 = time.monotonic()
    try:
        r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=timeout)
        return r.returncode, r.stdout, r.stderr, time.monotonic() - t0
    except subprocess.TimeoutExpired as e:
        return "timeout", e.stdout or "", e.stderr or "", time.monotonic() - t0


def method_supported(cli, method):
    """None when the CLI accepts the method's options, else the CLI's message."""
    args = METHOD_ARGS[method]
    if not args:
        return None
    with tempfile.TemporaryDirectory() as tmp:
        code, out, err, _ = run([cli, os.path.join(ROOT, "meshes", "tet.mesh"), os.path.join(tmp, "o.mesh"), "-q"] + args,
                                timeout=120)
    if code == 0:
        return None
    lines = [l for l in (err + out).splitlines() if l.strip()]
    return lines[0] if lines else f"exit {code}"


def first_error_lines(text, n=6):
    keep = [l for l in text.splitlines() if l.startswith(("error", "INVALID", "tetcollapse: error", "warning: reference"))
            or "Abort" in l or "Segmentation" in l]
    return keep[:n] or text.strip().splitlines()[-n:]


def coarsen(cli, mesh, method, strict, tmp):
    out = os.path.join(tmp, "out.msh")
    stats = os.path.join(tmp, "stats.json")
    cmd = [cli, mesh, out, "--target-factor", "1", "--check", "--stats", stats, "-q"] + METHOD_ARGS[method]
    if strict:
        cmd += ["--boundary", "strict"]
    code, so, se, secs = run(cmd)
    rec = {"exit": code, "wall_seconds": round(secs, 3)}
    s = {}
    if os.path.exists(stats):
        with open(stats) as f:
            s = json.load(f)
        rec.update(tets_in=s.get("tets_in"), tets_out=s.get("tets_out"), vertices_in=s.get("vertices_in"),
                   vertices_out=s.get("vertices_out"), iterations=len(s.get("iterations", [])),
                   seconds=s.get("seconds_total"), seconds_collapse=s.get("seconds_collapse"),
                   check=s.get("check"), device=s.get("device"))
    verdict = "valid" if code == 0 and s.get("check") == "valid" else ("invalid" if code == 1 else "error")
    if verdict == "invalid" and "reference_invalid" in se + so:
        verdict = "input_invalid"  # the checker says the input already had the defect
    if verdict != "valid":
        rec["message"] = first_error_lines(se + so)
    # strict: the boundary exactly kept; features: within the run's boundary error bound, as far
    # as the checker's measurement can tell (its estimate is within hausdorff_error_bound)
    bound = None if strict else s.get("boundary_error_bound")
    if verdict == "valid" and (strict or (bound or 0) > 0):
        code2, so2, se2, _ = run([cli, "check", out, "--reference", mesh, "--json", "-", "-q"])
        try:
            ref = json.loads(so2)["reference"]
            h = rec["hausdorff"] = ref.get("hausdorff")
            rec["volume_change_rel"] = ref.get("volume_change_rel")
            if not strict:
                rec["hausdorff_rel"] = ref.get("hausdorff_rel")
                rec["boundary_error_bound"] = bound
            kept = h == 0 if strict else h is not None and h <= bound + ref.get("hausdorff_error_bound", 0)
            if code2 != 0 or not kept:
                verdict = "invalid"
                what = "strict boundary" if strict else f"boundary error bound {bound:g} exceeded"
                rec["message"] = [f"{what}: check exit {code2}, Hausdorff {h}"] + first_error_lines(se2)
        except (ValueError, KeyError) as e:
            verdict = "error"
            rec["message"] = [f"check --json unreadable ({e}): exit {code2}"] + first_error_lines(se2 + so2)
    rec["verdict"] = verdict
    rec["command"] = " ".join(cmd[:1] + [os.path.basename(mesh), "OUT"] + cmd[3:]).replace(stats, "S")
    return rec, out


def one(task):
    cli, mesh, name, method, failures = task
    result = {"mesh": name, "method": method}
    with tempfile.TemporaryDirectory(prefix="tc-robust-") as tmp:
        for mode in ("features", "strict"):
            rec, out = coarsen(cli, mesh, method, mode == "strict", tmp)
            result[mode] = rec
            if rec["verdict"] != "valid":  # keep the evidence
                dest = os.path.join(failures, f"{name}.{method}.{mode}")
                os.makedirs(dest, exist_ok=True)
                shutil.copy(mesh, dest)
                # --check does not write an invalid result: write it again without --check.
                cmd = [a for a in rec["command"].split() if a != "--check"]
                cmd = [cli, mesh, os.path.join(dest, "out.msh")] + cmd[3:cmd.index("--stats")] + \
                    cmd[cmd.index("--stats") + 2:]
                run(cmd)
                with open(os.path.join(dest, "record.json"), "w") as f:
                    json.dump(rec, f, indent=1)
            if os.path.exists(out):
                os.remove(out)
    return result


def machine():
    cpu = platform.processor()
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(l.split(":", 1)[1].strip() for l in f if l.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return f"{cpu}, {os.cpu_count()} cores, {platform.system()} {platform.release()}"


def commit():
    try:
        h = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", ROOT, "status", "--porcelain", "--untracked-files=no", "host", "cl", "include"],
                               capture_output=True, text=True).stdout.strip()
        return h + (" (with uncommitted changes in host/, cl/ or include/)" if dirty else "")
    except OSError:
        return "unknown"


def sample(names, n):
    """n names spread evenly over the sorted list (a fixed subset for a given corpus)."""
    if n >= len(names):
        return names
    step = len(names) / n
    return [names[int(i * step)] for i in range(n)]


def write_readme(path, doc):
    s = doc["summary"]
    lines = ["# Robustness campaign", "",
             "Every mesh of the corpus (`scripts/make_corpus.py`) coarsened to its median edge length",
             "(`--target-factor 1`) with each method, once with the default boundary protection",
             "(`features`) and once with `--boundary strict`; every output checked with the CGAL checker",
             "(`--check`); the two-sided boundary Hausdorff distance to the input (`tetcollapse check OUT",
             "--reference IN --json -`) must be exactly 0 for strict and, for features, at most the run's",
             "boundary error bound (the default 0.001 of the diagonal; plus the checker's own error bound, 1e-4",
             "of the diagonal, as its measurement is an estimate within that). Any invalid output fails the",
             "campaign.", "",
             "## Summary", "",
             f"- **{s['meshes']} meshes, {s['runs']} runs: {s['valid']} valid, {s['invalid']} invalid, "
             f"{s['error']} errors** (crash, refused input or timeout), {s['input_invalid']} runs on inputs the checker "
             "finds invalid (not counted as failures)",
             f"- methods run: {', '.join(doc['methods_run'])}"]
    if s.get("features_hausdorff_over_bound_max") is not None:
        lines.append(f"- features: the largest boundary Hausdorff distance measured, "
                     f"{s['features_hausdorff_over_bound_max']:.3f} x the run's boundary error bound")
    for m, why in doc["methods_skipped"].items():
        lines.append(f"- method `{m}` skipped: the CLI rejects its option (`{why}`)")
    lines += [f"- tets in total: {s['tets_in']:,} in, {s['tets_out_features']:,} out (features), "
              f"{s['tets_out_strict']:,} out (strict)",
              f"- CLI time (sum of `seconds_total`): {s['seconds']:.1f} s; campaign wall time {doc['wall_seconds']:.0f} s "
              f"with {doc['jobs']} jobs",
              f"- command: `{doc['command']}`",
              f"- corpus: `{doc['corpus_command']}`",
              f"- machine: {doc['machine']}", f"- device: {doc['device']}", f"- commit: {doc['commit']}",
              f"- date: {doc['date']}", ""]
    bad = [r for r in doc["results"] for mode in ("features", "strict") if r[mode]["verdict"] != "valid"]
    if bad:
        lines += ["## Failures", "", "| mesh | method | boundary | verdict | command | finding |", "|---|---|---|---|---|---|"]
        for r in doc["results"]:
            for mode in ("features", "strict"):
                rec = r[mode]
                if rec["verdict"] != "valid":
                    msg = "<br>".join(m.replace("|", "\\|") for m in rec.get("message", []))
                    lines.append(f"| {r['mesh']} | {r['method']} | {mode} | {rec['verdict']} | `{rec['command']}` | {msg} |")
        lines.append("")
    lines += ["## Per category", "", "| category | meshes | tets in (median) | reduction features (median) | "
              "reduction strict (median) | iterations (median) | invalid/errors |", "|---|---:|---:|---:|---:|---:|---:|"]
    for cat, c in sorted(doc["categories"].items()):
        lines.append(f"| {cat} | {c['meshes']} | {c['tets_in_median']:,} | {c['reduction_features_median']:.1%} | "
                     f"{c['reduction_strict_median']:.1%} | {c['iterations_median']} | {c['failed']} |")
    lines += ["", "## Every run", "",
              "tets out / iterations / seconds (the CLI's `seconds_total`) for each boundary mode; H/E = features "
              "Hausdorff over the bound; H = strict Hausdorff.",
              "", "| mesh | category | method | tets in | features: tets out | it. | s | H/E | verdict | strict: tets out | "
              "it. | s | H | verdict |",
              "|---|---|---|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---|"]

    def cell(v, fmt="{}"):
        return "" if v is None else fmt.format(v)

    def over(rec):
        h, e = rec.get("hausdorff"), rec.get("boundary_error_bound")
        return h / e if h is not None and e else None

    for r in doc["results"]:
        f, st = r["features"], r["strict"]
        lines.append(f"| {r['mesh']} | {r.get('category', '')} | {r['method']} | {cell(f.get('tets_in'), '{:,}')} | "
                     f"{cell(f.get('tets_out'), '{:,}')} | {cell(f.get('iterations'))} | {cell(f.get('seconds'), '{:.2f}')} | "
                     f"{cell(over(f), '{:.3f}')} | {f['verdict']} | {cell(st.get('tets_out'), '{:,}')} | {cell(st.get('iterations'))} | "
                     f"{cell(st.get('seconds'), '{:.2f}')} | {cell(st.get('hausdorff'), '{:g}')} | {st['verdict']} |")
    with open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")


def median(xs):
    xs = sorted(xs)
    if not xs:
        return 0
    return xs[len(xs) // 2] if len(xs) % 2 else (xs[len(xs) // 2 - 1] + xs[len(xs) // 2]) / 2


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--corpus", default=os.path.join(ROOT, "build", "corpus"))
    ap.add_argument("--cli", default=os.environ.get("TETCOLLAPSE", os.path.join(ROOT, "build", "tetcollapse")))
    ap.add_argument("--methods", default="parallel,sequential,atomic-min")
    ap.add_argument("--sample", type=int, default=0, help="only N meshes spread evenly over the sorted corpus")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--out", default=os.path.join(ROOT, "bench", "robustness"))
    ap.add_argument("--commit", help="the commit the CLI was built from (default: this checkout's HEAD)")
    args = ap.parse_args()

    cli = os.path.abspath(args.cli)
    if not os.access(cli, os.X_OK):
        sys.exit(f"robustness.py: no CLI at {cli} (build it, or pass --cli)")
    manifest_path = os.path.join(args.corpus, "MANIFEST.json")
    if not os.path.exists(manifest_path):
        sys.exit(f"robustness.py: no corpus at {args.corpus} (run scripts/make_corpus.py {args.corpus})")
    with open(manifest_path) as f:
        manifest = {m["name"]: m for m in json.load(f)["meshes"] if "skipped" not in m}
    names = sorted(n for n in manifest if os.path.exists(os.path.join(args.corpus, manifest[n]["file"])))
    if args.sample:
        names = sample(names, args.sample)

    methods, skipped = [], {}
    for m in args.methods.split(","):
        if m not in METHOD_ARGS:
            sys.exit(f"robustness.py: unknown method '{m}' (known: {', '.join(METHOD_ARGS)})")
        why = method_supported(cli, m)
        if why is None:
            methods.append(m)
        else:
            skipped[m] = why
            print(f"note: method {m} skipped: the CLI rejects {' '.join(METHOD_ARGS[m])}: {why}", flush=True)
    if not methods:
        sys.exit("robustness.py: no method left to run")

    out_dir = os.path.abspath(args.out)
    failures = os.path.join(ROOT, "build", "robustness-failures")
    if os.path.isdir(failures):
        shutil.rmtree(failures)
    tasks = [(cli, os.path.join(args.corpus, manifest[n]["file"]), n, m, failures) for n in names for m in methods]
    t0 = time.monotonic()
    results = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        for k, r in enumerate(pool.map(one, tasks)):
            r["category"] = manifest[r["mesh"]]["category"]
            results.append(r)
            f, s = r["features"], r["strict"]
            print(f"[{k + 1}/{len(tasks)}] {r['mesh']} {r['method']}: {f.get('tets_in')} -> {f.get('tets_out')} "
                  f"{f['verdict']} (H {f.get('hausdorff')}), strict -> {s.get('tets_out')} {s['verdict']} (H {s.get('hausdorff')})", flush=True)
    wall = time.monotonic() - t0

    runs = [r[mode] for r in results for mode in ("features", "strict")]
    count = {v: sum(1 for x in runs if x["verdict"] == v) for v in ("valid", "invalid", "error", "input_invalid")}
    cats = {}
    for r in results:
        c = cats.setdefault(r["category"], [])
        c.append(r)
    categories = {}
    for cat, rs in cats.items():
        def red(mode):
            return median([1 - r[mode]["tets_out"] / r[mode]["tets_in"] for r in rs if r[mode].get("tets_out") is not None])
        categories[cat] = dict(
            meshes=len({r["mesh"] for r in rs}), tets_in_median=int(median([r["features"].get("tets_in") or 0 for r in rs])),
            reduction_features_median=red("features"), reduction_strict_median=red("strict"),
            iterations_median=median([r["features"].get("iterations") or 0 for r in rs]),
            failed=sum(1 for r in rs for mode in ("features", "strict") if r[mode]["verdict"] != "valid"))
    device = next((x.get("device") for x in runs if x.get("device")), "unknown")
    cmd = "scripts/robustness.py " + " ".join(
        a for a in sys.argv[1:]) if len(sys.argv) > 1 else "scripts/robustness.py"
    doc = {
        "command": cmd,
        "corpus_command": f"scripts/make_corpus.py {os.path.relpath(args.corpus, ROOT)}",
        "cli": os.path.relpath(cli, ROOT),
        "machine": machine(), "device": device, "commit": args.commit or commit(),
        "date": datetime.datetime.now().strftime("%Y-%m-%d %H:%M"),
        "jobs": args.jobs, "wall_seconds": wall,
        "methods_run": methods, "methods_skipped": skipped,
        "summary": dict(meshes=len(names), runs=len(runs), **count,
                        tets_in=sum(r["features"].get("tets_in") or 0 for r in results),
                        tets_out_features=sum(r["features"].get("tets_out") or 0 for r in results),
                        tets_out_strict=sum(r["strict"].get("tets_out") or 0 for r in results),
                        seconds=sum((x.get("seconds") or 0) for x in runs),
                        features_hausdorff_over_bound_max=max(
                            (r["features"]["hausdorff"] / r["features"]["boundary_error_bound"] for r in results
                             if r["features"].get("boundary_error_bound") and r["features"].get("hausdorff") is not None),
                            default=None)),
        "categories": categories,
        "results": results,
    }
    os.makedirs(out_dir, exist_ok=True)
    with open(os.path.join(out_dir, "results.json"), "w") as f:
        json.dump(doc, f, indent=1)
    write_readme(os.path.join(out_dir, "README.md"), doc)
    print(f"{len(names)} meshes x {len(methods)} methods x 2 boundary modes: {count['valid']} valid, "
          f"{count['invalid']} invalid, {count['error']} errors ({wall:.0f} s); wrote {out_dir}/results.json and README.md")
    if count["invalid"] or count["error"]:
        print(f"FAILED: inputs and outputs kept in {failures}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
