#!/usr/bin/env python3
"""Counts the edges of a PLY mesh written by oocsimp by how many triangles share them:
boundary (1: holes), manifold (2) and non-manifold (3 or more). For the README's "Limits"
figures; reads binary little-endian or ascii PLY with x, y, z (float or double) and a face list."""
import struct
import sys
from collections import Counter


def read_ply(path):
    with open(path, "rb") as f:
        header = []
        while True:
            line = f.readline().decode("ascii").strip()
            header.append(line)
            if line == "end_header":
                break
        fmt = next(l.split()[1] for l in header if l.startswith("format"))
        elements, current = [], None
        for l in header:
            w = l.split()
            if w[0] == "element":
                current = [w[1], int(w[2]), []]
                elements.append(current)
            elif w[0] == "property":
                current[2].append(w[1:])
        sizes = {"char": "b", "uchar": "B", "short": "h", "ushort": "H", "int": "i", "uint": "I",
                 "float": "f", "double": "d", "int8": "b", "uint8": "B", "int32": "i", "uint32": "I",
                 "float32": "f", "float64": "d"}
        faces = []
        if fmt == "ascii":
            rest = f.read().decode("ascii").split("\n")
            pos = 0
            for name, count, props in elements:
                for _ in range(count):
                    w = rest[pos].split()
                    pos += 1
                    if name == "face":
                        n = int(w[0])
                        faces.append(tuple(int(x) for x in w[1:1 + n]))
            return faces
        for name, count, props in elements:
            if name != "face":
                rec = "<" + "".join(sizes[p[0]] for p in props)
                f.read(struct.calcsize(rec) * count)
                continue
            (_, ct, it, _) = props[0]
            cs, isz = struct.calcsize(sizes[ct]), struct.calcsize(sizes[it])
            for _ in range(count):
                n = struct.unpack("<" + sizes[ct], f.read(cs))[0]
                faces.append(struct.unpack("<" + sizes[it] * n, f.read(isz * n)))
        return faces


def main():
    for path in sys.argv[1:]:
        faces = read_ply(path)
        edges = Counter()
        for face in faces:
            for i in range(len(face)):
                a, b = face[i], face[(i + 1) % len(face)]
                edges[(min(a, b), max(a, b))] += 1
        share = Counter(edges.values())
        boundary = share.get(1, 0)
        nonmanifold = sum(v for k, v in share.items() if k >= 3)
        print(f"{path}: {len(faces)} triangles, {len(edges)} edges: {boundary} boundary "
              f"({100.0 * boundary / max(1, len(edges)):.3f}%), {nonmanifold} non-manifold "
              f"({100.0 * nonmanifold / max(1, len(edges)):.3f}%)")


if __name__ == "__main__":
    main()
