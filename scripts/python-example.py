#!/usr/bin/python3
"""oocsimp from Python on a real scan, against Open3D's quadric decimation in the same run.

  PYTHONPATH=build/python scripts/python-example.py build/bench/scans/bunny00.ply 5000
(scripts/fetch-scans.sh gives the scans; python3-open3d must be installed.)"""
import sys, time
import numpy as np, open3d as o3d, oocsimp

path, target = sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 5000
mesh = o3d.io.read_triangle_mesh(path)
v, f = np.asarray(mesh.vertices), np.asarray(mesh.triangles)
t0 = time.perf_counter(); ov, of = oocsimp.simplify(v, f, target_tris=target); t_ours = time.perf_counter() - t0
t0 = time.perf_counter(); theirs = mesh.simplify_quadric_decimation(target); t_o3d = time.perf_counter() - t0
tv, tf = np.asarray(theirs.vertices), np.asarray(theirs.triangles)
ours_d = oocsimp.measure(path, (ov, of), samples=200000)["symmetric"]["of_diagonal"]
o3d_d = oocsimp.measure(path, (tv, tf), samples=200000)["symmetric"]["of_diagonal"]
print(f"{path}: {len(f)} -> {target} triangles (oocsimp {len(of)}, Open3D {len(tf)})")
print(f"time  oocsimp {t_ours:.3f} s  Open3D {t_o3d:.3f} s  ratio {t_ours / t_o3d:.2f}x")
print(f"rms   oocsimp {ours_d['rms']:.3e}  Open3D {o3d_d['rms']:.3e}  ratio {ours_d['rms'] / o3d_d['rms']:.2f}x (of the diagonal)")
print(f"haus  oocsimp {ours_d['hausdorff']:.3e}  Open3D {o3d_d['hausdorff']:.3e}  ratio {ours_d['hausdorff'] / o3d_d['hausdorff']:.2f}x")
