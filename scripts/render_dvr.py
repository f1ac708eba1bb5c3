#!/usr/bin/python3
"""Direct volume rendering of a tet mesh's vertex field, input against output.

    scripts/render_dvr.py IN.vtu OUT.vtu --field NAME [--png PAIR.png] [--size 400]

Renders both meshes with VTK's unstructured-grid volume ray casting (Debian python3-vtk9),
off screen, with one camera (fitted to IN) and one transfer function (IN's field range: a
colour ramp and an opacity ramp), writes IN | OUT | 4 x |difference| side by side to --png,
and prints the PSNR (dB) and the SSIM of OUT's image against IN's (SSIM on the luminance, 7 x 7
windows, the usual constants). Without a display it runs itself again under xvfb-run (Debian
xvfb). Used by bench/volume_rendering.py; the tests run it on a small mesh.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys


def _grid(vtk, path, field):
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    g = r.GetOutput()
    if g.GetPointData().GetArray(field) is None:
        sys.exit(f"render_dvr.py: {path} has no vertex field '{field}'")
    g.GetPointData().SetActiveScalars(field)
    return g


def _render(vtk, grid, field, rng, bounds, size):
    import numpy as np
    from vtk.util.numpy_support import vtk_to_numpy
    tri = vtk.vtkDataSetTriangleFilter()  # the ray caster takes tets only
    tri.SetInputData(grid)
    mapper = vtk.vtkUnstructuredGridVolumeRayCastMapper()
    mapper.SetInputConnection(tri.GetOutputPort())
    color = vtk.vtkColorTransferFunction()
    color.AddRGBPoint(rng[0], 0.1, 0.2, 0.8)
    color.AddRGBPoint(0.5 * (rng[0] + rng[1]), 0.9, 0.9, 0.3)
    color.AddRGBPoint(rng[1], 0.9, 0.1, 0.1)
    opacity = vtk.vtkPiecewiseFunction()
    opacity.AddPoint(rng[0], 0.0)
    opacity.AddPoint(rng[1], 0.8)
    prop = vtk.vtkVolumeProperty()
    prop.SetColor(color)
    prop.SetScalarOpacity(opacity)
    prop.SetScalarOpacityUnitDistance(0.05 * max(bounds[1] - bounds[0], bounds[3] - bounds[2], bounds[5] - bounds[4]))
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    ren = vtk.vtkRenderer()
    ren.AddVolume(volume)
    ren.SetBackground(1, 1, 1)
    cam = ren.GetActiveCamera()
    c = [(bounds[2 * i] + bounds[2 * i + 1]) / 2 for i in range(3)]
    cam.SetFocalPoint(*c)
    cam.SetPosition(c[0] + 1.0, c[1] - 1.5, c[2] + 1.2)
    cam.SetViewUp(0, 0, 1)
    ren.ResetCamera(bounds)
    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(size, size)
    win.AddRenderer(ren)
    win.Render()
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.SetInputBufferTypeToRGB()
    grab.Update()
    img = grab.GetOutput()
    w, h, _ = img.GetDimensions()
    return vtk_to_numpy(img.GetPointData().GetScalars()).reshape(h, w, 3).astype(np.float64)


def _ssim(a, b):
    import numpy as np
    la = a @ np.array([0.299, 0.587, 0.114])
    lb = b @ np.array([0.299, 0.587, 0.114])

    def box(x, k=7):  # mean over k x k windows (valid part), by summed-area tables
        s = np.pad(np.cumsum(np.cumsum(x, 0), 1), ((1, 0), (1, 0)))
        return (s[k:, k:] - s[:-k, k:] - s[k:, :-k] + s[:-k, :-k]) / (k * k)
    c1, c2 = (0.01 * 255) ** 2, (0.03 * 255) ** 2
    ma, mb = box(la), box(lb)
    va, vb, cov = box(la * la) - ma * ma, box(lb * lb) - mb * mb, box(la * lb) - ma * mb
    return float(np.mean((2 * ma * mb + c1) * (2 * cov + c2) / ((ma * ma + mb * mb + c1) * (va + vb + c2))))


def compare(inp, out, field, png=None, size=400):
    """Renders both; returns {"psnr": dB, "ssim": ...} and writes the side-by-side PNG."""
    if not os.environ.get("DISPLAY"):
        args = [sys.executable, os.path.abspath(__file__), inp, out, "--field", field, "--size", str(size), "--json"]
        if png:
            args += ["--png", png]
        xvfb = shutil.which("xvfb-run")
        if not xvfb:
            sys.exit("render_dvr.py: no display and no xvfb-run (Debian xvfb)")
        p = subprocess.run([xvfb, "-a"] + args, capture_output=True, text=True)
        if p.returncode != 0:
            sys.exit(f"render_dvr.py failed: {p.stderr.strip()[-400:]}")
        return json.loads(p.stdout.strip().splitlines()[-1])
    import numpy as np
    import vtk
    a, b = _grid(vtk, inp, field), _grid(vtk, out, field)
    rng = a.GetPointData().GetArray(field).GetRange()
    bounds = a.GetBounds()
    ia, ib = _render(vtk, a, field, rng, bounds, size), _render(vtk, b, field, rng, bounds, size)
    mse = float(np.mean((ia - ib) ** 2))
    psnr = float("inf") if mse == 0 else 10 * np.log10(255.0 ** 2 / mse)
    result = {"psnr": psnr, "ssim": _ssim(ia, ib)}
    if png:
        diff = np.clip(255 - 4 * np.abs(ia - ib), 0, 255)
        pair = np.concatenate([ia, ib, diff], axis=1).astype(np.uint8)
        h, w, _ = pair.shape
        from vtk.util.numpy_support import numpy_to_vtk
        img = vtk.vtkImageData()
        img.SetDimensions(w, h, 1)
        img.GetPointData().SetScalars(numpy_to_vtk(pair.reshape(-1, 3), deep=True))
        wr = vtk.vtkPNGWriter()
        wr.SetFileName(png)
        wr.SetInputData(img)
        wr.Write()
    return result


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("input")
    ap.add_argument("output")
    ap.add_argument("--field", required=True)
    ap.add_argument("--png")
    ap.add_argument("--size", type=int, default=400)
    ap.add_argument("--json", action="store_true", help="print the result as one JSON line")
    a = ap.parse_args()
    r = compare(a.input, a.output, a.field, a.png, a.size)
    print(json.dumps(r) if a.json else f"PSNR {r['psnr']:.2f} dB, SSIM {r['ssim']:.4f}")


if __name__ == "__main__":
    main()
