#!/usr/bin/env bash
# Real laser scans for the quality benchmarks, from Debian's own packages (the
# machines reach no network but Debian's): CGAL's demo data (package libcgal-demo)
# carries the Stanford bunny (bunny00.off, 75k triangles) and the Stanford
# armadillo (armadillo.off, 52k triangles) as OFF files. They are converted to
# binary PLY under build/bench/scans/ and their paths printed, one a line:
#
#   scripts/bench-quality.sh $(scripts/fetch-scans.sh)
#
# Both are the scans as CGAL ships them (closed, already reduced from the raw
# range images), not multi-gigabyte ones; no such scan is packaged.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
dir="$root/build/bench/scans"
mkdir -p "$dir"
names=(bunny00 armadillo)

missing=0
for n in "${names[@]}"; do [ -f "$dir/$n.ply" ] || missing=1; done
if [ $missing = 1 ]; then
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
  chmod 755 "$work"  # apt-get download runs as _apt where it can
  (cd "$work" && apt-get download libcgal-demo >/dev/null) ||
    { echo "fetch-scans.sh: apt-get download libcgal-demo failed (no Debian mirror?)" >&2; exit 1; }
  dpkg-deb -x "$work"/libcgal-demo_*.deb "$work/pkg"
  tar -xzf "$work/pkg/usr/share/doc/libcgal-dev/data.tar.gz" -C "$work" \
    $(for n in "${names[@]}"; do echo "data/meshes/$n.off"; done)
  for n in "${names[@]}"; do
    python3 - "$work/data/meshes/$n.off" "$dir/$n.ply.part" <<'EOF'
# OFF (ascii, triangles and polygons) to binary little-endian PLY; polygons are
# written as they are (oocsimp fans them).
import struct, sys
words = open(sys.argv[1]).read().split()
if words[0] != "OFF":
    sys.exit(sys.argv[1] + ": not an OFF file")
nv, nf = int(words[1]), int(words[2])
at = 4
with open(sys.argv[2], "wb") as out:
    out.write(("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
               "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
               % (nv, nf)).encode())
    for i in range(nv):
        out.write(struct.pack("<3f", *map(float, words[at:at + 3])))
        at += 3
    for i in range(nf):
        k = int(words[at])
        out.write(struct.pack("<B%di" % k, k, *map(int, words[at + 1:at + 1 + k])))
        at += 1 + k
EOF
    mv "$dir/$n.ply.part" "$dir/$n.ply"
  done
fi
for n in "${names[@]}"; do echo "$dir/$n.ply"; done
