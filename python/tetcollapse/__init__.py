"""tetcollapse: coarsening of unstructured tetrahedral meshes by massively parallel edge collapse.

    import numpy as np, tetcollapse
    out = tetcollapse.collapse(points, tets, target_factor=2)      # NumPy (N, 3) and (M, 4)
    out["points"], out["tets"], out["stats"]["tets_out"]

The option names are those of the command line, with underscores (--target-factor ->
target_factor). Errors: ValueError for bad input, tetcollapse.DeviceError (a RuntimeError) for
the OpenCL device. With meshio installed, from_meshio / to_meshio convert meshio.Mesh objects.
"""
from ._core import DeviceError, __version__, check, collapse, devices, improve, read, write  # noqa: F401

__all__ = ["collapse", "improve", "check", "read", "write", "devices", "from_meshio", "to_meshio", "DeviceError"]


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
