#!/usr/bin/python3
"""Open3D's quadric edge collapse as a peer of scripts/bench-quality.sh.

    open3d_decimate.py INPUT OUTPUT TARGET

Loads INPUT, runs TriangleMesh.simplify_quadric_decimation(TARGET) (Garland &
Heckbert, Open3D's own; Debian python3-open3d) and writes OUTPUT as binary PLY.
Prints one line of "key value" pairs, as the C++ peers in bench/ do: the seconds
of each step, the output's triangles, the peak RSS (getrusage) and the anonymous
memory right after the collapse, while input and output are both held (RssAnon:
Open3D offers no peak of its own).
"""
import resource
import sys
import time

import open3d as o3d


def rss_anon_mib():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("RssAnon:"):
                return int(line.split()[1]) / 1024
    return 0.0


def main():
    if len(sys.argv) != 4:
        sys.exit("usage: open3d_decimate.py INPUT OUTPUT TARGET")
    source, output, target = sys.argv[1], sys.argv[2], int(sys.argv[3])
    t0 = time.perf_counter()
    mesh = o3d.io.read_triangle_mesh(source)
    if len(mesh.triangles) == 0:
        sys.exit(f"{source}: no triangles")
    t1 = time.perf_counter()
    result = mesh.simplify_quadric_decimation(target_number_of_triangles=target)
    t2 = time.perf_counter()
    anon = rss_anon_mib()
    if not o3d.io.write_triangle_mesh(output, result, write_ascii=False, compressed=False):
        sys.exit(f"{output}: cannot write")
    t3 = time.perf_counter()
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"seconds {t3 - t0:.3f} load {t1 - t0:.3f} simplify {t2 - t1:.3f} write {t3 - t2:.3f} "
          f"triangles {len(result.triangles)} peak_rss_mib {peak:.1f} peak_anon_mib {anon:.1f}")


if __name__ == "__main__":
    main()
