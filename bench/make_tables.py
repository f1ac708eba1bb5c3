#!/usr/bin/python3
"""Rewrites the tables of bench/README.md from the results files.

    bench/make_tables.py [--readme FILE] [--only NAME,...] [--check] [--list]

Every table of the README sits between two markers,

    <!-- table:NAME -->
    ... generated: the command, where and at which commit it was recorded, the table ...
    <!-- /table:NAME -->

and this script replaces what is between them (nothing else) with what it makes of the
results files:

    w1              bench/results/w1.json, w1_quality_guard.json        (bench_collapse --json)
    table2, fig7,   the newest result of bench/run_suite.py holding that part: bench/results/*.json
    fig8, fig9      with a "parts" entry (table2.json, fig7.json, suite.json, ...; not the smoke run),
                    by its date; the tables are bench/plot_suite.py's
    peers_bracket,  bench/results/peers_bracket.json, peers_robot514k.json  (bench/peers.py; its table)
    peers_robot514k
    shared_meshes   bench/results/shared_meshes.json                    (bench/shared_meshes.py; its table)
    quality_peers   bench/results/quality_peers.json                    (bench/quality_peers.py; its table)
    quality_generality bench/results/quality_generality.json           (bench/quality_generality.py; its table)
    improve_slivers bench/results/improve_slivers.json                  (bench/improve_slivers.py; its table)
    improve_paths   bench/results/improve_paths.json                    (bench/improve_paths.py; its tables)
    volume_rendering bench/results/volume_rendering.json               (bench/volume_rendering.py; its table)
    field_generality bench/results/field_generality.json               (bench/field_generality.py; its table)
    cold_start      bench/results/cold_start.json                       (bench/cold_start.py; its table)
    mpi_scale       bench/results/mpi_scale.json                        (bench/mpi_scale.py; its table)
    mpi_scale_10m   bench/results/mpi_scale_10m.json                    (the same on the 10.7M-tet mesh)
    mpi_field       bench/results/mpi_field.json                        (the same with --max-field-error)
    scale           bench/results/scale.json                            (bench/scale.py; its table)
    robustness      bench/robustness/results.json                       (scripts/robustness.py)
    io, primitives, bench/results/io.json, primitives.json, connectivity.json, checker.json,
    connectivity,   boundary_rule.json
    checker,
    boundary_rule

--only NAME,...: only those tables. --check: change nothing, exit 1 when a table differs from
what the results give (or a marker is missing). --list: print which file each table comes from.
A marker pair missing from the README is reported, not added.
"""
import argparse
import glob
import json
import os
import statistics
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
RESULTS = os.path.join(HERE, "results")
sys.path.insert(0, HERE)

SUITE_PARTS = ("table2", "fig7", "fig8", "fig9")


def rel(path):
    return os.path.relpath(path, ROOT)


def load(path):
    with open(path) as f:
        return json.load(f)


def n(x, spec=","):
    return "-" if x is None else format(x, spec)


# ---- the results of bench/run_suite.py ------------------------------------------------------------

def suite_source(part):
    """The newest run_suite.py result holding `part` (the smoke run excluded): (path, result)."""
    best = None
    for path in sorted(glob.glob(os.path.join(RESULTS, "*.json"))):
        try:
            r = load(path)
        except ValueError:
            continue
        if not isinstance(r, dict) or "parts" not in r or r.get("label") == "smoke" or part not in r["parts"]:
            continue
        if best is None or r.get("date_utc", "") > best[1].get("date_utc", ""):
            best = (path, r)
    return best


def suite_recorded(path, r):
    m, g, s = r.get("machine", {}), r.get("git", {}), r.get("settings", {})
    devs = "; ".join(f"{d['name']} ({d.get('platform')} {d.get('driver')}, {d.get('compute_units')} compute units)"
                     for d in r.get("devices_used", []))
    reps = f"{s.get('reps')} (sequential {s.get('seq_reps')}" + "".join(
        f", {k} {v}" for k, v in (s.get("method_reps") or {}).items()) + ")"
    lb, la = r.get("load_before") or [None], r.get("load_after") or [None]
    return [f"Command: `{r.get('command')}`. "
            f"Recorded: `{rel(path)}`; commit {str(g.get('commit'))[:7]}"
            + (" (with uncommitted source changes)" if g.get("dirty_sources") else "")
            + f"; {m.get('cpu_model')}, {m.get('cores')} cores, {m.get('mem_total_gib')} GiB; device {devs or 'none'}; "
            f"repetitions {reps}, median; min_quality {s.get('min_quality')}; load average {lb[0]} before, {la[0]} after.",
            ""]


def suite_block(part):
    import plot_suite
    src = suite_source(part)
    if src is None:
        return None, f"no results file in bench/results/ holds part {part}"
    path, r = src
    lines = suite_recorded(path, r) + plot_suite.part_markdown(r, part, heading=False, notes=False)
    return "\n".join(lines).rstrip("\n"), path


# ---- W1 (bench_collapse --json) -----------------------------------------------------------------

W1_LABELS = {(0, 0): "eps_c 0, min_quality 0 (**W1**)", (700, 0): "eps_c 700, min_quality 0",
             (0, 0.1): "eps_c 0, min_quality 0.1 (the CLI's default guard)", (700, 0.1): "eps_c 700, min_quality 0.1"}


def w1_block():
    files = [os.path.join(RESULTS, "w1.json"), os.path.join(RESULTS, "w1_quality_guard.json")]
    docs = [(f, load(f)) for f in files if os.path.exists(f)]
    if not docs:
        return None, "no bench/results/w1.json"
    lines = []
    for f, d in docs:
        rec = d.get("recorded", {})
        load_txt = rec.get("load_average") or rec.get("load_note") or "not recorded"
        lines.append(f"- Command: `{rec.get('command', '(not recorded)')}`. Recorded: `{rel(f)}`; commit "
                     f"{rec.get('commit', '?')}; {rec.get('machine', '?')}; device {d.get('device')}; median of "
                     f"{d.get('runs')} runs; load average {load_txt}.")
    mesh = docs[0][1]
    lines.append("")
    lines.append(f"Mesh `{os.path.basename(mesh['mesh'])}`: {mesh['tets_in']:,} tets, {mesh['vertices_in']:,} vertices; "
                 f"target {mesh['workloads'][0]['target_length']} (2 x the median edge length). Iterations: those "
                 "run, a last one that finds nothing to collapse included.")
    lines.append("")
    lines += ["| variant | matching: median (min) | tets out, iterations | greedy: median (min) | tets out, iterations "
              "| greedy / matching |", "|---|---:|---:|---:|---:|---:|"]
    work = {}
    for f, d in docs:
        for w in d["workloads"]:
            work[(w["eps_c"], w["min_quality"], w["conflicts"])] = w
    keys = sorted({(e, q) for e, q, _ in work}, key=lambda k: (k[1], k[0]))
    for e, q in keys:
        cells = []
        for c in ("matching", "greedy"):
            w = work.get((e, q, c))
            if w is None:
                cells += ["-", "-"]
                continue
            t = f"{w['seconds_median']:.3f} s ({min(w['seconds_runs']):.3f})"
            if (e, q, c) == (0, 0, "matching"):
                t = f"**{w['seconds_median']:.3f} s** ({min(w['seconds_runs']):.3f})"
            cells += [t, f"{w['tets_out']:,}, {w['iterations']}"]
        m, g = work.get((e, q, "matching")), work.get((e, q, "greedy"))
        ratio = f"{g['seconds_median'] / m['seconds_median']:.2f}x" if m and g else "-"
        lines.append(f"| {W1_LABELS.get((e, q), f'eps_c {e}, min_quality {q}')} | " + " | ".join(cells) + f" | {ratio} |")
    w = work.get((0, 0, "matching"))
    if w:
        st = w["stage_seconds"]
        total = sum(st.values())
        # (results written before the stage names were select and guard used admissible and pass2)
        names = {"connectivity": "connectivity", "cost": "cost", "select": "selection", "admissible": "selection",
                 "pass1": "pass 1", "guard": "surface guard", "pass2": "surface guard",
                 "collapse": "collapse, compaction and host tail"}
        parts = ", ".join(f"{names.get(k, k)} {v:.3f} s" for k, v in st.items() if v)
        select = st.get("select", st.get("admissible", 0))
        lines += ["", f"W1 (matching), the run of the median: {parts} ({100 * select / total:.0f}% "
                  f"selection); collapses per iteration {', '.join(f'{x:,}' for x in w['collapses_per_iteration'])}."]
    return "\n".join(lines), files[0]


# ---- peers, shared meshes, robustness -------------------------------------------------------------

def peers_block(name):
    import peers
    path = os.path.join(RESULTS, f"peers_{name}.json")
    if not os.path.exists(path):
        return None, f"no {rel(path)}"
    rows = load(path)
    r0 = rows[0]
    loads = [x for r in rows for x in (r.get("load_avg") or []) if x is not None]
    runs = sorted({len(r["seconds_runs"]) for r in rows if r.get("seconds_runs")})
    lines = [f"Recorded: `{rel(path)}`; mesh `{r0['mesh']}` ({r0['tets_in']:,} tets), target length "
             f"{r0['target_length']:.6g}; {'/'.join(map(str, runs))} run(s) per row; load average "
             f"{min(loads):.1f}-{max(loads):.1f} over the rows."]
    notes = {}
    for r in rows:
        if r.get("note"):
            notes.setdefault(r["note"], []).append(r["peer"])
    lines += [f"Rows {', '.join(p)}: {t}." for t, p in notes.items()]
    lines += ["", peers.markdown(rows)]
    return "\n".join(lines), path


def shared_meshes_block():
    import shared_meshes
    path = os.path.join(RESULTS, "shared_meshes.json")
    if not os.path.exists(path):
        return None, f"no {rel(path)}"
    res = load(path)
    return shared_meshes.table(res["runs"], res["meta"], rel(path)), path


def recorded_block(name, module):
    """A results file written by a script that records its command, commit and device."""
    mod = __import__(module)
    path = os.path.join(RESULTS, f"{name}.json")
    if not os.path.exists(path):
        return None, f"no {rel(path)}"
    doc = load(path)
    head = (f"Recorded: `{rel(path)}` by `{doc['command']}` at commit {doc['commit']} on "
            f"{doc.get('device') or 'the default device'}.")
    return head + "\n\n" + mod.table(doc), path


def printed_block(name, module):
    """A results file whose script prints its own table, head line included, from the path."""
    import contextlib
    import io
    mod = __import__(module)
    path = os.path.join(RESULTS, f"{name}.json")
    if not os.path.exists(path):
        return None, f"no {rel(path)}"
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        mod.table(path)
    return f"Recorded: `{rel(path)}`; " + out.getvalue().rstrip("\n"), path


def robustness_block():
    path = os.path.join(HERE, "robustness", "results.json")
    if not os.path.exists(path):
        return None, f"no {rel(path)}"
    d = load(path)
    s = d["summary"]
    lines = [f"Command: `{d['command']}` (corpus: `{d['corpus_command']}`). "
             f"Recorded: `{rel(path)}` (every run: `bench/robustness/README.md`); commit {d['commit']}; {d['machine']}; "
             f"device {d['device']}; {d['jobs']} jobs, {d['wall_seconds']:.0f} s.", "",
             f"**{s['meshes']} meshes, {s['runs']} runs: {s['valid']} valid, {s['invalid']} invalid, {s['error']} errors** "
             f"(crash, refused input or timeout); {s.get('input_invalid', 0)} runs on inputs the checker finds invalid."
             + (f" In features mode the largest boundary distance measured is "
                f"{s['features_hausdorff_over_bound_max']:.3f} x the run's boundary error bound."
                if s.get("features_hausdorff_over_bound_max") is not None else ""),
             "", "| method | runs | valid | tets in | tets out (features) | tets out (strict) | iterations, median "
             "(features / strict) | CLI seconds, sum |", "|---|---:|---:|---:|---:|---:|---:|---:|"]
    methods = d.get("methods_run") or sorted({r["method"] for r in d["results"]})
    for m in methods:
        rs = [r for r in d["results"] if r["method"] == m]
        recs = [r[mode] for r in rs for mode in ("features", "strict")]
        valid = sum(1 for x in recs if x.get("verdict") == "valid")

        def tot(mode, key):
            return sum(r[mode].get(key) or 0 for r in rs)

        def med(mode):
            its = [r[mode]["iterations"] for r in rs if r[mode].get("iterations") is not None]
            return statistics.median(its) if its else None

        secs = sum(x.get("seconds") or 0 for x in recs)
        lines.append(f"| {m} | {len(recs)} | {valid} | {tot('features', 'tets_in'):,} | {tot('features', 'tets_out'):,} | "
                     f"{tot('strict', 'tets_out'):,} | {n(med('features'), 'g')} / {n(med('strict'), 'g')} | {secs:.1f} |")
    return "\n".join(lines), path


# ---- the figures transcribed into JSON ------------------------------------------------------------

def transcribed_recorded(path, d):
    commit = d.get("commit") or f"not recorded (the figures were recorded at {d.get('recorded_in_commit')})"
    out = [f"Command: `{d['command']}`. "
           f"Recorded: `{rel(path)}`; commit {commit}; load average {d.get('load_average')}"
           + (f"; {d['settings']}" if d.get("settings") else "")
           + (f"; device {d['device']}" if d.get("device") else "")
           + (f"; {d['machine']}" if d.get("machine") else "") + ". " + d["source"][0].upper() + d["source"][1:] + "."]
    return out


def ratio(r):
    return "-" if r is None else f"{r:.2f}" if r < 2 else f"{r:.1f}"


def io_block():
    path = os.path.join(RESULTS, "io.json")
    d = load(path)
    lines = transcribed_recorded(path, d)
    lines += [f"Mesh `{d['mesh']}` ({d['vertices']:,} vertices, {d['tets']:,} tets), median of {d['runs']}. `read` is "
              f"{d['definitions']['read_ms']}; `raw read` is {d['definitions']['raw_read_ms']}.", "",
              "| format | MB | write ms | read ms | raw read ms | read / raw |", "|---|---:|---:|---:|---:|---:|"]
    notes = []
    for f in d["formats"]:
        raw = f.get("raw_read_ms")
        mark = ""
        if f.get("note"):
            notes.append(f"{f['format']}: {f['note']}")
            mark = f" ({len(notes)})"
        lines.append(f"| {f['format']}{mark} | {f['mb']:.1f} | {f['write_ms']:.1f} | {f['read_ms']:.1f} | "
                     f"{n(raw, '.1f')} | {ratio(f.get('read_over_raw'))} |")
    lines += [""] + [f"({i}) {t}." for i, t in enumerate(notes, 1)]
    return "\n".join(lines), path


def primitives_block():
    path = os.path.join(RESULTS, "primitives.json")
    d = load(path)
    lines = transcribed_recorded(path, d)
    lines += [f"{d['note'][0].upper() + d['note'][1:]}.", "", "| | " + " | ".join(d["sizes"]) + " |",
              "|---|" + "---:|" * len(d["sizes"])]
    for r in d["rows"]:
        lines.append(f"| {r['what']} | " + " | ".join(f"{v:g} ms" for v in r["ms"]) + " |")
    pb = d["program_build"]
    lines += ["", f"Program build: {pb['cold_seconds']} s with an empty program cache, {pb['cached_seconds']} s with "
              f"the on-disk cache ({pb['note']})."]
    return "\n".join(lines), path


def connectivity_block():
    path = os.path.join(RESULTS, "connectivity.json")
    d = load(path)
    lines = transcribed_recorded(path, d)
    lines += [f"{d['note'][0].upper() + d['note'][1:]}.", "",
              "| mesh | CPU reference, one thread | device (PoCL, 2 compute units) | result size | peak memory of the device build |",
              "|---|---:|---:|---:|---:|"]
    for m in d["meshes"]:
        lines.append(f"| {m['mesh']} | {m['cpu_seconds']} s | {m['device_seconds']} s | "
                     + (f"{m['result_bytes_per_tet']} B/tet" if m.get("result_bytes_per_tet") else "-")
                     + f" | {m['peak_bytes_per_tet']} B/tet"
                     + (f" ({m['note']})" if m.get("note") else "") + " |")
    return "\n".join(lines), path


def checker_block():
    path = os.path.join(RESULTS, "checker.json")
    d = load(path)
    lines = transcribed_recorded(path, d) + [""]
    lines += ["| mesh | runs | total (median) | " + " | ".join(d["phases_seconds"]) + " | bound |",
              "|---|---:|---:|" + "---:|" * len(d["phases_seconds"]) + "---:|"]
    at_load = f" ({d['total_seconds_at_load_6']} s at load 6)" if "total_seconds_at_load_6" in d else ""
    lines.append(f"| {d['mesh']} | {d['runs']} | {d['total_seconds']} s{at_load} | "
                 + " | ".join(v if isinstance(v, str) else f"{v} s" for v in d["phases_seconds"].values())
                 + f" | {d['bound_seconds']} s |")
    lines += ["", f"Without the Hausdorff distance; {d['hausdorff_note']}."]
    return "\n".join(lines), path


def locate_block():
    path = os.path.join(RESULTS, "locate.json")
    d = load(path)
    lines = [f"Recorded: `{rel(path)}` by `{d['command']}` at commit {d['commit']} on {d['device']}.", "",
             "| mesh | tets | points | host grid: build | locate | device BVH: build | locate | locate, device vs host |",
             "|---|---:|---:|---:|---:|---:|---:|---:|",
             f"| {d['mesh']} | {d['tets']:,} | {d['queries']:,} | {d['host_build']:.3f} s | {d['host_locate']:.3f} s | "
             f"{d['device_build']:.3f} s | {d['device_locate']:.3f} s | {d['device_locate'] / d['host_locate']:.2f}x |",
             "", f"Medians of {d['runs']} runs; each located all {d['found_device']:,} points (the tests check that both give the same tet)."]
    return "\n".join(lines), path


def boundary_rule_block():
    path = os.path.join(RESULTS, "boundary_rule.json")
    d = load(path)
    lines = transcribed_recorded(path, d) + [""]
    lines += ["| mesh | tets in | tets out, default rule | tets out, paper's rule | default removes more | "
              "iterations (default / paper) |", "|---|---:|---:|---:|---:|---:|"]
    for m in d["meshes"]:
        i, a, b = m["tets_in"], m["tets_out_default"], m["tets_out_paper"]
        lines.append(f"| {m['mesh']} | {i:,} | {a:,} (-{100 * (i - a) / i:.1f}%) | {b:,} (-{100 * (i - b) / i:.1f}%) | "
                     f"+{100 * (b - a) / (i - b):.1f}% | {m['iterations_default']} / {m['iterations_paper']} |")
    lines += ["", "\"Default removes more\": the default rule's extra removed tets relative to the paper rule's removals."]
    return "\n".join(lines), path


BLOCKS = {
    "w1": w1_block,
    "table2": lambda: suite_block("table2"),
    "fig7": lambda: suite_block("fig7"),
    "fig8": lambda: suite_block("fig8"),
    "fig9": lambda: suite_block("fig9"),
    "peers_bracket": lambda: peers_block("bracket"),
    "peers_robot514k": lambda: peers_block("robot514k"),
    "shared_meshes": shared_meshes_block,
    "quality_peers": lambda: recorded_block("quality_peers", "quality_peers"),
    "quality_generality": lambda: recorded_block("quality_generality", "quality_generality"),
    "improve_slivers": lambda: recorded_block("improve_slivers", "improve_slivers"),
    "improve_paths": lambda: recorded_block("improve_paths", "improve_paths"),
    "volume_rendering": lambda: recorded_block("volume_rendering", "volume_rendering"),
    "field_generality": lambda: recorded_block("field_generality", "field_generality"),
    "cold_start": lambda: recorded_block("cold_start", "cold_start"),
    "python_overhead": lambda: recorded_block("python_overhead", "python_overhead"),
    "mpi_scale": lambda: printed_block("mpi_scale", "mpi_scale"),
    "mpi_scale_10m": lambda: printed_block("mpi_scale_10m", "mpi_scale"),
    "mpi_field": lambda: printed_block("mpi_field", "mpi_scale"),
    "scale": lambda: printed_block("scale", "scale"),
    "robustness": robustness_block,
    "io": io_block,
    "primitives": primitives_block,
    "connectivity": connectivity_block,
    "checker": checker_block,
    "locate": locate_block,
    "boundary_rule": boundary_rule_block,
}


# ---- the README ---------------------------------------------------------------------------------

def begin(name):
    return f"<!-- table:{name} -->"


def end(name):
    return f"<!-- /table:{name} -->"


def substitute(text, bodies):
    """text with the lines between each pair of markers replaced; (new text, names without markers)."""
    missing = []
    lines = text.split("\n")
    for name, body in bodies.items():
        try:
            i = lines.index(begin(name))
            j = lines.index(end(name), i + 1)
        except ValueError:
            missing.append(name)
            continue
        lines = lines[:i + 1] + body.split("\n") + lines[j:]
    return "\n".join(lines), missing


def replace_blocks(readme, bodies):
    """Rewrites the tables `bodies` (name -> markdown) of the file readme between their markers;
    returns the names whose markers are missing."""
    with open(readme) as f:
        text = f.read()
    new, missing = substitute(text, bodies)
    if new != text:
        with open(readme, "w") as f:
            f.write(new)
    for name in missing:
        print(f"make_tables.py: {readme} has no markers for table {name} ({begin(name)} ... {end(name)})",
              file=sys.stderr)
    return missing


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--readme", default=os.path.join(HERE, "README.md"))
    ap.add_argument("--only", default="", help="comma-separated table names (default: every table)")
    ap.add_argument("--check", action="store_true", help="write nothing; exit 1 if a table is not up to date")
    ap.add_argument("--list", action="store_true", help="print the results file of each table")
    a = ap.parse_args()
    names = [s for s in a.only.split(",") if s] or list(BLOCKS)
    unknown = [s for s in names if s not in BLOCKS]
    if unknown:
        ap.error(f"unknown table(s) {unknown}; known: {', '.join(BLOCKS)}")
    bodies, failed = {}, False
    for name in names:
        body, src = BLOCKS[name]()
        if body is None:
            print(f"make_tables.py: table {name}: {src}", file=sys.stderr)
            failed = True
            continue
        bodies[name] = body
        if a.list:
            print(f"{name:16s} {rel(src)}")
    # a part of the suite whose newest result is not the file named after it: say which file is stale
    for part in SUITE_PARTS:
        if part in names:
            src = suite_source(part)
            own = os.path.join(RESULTS, f"{part}.json")
            if src and os.path.exists(own) and os.path.abspath(src[0]) != own:
                print(f"make_tables.py: {rel(own)} is older than {rel(src[0])} for {part}; delete it", file=sys.stderr)
    with open(a.readme) as f:
        text = f.read()
    new, missing = substitute(text, bodies)
    for name in missing:
        print(f"make_tables.py: {rel(a.readme)} has no markers for table {name} ({begin(name)} ... {end(name)})",
              file=sys.stderr)
    if a.check:
        if new != text or missing or failed:
            print(f"make_tables.py: {rel(a.readme)} is not up to date (run bench/make_tables.py)", file=sys.stderr)
            sys.exit(1)
        return
    if new != text:
        with open(a.readme, "w") as f:
            f.write(new)
        print(f"make_tables.py: rewrote {len(bodies) - len(missing)} table(s) of {rel(a.readme)}", file=sys.stderr)
    sys.exit(1 if missing or failed else 0)


if __name__ == "__main__":
    main()
