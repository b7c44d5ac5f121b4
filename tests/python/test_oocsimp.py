"""The Python module against properties known without it: exact counts, a plane that
stays flat, constant attributes that stay constant, distances of shifted planes, the
CLI's bytes, Python's exceptions and Ctrl-C.

Run by ctest with PYTHONPATH=build/python and OOCSIMP_CLI=the oocsimp program.
"""
import os
import subprocess
import sys
import tempfile
import textwrap
import unittest

import numpy as np

import oocsimp

CLI = os.environ.get("OOCSIMP_CLI", "oocsimp")


def grid(n, height=None):
    """An n x n grid of vertices on [0, 1]^2 (z = height(x, y) or 0), two triangles a square."""
    x, y = np.meshgrid(np.linspace(0.0, 1.0, n), np.linspace(0.0, 1.0, n))
    z = height(x, y) if height else np.zeros_like(x)
    vertices = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)
    i = np.arange(n * n).reshape(n, n)
    a, b, c, d = i[:-1, :-1].ravel(), i[1:, :-1].ravel(), i[:-1, 1:].ravel(), i[1:, 1:].ravel()
    faces = np.concatenate([np.stack([a, b, d], 1), np.stack([a, d, c], 1)]).astype(np.int32)
    return vertices, faces


def wavy(x, y):
    return 0.1 * np.sin(6 * x) * np.cos(6 * y)


class Simplify(unittest.TestCase):
    def test_exact_target_and_types(self):
        v, f = grid(120, wavy)
        for vt, ft in [(np.float64, np.int32), (np.float32, np.int64), (np.float64, np.uint32)]:
            with self.subTest(vertices=vt.__name__, faces=ft.__name__):
                v2, f2 = oocsimp.simplify(v.astype(vt), f.astype(ft), target_tris=1000)
                self.assertEqual(f2.shape, (1000, 3))
                self.assertEqual(v2.dtype, vt)
                self.assertEqual(f2.dtype, ft)
                self.assertTrue((f2 >= 0).all() and (f2 < len(v2)).all())
                self.assertEqual(len(np.unique(f2)), len(v2))  # every vertex is used

    def test_ratio_and_a_plane_stays_flat(self):
        v, f = grid(100)
        v2, f2 = oocsimp.simplify(v, f, target_ratio=0.1)
        self.assertEqual(len(f2), round(0.1 * len(f)))
        self.assertEqual(np.abs(v2[:, 2]).max(), 0.0)
        # The plane's area is kept: the unit square.
        a, b, c = v2[f2[:, 0]], v2[f2[:, 1]], v2[f2[:, 2]]
        area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum()
        self.assertAlmostEqual(area, 1.0, places=9)

    def test_a_locked_boundary_stays(self):
        v, f = grid(60, wavy)
        def outline(vs, fs):
            edges = np.sort(np.concatenate([fs[:, [0, 1]], fs[:, [1, 2]], fs[:, [2, 0]]]), axis=1)
            unique, counts = np.unique(edges, axis=0, return_counts=True)
            ends = np.round(vs[unique[counts == 1]], 12)  # (edges, 2, 3); the collapse works relative to the box
            return sorted(tuple(sorted(map(tuple, e))) for e in ends.tolist())
        v2, f2 = oocsimp.simplify(v, f, target_tris=600, lock_boundary=True)
        self.assertEqual(len(f2), 600)
        self.assertEqual(outline(v2, f2), outline(v, f))
        v3, f3 = oocsimp.simplify(v, f, target_tris=600)
        self.assertLess(len(outline(v3, f3)), len(outline(v, f)))
        # Floating cells keep it too, each boundary vertex a cluster of its own; the
        # uniform grid cannot find it.
        v5, f5 = oocsimp.simplify(v, f, grid=10, lock_boundary=True)
        self.assertLess(len(f5), len(f) // 4)
        rim = {tuple(p) for e in np.asarray(outline(v, f)).tolist() for p in e}
        kept = set(map(tuple, np.round(np.asarray(v5), 12).tolist()))
        self.assertEqual(rim - kept, set())
        with self.assertRaisesRegex(ValueError, "lock_boundary"):
            oocsimp.simplify(v, f, grid=10, method="uniform", lock_boundary=True)
        # Chosen vertices, as indices or as a mask, stay where they are.
        chosen = np.arange(7, len(v), 97)
        mask = np.zeros(len(v), dtype=bool)
        mask[chosen] = True
        for locked in (chosen, mask):
            v4, f4 = oocsimp.simplify(v, f, target_tris=600, locked=locked)
            kept = {tuple(p) for p in np.round(v4, 12).tolist()}
            self.assertTrue(all(tuple(p) in kept for p in np.round(v[chosen], 12).tolist()))
        with self.assertRaisesRegex(ValueError, "locked"):
            oocsimp.simplify(v, f, target_tris=600, locked=[len(v)])

    def test_strided_and_contiguous_input_agree(self):
        v, f = grid(80, wavy)
        wide = np.zeros((len(v), 5))
        wide[:, 1:4] = v  # rows 40 bytes apart, read in place
        a = oocsimp.simplify(v, f, target_tris=500)
        b = oocsimp.simplify(wide[:, 1:4], f, target_tris=500)
        c = oocsimp.simplify(np.asfortranarray(v), np.asfortranarray(f), target_tris=500)  # copied
        for other in (b, c):
            np.testing.assert_array_equal(a[0], other[0])
            np.testing.assert_array_equal(a[1], other[1])

    def test_methods_and_sizes(self):
        v, f = grid(150, wavy)
        for method in ("floating", "uniform", "curvature", "qem"):
            with self.subTest(method=method):
                if method == "qem":
                    v2, f2 = oocsimp.simplify(v, f, method=method, target_tris=800)
                    self.assertEqual(len(f2), 800)
                else:
                    v2, f2 = oocsimp.simplify(v, f, method=method, grid=20)
                    self.assertGreater(len(f2), 0)
                    self.assertLess(len(f2), len(f) // 10)

    def test_constant_attributes_stay_constant(self):
        v, f = grid(90, wavy)
        colors = np.tile(np.array([[10, 200, 30]], dtype=np.uint8), (len(v), 1))
        normals = np.tile([[0.0, 0.6, 0.8]], (len(v), 1))
        v2, f2, attrs = oocsimp.simplify(v, f, target_tris=600, colors=colors, normals=normals)
        self.assertEqual(sorted(attrs), ["colors", "normals"])
        self.assertEqual(attrs["colors"].dtype, np.uint8)
        self.assertEqual(attrs["colors"].shape, (len(v2), 3))
        self.assertTrue((attrs["colors"] == [10, 200, 30]).all())
        np.testing.assert_allclose(attrs["normals"], np.tile([[0.0, 0.6, 0.8]], (len(v2), 1)), atol=1e-6)

    def test_uvs_follow_a_plane_and_a_seam_collapses_closed(self):
        # A flat grid cut along x = 0.5 into two charts: the seam's vertices doubled,
        # each side with its own u (the plane's x, shifted by 10 on the right chart).
        n = 41
        v, f = grid(n)
        uv = v[:, :2].copy()
        seam = np.where(np.isclose(v[:, 0], 0.5))[0]
        extra = np.arange(len(v), len(v) + len(seam))
        v2 = np.concatenate([v, v[seam]])
        uv2 = np.concatenate([uv, uv[seam]])
        uv2[:, 0] += np.where(v2[:, 0] > 0.5, 10.0, 0.0)
        uv2[extra, 0] += 10.0
        remap = np.arange(len(v))
        remap[seam] = extra
        f2 = f.copy()
        right = v[f].mean(axis=1)[:, 0] > 0.5  # faces of the right chart take the doubles
        f2[right] = remap[f[right]]
        out_v, out_f, attrs = oocsimp.simplify(v2, f2, target_tris=300, uvs=uv2)
        self.assertEqual(len(out_f), 300)
        u = attrs["uvs"]
        # Every face lies in one chart: its u all below 1 or all above 10.
        chart = u[out_f][:, :, 0] > 5
        self.assertTrue((chart.all(axis=1) | (~chart).all(axis=1)).all())
        # The uv is the plane's position (the shift taken off) within rounding.
        expected = out_v[:, :2].copy()
        expected[:, 0] += np.where(u[:, 0] > 5, 10.0, 0.0)
        self.assertLess(np.abs(u - expected).max(), 1e-6)
        # The seam simplifies with both sides together: the vertices on x = 0.5 of the
        # left chart and of the right one are at the same positions, fewer than before.
        on_seam = np.isclose(out_v[:, 0], 0.5, rtol=0, atol=1e-12)
        left = {tuple(p) for p in out_v[on_seam & (u[:, 0] < 5)].tolist()}
        right = {tuple(p) for p in out_v[on_seam & (u[:, 0] > 5)].tolist()}
        self.assertEqual(left, right)
        self.assertLess(len(left), len(seam))
        # Welded by position, the only open edges are the grid's outline: the seam is closed.
        edges = {}
        for t in out_f.tolist():
            for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
                key = tuple(sorted((tuple(out_v[a]), tuple(out_v[b]))))
                edges[key] = edges.get(key, 0) + 1
        outline = lambda p: p[0] in (0.0, 1.0) or p[1] in (0.0, 1.0)
        inner_open = [e for e, n in edges.items() if n == 1 and not (outline(e[0]) and outline(e[1]))]
        self.assertEqual(inner_open, [])

    def test_rgba_colours_keep_their_alpha(self):
        v, f = grid(40)
        rgba = np.tile(np.array([[0.1, 0.2, 0.3, 0.5]], dtype=np.float32), (len(v), 1))
        _, _, attrs = oocsimp.simplify(v, f, target_tris=100, colors=rgba)
        self.assertEqual(attrs["colors"].shape[1], 4)
        np.testing.assert_allclose(attrs["colors"][:, 3], 0.5, atol=1e-6)


class Warnings(unittest.TestCase):
    def test_a_run_that_removes_nothing_warns_naming_the_keyword(self):
        v, f = grid(30, wavy)
        with self.assertWarnsRegex(UserWarning, "nothing was removed; a smaller grid"):
            v2, f2 = oocsimp.simplify(v, f, method="uniform", grid=512)
        self.assertEqual(len(f2), len(f))
        import warnings
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            oocsimp.simplify(v, f, method="uniform", grid=8)  # removes some: no warning

    def test_max_error_as_a_percentage_of_the_diagonal(self):
        v, f = grid(60, wavy)
        diagonal = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
        v1, f1 = oocsimp.simplify(v, f, max_error="0.5%")
        v2, f2 = oocsimp.simplify(v, f, max_error=0.5 / 100 * diagonal)
        self.assertLess(len(f1), len(f))
        self.assertTrue(np.array_equal(f1, f2) and np.array_equal(v1, v2))


class Errors(unittest.TestCase):
    def setUp(self):
        self.v, self.f = grid(20)

    def test_bad_options_are_value_errors_naming_the_keyword(self):
        with self.assertRaisesRegex(ValueError, "target_tris"):
            oocsimp.simplify(self.v, self.f, target_tris=2)
        with self.assertRaisesRegex(ValueError, "target_ratio"):
            oocsimp.simplify(self.v, self.f, target_ratio=1.5)
        with self.assertRaisesRegex(ValueError, "method must be one of"):
            oocsimp.simplify(self.v, self.f, method="magic")
        with self.assertRaisesRegex(ValueError, "^mem: "):
            oocsimp.simplify(self.v, self.f, mem="lots")
        with self.assertRaises(TypeError):
            oocsimp.simplify(self.v, self.f, target_triangles=10)
        with self.assertRaisesRegex(ValueError, "uvs"):
            oocsimp.simplify(self.v, self.f, grid=8, uvs=np.zeros((len(self.v), 2)))

    def test_a_zero_that_would_mean_no_target_is_refused_as_the_cli_refuses_it(self):
        # The command line's --target-tris 0 exits 2; here each such zero is a ValueError
        # naming its keyword, not a run of the default.
        for keyword, value in [("target_tris", 0), ("target_tris", 3), ("target_ratio", 0), ("max_error", 0),
                               ("grid", 0), ("cell", 0), ("ratio", 0), ("max_error", "0%"), ("max_error", "0.1")]:
            with self.subTest(keyword=keyword, value=value):
                with self.assertRaisesRegex(ValueError, "^" + keyword):
                    oocsimp.simplify(self.v, self.f, **{keyword: value})
        cli = subprocess.run([CLI, "simplify", "in.ply", "-o", "out.ply", "--target-tris", "0"],
                             capture_output=True, text=True)
        self.assertEqual(cli.returncode, 2)

    def test_bad_arrays(self):
        with self.assertRaisesRegex(ValueError, r"vertices must have shape \(n, 3\)"):
            oocsimp.simplify(self.v[:, :2], self.f, target_tris=10)
        with self.assertRaisesRegex(ValueError, "faces"):
            oocsimp.simplify(self.v, self.f.astype(np.float64), target_tris=10)
        bad = self.f.astype(np.int64)
        bad[3, 1] = len(self.v)
        with self.assertRaisesRegex(ValueError, r"faces\[3, 1\]"):
            oocsimp.simplify(self.v, bad, target_tris=10)
        bad = self.f.copy()
        bad[0, 0] = -1
        with self.assertRaises(ValueError):  # int32 read in place: the library names it
            oocsimp.simplify(self.v, bad, target_tris=10)
        with self.assertRaisesRegex(ValueError, "colors must have a row per vertex"):
            oocsimp.simplify(self.v, self.f, target_tris=10, colors=np.zeros((3, 3)))

    def test_files(self):
        with tempfile.TemporaryDirectory() as d:
            with self.assertRaises(OSError):
                oocsimp.simplify_file(os.path.join(d, "absent.ply"), os.path.join(d, "o.ply"))
            text = os.path.join(d, "text.obj")
            with open(text, "w") as out:
                out.write("hello\n")
            with self.assertRaises(oocsimp.InputError) as caught:
                oocsimp.simplify_file(text, os.path.join(d, "o.ply"))
            self.assertIsInstance(caught.exception, ValueError)
            self.assertIn("line 1", str(caught.exception))
            self.assertFalse(os.path.exists(os.path.join(d, "o.ply")))


class Files(unittest.TestCase):
    def test_simplify_file_gives_the_cli_bytes(self):
        with tempfile.TemporaryDirectory() as d:
            mesh = os.path.join(d, "parts.ply")
            subprocess.run([CLI, "generate", "--shape", "parts", "--tris", "60000", "--quiet", "-o", mesh], check=True)
            cases = [
                ({"target_tris": 3000}, ["--target-tris", "3000"], "a.ply"),
                ({"method": "floating", "grid": 40, "threads": 1}, ["--method", "floating", "--grid", "40", "--threads", "1"], "b.obj"),
                ({"method": "uniform", "grid": 30, "normals": True, "ascii": True}, ["--method", "uniform", "--grid", "30", "--normals", "--ascii"], "c.ply"),
                ({"target_ratio": 0.05, "mem": "64M"}, ["--target-ratio", "0.05", "--mem", "64M"], "d.stl"),
            ]
            for kw, flags, name in cases:
                with self.subTest(kw=kw):
                    ours, theirs = os.path.join(d, "py-" + name), os.path.join(d, "cli-" + name)
                    stats = oocsimp.simplify_file(mesh, ours, **kw)
                    subprocess.run([CLI, "simplify", "--quiet", mesh, "-o", theirs] + flags, check=True)
                    with open(ours, "rb") as a, open(theirs, "rb") as b:
                        self.assertEqual(a.read(), b.read())
                    self.assertGreater(stats["input"]["triangles"], 50000)
                    self.assertGreater(stats["output"]["triangles"], 0)
                    if "target_tris" in kw:
                        self.assertEqual(stats["output"]["triangles"], kw["target_tris"])

    def test_measure_shifted_planes(self):
        v, f = grid(30)
        up = v + [0.0, 0.0, 0.25]
        same = oocsimp.measure((v, f), (v, f), samples=20000)
        self.assertAlmostEqual(same["symmetric"]["hausdorff"], 0.0, places=12)
        shifted = oocsimp.measure((v, f), (up, f), samples=20000)
        for key in ("hausdorff", "mean", "rms"):
            self.assertAlmostEqual(shifted["symmetric"][key], 0.25, places=12)
        with tempfile.TemporaryDirectory() as d:
            a, b = os.path.join(d, "a.obj"), os.path.join(d, "b.obj")
            for path, verts in ((a, v), (b, up)):
                with open(path, "w") as out:
                    out.writelines("v %r %r %r\n" % tuple(p) for p in verts)
                    out.writelines("f %d %d %d\n" % tuple(t + 1) for t in f)
            from_files = oocsimp.measure(a, b, samples=20000)
            self.assertAlmostEqual(from_files["symmetric"]["hausdorff"], 0.25, places=12)


class Interrupt(unittest.TestCase):
    def test_ctrl_c_cancels_and_leaves_nothing(self):
        with tempfile.TemporaryDirectory() as d:
            mesh, tmp = os.path.join(d, "big.ply"), os.path.join(d, "tmp")
            os.mkdir(tmp)
            subprocess.run([CLI, "generate", "--tris", "4000000", "--quiet", "-o", mesh], check=True)
            # interrupt_main() is what SIGINT does to the main thread: it sets the flag
            # the run's progress callback checks.
            script = textwrap.dedent(f"""
                import _thread, threading, oocsimp
                threading.Timer(0.3, _thread.interrupt_main).start()
                try:
                    oocsimp.simplify_file({mesh!r}, {os.path.join(d, 'o.ply')!r}, method="floating", grid=600,
                                          threads=1, tmp={tmp!r})
                    print("finished")
                except KeyboardInterrupt:
                    print("interrupted")
            """)
            run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=os.environ)
            self.assertEqual(run.stdout.strip(), "interrupted", run.stderr)
            self.assertFalse(os.path.exists(os.path.join(d, "o.ply")))
            self.assertEqual(os.listdir(tmp), [])


class Open3D(unittest.TestCase):
    def test_round_trip(self):
        try:
            import open3d as o3d
        except ImportError:
            self.skipTest("open3d is not installed (python3-open3d)")
        sphere = o3d.geometry.TriangleMesh.create_sphere(radius=1.0, resolution=60)
        v, f = oocsimp.simplify(np.asarray(sphere.vertices), np.asarray(sphere.triangles), target_tris=1000)
        out = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(v), o3d.utility.Vector3iVector(f))
        self.assertEqual(len(out.triangles), 1000)
        self.assertTrue(out.is_watertight())
        radii = np.linalg.norm(v, axis=1)
        self.assertLess(np.abs(radii - 1.0).max(), 0.05)
        # A .glb written by oocsimp, read by Open3D: the same triangles.
        with tempfile.TemporaryDirectory() as d:
            ply, glb = os.path.join(d, "s.ply"), os.path.join(d, "s.glb")
            o3d.io.write_triangle_mesh(ply, sphere)
            oocsimp.simplify_file(ply, glb, target_tris=1000, normals=True)
            back = o3d.io.read_triangle_mesh(glb)
            self.assertEqual(len(back.triangles), 1000)
            self.assertTrue(back.has_vertex_normals())
            self.assertLess(np.abs(np.linalg.norm(np.asarray(back.vertices), axis=1) - 1.0).max(), 0.05)
            # A .glb written by Open3D (tinygltf), read by oocsimp: the same mesh.
            theirs, ours = os.path.join(d, "o3d.glb"), os.path.join(d, "o3d.ply")
            sphere.compute_vertex_normals()
            self.assertTrue(o3d.io.write_triangle_mesh(theirs, sphere))
            stats = oocsimp.simplify_file(theirs, ours, target_tris=2000)
            self.assertEqual(stats["input"]["triangles"], len(sphere.triangles))
            again = o3d.io.read_triangle_mesh(ours)
            self.assertEqual(len(again.triangles), 2000)
            self.assertTrue(again.is_watertight())


if __name__ == "__main__":
    unittest.main()
