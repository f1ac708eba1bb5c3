#!/usr/bin/python3
"""Plots and markdown tables of a bench/run_suite.py result.

    bench/plot_suite.py [RESULT.json] [--out-dir DIR] [--markdown FILE] [--no-plots] [--parts fig7,fig8,table2,fig9]

RESULT.json defaults to bench/results/suite.json. Writes, with Debian's matplotlib (python3-matplotlib):
  DIR/fig7_<mesh>.png   collapses per iteration, every method (paper Fig. 7)
  DIR/fig8_<mesh>.png   run time against the threshold, overall (solid) and collapse-only (dashed),
                        logarithmic time axis (paper Fig. 8)
  DIR/fig9.png          run time and tets left against eps_c, ours (paper Fig. 9)
DIR defaults to bench/plots, or bench/plots/smoke for a result labelled "smoke".
Prints markdown tables (Fig. 7 iterations and the suite's goals, Fig. 8, Table 2, Fig. 9,
failures) on stdout, and into --markdown FILE when given. --parts limits both to those parts (e.g. to
redraw only fig8 from a result whose other parts newer files supersede). The tables of bench/README.md
are written by bench/make_tables.py, which takes each part from the newest result holding it.
"""
import argparse
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
METHOD_NAMES = {"ours": "ours (two-pass)", "atomic-min": "atomic-min (Gautron & Kenzel)", "sequential": "CPU sequential",
                "sequential-paper": "CPU sequential, paper's reading"}
METHOD_COLORS = {"ours": "tab:blue", "atomic-min": "tab:orange", "sequential": "tab:green",
                 "sequential-paper": "tab:olive"}
DEVICE_STYLES = ["o", "s", "^", "D", "v"]


def label_of(e, multi_device):
    name = METHOD_NAMES.get(e["method"], e["method"])
    if multi_device and e.get("device"):
        name += f" @ {e['device']['name']}"
    return name


def stem(mesh):
    return os.path.splitext(os.path.basename(mesh))[0]


def short(msg, n=110):
    msg = str(msg)
    return msg if len(msg) <= n else msg[:n] + "..."


def fmt(x, digits=3):
    return "-" if x is None else f"{x:.{digits}f}"


def multi_device(result):
    return len(result.get("devices_used", [])) > 1


def header_lines(r):
    m = r.get("machine", {})
    g = r.get("git", {})
    devs = "; ".join(f"[{d['index']}] {d['name']} ({d.get('platform')}, driver {d.get('driver')}, {d.get('type')}, "
                     f"{d.get('compute_units')} CU)" for d in r.get("devices_used", []))
    lines = [
        f"Result `{r.get('label')}`: {r.get('note')}.",
        f"Command `{r.get('command')}`, {r.get('date_utc')}, commit {str(g.get('commit'))[:7]}"
        + (" (sources modified)" if g.get("dirty_sources") else "") + ".",
        f"Machine {m.get('hostname')}: {m.get('cpu_model')}, {m.get('cores')} cores, {m.get('mem_total_gib')} GiB; "
        f"load average before {r.get('load_before')}, after {r.get('load_after')}.",
        f"Devices: {devs or 'none'}.",
        f"Repetitions: {r['settings']['reps']} (sequential {r['settings']['seq_reps']}"
        + "".join(f", {k} {v}" for k, v in (r['settings'].get('method_reps') or {}).items()) + "), min_quality "
        f"{r['settings']['min_quality']}, boundary {r['settings']['boundary']}.",
    ]
    return lines


# ---- plots ------------------------------------------------------------------------------------

def plot_fig7(plt, r, out_dir, tag):
    files = []
    md = multi_device(r)
    for m in r["parts"].get("fig7", {}).get("data", []):
        if m.get("status") != "ok":
            continue
        fig, ax = plt.subplots(figsize=(7, 4.2))
        for i, e in enumerate(m["results"]):
            if e.get("status") != "ok":
                ax.plot([], [], color=METHOD_COLORS.get(e["method"]), label=label_of(e, md) + ": failed")
                continue
            c = e["collapsed"]
            xs = [k + 1 for k, v in enumerate(c) if v > 0]
            ys = [v for v in c if v > 0]
            dev_i = e["device"]["index"] if e.get("device") else 0
            ax.plot(xs, ys, marker=DEVICE_STYLES[dev_i % len(DEVICE_STYLES)], markersize=3,
                    color=METHOD_COLORS.get(e["method"]),
                    label=f"{label_of(e, md)}: {e['iterations_collapsing']} iterations")
        ax.set_yscale("log")
        ax.set_xlabel("iteration")
        ax.set_ylabel("collapses in the iteration")
        ax.set_title(f"{tag}Fig. 7: {m['mesh']} ({m['info']['tets']:,} tets)\n"
                     "edges below the median length, eps_c 0", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        f = os.path.join(out_dir, f"fig7_{stem(m['mesh'])}.png")
        fig.tight_layout()
        fig.savefig(f, dpi=120)
        plt.close(fig)
        files.append(f)
    return files


def plot_fig8(plt, r, out_dir, tag):
    files = []
    md = multi_device(r)
    for m in r["parts"].get("fig8", {}).get("data", []):
        if m.get("status") != "ok":
            continue
        fig, ax = plt.subplots(figsize=(9.5, 4.2))
        series = {}
        for p in m["points"]:
            for e in p["results"]:
                key = (e["method"], json.dumps(e.get("device")))
                series.setdefault(key, {"e": e, "pts": []})
                if e.get("status") == "ok":
                    series[key]["pts"].append((p["threshold"], e["median"]["seconds_collapse"],
                                               e["median"]["seconds_collapse_only"]))
        for (method, _), s in series.items():
            e = s["e"]
            lab = label_of(e, md)
            col = METHOD_COLORS.get(method)
            if not s["pts"]:
                ax.plot([], [], color=col, label=lab + ": failed")
                continue
            xs = [q[0] for q in s["pts"]]
            ax.plot(xs, [q[1] for q in s["pts"]], "-o", markersize=3, color=col, label=lab + " overall")
            ax.plot(xs, [max(q[2], 1e-6) for q in s["pts"]], "--", marker="x", markersize=3, color=col,
                    label=lab + " collapsing")
        peers_shown = False
        for p in m["points"]:
            for row in (p.get("peers") or {}).get("rows", []):
                if row.get("seconds") is not None and not str(row.get("peer", "")).startswith("tetcollapse"):
                    ax.plot([p["threshold"]], [row["seconds"]], "k+", markersize=6,
                            label=None if peers_shown else "peers (wall clock, bench/peers.py)")
                    peers_shown = True
        el = m["info"]["edge_length"]
        ax.set_yscale("log")
        ax.set_xlabel(f"edge length threshold (min {el['min']:.4g} .. median {el['median']:.4g})")
        ax.set_ylabel("seconds (median)")
        ax.set_title(f"{tag}Fig. 8: {m['mesh']} ({m['info']['tets']:,} tets), eps_c 0\n"
                     "overall (solid, with connectivity) and collapsing only (dashed)", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
        f = os.path.join(out_dir, f"fig8_{stem(m['mesh'])}.png")
        fig.tight_layout()
        fig.savefig(f, dpi=120)
        plt.close(fig)
        files.append(f)
    return files


def plot_fig9(plt, r, out_dir, tag):
    m = r["parts"].get("fig9", {}).get("data")
    if not m or m.get("status") != "ok":
        return []
    md = multi_device(r)
    fig, ax = plt.subplots(figsize=(7, 4.2))
    ax2 = ax.twinx()
    eps = [p["eps_c"] for p in m["points"]]
    pos = list(range(len(eps)))
    by_dev = {}
    for i, p in enumerate(m["points"]):
        for e in p["results"]:
            by_dev.setdefault(json.dumps(e.get("device")), []).append((i, e))
    for k, (dev, lst) in enumerate(by_dev.items()):
        ok = [(i, e) for i, e in lst if e.get("status") == "ok"]
        if not ok:
            continue
        lab = label_of(ok[0][1], md)
        ax.plot([i for i, _ in ok], [e["median"]["seconds_collapse"] for _, e in ok], "-",
                color=METHOD_COLORS["ours"], marker=DEVICE_STYLES[k % len(DEVICE_STYLES)], label=lab + ": run time")
        ax2.plot([i for i, _ in ok], [e["tets_out"] for _, e in ok], ":", marker=DEVICE_STYLES[k % len(DEVICE_STYLES)],
                 color="tab:red", label=lab + ": tets left")
        for i, e in ok:
            ax.annotate(f"{e['median']['seconds_collapse']:.2f} s", (i, e["median"]["seconds_collapse"]),
                        textcoords="offset points", xytext=(0, 6), ha="center", fontsize=7)
    ax.set_xticks(pos)
    ax.set_xticklabels([str(e) for e in eps])
    ax.set_xlabel("eps_c (stop when an iteration collapses fewer edges)")
    ax.set_ylabel("seconds (median, collapse incl. connectivity)")
    ax2.set_ylabel("tets left")
    ax.set_ylim(0, ax.get_ylim()[1] * 1.25)
    ax2.set_ylim(0, ax2.get_ylim()[1] * 1.25)
    ax.set_title(f"{tag}Fig. 9: {m['mesh']} ({m['info']['tets']:,} tets)\nto 2 x median edge length, ours",
                 fontsize=9)
    ax.grid(True, alpha=0.3)
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, fontsize=8, loc="lower center")
    f = os.path.join(out_dir, "fig9.png")
    fig.tight_layout()
    fig.savefig(f, dpi=120)
    plt.close(fig)
    return [f]


# ---- markdown ---------------------------------------------------------------------------------

def part_markdown(r, part, heading=True, notes=True):
    """The markdown lines of one part ("fig7", "fig8", "table2", "fig9") of result r, with its
    heading unless heading=False and the Fig. 7 goals and the notes under Table 2 unless
    notes=False ([] when r does not hold the part). bench/make_tables.py puts these into
    bench/README.md."""
    md = multi_device(r)
    parts = r.get("parts", {})
    if part not in parts:
        return []
    out = []
    if part == "fig7":
        if heading:
            out += ["#### Fig. 7: iterations below the median edge length (eps_c 0)", "",
                    "One run per method and mesh (the sequence of collapses is deterministic; more runs of the same "
                    "configuration, e.g. from fig8, are checked to give the same counts).", ""]
        out += ["| mesh | tets in | method | iterations | tets out | collapses per iteration (first 8) |",
                "|---|---:|---|---:|---:|---|"]
        goals = []
        for m in parts["fig7"]["data"]:
            if m.get("status") != "ok":
                out.append(f"| {m['mesh']} | | skipped: {m.get('message')} | | | |")
                continue
            for e in m["results"]:
                if e.get("status") != "ok":
                    out.append(f"| {m['mesh']} | {m['info']['tets']:,} | {label_of(e, md)} | failed: {short(e.get('message'))} | | |")
                else:
                    first = ", ".join(str(x) for x in e["collapsed"][:8])
                    if not e.get("deterministic", True):
                        first = "**counts differ between runs** " + first
                    out.append(f"| {m['mesh']} | {m['info']['tets']:,} | {label_of(e, md)} | "
                               f"{e['iterations_collapsing']} | {e['tets_out']:,} | {first}, ... |")
            goals += [(m["mesh"], g) for g in m.get("goals", [])]
        if not notes:
            out.append("")
            return out
        out += ["", "Goals (iterations that collapse at least one edge):", "",
                "| mesh | goal | verdict | detail |", "|---|---|---|---|"]
        for mesh, g in goals:
            out.append(f"| {mesh} | {g['goal']}{g.get('device_tag', '')} | **{g['verdict']}** | {g['detail']} |")
        if not goals:
            out.append("| - | - | not evaluated | no Fig. 7 mesh ran |")
        out.append("")

    if part == "fig8":
        if heading:
            out += ["#### Fig. 8: run time against the threshold (eps_c 0), median seconds: overall / collapsing", ""]
        cols = []
        for m in parts["fig8"]["data"]:
            for p in m.get("points", []):
                for e in p["results"]:
                    lab = label_of(e, md)
                    if lab not in cols:
                        cols.append(lab)
        out.append("| mesh (tets) | threshold (fraction of the median) | " + " | ".join(cols) + " | tets out (ours) |")
        out.append("|---|---:|" + "---:|" * len(cols) + "---:|")
        for m in parts["fig8"]["data"]:
            if m.get("status") != "ok":
                out.append(f"| {m['mesh']} | skipped ({m.get('message')}) |" + " |" * (len(cols) + 1))
                continue
            for p in m["points"]:
                cells = {}
                tets = "-"
                for e in p["results"]:
                    lab = label_of(e, md)
                    if e.get("status") == "ok":
                        cells[lab] = f"{fmt(e['median']['seconds_collapse'])} / {fmt(e['median']['seconds_collapse_only'])}"
                        if e["method"] == "ours" and tets == "-":
                            tets = f"{e['tets_out']:,}"
                    else:
                        cells[lab] = "failed"
                out.append(f"| {m['mesh']} ({m['info']['tets']:,}) | {p['threshold']:.4g} ({p['fraction']:.2f}) | "
                           + " | ".join(cells.get(c, "-") for c in cols) + f" | {tets} |")
        out.append("")

    if part == "table2":
        t = parts["table2"]["data"]
        if heading:
            out += [f"#### Table 2: {t['mesh']} to 2 x median edge length, eps_c 0", ""]
        if t.get("status") != "ok":
            out += [f"skipped ({t.get('message')})", ""]
        else:
            out += ["| method | run time (s) | speedup of ours | collapsing only (s) | whole CLI (s) | reps | iterations | tets out |",
                    "|---|---:|---:|---:|---:|---:|---:|---:|"]
            for row in t["rows"]:
                name = row["name"] + (" (peer)" if row["method"] == "peer" else "")
                if row["status"] != "ok":
                    out.append(f"| {name} | failed: {short(row.get('message'))} | | | | | | |")
                elif row["method"] == "peer":
                    tets = f"{row['tets_out']:,}" if isinstance(row.get("tets_out"), int) else "-"
                    alg = (f"{fmt(row.get('seconds'))} | {fmt(row.get('speedup'), 2)}x" if row.get("seconds") is not None
                           else "- | -")
                    out.append(f"| {name} | {alg} | | {fmt(row.get('seconds_wall'))} (ours {fmt(row.get('speedup_wall'), 2)}x "
                               f"faster) | | | {tets} |")
                else:
                    out.append(f"| {row['name']} | {fmt(row['seconds'])} | {fmt(row['speedup'], 2)}x | "
                               f"{fmt(row['seconds_collapse_only'])} | {fmt(row['seconds_total'])} | {row['reps']} | "
                               f"{row['iterations']} | {row['tets_out']:,} |")
            pe = t.get("peers")
            if pe and pe.get("status") != "ok":
                out.append(f"\nPeers: {pe.get('status')} ({pe.get('message')}).")
            out.append("")
            if notes:
                out.append("Run time = `seconds_collapse` (collapse() with the connectivity rebuilds, without file I/O); "
                           "speedup of ours = run time of the row / run time of ours in the same run. Peers: their own "
                           "algorithm time where they report one; the whole-process column compares their wall clock "
                           "with ours' whole CLI process (file I/O included).")
                out.append("")

    if part == "fig9":
        m = parts["fig9"]["data"]
        if heading:
            out += [f"#### Fig. 9: {m['mesh']} to 2 x median edge length, eps_c swept (ours)", ""]
        if m.get("status") != "ok":
            out += [f"skipped ({m.get('message')})", ""]
        else:
            out += ["| eps_c | device | run time (s) | iterations | tets | vertices |", "|---:|---|---:|---:|---:|---:|"]
            for p in m["points"]:
                for e in p["results"]:
                    dev = e["device"]["name"] if e.get("device") else "-"
                    if e.get("status") != "ok":
                        out.append(f"| {p['eps_c']} | {dev} | failed: {short(e.get('message'))} | | | |")
                    else:
                        out.append(f"| {p['eps_c']} | {dev} | {fmt(e['median']['seconds_collapse'])} | "
                                   f"{e['iterations_collapsing']} | {e['tets_out']:,} | {e['vertices_out']:,} |")
            out.append("")
    return out


PARTS = ("fig7", "fig8", "table2", "fig9")


def markdown(r, parts=PARTS):
    out = header_lines(r)
    out.append("")
    for part in parts:
        out += part_markdown(r, part)

    fails = r.get("failures", [])
    if fails:
        seen = {}
        for f in fails:
            seen.setdefault((f["method"], f["message"]), 0)
            seen[(f["method"], f["message"])] += 1
        out += ["Failed runs:", ""]
        for (meth, msg), n in seen.items():
            out.append(f"- {meth} ({n} configuration{'s' if n > 1 else ''}): `{msg}`")
        out.append("")
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("result", nargs="?", default=os.path.join(HERE, "results", "suite.json"))
    ap.add_argument("--out-dir", default=None)
    ap.add_argument("--markdown", default=None, help="also write the tables to this file")
    ap.add_argument("--no-plots", action="store_true")
    ap.add_argument("--parts", default=",".join(PARTS), help="comma-separated subset of " + ",".join(PARTS))
    a = ap.parse_args()
    parts = [p for p in a.parts.split(",") if p]
    unknown = [p for p in parts if p not in PARTS]
    if unknown:
        ap.error(f"unknown part(s) {unknown}; known: {', '.join(PARTS)}")
    with open(a.result) as f:
        r = json.load(f)
    smoke = r.get("label") == "smoke"
    out_dir = a.out_dir or os.path.join(HERE, "plots", "smoke" if smoke else "")
    text = markdown(r, [p for p in PARTS if p in parts])
    print(text)
    if a.markdown:
        with open(a.markdown, "w") as f:
            f.write(text + "\n")
    if a.no_plots:
        return
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        sys.exit("plot_suite.py: matplotlib is missing: apt-get install python3-matplotlib and run with /usr/bin/python3")
    os.makedirs(out_dir, exist_ok=True)
    tag = "SMOKE RUN - " if smoke else ""
    plotters = {"fig7": plot_fig7, "fig8": plot_fig8, "fig9": plot_fig9}
    files = [f for p in parts if p in plotters for f in plotters[p](plt, r, out_dir, tag)]
    for f in files:
        print(f"wrote {os.path.relpath(f)}", file=sys.stderr)


if __name__ == "__main__":
    main()
