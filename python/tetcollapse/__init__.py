"""tetcollapse: coarsening of unstructured tetrahedral meshes by massively parallel edge collapse.

    import numpy as np, tetcollapse
    out = tetcollapse.collapse(points, tets, target_factor=2)      # NumPy (N, 3) and (M, 4)
    out["points"], out["tets"], out["stats"]["tets_out"]

The option names are those of the command line, with underscores (--target-factor ->
target_factor). Errors: ValueError for bad input, tetcollapse.DeviceError (a RuntimeError) for
the OpenCL device. With meshio installed, from_meshio / to_meshio convert meshio.Mesh objects;
with PyVista, from_pyvista / to_pyvista convert pyvista.UnstructuredGrid objects:

    points, tets, labels, fields = tetcollapse.from_pyvista(grid)
    out = tetcollapse.collapse(points, tets, labels=labels, vertex_fields=fields, target_factor=2)
    tetcollapse.to_pyvista(out).plot()
"""
from ._core import DeviceError, __version__, check, collapse, devices, improve, read, write  # noqa: F401

# A first run on a device compiles the kernels in helper processes, one per core (PoCL compiles one
# program at a time in a process): this interpreter again, running the module's helper loop, with
# the device's index as its last argument.
import os as _os
import sys as _sys

from . import _core

_COMPILE_HELPER = [_sys.executable, "-c",
                   "import sys; sys.path.insert(0, %r); from tetcollapse import _core; "
                   "sys.exit(_core._compile_helper(int(sys.argv[1])))" % _os.path.dirname(_os.path.dirname(__file__))]
_core._set_compile_helper(_COMPILE_HELPER)

__all__ = ["collapse", "improve", "check", "read", "write", "devices", "from_meshio", "to_meshio", "from_pyvista",
           "to_pyvista", "DeviceError"]


def from_meshio(mesh):
    """(points, tets, labels, vertex_fields) of a meshio.Mesh: its tetra cells, their first
    integer cell data as labels, its point data as vertex fields."""
    import numpy as np
    blocks = [i for i, c in enumerate(mesh.cells) if c.type == "tetra"]
    if not blocks:
        raise ValueError("the meshio mesh has no tetra cells")
    tets = np.concatenate([mesh.cells[i].data for i in blocks]).astype(np.int32)
    labels = None
    for values in mesh.cell_data.values():
        parts = [np.asarray(values[i]) for i in blocks]
        if all(np.issubdtype(p.dtype, np.integer) and p.ndim == 1 for p in parts):
            labels = np.concatenate(parts).astype(np.int32)
            break
    fields = {k: np.asarray(v, dtype=float) for k, v in mesh.point_data.items()}
    return np.asarray(mesh.points, dtype=float), tets, labels, fields


def to_meshio(result):
    """A meshio.Mesh of a result of collapse() or improve()."""
    import meshio
    cell_data = {"label": [result["labels"]]} if "labels" in result else {}
    return meshio.Mesh(result["points"], [("tetra", result["tets"])], point_data=dict(result["vertex_fields"]),
                       cell_data=cell_data)


def from_pyvista(grid):
    """(points, tets, labels, vertex_fields) of a pyvista.UnstructuredGrid (or any PyVista
    dataset cast to one): its tetra cells, their first integer cell data as labels, its point
    data as vertex fields. Other cells are left out."""
    import numpy as np
    import pyvista
    if not isinstance(grid, pyvista.UnstructuredGrid):
        grid = grid.cast_to_unstructured_grid()
    is_tet = np.asarray(grid.celltypes) == pyvista.CellType.TETRA
    if not is_tet.any():
        raise ValueError("the PyVista grid has no tetra cells")
    tets = np.asarray(grid.cells_dict[pyvista.CellType.TETRA], dtype=np.int32)
    labels = None
    for name in grid.cell_data.keys():
        values = np.asarray(grid.cell_data[name])
        if values.ndim == 1 and np.issubdtype(values.dtype, np.integer):
            labels = values[is_tet].astype(np.int32)
            break
    fields = {name: np.asarray(grid.point_data[name], dtype=float) for name in grid.point_data.keys()}
    return np.asarray(grid.points, dtype=float), tets, labels, fields


def to_pyvista(result):
    """A pyvista.UnstructuredGrid of a result of collapse() or improve(): point data the vertex
    fields, cell data "label" the labels."""
    import numpy as np
    import pyvista
    grid = pyvista.UnstructuredGrid({pyvista.CellType.TETRA: np.asarray(result["tets"])}, np.asarray(result["points"]))
    for name, values in result["vertex_fields"].items():
        grid.point_data[name] = values
    if "labels" in result:
        grid.cell_data["label"] = result["labels"]
    return grid
