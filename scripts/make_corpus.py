#!/usr/bin/python3
"""Generates the robustness corpus: a few hundred varied tetrahedral meshes.

    scripts/make_corpus.py [OUT_DIR] [--jobs N] [--only NAME,...] [--ci-sample] [--list]

OUT_DIR defaults to build/corpus (not committed). Every mesh is written as Gmsh 4.1 binary
(<name>.msh) and described in OUT_DIR/MANIFEST.json (category, what it is, vertices, tets).
--ci-sample writes only the small fixed subset that is committed in meshes/corpus/.

Categories (each recipe is a function of its name and a fixed seed, so the corpus is
deterministic and a single mesh can be regenerated with --only):
  cad        boxes with fillets, through holes, blind pockets, slots and bosses (OpenCASCADE booleans)
  thinplate  plates of thickness 0.3%..5% of their length, some with holes, some one element thick
  holes      tori, linked tori, plates with many holes, blocks with crossing tunnels (genus > 1)
  multimat   nested and multi-material bodies: fragments give several physical volumes
  graded     size fields (distance/threshold to points, curves and faces; box fields)
  aniso      isotropic meshes whose coordinates are then scaled by very different factors per axis
  perturbed  interior vertices moved randomly as far as possible without inverting a tet
  sliver     TetGen without -q: Delaunay of jittered lattices and random points, -p without quality
  multicomp  several disjoint bodies in one mesh, some with narrow gaps
  surface    the surfaces of ../shared/meshes/surfaces tetrahedralized with TetGen (skipped if absent)

Needs Debian's gmsh Python module (python3-gmsh), tetgen, numpy and meshio
(scripts/setup.sh --with-tools). Run with /usr/bin/python3.
"""
import argparse
import json
import math
import concurrent.futures
import os
import random
import shutil
import subprocess
import sys
import tempfile

import numpy as np

try:
    import gmsh
except ImportError:
    sys.exit("make_corpus.py: the gmsh Python module is missing (apt-get install python3-gmsh; "
             "run with /usr/bin/python3)")

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED_SURFACES = os.path.normpath(os.path.join(HERE, "..", "..", "shared", "meshes", "surfaces"))

MIN_TETS, MAX_TETS = 400, 65000
# Empirical: gmsh's 3D Delaunay with a uniform size h gives about 5 V / h^3 tets.
TETS_PER_H3 = 5.0

# The meshes committed in meshes/corpus/ (CI sample, tests/cli/test_robustness_sample.cpp):
# small members of every category, chosen from the corpus after generating it.
CI_SAMPLE = [
    "cad_028", "cad_032", "thinplate_014", "thinplate_024", "holes_017", "holes_022", "multimat_005",
    "multimat_024", "multimat_036", "graded_024", "graded_027", "aniso_003", "aniso_019", "perturbed_002",
    "perturbed_021", "sliver_012", "sliver_015", "sliver_024", "multicomp_013", "multicomp_022",
]


class Skip(Exception):
    """The recipe cannot make a mesh in the size range (recorded in the manifest)."""


# --------------------------------------------------------------------------------------------
# gmsh helpers

def gmsh_start():
    gmsh.initialize(readConfigFiles=False)
    gmsh.option.setNumber("General.AbortOnError", 0)
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.NumThreads", 1)  # one thread: deterministic


def new_model(name):
    gmsh.clear()
    gmsh.model.add(name)
    gmsh.option.setNumber("Mesh.RandomSeed", 1)
    gmsh.option.setNumber("Mesh.Algorithm", 6)
    gmsh.option.setNumber("Mesh.Algorithm3D", 1)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 1)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 1)
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 1e22)
    gmsh.option.setNumber("Mesh.Binary", 1)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.SaveAll", 0)


def occ_volume():
    occ = gmsh.model.occ
    return sum(occ.getMass(3, t) for _, t in occ.getEntities(3))


def count_tets():
    types, tags, _ = gmsh.model.mesh.getElements(3)
    return sum(len(t) for ty, t in zip(types, tags) if ty == 4)


def mesh_to_target(target, build, size_setup=None):
    """Builds the geometry with build(), then meshes it with a uniform size chosen for about
    `target` tets (size_setup(h) may install fields instead); corrects h up to 4 times."""
    build()
    gmsh.model.occ.synchronize()
    vol = occ_volume()
    h = (TETS_PER_H3 * vol / target) ** (1 / 3)
    for _ in range(5):
        gmsh.model.mesh.clear()
        if size_setup:
            size_setup(h)
        else:
            gmsh.option.setNumber("Mesh.MeshSizeMin", h)
            gmsh.option.setNumber("Mesh.MeshSizeMax", h)
        gmsh.model.mesh.generate(3)
        n = count_tets()
        if MIN_TETS <= n <= MAX_TETS and 0.4 * target <= n <= 2.5 * target:
            return n
        if n == 0:
            raise Skip("gmsh made no tets")
        h *= (n / target) ** (1 / 3)
    if MIN_TETS <= n <= MAX_TETS:
        return n
    raise Skip(f"{n} tets after size corrections")


def extract_tets():
    """Every linear tet of the current gmsh model: coordinates (N,3), tets (M,4) zero-based,
    label per tet (the physical tag of its volume, else the volume's entity tag)."""
    tags, coords, _ = gmsh.model.mesh.getNodes()
    X = coords.reshape(-1, 3)
    index = np.full(int(tags.max()) + 1, -1, dtype=np.int64)
    index[tags.astype(np.int64)] = np.arange(len(tags))
    T, L = [], []
    for dim, ent in gmsh.model.getEntities(3):
        phys = gmsh.model.getPhysicalGroupsForEntity(dim, ent)
        label = int(phys[0]) if len(phys) else int(ent)
        etags, enodes = gmsh.model.mesh.getElementsByType(4, ent)
        if len(etags) == 0:
            continue
        T.append(index[enodes.astype(np.int64)].reshape(-1, 4))
        L.append(np.full(len(etags), label, dtype=np.int64))
    T = np.concatenate(T)
    used = np.unique(T)
    remap = np.full(len(X), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    return X[used].copy(), remap[T], np.concatenate(L)


def signed_volumes(X, T):
    a, b, c, d = (X[T[:, i]] for i in range(4))
    return np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) / 6.0


def save_tets(path, X, T, labels=None):
    """Writes tets (made positive) as Gmsh 4.1 binary through gmsh's own writer: one discrete
    volume per label, with a physical group per label when there are several."""
    T = T.copy()
    vol = signed_volumes(X, T)
    if np.any(vol == 0):
        raise Skip("a tet of zero volume")
    neg = vol < 0
    T[neg, 2], T[neg, 3] = T[neg, 3].copy(), T[neg, 2].copy()
    if labels is None:
        labels = np.ones(len(T), dtype=np.int64)
    new_model("save")
    values = sorted(set(int(v) for v in labels))
    for k, value in enumerate(values):
        gmsh.model.addDiscreteEntity(3, value)
        if k == 0:
            gmsh.model.mesh.addNodes(3, value, list(range(1, len(X) + 1)), X.ravel().tolist())
        sel = T[labels == value]
        gmsh.model.mesh.addElementsByType(value, 4, [], (sel + 1).ravel().tolist())
    if len(values) > 1:
        for value in values:
            gmsh.model.addPhysicalGroup(3, [value], value)
    gmsh.write(path)
    return len(T)


# --------------------------------------------------------------------------------------------
# geometry recipes (each takes a random.Random and builds OCC entities)

def loguniform(rng, lo, hi):
    return math.exp(rng.uniform(math.log(lo), math.log(hi)))


def target_tets(rng):
    if rng.random() < 0.1:
        return int(loguniform(rng, 30000, 55000))
    return int(loguniform(rng, 800, 25000))


def occ_cad_part(rng):
    """A machined block: filleted or chamfered edges, through holes, blind pockets, a slot,
    bosses on top. Returns nothing; leaves one volume in the OCC model."""
    occ = gmsh.model.occ
    L, W, H = rng.uniform(1.5, 3.0), rng.uniform(1.0, 2.0), rng.uniform(0.3, 1.0)
    box = occ.addBox(0, 0, 0, L, W, H)
    edge_op = rng.choice(["all", "vertical", "none"])
    if edge_op != "none":  # round all edges, or only the four vertical ones
        occ.synchronize()
        edges = [t for _, t in occ.getEntities(1)]  # the box is the only entity so far
        if edge_op == "vertical":
            edges = [t for t in edges if abs(gmsh.model.getBoundingBox(1, t)[5] - gmsh.model.getBoundingBox(1, t)[2]) > 0.5 * H]
        r = rng.uniform(0.03, 0.2) * H
        box = occ.fillet([box], edges, [r], removeVolume=True)[0][1]
    body = [(3, box)]
    tools = []
    for _ in range(rng.randint(0, 5)):  # through holes
        r = rng.uniform(0.05, 0.2) * min(L, W)
        x, y = rng.uniform(r + 0.1, L - r - 0.1), rng.uniform(r + 0.1, W - r - 0.1)
        tools.append((3, occ.addCylinder(x, y, -0.1, 0, 0, H + 0.2, r)))
    for _ in range(rng.randint(0, 2)):  # blind pockets
        a, b = rng.uniform(0.2, 0.4) * L, rng.uniform(0.2, 0.4) * W
        x, y = rng.uniform(0.05, L - a - 0.05), rng.uniform(0.05, W - b - 0.05)
        tools.append((3, occ.addBox(x, y, H * rng.uniform(0.3, 0.7), a, b, H)))
    if rng.random() < 0.3:  # a slot along x
        w = rng.uniform(0.05, 0.15) * W
        tools.append((3, occ.addBox(-0.1, rng.uniform(0.2, 0.7) * W, H * 0.6, L + 0.2, w, H)))
    if tools:
        body, _ = occ.cut(body, tools)
    bosses = []
    for _ in range(rng.randint(0, 3)):
        r = rng.uniform(0.05, 0.15) * min(L, W)
        x, y = rng.uniform(r, L - r), rng.uniform(r, W - r)
        bosses.append((3, occ.addCylinder(x, y, H * 0.5, 0, 0, H * rng.uniform(0.7, 1.2), r)))
    if bosses:
        body, _ = occ.fuse(body, bosses)
    if len(body) > 1:  # a cut may split the block; keep it as several volumes only if fused fails
        body, _ = occ.fuse(body[:1], body[1:])


def occ_thin_plate(rng):
    occ = gmsh.model.occ
    L, W = rng.uniform(1, 3), rng.uniform(1, 2)
    t = L * loguniform(rng, 0.003, 0.05)
    plate = [(3, occ.addBox(0, 0, 0, L, W, t))]
    holes = [(3, occ.addCylinder(rng.uniform(0.2, L - 0.2), rng.uniform(0.2, W - 0.2), -t, 0, 0, 3 * t,
                                 rng.uniform(0.03, 0.12)))
             for _ in range(rng.choice([0, 0, 1, 3, 6]))]
    if holes:
        occ.cut(plate, holes)
    return t


def occ_torus(rng, x=0.0, y=0.0, z=0.0, axis=(0, 0, 1)):
    R = rng.uniform(0.6, 1.2)
    r = R * rng.uniform(0.08, 0.45)
    return occ_axis_torus(x, y, z, R, r, axis)


def occ_axis_torus(x, y, z, R, r, axis):
    """A torus around an axis through (x, y, z); gmsh 4.8's addTorus has no axis argument, so
    it is made around z and rotated."""
    occ = gmsh.model.occ
    t = occ.addTorus(0, 0, 0, R, r)
    if tuple(axis) == (0, 1, 0):
        occ.rotate([(3, t)], 0, 0, 0, 1, 0, 0, math.pi / 2)
    elif tuple(axis) == (1, 0, 0):
        occ.rotate([(3, t)], 0, 0, 0, 0, 1, 0, math.pi / 2)
    occ.translate([(3, t)], x, y, z)
    return t


def occ_holes(rng, kind):
    occ = gmsh.model.occ
    if kind == "torus":
        occ_torus(rng)
    elif kind == "linked":
        R, r = 1.0, rng.uniform(0.1, 0.3)
        occ_axis_torus(0, 0, 0, R, r, (0, 0, 1))
        occ_axis_torus(R, 0, 0, R, r, (0, 1, 0))
    elif kind == "plate":
        n, m = rng.randint(3, 8), rng.randint(2, 6)
        t = rng.uniform(0.05, 0.3)
        plate = [(3, occ.addBox(0, 0, 0, n, m, t))]
        rad = rng.uniform(0.15, 0.4)
        holes = [(3, occ.addCylinder(i + 0.5, j + 0.5, -1, 0, 0, 2 + t, rad)) for i in range(n) for j in range(m)]
        occ.cut(plate, holes)
    else:  # block with tunnels crossing in several directions
        block = [(3, occ.addBox(0, 0, 0, 2, 2, 2))]
        tunnels = []
        for axis in range(3):
            for _ in range(rng.randint(1, 2)):
                r = rng.uniform(0.12, 0.3)
                u, v = rng.uniform(0.4, 1.6), rng.uniform(0.4, 1.6)
                p, d = [u, v, -0.5], [0, 0, 3]
                p = p[3 - axis:] + p[:3 - axis]
                d = d[3 - axis:] + d[:3 - axis]
                tunnels.append((3, occ.addCylinder(*p, *d, r)))
        occ.cut(block, tunnels)


def occ_multimat(rng, kind):
    """Several volumes sharing faces (fragment), each its own physical group."""
    occ = gmsh.model.occ
    if kind == "inclusion":
        objs = [(3, occ.addBox(0, 0, 0, 2, 2, 2))]
        tools = [(3, occ.addSphere(rng.uniform(0.6, 1.4), rng.uniform(0.6, 1.4), rng.uniform(0.6, 1.4),
                                   rng.uniform(0.2, 0.5))) for _ in range(rng.randint(1, 3))]
    elif kind == "layers":
        n = rng.randint(2, 5)
        zs = sorted(rng.uniform(0.05, 0.95) for _ in range(n - 1))
        zs = [0.0] + zs + [1.0]
        objs = [(3, occ.addBox(0, 0, zs[i], 2, 1.5, zs[i + 1] - zs[i])) for i in range(n)]
        tools = []
    elif kind == "nested":
        objs = [(3, occ.addSphere(0, 0, 0, 1.0))]
        tools = [(3, occ.addSphere(rng.uniform(-0.1, 0.1), 0, 0, rng.uniform(0.55, 0.75))),
                 (3, occ.addBox(-0.25, -0.25, -0.25, 0.5, 0.5, rng.uniform(0.3, 0.5)))]
    else:  # fibres through a block
        objs = [(3, occ.addBox(0, 0, 0, 2, 1, 1))]
        tools = [(3, occ.addCylinder(-0.2, rng.uniform(0.2, 0.8), rng.uniform(0.2, 0.8), 2.4, 0, 0,
                                     rng.uniform(0.05, 0.12))) for _ in range(rng.randint(1, 4))]
    if tools:
        occ.fragment(objs, tools)
    else:
        occ.fragment(objs[:1], objs[1:])
    occ.synchronize()
    vols = [t for _, t in occ.getEntities(3)]
    for k, v in enumerate(vols):
        gmsh.model.addPhysicalGroup(3, [v], k + 1)


def occ_shape(rng, x=0.0, y=0.0, z=0.0, scale=1.0):
    occ = gmsh.model.occ
    kind = rng.choice(["box", "sphere", "cylinder", "cone", "torus", "wedge"])
    s = scale
    if kind == "box":
        return occ.addBox(x, y, z, s * rng.uniform(0.3, 1), s * rng.uniform(0.3, 1), s * rng.uniform(0.3, 1))
    if kind == "sphere":
        return occ.addSphere(x + s * 0.5, y + s * 0.5, z + s * 0.5, s * rng.uniform(0.2, 0.5))
    if kind == "cylinder":
        return occ.addCylinder(x + 0.5 * s, y + 0.5 * s, z, 0, 0, s * rng.uniform(0.4, 1), s * rng.uniform(0.15, 0.45))
    if kind == "cone":
        return occ.addCone(x + 0.5 * s, y + 0.5 * s, z, 0, 0, s, s * rng.uniform(0.2, 0.5), s * rng.uniform(0, 0.2))
    if kind == "torus":
        return occ.addTorus(x + 0.5 * s, y + 0.5 * s, z + 0.3 * s, 0.3 * s, s * rng.uniform(0.05, 0.15))
    return occ.addWedge(x, y, z, s * rng.uniform(0.4, 1), s * rng.uniform(0.4, 1), s * rng.uniform(0.4, 1))


def occ_any_single(rng):
    """One body of any kind: CAD part, torus, tunnels, simple shape."""
    k = rng.randint(0, 3)
    if k == 0:
        occ_cad_part(rng)
    elif k == 1:
        occ_holes(rng, rng.choice(["torus", "tunnels", "plate"]))
    elif k == 2:
        occ_shape(rng)
    else:
        occ_multimat(rng, rng.choice(["inclusion", "layers", "fibres"]))


# --------------------------------------------------------------------------------------------
# recipes: name -> function(rng, path) returning a description

def r_cad(rng, path):
    n = mesh_to_target(target_tets(rng), lambda: occ_cad_part(rng))
    gmsh.write(path)
    return "machined block (fillets/holes/pockets/bosses)", n


def r_thinplate(rng, path):
    one_layer = rng.random() < 0.3
    state = {}

    def build():
        state["t"] = occ_thin_plate(rng)

    if one_layer:
        def size(h):
            hh = max(h, 2.0 * state["t"])
            gmsh.option.setNumber("Mesh.MeshSizeMin", hh)
            gmsh.option.setNumber("Mesh.MeshSizeMax", hh)
        n = mesh_to_target(target_tets(rng), build, size)
    else:
        n = mesh_to_target(target_tets(rng), build)
    gmsh.write(path)
    return f"thin plate, thickness {state['t']:.3g}{' (size >= 2x thickness)' if one_layer else ''}", n


def r_holes(rng, path):
    kind = rng.choice(["torus", "linked", "plate", "tunnels"])
    n = mesh_to_target(target_tets(rng), lambda: occ_holes(rng, kind))
    gmsh.write(path)
    return f"holes/tunnels: {kind}", n


def r_multimat(rng, path):
    kind = rng.choice(["inclusion", "layers", "nested", "fibres"])
    n = mesh_to_target(target_tets(rng), lambda: occ_multimat(rng, kind))
    gmsh.write(path)
    return f"multi-material: {kind} ({len(gmsh.model.getPhysicalGroups(3))} physical volumes)", n


def r_graded(rng, path):
    ratio = loguniform(rng, 4, 25)
    kind = rng.choice(["point", "curve", "surface", "box"])

    def size(h):
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeMin", 0)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 1e22)
        f = gmsh.model.mesh.field
        for tag in list(range(1, 4)):
            try:
                f.remove(tag)
            except Exception:
                pass
        # Most of the volume is far from the feature: the fine end is nearer h than the coarse end,
        # so the tet count stays near the target (fine = h / ratio would multiply it).
        fine, coarse = h / ratio ** (1 / 3), h * ratio ** (2 / 3)
        xmin, ymin, zmin, xmax, ymax, zmax = gmsh.model.getBoundingBox(-1, -1)
        diag = math.dist((xmin, ymin, zmin), (xmax, ymax, zmax))
        if kind == "box":
            f.add("Box", 1)
            f.setNumber(1, "VIn", fine)
            f.setNumber(1, "VOut", coarse)
            for key, lo, hi in (("X", xmin, xmax), ("Y", ymin, ymax), ("Z", zmin, zmax)):
                f.setNumber(1, key + "Min", lo)
                f.setNumber(1, key + "Max", lo + 0.4 * (hi - lo))
            f.setNumber(1, "Thickness", 0.2 * diag)
        else:
            f.add("Distance", 2)
            ents = gmsh.model.getEntities({"point": 0, "curve": 1, "surface": 2}[kind])
            key = {"point": "PointsList", "curve": "CurvesList", "surface": "SurfacesList"}[kind]
            f.setNumbers(2, key, [ents[0][1]])
            f.add("Threshold", 1)
            f.setNumber(1, "InField", 2)
            f.setNumber(1, "SizeMin", fine)
            f.setNumber(1, "SizeMax", coarse)
            f.setNumber(1, "DistMin", 0.02 * diag)
            f.setNumber(1, "DistMax", 0.6 * diag)
        f.setAsBackgroundMesh(1)

    n = mesh_to_target(target_tets(rng), lambda: occ_any_single(rng), size)
    gmsh.write(path)
    return f"graded ({kind} field, size ratio {ratio:.3g})", n


def r_aniso(rng, path):
    n = mesh_to_target(target_tets(rng), lambda: occ_any_single(rng))
    X, T, L = extract_tets()
    scale = [1.0, 1.0, 1.0]
    axis = rng.randrange(3)
    scale[axis] = rng.choice([loguniform(rng, 0.02, 0.2), loguniform(rng, 5, 40)])
    if rng.random() < 0.5:
        other = (axis + 1 + rng.randrange(2)) % 3
        scale[other] = loguniform(rng, 0.2, 5)
    X = X * np.array(scale)
    n = save_tets(path, X, T, L)
    return f"anisotropic: coordinates scaled by ({scale[0]:.3g}, {scale[1]:.3g}, {scale[2]:.3g})", n


def perturb_interior(rng, X, T, amplitude):
    """Moves every interior vertex by a random vector of length up to amplitude x its shortest
    edge; moves that would leave a tet with less than 1e-4 of its volume are taken back, in
    rounds, so no tet is inverted. Returns the new coordinates and how many vertices moved."""
    nprng = np.random.default_rng(rng.randrange(2**32))
    faces = np.sort(np.concatenate([T[:, [1, 2, 3]], T[:, [0, 3, 2]], T[:, [0, 1, 3]], T[:, [0, 2, 1]]]), axis=1)
    uniq, counts = np.unique(faces, axis=0, return_counts=True)
    boundary = np.zeros(len(X), dtype=bool)
    boundary[uniq[counts == 1].ravel()] = True
    edges = np.concatenate([T[:, [i, j]] for i in range(4) for j in range(i + 1, 4)])
    lengths = np.linalg.norm(X[edges[:, 0]] - X[edges[:, 1]], axis=1)
    shortest = np.full(len(X), np.inf)
    np.minimum.at(shortest, edges[:, 0], lengths)
    np.minimum.at(shortest, edges[:, 1], lengths)
    direction = nprng.normal(size=X.shape)
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    step = direction * (amplitude * shortest * nprng.uniform(0, 1, size=len(X)))[:, None]
    step[boundary] = 0
    v0 = signed_volumes(X, T)
    moving = ~boundary
    for _ in range(50):
        Y = X + step * moving[:, None]
        bad = signed_volumes(Y, T) < 1e-4 * v0
        if not bad.any():
            return Y, int(moving.sum())
        moving[T[bad].ravel()] = False
    return X, 0


def r_perturbed(rng, path):
    n = mesh_to_target(target_tets(rng), lambda: occ_any_single(rng))
    X, T, L = extract_tets()
    amplitude = rng.uniform(0.15, 0.49)
    Y, moved = perturb_interior(rng, X, T, amplitude)
    n = save_tets(path, Y, T, L)
    return f"perturbed: {moved} interior vertices moved up to {amplitude:.2f} x shortest edge", n


def run_tetgen(args, cwd):
    r = subprocess.run(["tetgen", "-Q"] + args, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                       timeout=600)
    if r.returncode != 0:
        raise Skip(f"tetgen {' '.join(args)} failed: {r.stdout.strip()[-200:]}")


def read_tetgen(stem):
    """TetGen .node/.ele (our own output, so a plain whitespace split suffices)."""
    with open(stem + ".node") as f:
        rows = [l.split("#")[0].split() for l in f]
    rows = [r for r in rows if r]
    n, first = int(rows[0][0]), None
    pts = np.array([[float(v) for v in r[1:4]] for r in rows[1:n + 1]])
    first = int(rows[1][0])
    with open(stem + ".ele") as f:
        rows = [l.split("#")[0].split() for l in f]
    rows = [r for r in rows if r]
    m, per, nattr = int(rows[0][0]), int(rows[0][1]), int(rows[0][2])
    tets = np.array([[int(v) for v in r[1:5]] for r in rows[1:m + 1]], dtype=np.int64) - first
    labels = np.array([int(float(r[1 + per])) for r in rows[1:m + 1]]) if nattr else None
    return pts, tets, labels


def write_off(path, X, F):
    """Plain OFF without comments (Debian's tetgen 1.5 aborts on OFF comments and binary STL)."""
    with open(path, "w") as f:
        f.write(f"OFF\n{len(X)} {len(F)} 0\n")
        for p in X:
            f.write(f"{p[0]!r} {p[1]!r} {p[2]!r}\n")
        for t in F:
            f.write(f"3 {t[0]} {t[1]} {t[2]}\n")


def gmsh_surface(rng):
    """A closed triangulated surface of a random body (for tetgen -p), as (X, F)."""
    new_model("surf")
    occ_any_single(rng)
    gmsh.model.occ.synchronize()
    # Fragments leave inner faces; tetgen -p takes the outer skin only when the inner faces are gone.
    vols = gmsh.model.occ.getEntities(3)
    if len(vols) > 1:
        gmsh.model.occ.fuse(vols[:1], vols[1:])
        gmsh.model.occ.synchronize()
    h = (TETS_PER_H3 * occ_volume() / rng.uniform(300, 3000)) ** (1 / 3)
    gmsh.option.setNumber("Mesh.MeshSizeMin", h)
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)
    gmsh.model.mesh.generate(2)
    tags, coords, _ = gmsh.model.mesh.getNodes()
    index = {int(t): i for i, t in enumerate(tags)}
    F = []
    for _, s in gmsh.model.getEntities(2):
        _, en = gmsh.model.mesh.getElementsByType(2, s)
        F.extend(en.reshape(-1, 3).tolist())
    F = np.array([[index[int(v)] for v in f] for f in F])
    return coords.reshape(-1, 3), F


def r_sliver(rng, path):
    kind = rng.choice(["lattice", "random", "plc", "plc"])
    with tempfile.TemporaryDirectory() as tmp:
        if kind in ("lattice", "random"):
            target = target_tets(rng)
            npts = max(150, int(target / 6.3))
            nprng = np.random.default_rng(rng.randrange(2**32))
            if kind == "lattice":
                k = max(4, round(npts ** (1 / 3)))
                g = np.stack(np.meshgrid(*[np.arange(k)] * 3, indexing="ij"), -1).reshape(-1, 3).astype(float)
                jitter = loguniform(rng, 1e-4, 3e-2)
                g += nprng.uniform(-jitter, jitter, size=g.shape) * (g > 0) * (g < k - 1)
                g *= np.array([1.0, rng.uniform(0.5, 2), rng.uniform(0.5, 2)])
                pts, what = g, f"Delaunay of a {k}^3 lattice jittered by {jitter:.2g} (inside)"
            else:
                pts = nprng.uniform(0, 1, size=(npts, 3)) * np.array([1, rng.uniform(0.3, 1), rng.uniform(0.3, 1)])
                what = f"Delaunay of {npts} uniform random points in a box"
            with open(os.path.join(tmp, "p.node"), "w") as f:
                f.write(f"{len(pts)} 3 0 0\n")
                for i, p in enumerate(pts):
                    f.write(f"{i} {p[0]!r} {p[1]!r} {p[2]!r}\n")
            run_tetgen(["-z", "p.node"], tmp)
        else:
            X, F = gmsh_surface(rng)
            write_off(os.path.join(tmp, "p.off"), X, F)
            vol = abs(np.einsum("ij,ij->i", X[F[:, 0]], np.cross(X[F[:, 1]], X[F[:, 2]])).sum()) / 6
            a = vol / target_tets(rng) * 1.5
            what = f"tetgen -pYa{a:.3g} (no -q) of a gmsh surface with {len(F)} triangles"
            run_tetgen(["-pYza" + f"{a:.6g}", "p.off"], tmp)
        X, T, _ = read_tetgen(os.path.join(tmp, "p.1"))
    if not MIN_TETS <= len(T) <= MAX_TETS:
        raise Skip(f"{len(T)} tets")
    n = save_tets(path, X, T)
    return "sliver: " + what, n


def r_multicomp(rng, path):
    count = rng.randint(2, 6)
    narrow = rng.random() < 0.3

    def build():
        x = 0.0
        for _ in range(count):
            occ_shape(rng, x, rng.uniform(0, 0.3), rng.uniform(0, 0.3), scale=rng.uniform(0.6, 1.4))
            # Bounding boxes are disjoint: every shape fits in [x, x + 1.4 * scale] along x.
            x += 1.45 if not narrow else 1.41
        # OCC does not merge the bodies: they stay separate volumes and components.

    n = mesh_to_target(target_tets(rng), build)
    gmsh.write(path)
    return f"{count} disjoint bodies{' (narrow gaps)' if narrow else ''}", n


def surface_recipes():
    """(name, file, tetgen switches) for the shared surfaces present."""
    if not os.path.isdir(SHARED_SURFACES):
        return []
    out = []
    for f in sorted(os.listdir(SHARED_SURFACES)):
        stem = os.path.splitext(f)[0].lower().replace("-", "_")
        for k, (q, frac) in enumerate(((None, 1.0), ("1.4", 1.0), ("1.4", 0.25))):
            out.append((f"surface_{stem}_{k}", f, q, frac))
    return out


def r_surface(rng, path, surface, q, frac):
    import meshio  # Debian's python3-meshio
    m = meshio.read(os.path.join(SHARED_SURFACES, surface))
    X = m.points[:, :3].astype(float)
    F = np.concatenate([c.data for c in m.cells if c.type == "triangle"])
    # Merge the repeated corners of STL triangles (rounded to 1e-12 relative, as SOURCES.md did).
    key = np.round(X / max(np.abs(X).max(), 1e-300), 12)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    X, F = X[first], inverse.reshape(-1)[F]
    F = F[(F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 0] != F[:, 2])]
    vol = abs(np.einsum("ij,ij->i", X[F[:, 0]], np.cross(X[F[:, 1]], X[F[:, 2]])).sum()) / 6
    # Volume bound: about 4 tets per boundary triangle overall, times frac.
    a = vol / (4 * len(F)) * frac
    with tempfile.TemporaryDirectory() as tmp:
        write_off(os.path.join(tmp, "s.off"), X, F)
        sw = "-pYz" + (f"q{q}" if q else "") + f"a{a:.6g}"
        run_tetgen([sw, "s.off"], tmp)
        X, T, _ = read_tetgen(os.path.join(tmp, "s.1"))
    if not MIN_TETS <= len(T) <= MAX_TETS * 1.3:
        raise Skip(f"{len(T)} tets")
    n = save_tets(path, X, T)
    return f"shared surface {surface}: tetgen {sw}", n


CATEGORIES = [  # (prefix, count, recipe)
    ("cad", 70, r_cad),
    ("thinplate", 30, r_thinplate),
    ("holes", 45, r_holes),
    ("multimat", 40, r_multimat),
    ("graded", 30, r_graded),
    ("aniso", 25, r_aniso),
    ("perturbed", 30, r_perturbed),
    ("sliver", 35, r_sliver),
    ("multicomp", 25, r_multicomp),
]


def all_recipes():
    out = []
    for prefix, count, fn in CATEGORIES:
        for i in range(count):
            out.append((f"{prefix}_{i:03d}", prefix, fn, ()))
    for name, surface, q, frac in surface_recipes():
        out.append((name, "surface", r_surface, (surface, q, frac)))
    return out


def seed_of(name, attempt):
    # A stable seed from the name (Python's hash() is salted per process).
    return int.from_bytes(name.encode(), "little") % (2**31 - 1) + 7919 * attempt


def check_manifold(path):
    """Refuses a mesh whose boundary has an edge in more than two boundary triangles (OCC
    fragments can leave two volumes touching along an edge): the corpus holds valid inputs."""
    new_model("check")
    gmsh.merge(path)
    _, T, _ = extract_tets()
    faces = np.sort(np.concatenate([T[:, [1, 2, 3]], T[:, [0, 2, 3]], T[:, [0, 1, 3]], T[:, [0, 1, 2]]]), axis=1)
    uniq, counts = np.unique(faces, axis=0, return_counts=True)
    boundary = uniq[counts == 1]
    edges = np.sort(np.concatenate([boundary[:, [0, 1]], boundary[:, [1, 2]], boundary[:, [0, 2]]]), axis=1)
    _, per_edge = np.unique(edges, axis=0, return_counts=True)
    if (per_edge > 2).any():
        raise Skip(f"{int((per_edge > 2).sum())} non-manifold boundary edges")


def make_one_attempt(name, attempt, out_dir):
    """Makes one mesh with the seed of `attempt`, in this process. Returns the manifest entry,
    or raises Skip / gmsh's Exception."""
    recipes = {r[0]: r for r in all_recipes()}
    _, category, fn, extra = recipes[name]
    path = os.path.join(out_dir, name + ".msh")
    rng = random.Random(seed_of(name, attempt))
    gmsh_start()
    try:
        new_model(name)
        what, _ = fn(rng, path, *extra)
        check_manifold(path)
        return dict(name=name, file=name + ".msh", category=category, what=what, attempt=attempt, **gmsh_info(path))
    finally:
        gmsh.finalize()


def make_one(task):
    """Each attempt runs in a child process: gmsh can abort on a C++ exception (seen with some
    size fields), which must cost one attempt, not the whole run. A random layout that defeats
    OCC or gmsh moves on to the next seed."""
    name, category, out_dir, timeout = task
    path = os.path.join(out_dir, name + ".msh")
    last = ""
    for attempt in range(4):
        try:
            r = subprocess.run([sys.executable, os.path.abspath(__file__), out_dir, "--one", name, "--attempt", str(attempt)],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=timeout)
            if r.returncode == 0:
                return json.loads(r.stdout.strip().splitlines()[-1])
            tail = (r.stdout + r.stderr).strip().splitlines()
            last = tail[-1][:200] if tail else f"exit {r.returncode}"
        except subprocess.TimeoutExpired:
            last = f"took more than {timeout} s"
        if os.environ.get("CORPUS_DEBUG"):
            print(name, attempt, last, file=sys.stderr)
        if os.path.exists(path):
            os.remove(path)
        if category == "surface":  # no randomness in these recipes: another seed changes nothing
            break
    return dict(name=name, category=category, skipped=last)


def gmsh_info(path):
    new_model("info")
    gmsh.merge(path)
    tags, _, _ = gmsh.model.mesh.getNodes()
    return dict(tets=count_tets(), nodes=len(tags), bytes=os.path.getsize(path))


def write_sample_readme(out_dir, made):
    lines = ["# Robustness CI sample", "",
             "A fixed subset of the robustness corpus, written by `scripts/make_corpus.py meshes/corpus --ci-sample`",
             f"(gmsh {gmsh.__version__} and tetgen from Debian; deterministic: the same command rewrites the same files).",
             "`tests/cli/test_robustness_sample.cpp` coarsens each to its median edge length with `--check`, and",
             "with `--boundary strict`, whose boundary Hausdorff distance must be 0. The full campaign is",
             "`scripts/robustness.py` (results in `bench/robustness/`).", "",
             "| file | category | vertices | tets | what it is |", "|---|---|---:|---:|---|"]
    for m in made:
        lines.append(f"| `{m['file']}` | {m['category']} | {m['nodes']:,} | {m['tets']:,} | {m['what']} |")
    with open(os.path.join(out_dir, "README.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out", nargs="?", default=os.path.join(HERE, "..", "build", "corpus"))
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--only", help="comma-separated names")
    ap.add_argument("--ci-sample", action="store_true", help="only the meshes committed in meshes/corpus/")
    ap.add_argument("--list", action="store_true", help="print the names and exit")
    ap.add_argument("--timeout", type=int, default=600, help="seconds per attempt at one mesh")
    ap.add_argument("--one", help=argparse.SUPPRESS)  # internal: make this mesh in this process
    ap.add_argument("--attempt", type=int, default=0, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:
        try:
            print(json.dumps(make_one_attempt(args.one, args.attempt, os.path.abspath(args.out))))
            return 0
        except Skip as e:
            print(f"skip: {e}")
        except Exception as e:  # gmsh raises plain Exception on meshing/boolean failures
            print(f"{type(e).__name__}: {str(e)[:200]}")
        return 1
    if shutil.which("tetgen") is None:
        sys.exit("make_corpus.py: tetgen is not installed (apt-get install tetgen)")
    recipes = all_recipes()
    if args.list:
        print("\n".join(r[0] for r in recipes))
        return 0
    wanted = None
    if args.only:
        wanted = set(args.only.split(","))
    elif args.ci_sample:
        wanted = set(CI_SAMPLE)
    if wanted is not None:
        unknown = wanted - {r[0] for r in recipes}
        if unknown:
            sys.exit(f"make_corpus.py: unknown names: {', '.join(sorted(unknown))}")
        recipes = [r for r in recipes if r[0] in wanted]
    out_dir = os.path.abspath(args.out)
    os.makedirs(out_dir, exist_ok=True)
    tasks = [(name, cat, out_dir, args.timeout) for name, cat, _, _ in recipes]
    results = []
    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        for r in pool.map(make_one, tasks):
            results.append(r)
            if "skipped" in r:
                print(f"{r['name']}: skipped ({r['skipped']})", flush=True)
            else:
                print(f"{r['name']}: {r['tets']} tets, {r['nodes']} vertices - {r['what']}", flush=True)
    manifest = os.path.join(out_dir, "MANIFEST.json")
    old = []
    if wanted is not None and os.path.exists(manifest):
        with open(manifest) as f:
            old = [m for m in json.load(f)["meshes"] if m["name"] not in wanted]
    meshes = sorted(old + results, key=lambda m: m["name"])
    made = [m for m in meshes if "skipped" not in m]
    with open(manifest, "w") as f:
        json.dump({"generator": "scripts/make_corpus.py", "gmsh": gmsh.__version__, "meshes": meshes}, f, indent=1)
    if args.ci_sample:
        write_sample_readme(out_dir, made)
    print(f"{len(made)} meshes in {out_dir} ({len(meshes) - len(made)} skipped), "
          f"{sum(m['tets'] for m in made)} tets in total")
    return 0


if __name__ == "__main__":
    sys.exit(main())
