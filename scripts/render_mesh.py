#!/usr/bin/python3
"""Render tetrahedral meshes off screen to a PNG, side by side with one camera.

Each mesh is drawn as its boundary surface with the edges visible, coloured by its material
label when it has one (the same label gets the same colour in every panel). Reads what meshio
reads (.msh, .vtu, .vtk, .mesh, TetGen .node/.ele, ...); without meshio, .vtu and .vtk through
VTK's own readers. Needs VTK's Python module (Debian: python3-vtk9) and, without a display,
xvfb-run (Debian: xvfb), under which the script restarts itself when DISPLAY is unset.

docs/images/bracket.png was made with
    build/tetcollapse meshes/bracket.msh /tmp/bracket_coarse.vtu --target-factor 2
    scripts/render_mesh.py meshes/bracket.msh /tmp/bracket_coarse.vtu -o docs/images/bracket.png \\
        --size 1200x460 --zoom 1.12 --colours 128 \\
        --title "input: {tets} tets" --title "tetcollapse --target-factor 2: {tets} tets"

--cut AXIS<VALUE (or >) keeps only the tets whose centroid lies on that side of a plane, whole
tets, so the interior elements show in the cut face. --quality colours each tet by its smallest
dihedral angle instead of its label; docs/images/bracket_quality.png was made with
    build/tetcollapse meshes/bracket.msh /tmp/a.vtu --target-factor 2 --no-improve
    build/tetcollapse meshes/bracket.msh /tmp/b.vtu --target-factor 2
    scripts/render_mesh.py /tmp/a.vtu /tmp/b.vtu -o docs/images/bracket_quality.png --quality \\
        --cut "y<1.0" --size 1200x460 --zoom 1.12 --colours 128 \\
        --title "collapse alone (--no-improve): {tets} tets" \\
        --title "with the improvement phase (default): {tets} tets"
"""
import argparse
import os
import shutil
import sys

# Label arrays in the order of preference (the names tetcollapse's readers give them).
LABEL_NAMES = ["gmsh:physical", "medit:ref", "tetgen:region", "gmsh:geometrical"]

# A qualitative palette (Tableau 10, lightened a little so the edges stay visible).
PALETTE = [(0x6b, 0x9b, 0xc8), (0xf2, 0xa3, 0x5e), (0x7c, 0xb8, 0x6f), (0xe0, 0x6f, 0x70),
           (0xa7, 0x8b, 0xc4), (0xa8, 0x83, 0x78), (0xe8, 0x9f, 0xc9), (0xa0, 0xa0, 0xa0),
           (0xc8, 0xc8, 0x5a), (0x6c, 0xc4, 0xcf)]


def restart_under_xvfb():
    if os.environ.get("DISPLAY") or os.environ.get("RENDER_MESH_NO_XVFB"):
        return
    xvfb = shutil.which("xvfb-run")
    if xvfb is None:
        return  # an off-screen build of VTK (EGL, OSMesa) needs no display
    os.environ["RENDER_MESH_NO_XVFB"] = "1"
    os.execv(xvfb, [xvfb, "-a", "-s", "-screen 0 1920x1080x24", sys.executable] + sys.argv)


def read_tets(path, label_name):
    """Returns (points N x 3, tets M x 4, labels M or None, label name) for one mesh file."""
    import numpy as np
    try:
        import meshio
    except ImportError:
        meshio = None
    if meshio is not None:
        m = meshio.read(path)
        blocks = [i for i, c in enumerate(m.cells) if c.type == "tetra"]
        if not blocks:
            sys.exit(f"render_mesh: {path}: no tetrahedra")
        tets = np.concatenate([m.cells[i].data for i in blocks]).astype(np.int64)
        arrays = {name: np.concatenate([np.asarray(data[i]).reshape(len(m.cells[i].data), -1)[:, 0]
                                        for i in blocks])
                  for name, data in m.cell_data.items()}
        return np.asarray(m.points, dtype=float)[:, :3], tets, *pick_labels(arrays, label_name)
    import vtk
    from vtk.util import numpy_support as ns
    ext = os.path.splitext(path)[1].lower()
    if ext not in (".vtu", ".vtk"):
        sys.exit(f"render_mesh: {path}: without meshio only .vtu and .vtk are read")
    reader = vtk.vtkXMLUnstructuredGridReader() if ext == ".vtu" else vtk.vtkUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    grid = reader.GetOutput()
    types = ns.vtk_to_numpy(grid.GetCellTypesArray())
    conn = ns.vtk_to_numpy(grid.GetCells().GetConnectivityArray()).astype(np.int64)
    offsets = ns.vtk_to_numpy(grid.GetCells().GetOffsetsArray()).astype(np.int64)
    keep = np.flatnonzero(types == vtk.VTK_TETRA)
    tets = np.stack([conn[offsets[keep] + k] for k in range(4)], axis=1)
    cd = grid.GetCellData()
    arrays = {cd.GetArrayName(i): ns.vtk_to_numpy(cd.GetArray(i)).reshape(grid.GetNumberOfCells(), -1)[keep, 0]
              for i in range(cd.GetNumberOfArrays())}
    return ns.vtk_to_numpy(grid.GetPoints().GetData()).astype(float), tets, *pick_labels(arrays, label_name)


def pick_labels(arrays, label_name):
    import numpy as np
    if label_name == "none":
        return None, None
    names = [label_name] if label_name else LABEL_NAMES + sorted(arrays)
    for name in names:
        a = arrays.get(name)
        if a is not None and np.issubdtype(a.dtype, np.number) and np.all(np.mod(a, 1) == 0):
            return a.astype(np.int64), name
    if label_name:
        sys.exit(f"render_mesh: no integer cell array '{label_name}'")
    return None, None


def min_dihedral_deg(points, tets):
    """The smallest dihedral angle of each tet, in degrees (the angle between the two faces at an
    edge is pi minus the angle between their outward normals)."""
    import numpy as np
    p = points[tets]  # (M, 4, 3)
    normals = []
    for i in range(4):
        a, b, c = (p[:, j] for j in range(4) if j != i)
        n = np.cross(b - a, c - a)
        n *= np.where(np.einsum("ij,ij->i", n, p[:, i] - a) > 0, -1.0, 1.0)[:, None]  # outward
        normals.append(n / np.maximum(np.linalg.norm(n, axis=1), 1e-300)[:, None])
    cos = np.max([-np.einsum("ij,ij->i", normals[k], normals[l]) for k in range(4) for l in range(k + 1, 4)], axis=0)
    return np.degrees(np.arccos(np.clip(cos, -1, 1)))


def quality_rgb(angle):
    """Red below 10 degrees, through orange and yellow, to blue at 40 and above."""
    import numpy as np
    stops = np.array([0, 10, 20, 30, 40], float)
    colours = np.array([[200, 30, 30], [235, 90, 50], [245, 200, 80], [170, 205, 170], [95, 150, 205]], float)
    return np.stack([np.interp(angle, stops, colours[:, c]) for c in range(3)], axis=1).astype(np.uint8)


def surface_actor(points, tets, labels, cut, colour_of, edge_rgb, line_width, quality=False):
    import numpy as np
    import vtk
    from vtk.util import numpy_support as ns
    if cut is not None:
        axis, side, value = cut
        centroid = points[tets].mean(axis=1)[:, axis]
        keep = centroid < value if side == "<" else centroid > value
        tets = tets[keep]
        labels = labels[keep] if labels is not None else None
    grid = vtk.vtkUnstructuredGrid()
    pts = vtk.vtkPoints()
    pts.SetData(ns.numpy_to_vtk(np.ascontiguousarray(points), deep=True))
    grid.SetPoints(pts)
    cells = vtk.vtkCellArray()
    cells.SetData(ns.numpy_to_vtkIdTypeArray(np.arange(0, 4 * len(tets) + 1, 4, dtype=np.int64), deep=True),
                  ns.numpy_to_vtkIdTypeArray(np.ascontiguousarray(tets.reshape(-1)), deep=True))
    grid.SetCells(vtk.VTK_TETRA, cells)
    if quality:
        rgb = quality_rgb(min_dihedral_deg(points, tets))
    else:
        rgb = np.array([colour_of(v) for v in (labels if labels is not None else np.zeros(len(tets), int))],
                       dtype=np.uint8).reshape(-1, 3)
    colours = ns.numpy_to_vtk(rgb, deep=True, array_type=vtk.VTK_UNSIGNED_CHAR)
    colours.SetName("colour")
    grid.GetCellData().SetScalars(colours)
    surface = vtk.vtkDataSetSurfaceFilter()
    surface.SetInputData(grid)
    mapper = vtk.vtkPolyDataMapper()
    mapper.SetInputConnection(surface.GetOutputPort())
    mapper.SetScalarModeToUseCellData()
    mapper.SetColorModeToDirectScalars()
    actor = vtk.vtkActor()
    actor.SetMapper(mapper)
    prop = actor.GetProperty()
    prop.EdgeVisibilityOn()
    prop.SetEdgeColor(*edge_rgb)
    prop.SetLineWidth(line_width)
    prop.SetAmbient(0.35)
    prop.SetDiffuse(0.7)
    return actor


def write_palette_png(path, image_source, colours):
    """Writes the image as an indexed PNG of at most `colours` colours (a far smaller file)."""
    import struct
    import zlib
    import numpy as np
    import vtk
    from vtk.util import numpy_support as ns
    quant = vtk.vtkImageQuantizeRGBToIndex()
    quant.SetNumberOfColors(max(2, min(256, colours)))
    quant.SetInputConnection(image_source.GetOutputPort())
    quant.Update()
    out = quant.GetOutput()
    w, h, _ = out.GetDimensions()
    index = ns.vtk_to_numpy(out.GetPointData().GetScalars()).reshape(h, w)[::-1].astype(np.uint8)
    lut = quant.GetLookupTable()
    palette = bytes(int(round(255 * c)) for i in range(lut.GetNumberOfTableValues())
                    for c in lut.GetTableValue(i)[:3])

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    rows = b"".join(b"\0" + row.tobytes() for row in index)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 3, 0, 0, 0))
                + chunk(b"PLTE", palette) + chunk(b"IDAT", zlib.compress(rows, 9)) + chunk(b"IEND", b""))


def parse_cut(text):
    if text is None:
        return None
    for side in "<>":
        if side in text:
            axis, value = text.split(side, 1)
            if axis.strip().lower() in ("x", "y", "z"):
                return "xyz".index(axis.strip().lower()), side, float(value)
    sys.exit(f"render_mesh: --cut wants AXIS<VALUE or AXIS>VALUE, e.g. y<1.0, not '{text}'")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("meshes", nargs="+", help="mesh files, one panel each, left to right")
    ap.add_argument("-o", "--output", required=True, help="PNG to write")
    ap.add_argument("--title", action="append", default=[],
                    help="panel title, once per mesh; {tets} and {vertices} are replaced by the counts "
                         "(default: the file name and its tet count)")
    ap.add_argument("--size", default="1400x620", help="image size WxH in pixels (default 1400x620)")
    ap.add_argument("--azimuth", type=float, default=-35, help="camera azimuth in degrees (default -35)")
    ap.add_argument("--elevation", type=float, default=30, help="camera elevation in degrees (default 30)")
    ap.add_argument("--zoom", type=float, default=1.0, help="camera zoom (default 1)")
    ap.add_argument("--labels", default="",
                    help="cell array to colour by ('none': one colour; default: the first of "
                         + ", ".join(LABEL_NAMES) + ", else any integer cell array)")
    ap.add_argument("--cut", help="keep the tets with centroid on one side of a plane, e.g. 'y<1.0'")
    ap.add_argument("--quality", action="store_true",
                    help="colour each tet by its smallest dihedral angle: red below 10 degrees, orange, "
                         "yellow, blue at 40 and above (with --cut, the inside shows)")
    ap.add_argument("--colours", type=int, default=0,
                    help="write an indexed PNG of at most N colours (2-256), a much smaller file")
    ap.add_argument("--line-width", type=float, default=1.0, help="edge width in pixels (default 1)")
    args = ap.parse_args()
    if args.title and len(args.title) != len(args.meshes):
        sys.exit("render_mesh: give --title once per mesh, or not at all")
    width, height = (int(v) for v in args.size.lower().split("x"))
    cut = parse_cut(args.cut)

    restart_under_xvfb()
    import numpy as np
    import vtk

    meshes = [read_tets(path, args.labels) for path in args.meshes]
    values = sorted({int(v) for _, _, lab, _ in meshes if lab is not None for v in np.unique(lab)})
    index = {v: i for i, v in enumerate(values)}

    def colour_of(v):
        return PALETTE[index.get(int(v), 0) % len(PALETTE)]

    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(width, height)
    window.SetMultiSamples(8)
    camera = vtk.vtkCamera()
    bounds = np.array([np.inf, -np.inf] * 3)
    n = len(meshes)
    for i, ((points, tets, labels, _), path) in enumerate(zip(meshes, args.meshes)):
        used = np.unique(tets)
        lo, hi = points[used].min(axis=0), points[used].max(axis=0)
        bounds[0::2] = np.minimum(bounds[0::2], lo)
        bounds[1::2] = np.maximum(bounds[1::2], hi)
        renderer = vtk.vtkRenderer()
        renderer.SetViewport(i / n, 0, (i + 1) / n, 1)
        renderer.SetBackground(1, 1, 1)
        renderer.SetActiveCamera(camera)
        renderer.AddActor(surface_actor(points, tets, labels, cut, colour_of, (0.12, 0.14, 0.18),
                                        args.line_width, args.quality))
        title = args.title[i] if args.title else os.path.basename(path) + ": {tets} tets"
        text = vtk.vtkTextActor()
        text.SetInput(title.format(tets=f"{len(tets):,}", vertices=f"{len(used):,}"))
        tp = text.GetTextProperty()
        tp.SetFontSize(max(14, height // 24))
        tp.SetColor(0.1, 0.1, 0.1)
        tp.SetJustificationToCentered()
        tp.SetVerticalJustificationToTop()
        text.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
        text.GetPositionCoordinate().SetValue(0.5, 0.96)
        renderer.AddActor2D(text)
        window.AddRenderer(renderer)

    centre = (bounds[0::2] + bounds[1::2]) / 2
    camera.SetFocalPoint(*centre)
    camera.SetPosition(*(centre + np.array([0, -1, 0])))
    camera.SetViewUp(0, 0, 1)
    camera.Azimuth(args.azimuth)
    camera.Elevation(args.elevation)
    camera.OrthogonalizeViewUp()
    first = window.GetRenderers().GetFirstRenderer()
    first.ResetCamera(*bounds)
    camera.Zoom(args.zoom)
    window.Render()

    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.SetInputBufferTypeToRGB()
    grab.ReadFrontBufferOff()
    grab.Update()
    if args.colours:
        write_palette_png(args.output, grab, args.colours)
    else:
        writer = vtk.vtkPNGWriter()
        writer.SetFileName(args.output)
        writer.SetInputConnection(grab.GetOutputPort())
        writer.SetCompressionLevel(9)
        writer.Write()
    print(f"{args.output}: " + ", ".join(f"{os.path.basename(p)} {len(t):,} tets"
                                         for p, (_, t, _, _) in zip(args.meshes, meshes)))


if __name__ == "__main__":
    main()
