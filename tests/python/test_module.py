"""The Python module: NumPy in and out, the options of the command line, the errors as Python
exceptions, meshio when installed. Run by CTest with PYTHONPATH at build/python."""
import os
import sys
import tempfile
import unittest

import numpy as np

import tetcollapse


def cube(n):
    """[0,1]^3 in n^3 cells of 6 Kuhn tets (tetcollapse's make_cube_mesh), as arrays."""
    g = np.linspace(0, 1, n + 1)
    z, y, x = np.meshgrid(g, g, g, indexing="ij")
    points = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)
    idx = lambda i, j, k: (k * (n + 1) + j) * (n + 1) + i  # noqa: E731
    tets = []
    for k in range(n):
        for j in range(n):
            for i in range(n):
                for p in ((0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)):
                    c = [i, j, k]
                    v = [idx(i, j, k)]
                    for s in p:
                        c[s] += 1
                        v.append(idx(*c))
                    if p in ((0, 2, 1), (1, 0, 2), (2, 1, 0)):
                        v[2], v[3] = v[3], v[2]
                    tets.append(v)
    return points, np.array(tets, dtype=np.int32)


class Module(unittest.TestCase):
    def test_compile_helper_command_runs_the_helper_loop(self):
        # the command a first run starts per core (tetcollapse/__init__.py): another interpreter
        # that finds the module and serves compile requests until its input ends (here at once)
        import subprocess
        p = subprocess.run(tetcollapse._COMPILE_HELPER + ["0"], stdin=subprocess.DEVNULL, capture_output=True,
                           text=True, cwd=tempfile.gettempdir(), env=dict(os.environ, PYTHONPATH=""))
        self.assertEqual(p.returncode, 0, p.stderr)

    def test_collapse_numpy_in_and_out(self):
        points, tets = cube(6)
        field = points[:, 0] + 2 * points[:, 1]
        labels = np.where(points[tets].mean(axis=1)[:, 2] < 0.5, 1, 2)
        for method in ("parallel", "sequential"):
            out = tetcollapse.collapse(points, tets, target_factor=2, labels=labels, vertex_fields={"f": field},
                                       method=method)
            self.assertLess(out["tets"].shape[0], tets.shape[0])
            self.assertEqual(out["points"].shape[1], 3)
            self.assertEqual(out["tets"].dtype, np.int32)
            self.assertEqual(out["labels"].shape[0], out["tets"].shape[0])
            self.assertEqual(set(np.unique(out["labels"])), {1, 2}, "the materials are kept")
            f = out["vertex_fields"]["f"]
            np.testing.assert_allclose(f, out["points"][:, 0] + 2 * out["points"][:, 1], atol=1e-12,
                                       err_msg="a linear field stays exact")
            self.assertEqual(out["stats"]["tets_out"], out["tets"].shape[0])
            self.assertTrue(tetcollapse.check(out["points"], out["tets"])["valid"])

    def test_the_command_lines_boundary_error_bound_by_default(self):
        # features mode: 0.001 of the diagonal unless given; none in the other modes or with 0
        points, tets = cube(4)
        diagonal = np.sqrt(3.0)
        bound = lambda **kw: tetcollapse.collapse(points, tets, target_factor=2, **kw)["stats"]["boundary_error_bound"]  # noqa: E731
        self.assertAlmostEqual(bound(), 0.001 * diagonal, places=12)
        self.assertAlmostEqual(bound(max_boundary_error=0.01), 0.01 * diagonal, places=12)
        self.assertEqual(bound(max_boundary_error=0.0), 0.0)
        self.assertEqual(bound(boundary="strict"), 0.0)
        with self.assertRaises(ValueError):
            bound(boundary="strict", max_boundary_error=0.01)

    def test_cycles_as_the_command_line(self):
        # two cycles of collapse and improvement by default; one gives more tets; 0 is refused
        points, tets = cube(10)
        inner = ((points > 1e-9) & (points < 1 - 1e-9)).all(axis=1)
        points[inner] += np.random.default_rng(1).uniform(-0.02, 0.02, (int(inner.sum()), 3))  # not a lattice
        one = tetcollapse.collapse(points, tets, target_factor=2, cycles=1)
        two = tetcollapse.collapse(points, tets, target_factor=2)
        self.assertEqual(one["stats"]["cycles"], 1)
        self.assertEqual(two["stats"]["cycles"], 2)
        self.assertLess(two["tets"].shape[0], one["tets"].shape[0])
        self.assertTrue(tetcollapse.check(two["points"], two["tets"])["valid"])
        with self.assertRaises(ValueError):
            tetcollapse.collapse(points, tets, cycles=0)

    def test_field_options_of_the_command_line(self):
        points, tets = cube(8)
        rng = np.random.default_rng(5)
        inner = (points > 0) & (points < 1)
        points = points + np.where(inner, rng.uniform(-0.03, 0.03, points.shape), 0)
        bump = np.exp(-10 * ((points[:, 0] - 0.4) ** 2 + (points[:, 1] - 0.6) ** 2)) + points[:, 2]
        out = tetcollapse.collapse(points, tets, vertex_fields={"rho": bump}, preserve_field="rho",
                                   max_field_error=0.02)
        st = out["stats"]
        self.assertLess(out["points"].shape[0], points.shape[0])
        self.assertEqual(st["field_error_bound"], 0.02)
        self.assertLessEqual(st["field_error"], 0.02)
        self.assertGreater(st["field_error"], 0.0)
        self.assertNotIn("quality_before_improve", st, "no improvement phase under the field bound")
        tol = tetcollapse.collapse(points, tets, vertex_fields={"rho": bump}, preserve_field="rho",
                                   field_tolerance=0.05)
        self.assertLess(tol["points"].shape[0], points.shape[0])
        paper = tetcollapse.collapse(points, tets, vertex_fields={"rho": bump}, preserve_field="rho",
                                     field_tolerance=0.05, field_check=0)
        self.assertLessEqual(tol["points"].shape[0] - paper["points"].shape[0], points.shape[0] // 4,
                             "the check refuses some collapses, not most")
        self.assertGreaterEqual(tol["points"].shape[0], paper["points"].shape[0])
        with self.assertRaises(ValueError):
            tetcollapse.collapse(points, tets, vertex_fields={"rho": bump}, preserve_field="nope")

    def test_improve_and_check(self):
        points, tets = cube(5)
        rng = np.random.default_rng(3)
        inner = (points > 0) & (points < 1)
        points = points + np.where(inner, rng.uniform(-0.04, 0.04, points.shape), 0)
        out = tetcollapse.improve(points, tets)
        q = out["stats"]["quality"]
        self.assertGreaterEqual(q["min_dihedral_deg"], out["stats"]["quality_before"]["min_dihedral_deg"])
        bad = tets.copy()
        bad[0, [2, 3]] = bad[0, [3, 2]]  # one inverted tet
        report = tetcollapse.check(points, bad)
        self.assertFalse(report["valid"])
        self.assertIn("inverted_tet", str(report))

    def test_errors_are_python_exceptions(self):
        points, tets = cube(2)
        with self.assertRaises(ValueError):
            tetcollapse.collapse(points, tets[:, :3])
        with self.assertRaises(ValueError):
            tetcollapse.collapse(points, tets, boundary="sideways")
        with self.assertRaises(ValueError):
            tetcollapse.collapse(points, tets + 1000)
        with self.assertRaises(tetcollapse.DeviceError):
            tetcollapse.collapse(points, tets, device="no such device anywhere")
        self.assertTrue(issubclass(tetcollapse.DeviceError, RuntimeError))

    def test_read_write_and_meshio(self):
        bracket = os.path.join(os.environ.get("TC_PROJECT_MESHES", ""), "bracket.msh")
        m = tetcollapse.read(bracket)
        self.assertEqual(m["tets"].shape, (23925, 4))
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "b.vtu")
            tetcollapse.write(path, m["points"], m["tets"], vertex_fields={"x": m["points"][:, 0]})
            again = tetcollapse.read(path)
            np.testing.assert_array_equal(again["tets"], m["tets"])
            np.testing.assert_array_equal(again["vertex_fields"]["x"], m["points"][:, 0])
        self.assertTrue(any(d["fp64"] for d in tetcollapse.devices()))
        try:
            import meshio
        except ImportError:
            self.skipTest("meshio is not installed")
        mesh = meshio.Mesh(m["points"], [("tetra", m["tets"])], cell_data={"ref": [np.ones(len(m["tets"]), np.int32)]})
        points, tets, labels, fields = tetcollapse.from_meshio(mesh)
        out = tetcollapse.collapse(points, tets, labels=labels, target_factor=2)
        back = tetcollapse.to_meshio(out)
        self.assertEqual(len(back.cells[0].data), out["tets"].shape[0])

    def test_pyvista(self):
        try:
            import pyvista
        except ImportError:
            self.skipTest("PyVista is not installed (scripts/setup.sh --with-tools installs it)")
        points, tets = cube(5)
        labels = np.where(points[tets].mean(axis=1)[:, 0] < 0.5, 3, 7).astype(np.int32)
        grid = pyvista.UnstructuredGrid({pyvista.CellType.TETRA: tets}, points)
        grid.cell_data["mat"] = labels
        grid.point_data["f"] = points[:, 2]
        p, t, lab, fields = tetcollapse.from_pyvista(grid)
        np.testing.assert_array_equal(t, tets)
        np.testing.assert_array_equal(lab, labels)
        out = tetcollapse.collapse(p, t, labels=lab, vertex_fields=fields, target_factor=2)
        back = tetcollapse.to_pyvista(out)
        self.assertEqual(back.n_cells, out["tets"].shape[0])
        self.assertLess(back.n_cells, tets.shape[0])
        self.assertEqual(set(np.unique(back.cell_data["label"])), {3, 7})
        np.testing.assert_allclose(back.point_data["f"], back.points[:, 2], atol=1e-12)
        self.assertGreater(back.volume, 0.999)  # the unit cube, whole
        with self.assertRaises(ValueError):
            tetcollapse.from_pyvista(pyvista.UnstructuredGrid({pyvista.CellType.TRIANGLE: tets[:, :3]}, points))


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"])
