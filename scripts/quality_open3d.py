#!/usr/bin/python3
"""Symmetric surface distance between an input mesh and simplifications of it.

Independent of oocsimp's code: uses Open3D (Debian python3-open3d) for loading,
area-uniform sampling and exact point-to-triangle distances (RaycastingScene).

    quality_open3d.py INPUT CELL [NAME=SIMPLIFIED.ply ...]

Also simplifies INPUT with Open3D's simplify_vertex_clustering at voxel size CELL
(quadric contraction, Open3D's best) and reports it beside the given meshes. For
each: triangles, RMS and Hausdorff of the symmetric distance, both as a fraction of
the input's bounding-box diagonal.
"""
import sys

import numpy as np
import open3d as o3d

SAMPLES = 1_000_000


def load(path):
    m = o3d.io.read_triangle_mesh(path)
    if len(m.triangles) == 0:
        sys.exit(f"{path}: no triangles")
    return m


def one_sided(points, mesh):
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(mesh))
    return scene.compute_distance(o3d.core.Tensor(points, dtype=o3d.core.Dtype.Float32)).numpy()


def symmetric(a, a_points, b):
    b_points = np.asarray(b.sample_points_uniformly(SAMPLES).points)
    d_ab = one_sided(a_points, b)
    d_ba = one_sided(b_points, a)
    both = np.concatenate([d_ab, d_ba])
    return float(np.sqrt(np.mean(both ** 2))), float(both.max())


def main():
    o3d.utility.random.seed(1)
    src = load(sys.argv[1])
    cell = float(sys.argv[2])
    diag = float(np.linalg.norm(src.get_max_bound() - src.get_min_bound()))
    a_points = np.asarray(src.sample_points_uniformly(SAMPLES).points)
    runs = [(arg.split("=", 1)[0], load(arg.split("=", 1)[1])) for arg in sys.argv[3:]]
    o3d_mesh = src.simplify_vertex_clustering(voxel_size=cell,
                                              contraction=o3d.geometry.SimplificationContraction.Quadric)
    runs.append(("open3d-vertex-clustering", o3d_mesh))
    print(f"input {len(src.triangles)} triangles, diagonal {diag:.6g}, cell {cell:.6g}, {SAMPLES} samples per side")
    print(f"{'method':28s} {'triangles':>10s} {'rms/diag':>12s} {'hausdorff/diag':>15s}")
    for name, mesh in runs:
        rms, haus = symmetric(src, a_points, mesh)
        print(f"{name:28s} {len(mesh.triangles):10d} {rms / diag:12.3e} {haus / diag:15.3e}")


if __name__ == "__main__":
    main()
