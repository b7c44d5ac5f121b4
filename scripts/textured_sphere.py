"""Writes a textured OBJ for the seam benchmarks: the unit sphere made from a cube,
each of the cube's six faces subdivided N x N and mapped to its own chart of the
texture (3 x 2 charts), so that twelve seams run along the cube's edges and three
charts meet at each of its eight corners. Positions are written once (`v`), the
texture coordinates per chart (`vt`), and the faces name both (`f v/vt`).

    python3 scripts/textured_sphere.py N OUT.obj
"""
import math
import sys


def main():
    n, out = int(sys.argv[1]), sys.argv[2]
    index, positions, texcoords, faces = {}, [], [], []

    def position(x, y, z):
        key = (round(x * n), round(y * n), round(z * n))
        if key not in index:
            index[key] = len(positions) + 1
            r = math.sqrt(x * x + y * y + z * z)
            positions.append((x / r, y / r, z / r))
        return index[key]

    # Each cube face: its centre c and the axes a, b across it (a x b = c, outward).
    cube = [((1, 0, 0), (0, 1, 0), (0, 0, 1)), ((-1, 0, 0), (0, 0, 1), (0, 1, 0)),
            ((0, 1, 0), (0, 0, 1), (1, 0, 0)), ((0, -1, 0), (1, 0, 0), (0, 0, 1)),
            ((0, 0, 1), (1, 0, 0), (0, 1, 0)), ((0, 0, -1), (0, 1, 0), (1, 0, 0))]
    for chart, (c, a, b) in enumerate(cube):
        first = len(texcoords)
        for j in range(n + 1):
            for i in range(n + 1):
                texcoords.append(((chart % 3 + i / n) / 3 * 0.98, (chart // 3 + j / n) / 2 * 0.98))
        grid = []
        for j in range(n + 1):
            t = -1 + 2 * j / n
            grid.append([position(*(c[k] + (-1 + 2 * i / n) * a[k] + t * b[k] for k in range(3)))
                         for i in range(n + 1)])
        corner = lambda i, j: (grid[j][i], first + j * (n + 1) + i + 1)
        for j in range(n):
            for i in range(n):
                q = [corner(i, j), corner(i + 1, j), corner(i + 1, j + 1), corner(i, j + 1)]
                faces.append((q[0], q[1], q[2]))
                faces.append((q[0], q[2], q[3]))
    with open(out, "w") as f:
        for p in positions:
            f.write("v %.9g %.9g %.9g\n" % p)
        for t in texcoords:
            f.write("vt %.9g %.9g\n" % t)
        for t in faces:
            f.write("f %d/%d %d/%d %d/%d\n" % (t[0] + t[1] + t[2]))


if __name__ == "__main__":
    main()
