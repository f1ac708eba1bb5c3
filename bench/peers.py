#!/usr/bin/python3
"""Peers a user would pick instead of tetcollapse, on the same input and target.

    bench/peers.py --mesh M --target-length L [--tetcollapse PATH] [--reps N] --out-json F
                   [--cgal-peer PATH] [--mmg3d PATH] [--tetgen PATH] [--peers a,b,...]
                   [--work-dir DIR] [--timeout S] [--no-hausdorff]

Runs, on mesh M with the uniform target edge length L, in this order:
  tetcollapse           tetcollapse M OUT --target-length L            (default options, quality guard 0.1)
  tetcollapse_noimprove ... --no-improve                             (the collapse alone)
  tetcollapse_bounded   ... --max-boundary-error 0.001 (the default's bound, given)
  tetcollapse_unbounded ... --max-boundary-error 0     (no bound: the paper's method)
  tetcollapse_cyclesN   ... --cycles N                 (collapse and improvement N times)
                                                                       (the boundary error bound, as MMG's -hausd
                                                                        below: 0.001 x the bounding-box diagonal)
  tetcollapse_q0        ... --min-quality 0 --no-improve               (the paper: no quality guard, no
                                                                        improvement phase)
  mmg3d_hsiz            mmg3d_O3 IN.mesh -hsiz L                        (MMG3D, surface remeshed too)
  mmg3d_hsiz_nosurf     mmg3d_O3 IN.mesh -hsiz L -nosurf                (MMG3D, surface kept)
  mmg3d_hmin            mmg3d_O3 IN.mesh -hmin L                        (MMG3D, size from the input's edges,
  mmg3d_hmin_nosurf     mmg3d_O3 IN.mesh -hmin L -nosurf                 at least L: coarsening only)
  mmg3d_hmin_hausd      mmg3d_O3 IN.mesh -hmin L -hausd H               (H = 0.001 x the bounding-box diagonal:
                                                                        MMG's default -hausd 0.01 is in mesh
                                                                        units, and refines the curved surfaces of
                                                                        a mesh hundreds of units large)
  cgal_remesh           bench_peer_cgal M OUT.mesh L                    (CGAL tetrahedral_isotropic_remeshing,
                                                                        boundary protected)
  tetgen_rR             tetgen -rRm IN  (IN.node/.ele/.face, IN.mtr = L at every node)
                                                                       (TetGen 1.5 mesh coarsening with a sizing metric)
  tetgen_rR_keepbnd     the same with size 0 (= keep) at the boundary nodes
and writes a JSON list, one object per peer:
  peer, command, seconds (median wall clock of the command over --reps runs, file I/O included),
  seconds_algorithm (median of the tool's own timing of its work without file I/O, when it
  reports one: tetcollapse seconds_collapse, CGAL triangulation build + remeshing, MMG3D the
  "MMG3DLIB: ELAPSED TIME" of its library call, TetGen the sum of its phases but output),
  seconds_runs (every wall time), tets_in, tets_out, vertices_out, min_dihedral_deg, max_dihedral_deg, median_dihedral_deg,
  tets_below_10_deg, valid (from `tetcollapse check OUT --reference M`), check_errors,
  topology_changed, hausdorff_rel (boundary Hausdorff distance / bbox diagonal), load_avg
  (1-minute load average before and after the row) and, for a peer that was not run,
  skipped_reason (not installed, or the command failed: exit code and last line of stderr).

A peer's binary is looked up with --<peer> PATH, else on PATH (mmg3d_O3, mmg3d, tetgen), else
next to tetcollapse (bench_peer_cgal in <build>/bench/). The input is converted once with
`tetcollapse convert` to Medit .mesh (MMG3D) and TetGen .node/.ele (TetGen); the peers' outputs
(.mesh, .node/.ele) are read by `tetcollapse check` directly.

    bench/peers.py --table F.json    prints the rows of a results file as a markdown table
"""
import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
ALL_PEERS = ["tetcollapse", "tetcollapse_noimprove", "tetcollapse_bounded", "tetcollapse_unbounded", "tetcollapse_q0",
             "tetcollapse_cycles2", "tetcollapse_cycles3", "mmg3d_hsiz", "mmg3d_hsiz_nosurf", "mmg3d_hmin", "mmg3d_hmin_nosurf", "mmg3d_hmin_hausd",
             "cgal_remesh", "tetgen_rR", "tetgen_rR_keepbnd"]


class PeerFailed(Exception):
    pass


def run(cmd, timeout, cwd=None):
    """Runs cmd; returns (wall seconds, stdout, stderr). Raises PeerFailed on a non-zero exit."""
    t0 = time.perf_counter()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=cwd)
    except subprocess.TimeoutExpired:
        raise PeerFailed(f"timed out after {timeout} s")
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        lines = [l for l in (p.stderr + "\n" + p.stdout).splitlines() if l.strip()]
        raise PeerFailed(f"exit {p.returncode}: {lines[-1].strip() if lines else '(no output)'}")
    return wall, p.stdout, p.stderr


def find_tool(explicit, names, extra_dirs=()):
    if explicit:
        return explicit if os.access(explicit, os.X_OK) else None
    for n in names:
        p = shutil.which(n)
        if p:
            return p
        for d in extra_dirs:
            c = os.path.join(d, n)
            if os.access(c, os.X_OK):
                return c
    return None


def default_tetcollapse():
    for d in ("build", "build-peers", "build-lead"):
        p = os.path.join(ROOT, d, "tetcollapse")
        if os.access(p, os.X_OK):
            return p
    return shutil.which("tetcollapse")


def tetcollapse_or_exit(given, script):
    """The CLI a bench script runs: `given` (its --tetcollapse), else the build's; exits with a
    message when there is none."""
    tc = os.path.abspath(given or default_tetcollapse() or "")
    if not os.access(tc, os.X_OK):
        sys.exit(f"{script}: no tetcollapse binary (give --tetcollapse PATH)")
    return tc


def table_asked(table):
    """`SCRIPT --table F.json`: prints the markdown table(s) `table` makes of a results file, and
    says so (the script then stops)."""
    if len(sys.argv) == 3 and sys.argv[1] == "--table":
        with open(sys.argv[2]) as f:
            print(table(json.load(f)))
        return True
    return False


def provenance(script, tc):
    """What a results file records of its run: the command, the commit, the device (bench/make_tables.py
    prints them over the table)."""
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    device = subprocess.run([tc, "devices"], capture_output=True, text=True).stdout.strip().splitlines()
    return {"command": " ".join([f"bench/{script}"] + sys.argv[1:]), "commit": commit,
            "device": device[0] if device else None}


def write_boundary_faces(ele, face):
    """Writes the faces that lie in exactly one tet of the TetGen .ele file as a TetGen .face file."""
    with open(ele) as f:
        rows = [l.split() for l in f if l.strip() and not l.lstrip().startswith("#")]
    count = {}
    for r in rows[1:]:
        a, b, c, d = r[1:5]
        for t in ((a, b, c), (a, b, d), (a, c, d), (b, c, d)):
            k = tuple(sorted(t, key=int))
            count[k] = count.get(k, 0) + 1
    faces = [k for k, n in count.items() if n == 1]
    with open(face, "w") as f:
        f.write(f"{len(faces)} 0\n")
        first = int(rows[1][0])  # the same numbering base as the .ele
        for i, k in enumerate(faces):
            f.write(f"{i + first} {k[0]} {k[1]} {k[2]}\n")


def load():
    return round(os.getloadavg()[0], 2)


def check_output(tc, out, mesh, work, timeout, hausdorff):
    """Quality and validity of a peer's output, from `tetcollapse check OUT --reference M --json`."""
    js = os.path.join(work, "check.json")
    cmd = [tc, "check", out, "--reference", mesh, "--json", js, "-q", "--no-sol"]
    if not hausdorff:
        cmd.append("--no-hausdorff")
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    if p.returncode not in (0, 1) or not os.path.exists(js):
        return {"valid": None, "check_errors": [f"check failed (exit {p.returncode}): {p.stderr.strip()[-300:]}"]}
    with open(js) as f:
        r = json.load(f)
    q = r.get("quality", {})
    ref = r.get("reference", {})
    return {
        "tets_out": r["tets"],
        "vertices_out": r.get("referenced_vertices", r["vertices"]),
        "min_dihedral_deg": q.get("min_dihedral_deg", {}).get("min"),
        "max_dihedral_deg": q.get("max_dihedral_deg", {}).get("max"),
        "median_dihedral_deg": q.get("median_dihedral_deg"),
        "tets_below_10_deg": q.get("tets_below_10_deg"),
        "tets_below_13_deg": q.get("tets_below_13_deg"),
        "mean_ratio_min": q.get("mean_ratio", {}).get("min"),
        "valid": r["valid"],
        "check_errors": [f["code"] for f in r.get("findings", []) if f["severity"] == "error"],
        "topology_changed": ref.get("topology_changed"),
        "hausdorff_rel": ref.get("hausdorff_rel"),
        "volume_change_rel": ref.get("volume_change_rel"),
    }


def fmt(x, spec):
    return "-" if x is None else format(x, spec)


def markdown(rows):
    """The rows of a results file as a markdown table (bench/peers.py --table F.json)."""
    out = ["| peer | command | wall s | own s | tets out | min dihedral | max dihedral | tets < 10 deg | "
           "valid | Hausdorff rel |", "|---|---|---:|---:|---:|---:|---:|---:|---|---:|"]
    for r in rows:
        if "skipped_reason" in r:
            out.append(f"| {r['peer']} | `{r.get('command') or '-'}` | skipped: {r['skipped_reason'][:160]} "
                       "| | | | | | | |")
            continue
        valid = {True: "yes", False: "no: " + ", ".join(r.get("check_errors") or []), None: "?"}[r.get("valid")]
        out.append(f"| {r['peer']} | `{r['command']}` | {fmt(r.get('seconds'), '.2f')} | "
                   f"{fmt(r.get('seconds_algorithm'), '.2f')} | {fmt(r.get('tets_out'), ',')} | "
                   f"{fmt(r.get('min_dihedral_deg'), '.3g')} | {fmt(r.get('max_dihedral_deg'), '.4g')} | "
                   f"{fmt(r.get('tets_below_10_deg'), ',')} | {valid} | {fmt(r.get('hausdorff_rel'), '.2g')} |")
    return "\n".join(out)


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--table":
        with open(sys.argv[2]) as f:
            print(markdown(json.load(f)))
        return
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mesh", required=True)
    ap.add_argument("--target-length", type=float, required=True)
    ap.add_argument("--tetcollapse", default=None)
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--out-json", required=True)
    ap.add_argument("--cgal-peer", default=None, help="bench_peer_cgal (default: <tetcollapse dir>/bench/bench_peer_cgal)")
    ap.add_argument("--mmg3d", default=None)
    ap.add_argument("--tetgen", default=None)
    ap.add_argument("--peers", default=",".join(ALL_PEERS), help="comma-separated subset of " + ",".join(ALL_PEERS))
    ap.add_argument("--work-dir", default=None, help="keep inputs and outputs here (default: a temporary folder)")
    ap.add_argument("--timeout", type=float, default=3600, help="seconds per command")
    ap.add_argument("--no-hausdorff", action="store_true", help="check without the boundary Hausdorff distance")
    a = ap.parse_args()
    if a.reps < 1 or not a.target_length > 0:
        ap.error("--reps must be >= 1 and --target-length > 0")
    peers = [p.strip() for p in a.peers.split(",") if p.strip()]
    unknown = [p for p in peers if p not in ALL_PEERS]
    if unknown:
        ap.error(f"unknown peer(s) {unknown}; known: {ALL_PEERS}")

    tc = a.tetcollapse or default_tetcollapse()
    if not tc or not os.access(tc, os.X_OK):
        sys.exit("peers.py: no tetcollapse binary (give --tetcollapse PATH)")
    tc = os.path.abspath(tc)
    mesh = os.path.abspath(a.mesh)
    L = a.target_length
    tmp = None
    if a.work_dir:
        work = os.path.abspath(a.work_dir)
        os.makedirs(work, exist_ok=True)
    else:
        tmp = tempfile.TemporaryDirectory(prefix="tc_peers_")
        work = tmp.name

    info = json.loads(run([tc, "info", mesh, "--json"], a.timeout)[1])
    tets_in = info["tets"]
    box = info["bounding_box"]
    diagonal = sum((box["max"][k] - box["min"][k]) ** 2 for k in range(3)) ** 0.5
    inputs = {}  # converted copies of the input, made on first use

    def converted(ext):
        if ext not in inputs:
            base = os.path.join(work, "input")
            run([tc, "convert", mesh, base + ext, "--ascii"] if ext == ".mesh" else [tc, "convert", mesh, base + ext],
                a.timeout)
            inputs[ext] = base + ext
        return inputs[ext]

    mmg = find_tool(a.mmg3d, ["mmg3d_O3", "mmg3d"])
    tetgen = find_tool(a.tetgen, ["tetgen"])
    cgal = find_tool(a.cgal_peer, ["bench_peer_cgal"], [os.path.join(os.path.dirname(tc), "bench")])

    def setup(peer, d):
        """Returns (command, output file, how to get seconds_algorithm from one run) or raises
        PeerFailed for a peer that is not installed."""
        if peer.startswith("tetcollapse"):
            out = os.path.join(d, "out.mesh")
            stats = os.path.join(d, "stats.json")
            cmd = [tc, mesh, out, "--target-length", repr(L), "--stats", stats, "--quiet"]
            if peer == "tetcollapse_q0":
                cmd += ["--min-quality", "0", "--no-improve"]
            if peer == "tetcollapse_noimprove":
                cmd += ["--no-improve"]
            if peer == "tetcollapse_bounded":
                cmd += ["--max-boundary-error", "0.001"]
            if peer == "tetcollapse_unbounded":
                cmd += ["--max-boundary-error", "0"]
            if peer.startswith("tetcollapse_cycles"):
                cmd += ["--cycles", peer[len("tetcollapse_cycles"):]]

            def alg(stdout, stderr):  # the collapse and the improvement, without I/O
                with open(stats) as f:
                    st = json.load(f)
                return (st["seconds_collapse"] + st.get("improve", {}).get("seconds", 0) +
                        sum(c["seconds_collapse"] + c["seconds_improve"] for c in st.get("later_cycles", [])))
            return cmd, out, alg
        if peer.startswith("mmg3d"):
            if not mmg:
                raise PeerFailed("not installed: no mmg3d_O3 / mmg3d on PATH (MMG is not packaged by Debian 12; "
                                 "pip's mmgpy wheel ships mmg3d_O3)")
            src = converted(".mesh")
            out = os.path.join(d, "out.mesh")
            cmd = [mmg, "-v", "1", "-in", src, "-out", out]
            # -hsiz: uniform size L everywhere (refines where the input is coarser than L);
            # -hmin: the size MMG derives from the input's edge lengths, but never below L
            # (coarsens only, like tetcollapse)
            cmd += ["-hmin", repr(L)] if "_hmin" in peer else ["-hsiz", repr(L)]
            if peer.endswith("nosurf"):
                cmd.append("-nosurf")
            if peer.endswith("hausd"):
                cmd += ["-hausd", repr(0.001 * diagonal)]

            def alg(stdout, stderr):
                # "MMG3DLIB: ELAPSED TIME  1.23s": the library call (analysis + remeshing), no file I/O
                # (MMG writes "12.345s", "5m12s" or "1h05m12s")
                m = re.search(r"MMG3DLIB: ELAPSED TIME\s+(?:(\d+)h)?(?:(\d+)m)?([0-9.]+)s", stdout)
                return 3600 * int(m.group(1) or 0) + 60 * int(m.group(2) or 0) + float(m.group(3)) if m else None
            return cmd, out, alg
        if peer == "cgal_remesh":
            if not cgal:
                raise PeerFailed("not built: no bench_peer_cgal next to tetcollapse (build target bench_peer_cgal)")
            out = os.path.join(d, "out.mesh")
            cmd = [cgal, mesh, out, repr(L)]

            def alg(stdout, stderr):
                return json.loads(stdout.strip().splitlines()[-1])["seconds"]
            return cmd, out, alg
        if peer in ("tetgen_rR", "tetgen_rR_keepbnd"):
            if not tetgen:
                raise PeerFailed("not installed: no tetgen on PATH")
            node = converted(".node")
            base = os.path.join(d, "in")
            shutil.copy(node, base + ".node")
            shutil.copy(node[:-5] + ".ele", base + ".ele")
            # The boundary triangles: without a .face tetgen 1.5.0 -rR fails an assertion
            # (removevertexbyflips / sremovevertex) on most meshes.
            if os.path.exists(node[:-5] + ".face"):
                shutil.copy(node[:-5] + ".face", base + ".face")
            else:
                write_boundary_faces(base + ".ele", base + ".face")
            # .mtr: the wanted edge length at every node, in .node order (TetGen -m). TetGen -R
            # removes every node whose shortest edge is below its size; size 0 keeps a node, so
            # the _keepbnd variant gives the boundary nodes 0.
            keep = set()
            if peer.endswith("keepbnd"):
                with open(base + ".face") as f:
                    for r in [l.split() for l in f if l.strip() and not l.lstrip().startswith("#")][1:]:
                        keep.update(r[1:4])
            with open(base + ".node") as f:
                nodes = [l.split()[0] for l in f if l.strip() and not l.lstrip().startswith("#")]
            n = int(nodes[0].split()[0]) if nodes else 0
            with open(base + ".mtr", "w") as f:
                f.write(f"{n} 1\n")
                f.writelines("0\n" if v in keep else repr(L) + "\n" for v in nodes[1:n + 1])
            cmd = [tetgen, "-rRm", base]

            def alg(stdout, stderr):
                # TetGen prints the seconds of each phase; all but reading and writing the files
                phases = re.findall(r"^(.*) seconds:\s+([0-9.eE+-]+)", stdout, re.M)
                t = [float(v) for k, v in phases if k.strip() not in ("Output", "Total running")]
                return sum(t) if t else None
            return cmd, base + ".1.ele", alg
        raise AssertionError(peer)

    rows = []
    for peer in peers:
        d = os.path.join(work, peer)
        os.makedirs(d, exist_ok=True)
        row = {"peer": peer, "mesh": os.path.basename(mesh), "target_length": L, "tets_in": tets_in,
               "load_avg": [load()]}
        try:
            cmd, out, alg = setup(peer, d)
            row["command"] = " ".join(os.path.basename(c) if i == 0 or c == mesh else c.replace(work + "/", "")
                                      for i, c in enumerate(cmd))
            walls, algs = [], []
            for _ in range(a.reps):
                for f in os.listdir(d):  # a run must not find the previous run's output
                    if f.startswith("out.") or f.startswith("in.1."):
                        os.remove(os.path.join(d, f))
                wall, so, se = run(cmd, a.timeout, cwd=d)
                walls.append(wall)
                algs.append(alg(so, se))
            row["seconds"] = statistics.median(walls)
            row["seconds_runs"] = [round(w, 4) for w in walls]
            row["seconds_algorithm"] = statistics.median(algs) if None not in algs else None
            row.update(check_output(tc, out, mesh, d, a.timeout, not a.no_hausdorff))
        except PeerFailed as e:
            row["skipped_reason"] = str(e)
            row.setdefault("command", None)
        row["load_avg"].append(load())
        rows.append(row)
        print(f"{peer:20s} " + (f"skipped: {row['skipped_reason']}" if "skipped_reason" in row else
              f"{row['seconds']:8.3f} s  tets {tets_in} -> {row.get('tets_out')}  min dihedral "
              f"{row.get('min_dihedral_deg')}  valid {row.get('valid')}"), flush=True)

    os.makedirs(os.path.dirname(os.path.abspath(a.out_json)) or ".", exist_ok=True)
    with open(a.out_json, "w") as f:
        json.dump(rows, f, indent=1)
        f.write("\n")
    if tmp:
        tmp.cleanup()


if __name__ == "__main__":
    main()
