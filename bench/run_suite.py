#!/usr/bin/python3
"""The benchmark suite: the paper's Fig. 7, Fig. 8, Table 2 and Fig. 9 with the tetcollapse CLI.

    bench/run_suite.py [--cli PATH] [--meshes DIR] [--out FILE] [--parts fig7,fig8,table2,fig9]
                       [--reps N] [--seq-reps N] [--method-reps M=N,...] [--quick [--quick-mesh M]]
                       [--fig7-meshes A,B] [--fig8-meshes A,B,C] [--w1-mesh M] [--all-devices | --device INDEX]
                       [--methods ours,atomic-min,sequential] [--thresholds K] [--min-quality Q]
                       [--peers table2|all|none] [--peer-list A,B] [--peer-args "..."] [--peer-reps N]
                       [--timeout S] [--label TEXT]

Every measurement is one process of

    tetcollapse IN OUT --target-length L | --target-factor F --eps-c E --min-quality Q
                --stats S.json --quiet [--device I] + the method's flags

with the methods
    ours        --method parallel --conflicts two-pass --host-tail 0   (the paper's algorithm, every
                                                          iteration on the device)
    ours-tail   --method parallel --conflicts two-pass   (the CLI's default: on a CPU device the last
                                                          iterations on the host, README "host tail")
    atomic-min  --method parallel --conflicts atomic-min (Gautron and Kenzel 2023)
    sequential  --method sequential                      (CPU priority queue, no device; an edge an
                                                          earlier collapse changed is re-checked)
    sequential-paper  the same with --sequential-skip-invalidated (such an edge waits for the next
                      iteration: the paper's "skip if invalidated by a prior collapse")
A method that fails (non-zero exit, e.g. "not implemented yet", or a timeout) is recorded as failed
with the last line of its error output, and the suite goes on with the others.

Parts (paper section 4):
  fig7    collapses per iteration below the median edge length (--target-factor 1, eps_c 0) on
          Block 250k and featuretype 497k; the goals: ours needs <= 1.5 x the iterations
          of sequential and >= 50% fewer than atomic-min (printed PASS / FAIL / UNKNOWN).
  fig8    run time against the threshold, K thresholds from the minimum to the median edge length
          (from `tetcollapse info --json`), on Block 250k, featuretype 497k and fusee 88k:
            overall      = seconds_collapse of --stats: collapse() including the rebuild of the
                           connectivity every iteration, without file I/O and host<->device copies
            collapse     = sum over the iterations of the stage times without connectivity
                           (cost + admissible + pass1 + pass2 + collapse), i.e. the paper's
                           "collapsing" curves that abstract from the data structure.
  table2  W1: robot 514k, --target-factor 2, eps_c 0, min_quality 0; every method and, when
          bench/peers.py exists, the peers (MMG3D, CGAL, TetGen); median of the repetitions and
          speedups of ours (time of a method / time of ours, both from this run).
  fig9    W1 with eps_c in 0, 100, 300, 700, 1000, 3000 (ours): run time, tets and vertices left.

Timing rules: a warm-up run per (device, method) fills the kernel binary cache first (its time is
discarded); the repetitions of one configuration are interleaved over the methods (rep 1 of every
method, then rep 2, ...), so a change of the machine's load hits all of them alike; every figure is
the median of its repetitions; every ratio is taken between medians of the same run. The load
average is recorded before and after the suite, each part, and each process.

--quick: a smoke run: every part on one small mesh (--quick-mesh, default wrenchnut 27k) with 1
repetition, fig8 with 3 thresholds, fig9 with eps_c 0, 700, 3000; its results are labelled "smoke".
The meshes of each part can be changed with --fig7-meshes, --fig8-meshes and --w1-mesh, the
repetitions of one method with --method-reps (e.g. atomic-min=3).
Output: one JSON file (default bench/results/suite.json, with --quick bench/results/smoke.json);
bench/plot_suite.py turns it into PNGs and markdown tables.
"""
import argparse
import datetime
import json
import os
import platform
import shlex
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

METHODS = {
    # the paper's algorithm, every iteration on the device (the figures' iteration counts)
    "ours": ["--method", "parallel", "--conflicts", "two-pass", "--host-tail", "0"],
    # the CLI's default: the last iterations on the host on CPU devices (README, host tail)
    "ours-tail": ["--method", "parallel", "--conflicts", "two-pass"],
    "atomic-min": ["--method", "parallel", "--conflicts", "atomic-min"],
    "sequential": ["--method", "sequential"],
    "sequential-paper": ["--method", "sequential", "--sequential-skip-invalidated"],
}
DEVICE_METHODS = ("ours", "ours-tail", "atomic-min")  # the ones that run on an OpenCL device

FIG7_MESHES = ["gen_gmsh_Block_250k.msh", "gen_tetgen_featuretype_497k.msh"]
FIG8_MESHES = ["gen_gmsh_Block_250k.msh", "gen_tetgen_featuretype_497k.msh", "gen_gmsh_917_fusee_88k.msh"]
W1_MESH = "gen_tetgen_thingi255172_make-robot_514k.msh"
# --quick runs every part on this one small mesh, so that every method finishes in a few minutes
# (atomic-min took 716 s for fusee 88k at load ~9 on the 2-core development machine)
QUICK_MESH = "gen_gmsh_wrenchnut_27k.msh"
FIG9_EPS_C = [0, 100, 300, 700, 1000, 3000]
STAGES_COLLAPSE_ONLY = ("seconds_cost", "seconds_select", "seconds_guard", "seconds_collapse")


def log(msg):
    print(msg, flush=True)


def loadavg():
    try:
        with open("/proc/loadavg") as f:
            return [float(x) for x in f.read().split()[:3]]
    except OSError:
        return None


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def mem_total_gib():
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemTotal:"):
                    return round(int(line.split()[1]) / 1048576, 1)
    except (OSError, ValueError):
        pass
    return None


def git_info():
    def git(*args):
        p = subprocess.run(["git", "-C", ROOT, *args], capture_output=True, text=True)
        return p.stdout.rstrip("\n") if p.returncode == 0 else None  # keep the leading blank of "git status"
    status = git("status", "--porcelain", "--untracked-files=no", "--", "host", "cl", "include", "CMakeLists.txt")
    # other people's uncommitted edits in the source folders end up in the binary: say which
    return {"commit": git("rev-parse", "HEAD"), "describe": git("log", "-1", "--format=%h %s"),
            "dirty_sources": bool(status) if status is not None else None,
            "modified_files": [l[3:] for l in status.splitlines()] if status else []}


def machine_info():
    return {"hostname": socket.gethostname(), "cpu_model": cpu_model(), "cores": os.cpu_count(),
            "mem_total_gib": mem_total_gib(), "os": platform.platform(), "python": sys.version.split()[0]}


def default_cli():
    for d in ("build-suite", "build"):
        p = os.path.join(ROOT, d, "tetcollapse")
        if os.access(p, os.X_OK):
            return p
    return None


def last_line(text):
    lines = [l.strip() for l in text.splitlines() if l.strip()]
    return lines[-1] if lines else "(no output)"


def median(xs):
    xs = [x for x in xs if x is not None]
    return statistics.median(xs) if xs else None


class Suite:
    def __init__(self, args):
        self.args = args
        self.cli = args.cli
        self.work = tempfile.mkdtemp(prefix="tc_suite_")
        self.mesh_info = {}
        self.cache = {}      # key of a configuration -> entry (shared between parts)
        self.warmed = set()  # (device index, method)
        self.failures = []

    # ---- helpers -------------------------------------------------------------------------
    def mesh_path(self, name):
        p = os.path.join(self.args.meshes, name)
        return p if os.path.exists(p) else None

    def info(self, name):
        """`tetcollapse info --json` of a shared mesh (counts, edge length min/median/max)."""
        if name not in self.mesh_info:
            p = subprocess.run([self.cli, "info", "--json", self.mesh_path(name)], capture_output=True, text=True)
            if p.returncode != 0:
                raise RuntimeError(f"tetcollapse info {name}: {last_line(p.stderr)}")
            j = json.loads(p.stdout)
            self.mesh_info[name] = {"file": name, "vertices": j["vertices"], "tets": j["tets"], "edges": j["edges"],
                                    "edge_length": j["edge_length"]}
        return self.mesh_info[name]

    def method_list(self):
        """(method, device) pairs: device methods on every selected device, sequential once."""
        out = []
        for m in self.args.methods:
            if m in DEVICE_METHODS:
                out += [(m, d) for d in self.devices]
            else:
                out.append((m, None))
        return out

    def command(self, mesh, method, device, threshold, eps_c, extra=()):
        ext = ".meshb"  # output only; the binary Medit writer is the fastest (bench/README.md, I/O)
        cmd = [self.cli, self.mesh_path(mesh), os.path.join(self.work, "out" + ext)]
        cmd += threshold
        # the paper's method: no boundary error bound (the command's default in features mode)
        cmd += ["--eps-c", str(eps_c), "--min-quality", repr(self.args.min_quality), "--max-boundary-error", "0", "--quiet"]
        cmd += METHODS[method]
        if device is not None:
            cmd += ["--device", str(device["index"])]
        cmd += list(extra)
        return cmd

    def run_once(self, cmd):
        """One process; returns a summary of its --stats or {'ok': False, 'message': ...}."""
        stats = os.path.join(self.work, "stats.json")
        if os.path.exists(stats):
            os.remove(stats)
        load = loadavg()
        t0 = time.perf_counter()
        try:
            p = subprocess.run(cmd + ["--stats", stats], capture_output=True, text=True, timeout=self.args.timeout)
        except subprocess.TimeoutExpired:
            return {"ok": False, "message": f"timed out after {self.args.timeout} s", "load1_before": load[0] if load else None}
        wall = time.perf_counter() - t0
        if p.returncode != 0 or not os.path.exists(stats):
            return {"ok": False, "exit_code": p.returncode, "message": last_line(p.stderr + "\n" + p.stdout),
                    "load1_before": load[0] if load else None}
        with open(stats) as f:
            s = json.load(f)
        its = s.get("iterations", [])
        conn = sum(it.get("seconds_connectivity", 0) for it in its)
        stage_sum = sum(it.get(k, 0) for it in its for k in STAGES_COLLAPSE_ONLY)
        if stage_sum == 0 and its:  # a method that reports only per-iteration totals
            stage_sum = sum(it.get("seconds_total", 0) for it in its) - conn
        return {
            "ok": True, "wall": wall, "load1_before": load[0] if load else None,
            "seconds_total": s.get("seconds_total"), "seconds_collapse": s.get("seconds_collapse"),
            "seconds_collapse_only": stage_sum, "seconds_connectivity": conn,
            "seconds_read": s.get("seconds_read"), "seconds_write": s.get("seconds_write"),
            "seconds_upload": s.get("seconds_upload"), "seconds_download": s.get("seconds_download"),
            "device": s.get("device"), "method": s.get("method"), "conflicts": s.get("conflicts"),
            "target_length": s.get("target_length"), "median_edge_length": s.get("median_edge_length"),
            "tets_in": s.get("tets_in"), "tets_out": s.get("tets_out"),
            "vertices_in": s.get("vertices_in"), "vertices_out": s.get("vertices_out"),
            "iterations": len(its),
            "iterations_collapsing": sum(1 for it in its if it.get("collapsed", 0) > 0),
            "collapsed": [it.get("collapsed", 0) for it in its],
            "seconds_per_iteration": [it.get("seconds_total", 0) for it in its],
            "seconds_connectivity_per_iteration": [it.get("seconds_connectivity", 0) for it in its],
        }

    def warm_up(self, method, device, mesh):
        key = (device["index"] if device else None, method)
        if key in self.warmed:
            return
        self.warmed.add(key)
        cmd = self.command(mesh, method, device, ["--target-factor", "1"], 0, ["--max-iterations", "1"])
        r = self.run_once(cmd)
        log(f"  warm-up {method}{self.dev_tag(device)}: " + ("ok" if r["ok"] else "failed: " + r["message"]))

    @staticmethod
    def dev_tag(device):
        return "" if device is None else f" @ device {device['index']} ({device['name']})"

    def measure(self, mesh, threshold, eps_c, reps_of, pairs):
        """Runs every (method, device) pair on one configuration, the repetitions interleaved.
        Returns one entry per pair (shared with other parts through self.cache)."""
        entries = []
        for method, device in pairs:
            key = (mesh, tuple(threshold), eps_c, method, device["index"] if device else None)
            if key not in self.cache:
                dev = None if device is None else {k: device.get(k) for k in
                                                   ("index", "name", "platform", "vendor", "driver", "type", "compute_units")}
                self.cache[key] = {"method": method, "device": dev, "status": "pending", "command": None, "runs": []}
            entries.append((self.cache[key], method, device, reps_of(method)))
        for _, method, device, _ in entries:
            self.warm_up(method, device, mesh)
        rep = 0
        while True:
            todo = [(e, m, d, n) for e, m, d, n in entries if e["status"] != "failed" and len(e["runs"]) < n]
            if not todo:
                break
            for e, method, device, n in todo:
                if len(e["runs"]) > rep:
                    continue
                cmd = self.command(mesh, method, device, threshold, eps_c)
                e["command"] = " ".join(os.path.basename(c) if i == 0 else c for i, c in enumerate(cmd)) + " --stats S.json"
                r = self.run_once(cmd)
                if not r["ok"]:
                    e["status"] = "failed"
                    e["message"] = r["message"]
                    self.failures.append({"mesh": mesh, "method": method, "device": e["device"],
                                          "threshold": threshold, "eps_c": eps_c, "message": r["message"]})
                    log(f"    {method}{self.dev_tag(device)}: FAILED: {r['message']}")
                    continue
                e["runs"].append(r)
                log(f"    {method}{self.dev_tag(device)} rep {len(e['runs'])}/{n}: collapse {r['seconds_collapse']:.3f} s"
                    f" (collapse-only {r['seconds_collapse_only']:.3f} s), {r['iterations_collapsing']} iterations,"
                    f" tets {r['tets_in']} -> {r['tets_out']}, load {r['load1_before']}")
            rep += 1
        out = []
        for e, _, _, _ in entries:
            if e["status"] != "failed" and e["runs"]:
                e["status"] = "ok"
                summarize(e)
            out.append(e)
        return out

    def peers(self, mesh, target_length):
        script = os.path.join(HERE, "peers.py")
        if not os.path.exists(script):
            return {"status": "absent", "message": "bench/peers.py not found"}
        out = os.path.join(self.work, "peers.json")
        cmd = ["/usr/bin/python3", script, "--mesh", self.mesh_path(mesh), "--target-length", repr(target_length),
               "--out-json", out, "--tetcollapse", self.cli, "--reps", str(self.args.peer_reps),
               "--timeout", str(self.args.timeout)]
        if self.args.peer_list:
            cmd += ["--peers", self.args.peer_list]
        cmd += shlex.split(self.args.peer_args)
        log("  peers: " + " ".join(cmd[1:]))
        load = loadavg()
        try:
            p = subprocess.run(cmd, capture_output=True, text=True, timeout=self.args.timeout * 8)
        except subprocess.TimeoutExpired:
            return {"status": "failed", "message": "peers.py timed out"}
        res = {"status": "ok", "command": " ".join(["bench/peers.py"] + cmd[2:]), "load_before": load,
               "load_after": loadavg()}
        if p.returncode != 0 or not os.path.exists(out):
            res.update(status="failed", message=last_line(p.stderr + "\n" + p.stdout))
            return res
        with open(out) as f:
            res["rows"] = json.load(f)
        for row in res["rows"]:
            log(f"    peer {row.get('peer')}: " + (f"{row.get('seconds')} s, tets {row.get('tets_out')}"
                                                   if row.get("seconds") is not None else
                                                   f"skipped: {row.get('skipped_reason')}"))
        return res

    # ---- parts ---------------------------------------------------------------------------
    def part_fig7(self):
        a = self.args
        out = []
        meshes = a.fig7_meshes
        for mesh in meshes:
            if not self.mesh_path(mesh):
                log(f"fig7: {mesh} not in {a.meshes}: skipped")
                out.append({"mesh": mesh, "status": "skipped", "message": "mesh not found"})
                continue
            log(f"fig7: {mesh}, --target-factor 1, eps_c 0")
            info = self.info(mesh)
            # the collapse sequence is deterministic: one repetition suffices (more are reused from fig8)
            entries = self.measure(mesh, ["--target-factor", "1"], 0, lambda m: 1, self.method_list())
            res = {"mesh": mesh, "status": "ok", "info": info, "target": "1 x median edge length", "eps_c": 0,
                   "results": entries, "goals": fig7_goals(entries)}
            for g in res["goals"]:
                log(f"  goal {g['goal']}{g.get('device_tag', '')}: {g['verdict']} ({g['detail']})")
            out.append(res)
        return out

    def part_fig8(self):
        a = self.args
        out = []
        meshes = a.fig8_meshes
        k = a.thresholds if a.thresholds else (3 if a.quick else 5)
        for mesh in meshes:
            if not self.mesh_path(mesh):
                log(f"fig8: {mesh} not in {a.meshes}: skipped")
                out.append({"mesh": mesh, "status": "skipped", "message": "mesh not found"})
                continue
            info = self.info(mesh)
            lo, med = info["edge_length"]["min"], info["edge_length"]["median"]
            points = []
            for i in range(k):
                frac = i / (k - 1) if k > 1 else 1.0
                if frac >= 1.0:  # the median itself, the same configuration as fig7
                    thr, t = med, ["--target-factor", "1"]
                else:
                    thr = lo + frac * (med - lo)
                    t = ["--target-length", repr(thr)]
                log(f"fig8: {mesh}, threshold {thr:.6g} ({frac:.2f} of the way from min to median)")
                entries = self.measure(mesh, t, 0, self.reps_of, self.method_list())
                p = {"threshold": thr, "fraction": frac, "results": entries}
                if a.peers == "all":
                    p["peers"] = self.peers(mesh, thr)
                points.append(p)
            out.append({"mesh": mesh, "status": "ok", "info": info, "eps_c": 0, "points": points})
        return out

    def part_table2(self):
        a = self.args
        mesh = a.w1_mesh
        if not self.mesh_path(mesh):
            log(f"table2: {mesh} not in {a.meshes}: skipped")
            return {"mesh": mesh, "status": "skipped", "message": "mesh not found"}
        info = self.info(mesh)
        log(f"table2: {mesh}, --target-factor 2, eps_c 0, min_quality {a.min_quality}")
        entries = self.measure(mesh, ["--target-factor", "2"], 0, self.reps_of, self.method_list())
        res = {"mesh": mesh, "status": "ok", "info": info, "target": "2 x median edge length", "eps_c": 0,
               "results": entries}
        if a.peers in ("table2", "all"):
            res["peers"] = self.peers(mesh, 2 * info["edge_length"]["median"])
        res["rows"] = table2_rows(entries, res.get("peers"))
        for r in res["rows"]:
            if r["status"] != "ok":
                log(f"  {r['name']}: failed: {r.get('message')}")
            elif r["method"] == "peer":
                log(f"  {r['name']} (peer): wall {fmt(r.get('seconds_wall'))} s (ours' whole CLI {fmt(r.get('speedup_wall'), 2)}x "
                    f"faster), own algorithm time {fmt(r.get('seconds'))} s")
            else:
                log(f"  {r['name']}: {fmt(r.get('seconds'))} s, speedup of ours {fmt(r.get('speedup'), 2)}x")
        return res

    def part_fig9(self):
        a = self.args
        mesh = a.w1_mesh
        if not self.mesh_path(mesh):
            log(f"fig9: {mesh} not in {a.meshes}: skipped")
            return {"mesh": mesh, "status": "skipped", "message": "mesh not found"}
        info = self.info(mesh)
        eps = [0, 700, 3000] if a.quick else FIG9_EPS_C
        pairs = [(m, d) for m, d in self.method_list() if m == "ours"]
        points = []
        for e in eps:
            log(f"fig9: {mesh}, --target-factor 2, eps_c {e}")
            points.append({"eps_c": e, "results": self.measure(mesh, ["--target-factor", "2"], e, self.reps_of, pairs)})
        return {"mesh": mesh, "status": "ok", "info": info, "target": "2 x median edge length", "points": points}

    def reps_of(self, method):
        if method in self.args.method_reps:
            return self.args.method_reps[method]
        return self.args.seq_reps if method.startswith("sequential") else self.args.reps


def summarize(e):
    runs = e["runs"]
    keys = ("seconds_collapse", "seconds_collapse_only", "seconds_connectivity", "seconds_total", "wall")
    e["median"] = {k: median([r.get(k) for r in runs]) for k in keys}
    e["min"] = {k: min(r[k] for r in runs) for k in ("seconds_collapse", "seconds_collapse_only")}
    e["max"] = {k: max(r[k] for r in runs) for k in ("seconds_collapse", "seconds_collapse_only")}
    first = runs[0]
    for k in ("tets_in", "tets_out", "vertices_in", "vertices_out", "iterations", "iterations_collapsing",
              "collapsed", "target_length", "median_edge_length"):
        e[k] = first.get(k)
    e["device_reported"] = first.get("device")  # the device name the CLI wrote in --stats
    e["deterministic"] = all(r["collapsed"] == first["collapsed"] and r["tets_out"] == first["tets_out"] for r in runs)
    e["reps"] = len(runs)
    e["load1"] = [r.get("load1_before") for r in runs]


def fmt(x, digits=3):
    return "-" if x is None else f"{x:.{digits}f}"


def fig7_goals(entries):
    """The goals: ours <= 1.5 x the iterations of sequential; ours >= 50% fewer than atomic-min.
    Iterations = iterations that collapsed at least one edge (the final empty iteration that every
    method runs to detect convergence is not counted); compared per device."""
    seq = next((e for e in entries if e["method"] == "sequential"), None)
    seqp = next((e for e in entries if e["method"] == "sequential-paper"), None)
    goals = []
    for ours in (e for e in entries if e["method"] == "ours"):
        tag = f" @ device {ours['device']['index']}" if ours.get("device") else ""
        am = next((e for e in entries if e["method"] == "atomic-min" and e.get("device") == ours.get("device")), None)
        checks = [("ours <= 1.5 x sequential iterations", seq, "sequential", 1.5),
                  ("ours >= 50% fewer iterations than atomic-min", am, "atomic-min", 0.5)]
        if seqp is not None:
            checks.insert(1, ("ours <= 1.5 x sequential-paper iterations", seqp, "sequential-paper", 1.5))
        for goal, other, other_name, limit in checks:
            g = {"goal": goal, "device_tag": tag, "limit_ratio": limit}
            if ours["status"] != "ok" or other is None or other["status"] != "ok":
                who = "ours" if ours["status"] != "ok" else other_name
                why = "was not selected (--methods)" if other is None else "failed"
                g.update(verdict="UNKNOWN", detail=f"{who} {why}")
            else:
                a, b = ours["iterations_collapsing"], other["iterations_collapsing"]
                ratio = a / b if b else float("inf")
                g.update(ours_iterations=a, other_iterations=b, ratio=ratio,
                         verdict="PASS" if ratio <= limit else "FAIL",
                         detail=f"ours {a} vs {other['method']} {b} iterations: ratio {ratio:.2f}, must be <= {limit}")
            goals.append(g)
    return goals


def table2_rows(entries, peers):
    """Rows of Table 2 with the speedup of ours = median time of the row / median time of ours
    (same device for the device methods; ours on the first device for sequential and peers)."""
    ours = {json.dumps(e["device"]): e for e in entries if e["method"] == "ours" and e["status"] == "ok"}
    first_ours = next(iter(ours.values()), None)
    rows = []
    for e in entries:
        name = e["method"] + (f" @ {e['device']['name']}" if e.get("device") else "")
        row = {"name": name, "method": e["method"], "device": e.get("device"), "status": e["status"],
               "message": e.get("message")}
        if e["status"] == "ok":
            ref = ours.get(json.dumps(e["device"])) if e.get("device") else first_ours
            s = e["median"]["seconds_collapse"]
            row.update(seconds=s, seconds_collapse_only=e["median"]["seconds_collapse_only"],
                       seconds_total=e["median"]["seconds_total"], reps=e["reps"], tets_out=e["tets_out"],
                       iterations=e["iterations_collapsing"],
                       speedup=(s / ref["median"]["seconds_collapse"]) if ref else None)
        rows.append(row)
    if peers and peers.get("status") == "ok":
        for p in peers.get("rows", []):
            if str(p.get("peer", "")).startswith("tetcollapse"):
                continue  # measured above with the same binary
            row = {"name": p.get("peer"), "method": "peer", "status": "ok" if p.get("seconds") is not None else "failed",
                   "message": p.get("skipped_reason"), "seconds_wall": p.get("seconds"),
                   "seconds": p.get("seconds_algorithm"), "tets_out": p.get("tets_out"),
                   "min_dihedral_deg": p.get("min_dihedral_deg")}
            if first_ours and row["status"] == "ok":
                # peers' wall clock includes file I/O: compare it with ours' whole CLI process;
                # their own algorithm time (when reported) with ours' seconds_collapse
                row["speedup_wall"] = p["seconds"] / first_ours["median"]["seconds_total"]
                if p.get("seconds_algorithm") is not None:
                    row["speedup"] = p["seconds_algorithm"] / first_ours["median"]["seconds_collapse"]
            rows.append(row)
    return rows


def list_devices(cli):
    p = subprocess.run([cli, "devices", "--json"], capture_output=True, text=True)
    if p.returncode != 0:
        return [], last_line(p.stderr)
    j = json.loads(p.stdout)
    devs = j.get("devices", [])
    for d in devs:
        d["default"] = d.get("name") == j.get("default")
    return devs, None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("--cli", default=None, help="tetcollapse binary (default: build-suite/ or build/)")
    ap.add_argument("--meshes", default=os.path.normpath(os.path.join(ROOT, "..", "shared", "meshes")))
    ap.add_argument("--out", default=None, help="JSON result (default bench/results/suite.json, smoke.json with --quick)")
    ap.add_argument("--parts", default="fig7,fig8,table2,fig9")
    ap.add_argument("--methods", default="ours,ours-tail,atomic-min,sequential,sequential-paper")
    ap.add_argument("--reps", type=int, default=None, help="repetitions of the device methods (default 20, --quick 1)")
    ap.add_argument("--seq-reps", type=int, default=None,
                    help="repetitions of the sequential method (default 3, --quick 1; it has no multimodal device timing)")
    ap.add_argument("--method-reps", default="",
                    help="repetitions per method, overriding --reps/--seq-reps, e.g. atomic-min=3,sequential=5")
    ap.add_argument("--fig7-meshes", default=None, help="comma-separated (default Block 250k, featuretype 497k)")
    ap.add_argument("--fig8-meshes", default=None, help="comma-separated (default Block 250k, featuretype 497k, fusee 88k)")
    ap.add_argument("--w1-mesh", default=None, help="mesh of table2 and fig9 (default robot 514k)")
    ap.add_argument("--quick-mesh", default=QUICK_MESH, help="the one mesh of every part with --quick")
    ap.add_argument("--thresholds", type=int, default=None, help="fig8: thresholds from min to median (default 5, --quick 3)")
    ap.add_argument("--min-quality", type=float, default=0.0, help="quality guard for every run (default 0: the paper's algorithm)")
    ap.add_argument("--quick", action="store_true", help="smoke run: few repetitions, a subset of meshes")
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--all-devices", action="store_true", help="run the device methods on every OpenCL device")
    g.add_argument("--device", type=int, default=None, help="OpenCL device index (default: the CLI's default device)")
    ap.add_argument("--peers", choices=("table2", "all", "none"), default="table2",
                    help="run bench/peers.py (when present) for table2 (default), for every fig8 threshold too, or never")
    ap.add_argument("--peer-list", default="mmg3d_hsiz,mmg3d_hsiz_nosurf,cgal_remesh,tetgen_rR",
                    help="--peers passed to bench/peers.py ('' = its default)")
    ap.add_argument("--peer-args", default="",
                    help="more options for bench/peers.py, written with '=', e.g. --peer-args='--no-hausdorff --cgal-peer PATH'")
    ap.add_argument("--peer-reps", type=int, default=None, help="--reps of bench/peers.py (default 3, --quick 1)")
    ap.add_argument("--timeout", type=float, default=3600, help="seconds per process")
    ap.add_argument("--label", default=None, help="label of the result (default 'full', 'smoke' with --quick)")
    a = ap.parse_args()
    a.reps = a.reps if a.reps is not None else (1 if a.quick else 20)
    a.seq_reps = a.seq_reps if a.seq_reps is not None else (1 if a.quick else 3)
    a.peer_reps = a.peer_reps if a.peer_reps is not None else (1 if a.quick else 3)
    a.label = a.label or ("smoke" if a.quick else "full")
    reps_text, a.method_reps = a.method_reps, {}
    for item in filter(None, reps_text.split(",")):
        name, _, n = item.partition("=")
        if name not in METHODS or not n.isdigit() or int(n) < 1:
            ap.error(f"--method-reps: '{item}' is not METHOD=N (methods: {', '.join(METHODS)})")
        a.method_reps[name] = int(n)
    q = [a.quick_mesh] if a.quick else None
    a.fig7_meshes = a.fig7_meshes.split(",") if a.fig7_meshes else (q or FIG7_MESHES)
    a.fig8_meshes = a.fig8_meshes.split(",") if a.fig8_meshes else (q or FIG8_MESHES)
    a.w1_mesh = a.w1_mesh or (a.quick_mesh if a.quick else W1_MESH)
    a.methods = [m for m in a.methods.split(",") if m]
    for m in a.methods:
        if m not in METHODS:
            ap.error(f"unknown method {m} (known: {', '.join(METHODS)})")
    parts = [p for p in a.parts.split(",") if p]
    for p in parts:
        if p not in ("fig7", "fig8", "table2", "fig9"):
            ap.error(f"unknown part {p}")
    a.cli = a.cli or default_cli()
    if not a.cli or not os.access(a.cli, os.X_OK):
        ap.error("no tetcollapse binary: build it (scripts/bench.sh) or pass --cli")
    a.cli = os.path.abspath(a.cli)
    a.out = a.out or os.path.join(HERE, "results", "smoke.json" if a.quick else "suite.json")

    suite = Suite(a)
    devices, err = list_devices(a.cli)
    if a.all_devices:
        suite.devices = devices
    elif a.device is not None:
        suite.devices = [d for d in devices if d["index"] == a.device]
        if not suite.devices:
            ap.error(f"no OpenCL device {a.device} (tetcollapse devices lists {len(devices)})")
    else:
        suite.devices = [d for d in devices if d.get("default")] or devices[:1]
    if not suite.devices and any(m in DEVICE_METHODS for m in a.methods):
        log(f"no OpenCL device ({err}): the device methods are skipped")
        a.methods = [m for m in a.methods if m not in DEVICE_METHODS]

    result = {
        "suite": "tetcollapse benchmark suite (paper section 4: Fig. 7, Fig. 8, Table 2, Fig. 9)",
        "label": a.label,
        "note": (f"SMOKE RUN: {a.reps} repetition(s), meshes {sorted(set(a.fig7_meshes + a.fig8_meshes + [a.w1_mesh]))}; "
                 "a test of the scripts, not a measurement to quote"
                 if a.label == "smoke" else "medians of repeated runs; ratios within this run"),
        "command": " ".join([os.path.relpath(sys.argv[0], ROOT)] + sys.argv[1:]),
        "date_utc": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "git": git_info(),
        "machine": machine_info(),
        "cli": os.path.relpath(a.cli, ROOT),
        "devices_present": devices,
        "devices_used": suite.devices,
        "settings": {"reps": a.reps, "seq_reps": a.seq_reps, "method_reps": a.method_reps, "methods": a.methods,
                     "parts": parts, "fig7_meshes": a.fig7_meshes, "fig8_meshes": a.fig8_meshes, "w1_mesh": a.w1_mesh,
                     "min_quality": a.min_quality, "boundary": "features (CLI default)", "quick": a.quick,
                     "peers": a.peers, "peer_reps": a.peer_reps, "timeout_s": a.timeout,
                     "method_flags": {m: METHODS[m] for m in a.methods},
                     "time_overall": "seconds_collapse of --stats: collapse() incl. connectivity, without file I/O "
                                     "and host<->device mesh transfers",
                     "time_collapse_only": "sum over iterations of cost+admissible+pass1+pass2+collapse stage seconds "
                                           "(no connectivity)",
                     "iterations": "iterations that collapsed >= 1 edge"},
        "load_before": loadavg(),
        "parts": {},
    }
    log(f"tetcollapse suite ({a.label}): {a.cli}, methods {a.methods}, devices "
        f"{[d['index'] for d in suite.devices]}, reps {a.reps} (sequential {a.seq_reps}), load {result['load_before']}")
    t0 = time.perf_counter()
    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    try:
        for p in parts:
            lb = loadavg()
            tp = time.perf_counter()
            res = getattr(suite, "part_" + p)()
            result["parts"][p] = {"load_before": lb, "load_after": loadavg(), "seconds": time.perf_counter() - tp,
                                  "data": res}
            result["failures"] = suite.failures
            write_json(a.out, result)  # after every part, so an interrupted suite keeps what it measured
    finally:
        shutil.rmtree(suite.work, ignore_errors=True)
    result["load_after"] = loadavg()
    result["seconds"] = time.perf_counter() - t0
    result["failures"] = suite.failures
    write_json(a.out, result)
    log(f"\nwrote {a.out} ({result['seconds']:.0f} s, load before {result['load_before']}, after {result['load_after']})")
    goals = [g for m in result["parts"].get("fig7", {}).get("data", []) for g in m.get("goals", [])]
    if goals:
        log("fig7 goals:")
        for m in result["parts"]["fig7"]["data"]:
            for g in m.get("goals", []):
                log(f"  {m['mesh']}: {g['goal']}{g['device_tag']}: {g['verdict']} ({g['detail']})")
    if suite.failures:
        log(f"{len(suite.failures)} configuration(s) failed:")
        seen = set()
        for f in suite.failures:
            k = (f["method"], f["message"])
            if k not in seen:
                seen.add(k)
                log(f"  {f['method']}: {f['message']}")


def write_json(path, obj):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        json.dump(obj, f, indent=1)
        f.write("\n")
    os.replace(tmp, path)


if __name__ == "__main__":
    main()
