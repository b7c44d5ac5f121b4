#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz/) with clang, ASan and UBSan in build-fuzz/
# and runs each for SECONDS of wall time, one after the other.
#
#   scripts/fuzz.sh SECONDS [TARGET...]
#   TARGETs: fuzz_ply_reader fuzz_obj_reader fuzz_stl_reader fuzz_off_reader fuzz_glb_reader fuzz_gzip_input
#            fuzz_simplify fuzz_hierarchy_file fuzz_hierarchy_build (default: all)
#
# Installs what is missing (scripts/setup-deps.sh, clang and its fuzzer runtime).
# Each run starts from a seed corpus written into build-fuzz/corpus/TARGET (generated
# meshes, hand-written tiny OBJ/STL/PLY files and broken variants of them; libFuzzer
# adds what it finds there, so later runs start where earlier ones left off). Inputs
# that crash, leak, time out (-timeout=10) or run out of memory (-rss_limit_mb=2048)
# are saved under build-fuzz/artifacts/TARGET/ (emptied when the target starts);
# the log is build-fuzz/logs/TARGET.log. Prints per target the executions, the CPU
# seconds and whether it found anything; exits 1 when any artifact exists.
# Reproduce a finding with: build-fuzz/TARGET build-fuzz/artifacts/TARGET/crash-...
#
# --ledger appends one row per target to tests/fuzz/hours.tsv (date, commit, target,
# wall and CPU seconds, executions, findings) and rewrites the table of totals in
# docs/building.md from it (scripts/fuzz-hours.sh). Two runs of different targets may
# go at once: the build and the seeding take turns (a lock in build-fuzz/).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
all_targets=(fuzz_ply_reader fuzz_obj_reader fuzz_stl_reader fuzz_off_reader fuzz_glb_reader fuzz_gzip_input fuzz_simplify
  fuzz_hierarchy_file fuzz_hierarchy_build)

usage() { echo "usage: scripts/fuzz.sh [--ledger] SECONDS [TARGET...]  (targets: ${all_targets[*]})" >&2; exit 2; }
ledger=""
if [ "${1:-}" = --ledger ]; then
  ledger="$root/tests/fuzz/hours.tsv"
  shift
fi
[ $# -ge 1 ] || usage
seconds="$1"
shift
[[ "$seconds" =~ ^[1-9][0-9]*$ ]] || usage
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=("${all_targets[@]}")
for t in "${targets[@]}"; do
  [[ " ${all_targets[*]} " == *" $t "* ]] || { echo "fuzz.sh: unknown target $t" >&2; usage; }
done

# The setup below (installing, building, writing the seeds and dictionaries) is done by
# one run at a time; the fuzzing itself is not.
build="$root/build-fuzz"
mkdir -p "$build"
exec 9>"$build/.setup.lock"
flock 9

# --- dependencies -------------------------------------------------------------------
"$root/scripts/setup-deps.sh"
install_pkgs() {
  echo "fuzz.sh: installing $*" >&2
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq >/dev/null
  $sudo apt-get install -y -qq --no-install-recommends "$@" >/dev/null
}
command -v clang++ >/dev/null 2>&1 || install_pkgs clang
fuzzer_runtime_present() {
  local dir
  dir="$(clang++ -print-resource-dir 2>/dev/null || true)"
  [ -n "$dir" ] && [ -f "$dir/lib/linux/libclang_rt.fuzzer-x86_64.a" ] && return 0
  compgen -G "/usr/lib/llvm-14/lib/clang/14*/lib/linux/libclang_rt.fuzzer-x86_64.a" >/dev/null
}
fuzzer_runtime_present || install_pkgs libclang-rt-14-dev
command -v perl >/dev/null 2>&1 || install_pkgs perl-base

# --- build --------------------------------------------------------------------------
OOCSIMP_BUILD_DIR="$build" "$root/scripts/build.sh" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DOOCSIMP_FUZZ=ON -DOOCSIMP_BUILD_TESTS=OFF -DOOCSIMP_BUILD_BENCH=OFF

# --- seed corpora -------------------------------------------------------------------
# Written afresh on every run (same names, so they replace themselves); never committed.
# The minimised corpora of earlier runs that are kept in tests/fuzz/corpus/TARGET are
# copied in too (at the end of this part).
corpus="$build/corpus"
seeds="$build/seeds"  # staging: every seed once, by format
rm -rf "$seeds"
mkdir -p "$seeds/ply" "$seeds/obj" "$seeds/stl" "$seeds/off" "$seeds/glb" "$seeds/gzip" "$seeds/4k"
export ASAN_OPTIONS="detect_leaks=1" UBSAN_OPTIONS="print_stacktrace=1"
cli="$build/oocsimp"

# Generated meshes, binary and ascii PLY; OBJ through `simplify` at coarse grids; STL
# converted from the ascii PLY by perl (binary STL with pack).
for shape in sphere terrain parts; do
  for n in 50 300 2000; do
    "$cli" generate --tris "$n" --shape "$shape" --seed 1 --quiet -o "$seeds/ply/gen-$shape-$n.ply"
    "$cli" generate --tris "$n" --shape "$shape" --seed 2 --quiet --ascii -o "$seeds/ply/gen-$shape-$n-ascii.ply"
  done
  for g in 4 16; do
    "$cli" simplify "$seeds/ply/gen-$shape-2000.ply" -o "$seeds/obj/gen-$shape-g$g.obj" --grid "$g" --threads 1 --quiet
    "$cli" simplify "$seeds/ply/gen-$shape-2000.ply" -o "$seeds/ply/simp-$shape-g$g-ascii.ply" --grid "$g" --threads 1 \
      --quiet --ascii
  done
done
ply_to_stl() {  # ply_to_stl ascii|binary IN.ply OUT.stl  (ascii PLY with only x y z and one face list)
  perl -e '
    my ($mode, $in, $out) = @ARGV;
    open(my $f, "<", $in) or die; my ($nv, $nf, @v);
    while (<$f>) { $nv = $1 if /^element vertex (\d+)/; $nf = $1 if /^element face (\d+)/; last if /^end_header/; }
    for (1 .. $nv) { my @c = split " ", scalar <$f>; push @v, [@c[0 .. 2]]; }
    my @t;
    for (1 .. $nf) { my @l = split " ", scalar <$f>; shift @l; push @t, [@l[0, $_ - 1, $_]] for 2 .. $#l; }
    open(my $o, ">", $out) or die; binmode $o;
    if ($mode eq "ascii") {
      print $o "solid converted\n";
      for my $t (@t) { print $o "  facet normal 0 0 0\n    outer loop\n";
        print $o "      vertex @{$v[$_]}\n" for @$t; print $o "    endloop\n  endfacet\n"; }
      print $o "endsolid converted\n";
    } else {
      print $o pack("A80 V", "binary stl converted by fuzz.sh", scalar @t);
      for my $t (@t) { print $o pack("f<3", 0, 0, 0), (map { pack("f<3", @{$v[$_]}) } @$t), pack("v", 0); }
    }' "$@"
}
for shape in sphere terrain parts; do
  for g in 4 16; do
    ply_to_stl ascii "$seeds/ply/simp-$shape-g$g-ascii.ply" "$seeds/stl/conv-$shape-g$g-ascii.stl"
    ply_to_stl binary "$seeds/ply/simp-$shape-g$g-ascii.ply" "$seeds/stl/conv-$shape-g$g.stl"
  done
done

# Hand-written tiny files and broken variants (truncated, bad counts, bad indices, NaN).
seed() { printf "$2" >"$seeds/$1"; }  # seed DIR/NAME PRINTF-FORMAT
xyz="property float x\nproperty float y\nproperty float z\n"
tet_v="0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
tet_f="3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n"
hdr_a="ply\nformat ascii 1.0\nelement vertex 4\n${xyz}element face 4\nproperty list uchar int vertex_indices\nend_header\n"
seed ply/tet-ascii.ply "${hdr_a}${tet_v}${tet_f}"
seed ply/quad-ascii-crlf.ply "ply\r\nformat ascii 1.0\r\ncomment quad\r\nelement vertex 4\r\nproperty double x\r\nproperty double y\r\nproperty double z\r\nelement face 1\r\nproperty list uchar int vertex_indices\r\nend_header\r\n0 0 0\r\n1 0 0\r\n1 1 0\r\n0 1 0\r\n4 0 1 2 3\r\n"
seed ply/extra-ascii.ply "ply\nformat ascii 1.0\nobj_info x\nelement camera 1\nproperty float f\nelement vertex 3\nproperty uchar red\n${xyz}property list uchar float uv\nelement face 2\nproperty uchar flags\nproperty list ushort uint vertex_index\nelement edge 1\nproperty int v1\nend_header\n1.5\n7 0 0 0 2 0.5 0.5\n8 1 0 0 0\n9 0 1 0 1 2\n0 3 0 1 2\n1 2 0 1\n5\n"
seed ply/truncated-ascii.ply "${hdr_a}0 0 0\n1 0 0\n0 1"
seed ply/badcount-ascii.ply "ply\nformat ascii 1.0\nelement vertex 40\n${xyz}element face 4\nproperty list uchar int vertex_indices\nend_header\n${tet_v}${tet_f}"
seed ply/badindex-ascii.ply "${hdr_a}${tet_v}3 0 2 1\n3 0 1 4\n3 0 -1 2\n3 1 2 3\n"
seed ply/nan-ascii.ply "${hdr_a}0 0 0\nnan 0 0\n0 inf 0\n0 0 1\n${tet_f}"
seed ply/listcount-ascii.ply "${hdr_a}${tet_v}3 0 2 1\n255 0 1 3\n3 0 3 2\n3 1 2 3\n"
seed ply/noend-ascii.ply "ply\nformat ascii 1.0\nelement vertex 4\n${xyz}"
seed ply/bom-cr-ascii.ply "\xef\xbb\xbf${hdr_a//\\n/\\r}${tet_v//\\n/\\r}${tet_f//\\n/\\r}"
seed ply/twoformats.ply "ply\nformat ascii 1.0\nformat binary_little_endian 1.0\nelement vertex 0\n${xyz}end_header\n"
seed ply/noface-trailing-ascii.ply "ply\nformat ascii 1.0\nelement vertex 4\n${xyz}end_header\n${tet_v}\n\n1 2\n"
seed ply/badformat.ply "ply\nformat binary_middle_endian 2.0\nelement vertex 0\n${xyz}end_header\n"
# Binary tetrahedra (little and big endian, float and double) built with perl's pack.
perl -e '
  my $dir = shift;
  my @v = ([0,0,0],[1,0,0],[0,1,0],[0,0,1]); my @f = ([0,2,1],[0,1,3],[0,3,2],[1,2,3]);
  sub put { my ($name, $s) = @_; open(my $o, ">", "$dir/$name") or die; binmode $o; print $o $s; }
  my $xyz = "property float x\nproperty float y\nproperty float z\n";
  for my $e (["le", "<", "little"], ["be", ">", "big"]) {
    my ($tag, $o, $fmt) = @$e;
    my $h = "ply\nformat binary_${fmt}_endian 1.0\nelement vertex 4\n${xyz}element face 4\nproperty list uchar int vertex_indices\nend_header\n";
    my $vb = join "", map { pack("f$o" . "3", @$_) } @v;
    my $fb = join "", map { pack("C l$o" . "3", 3, @$_) } @f;
    put("tet-$tag.ply", $h . $vb . $fb);
    put("truncated-$tag.ply", substr($h . $vb . $fb, 0, length($h) + 30));
    put("truncated-faces-$tag.ply", substr($h . $vb . $fb, 0, length($h . $vb) + 20));
    (my $hc = $h) =~ s/vertex 4/vertex 1000000000/;
    put("badcount-$tag.ply", $hc . $vb . $fb);
    (my $hf = $h) =~ s/face 4/face 7/;
    put("badfacecount-$tag.ply", $hf . $vb . $fb);
    put("badindex-$tag.ply", $h . $vb . pack("C l$o" . "3", 3, 0, 1, 4) . pack("C l$o" . "3", 3, 0, -1, 2) . substr($fb, 26));
    put("nan-$tag.ply", $h . pack("f$o" . "3", 0, "NaN", 0) . substr($vb, 12) . $fb);
    put("trailing-$tag.ply", $h . $vb . $fb . "xyz");
    my $hd = "ply\nformat binary_${fmt}_endian 1.0\nelement vertex 4\nproperty double x\nproperty double y\nproperty double z\nproperty uchar red\nelement face 4\nproperty list ushort uint vertex_indices\nend_header\n";
    put("double-$tag.ply", $hd . (join "", map { pack("d$o" . "3 C", @$_, 7) } @v) . (join "", map { pack("S$o L$o" . "3", 3, @$_) } @f));
    my $hl = "ply\nformat binary_${fmt}_endian 1.0\nelement vertex 4\n${xyz}property list uchar float uv\nelement face 4\nproperty list int int vertex_indices\nend_header\n";
    put("vertexlist-$tag.ply", $hl . (join "", map { pack("f$o" . "3 C f$o" . "2", @$_, 2, 0.5, 0.25) } @v) . (join "", map { pack("l$o l$o" . "3", 3, @$_) } @f));
  }
' "$seeds/ply"
seed obj/tet.obj "# tetrahedron\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
seed obj/forms.obj "mtllib a.mtl\no thing\nv 0 0 0\nv 1 0 0 1\nv 1 1 0 0.5 0.5 0.5\n  v 0 1 0\nvt 0 0\nvn 0 0 1\ng side\ns 1\nusemtl m\nf 1/1 2/1/1 3//1\nf -4 -2 -1\nf 1 2 3 4\nl 1 2\nf 1 2\n"
seed obj/crlf.obj "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n"
seed obj/cr-only.obj "v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r"
seed obj/bom.obj "\xef\xbb\xbfv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
seed obj/underflow.obj "v 1e-400 0 0\nv 1 -2e-324 0\nv 0 1 1e-310\nf 1 2 3\n"
seed obj/index0.obj "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"
seed obj/badindex.obj "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\nf -5 1 2\n"
seed obj/forward.obj "v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n"
seed obj/fewcoords.obj "v 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
seed obj/nan.obj "v 0 0 0\nv nan 0 0\nv 0 1 inf\nf 1 2 3\n"
seed obj/malformed.obj "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 a 2\nv 1e999 0 0\n"
seed obj/truncated.obj "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2"
# OFF: the writer's output, then the prefixes, comments, polygons and broken variants.
for shape in sphere parts; do
  "$cli" simplify "$seeds/ply/gen-$shape-2000.ply" -o "$seeds/off/gen-$shape-g8.off" --grid 8 --threads 1 --quiet
done
seed off/tet.off "OFF\n4 4 0\n${tet_v}${tet_f}"
seed off/counts-on-keyword.off "OFF 4 4 6\n${tet_v}${tet_f}"
seed off/coloured.off "CNOFF # colours and normals\n3 1 0\n0 0 0 0 0 1 255 0 0\n1 0 0 0 0 1 0 255 0\n0 1 0 0 0 1 0 0 255\n3 0 1 2 1 0 0\n"
seed off/quad.off "OFF\n\n# a quad\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n"
seed off/truncated.off "OFF\n4 4 0\n0 0 0\n1 0"
seed off/badindex.off "OFF\n4 2 0\n${tet_v}3 0 1 9\n3 0 -1 2\n"
seed off/shortface.off "OFF\n4 1 0\n${tet_v}5 0 1 2\n"
seed off/binary.off "OFF BINARY\n"
# glb: the writer's output, with and without attributes, and cut short.
for shape in sphere parts; do
  "$cli" simplify "$seeds/ply/gen-$shape-2000.ply" -o "$seeds/glb/gen-$shape.glb" --target-tris 300 --threads 1 --quiet
  "$cli" simplify "$seeds/ply/gen-$shape-2000.ply" -o "$seeds/glb/gen-$shape-normals.glb" --grid 8 --normals \
    --threads 1 --quiet
done
head -c 200 "$seeds/glb/gen-sphere.glb" >"$seeds/glb/truncated.glb"
# gzip: members of the text seeds, one and two of them, and a member cut short.
for f in "$seeds/obj/tet.obj" "$seeds/obj/forms.obj" "$seeds/off/tet.off"; do
  gzip -c "$f" >"$seeds/gzip/$(basename "$f").gz"
done
cat "$seeds/gzip/tet.obj.gz" "$seeds/gzip/tet.obj.gz" >"$seeds/gzip/two-members.obj.gz"
head -c 30 "$seeds/gzip/forms.obj.gz" >"$seeds/gzip/cut.obj.gz"
stl_facet() { printf "  facet normal 0 0 1\n    outer loop\n      vertex $1\n      vertex $2\n      vertex $3\n    endloop\n  endfacet\n"; }
{ echo "solid tet"; stl_facet "0 0 0" "0 1 0" "1 0 0"; stl_facet "0 0 0" "1 0 0" "0 0 1"
  stl_facet "0 0 0" "0 0 1" "0 1 0"; stl_facet "1 0 0" "0 1 0" "0 0 1"; echo "endsolid tet"; } >"$seeds/stl/tet-ascii.stl"
{ echo "solid a"; stl_facet "0 0 0" "0 1 0" "1 0 0"; echo "endsolid a"; echo "solid b"
  stl_facet "0 0 0" "1 0 0" "0 0 1"; echo "endsolid b"; } >"$seeds/stl/two-solids.stl"
{ echo "solid tet"; stl_facet "0 0 0" "0 1 0" "1 0 0"; } >"$seeds/stl/noend-ascii.stl"
{ echo "solid tet"; stl_facet "0 0 0" "nan 1 0" "1 0 0"; echo "endsolid"; } >"$seeds/stl/nan-ascii.stl"
seed stl/twocorners-ascii.stl "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\nendsolid x\n"
head -c 150 "$seeds/stl/tet-ascii.stl" >"$seeds/stl/truncated-ascii.stl"
perl -e '
  my $dir = shift;
  my @t = ([[0,0,0],[0,1,0],[1,0,0]], [[0,0,0],[1,0,0],[0,0,1]], [[0,0,0],[0,0,1],[0,1,0]], [[1,0,0],[0,1,0],[0,0,1]]);
  sub put { my ($name, $s) = @_; open(my $o, ">", "$dir/$name") or die; binmode $o; print $o $s; }
  my $body = join "", map { my $t = $_; pack("f<3", 0, 0, 1) . (join "", map { pack("f<3", @$_) } @$t) . pack("v", 0) } @t;
  put("tet.stl", pack("A80 V", "binary tetrahedron", 4) . $body);
  put("tet-solid-header.stl", pack("A80 V", "solid but binary", 4) . $body);
  put("badcount.stl", pack("A80 V", "declares five", 5) . $body);
  put("truncated.stl", substr(pack("A80 V", "truncated", 4) . $body, 0, 84 + 120));
  put("trailing.stl", pack("A80 V", "trailing", 4) . $body . "extra");
  put("nan.stl", pack("A80 V", "nan", 1) . pack("f<3", 0, 0, 1) . pack("f<9", 0, "NaN", 0, 1, 0, 0, 0, 1, 0) . pack("v", 0));
  put("empty.stl", pack("A80 V", "no triangles", 0));
' "$seeds/stl"

# .4k hierarchies of small generated meshes (with and without attributes), without
# their trailing checksums (fuzz_hierarchy_file makes them again), and a version 1
# copy of the attribute-free ones (version byte 1, the attribute count dropped).
for shape in sphere terrain parts; do
  for n in 50 300 2000; do
    "$cli" hierarchy "$seeds/ply/gen-$shape-$n.ply" -o "$seeds/h.4k" --threads 1 --quiet >/dev/null
    head -c -8 "$seeds/h.4k" >"$seeds/4k/$shape-$n.4k"
    { head -c 8 "$seeds/4k/$shape-$n.4k"; printf '\001'; tail -c +10 "$seeds/4k/$shape-$n.4k" | head -c -4; } \
      >"$seeds/4k/$shape-$n-v1.4k"
  done
  "$cli" generate --tris 300 --shape "$shape" --seed 3 --attributes --quiet -o "$seeds/coloured.ply"
  "$cli" hierarchy "$seeds/coloured.ply" -o "$seeds/h.4k" --threads 1 --quiet >/dev/null
  head -c -8 "$seeds/h.4k" >"$seeds/4k/$shape-coloured.4k"
done
rm -f "$seeds/h.4k" "$seeds/coloured.ply"

# Each reader gets its format; the simplify target gets every seed under 64 KiB behind
# a few variant-selector bytes (see tests/fuzz/fuzz_simplify.cpp).
for fmt in ply obj stl off glb; do
  mkdir -p "$corpus/fuzz_${fmt}_reader"
  cp "$seeds/$fmt"/* "$corpus/fuzz_${fmt}_reader/"
done
mkdir -p "$corpus/fuzz_gzip_input"
cp "$seeds/gzip"/* "$corpus/fuzz_gzip_input/"
mkdir -p "$corpus/fuzz_hierarchy_file"
cp "$seeds/4k"/* "$corpus/fuzz_hierarchy_file/"
mkdir -p "$corpus/fuzz_simplify"
add_simplify_seeds() {  # add_simplify_seeds FMT SELECTOR-OCTALS...
  local fmt="$1" f sel
  shift
  for f in "$seeds/$fmt"/*; do
    [ "$(stat -c %s "$f")" -lt 65536 ] || continue
    for sel in "$@"; do
      { printf "\\$sel"; cat "$f"; } >"$corpus/fuzz_simplify/$sel-$(basename "$f")"
    done
  done
}
add_simplify_seeds ply 000 007 054 330  # plain; zst+tiles; tiles+sphere+centre; ascii out+sphere+heaviest+mean
add_simplify_seeds obj 001 125          # plain; tiles+heaviest+mean
add_simplify_seeds stl 002 216          # plain; tiles+sphere+ascii out
# The hierarchy's builder gets the PLY and OBJ seeds behind its selector byte (see
# tests/fuzz/fuzz_hierarchy_build.cpp): bit 0 the format, bits 1-2 the sets a level.
mkdir -p "$corpus/fuzz_hierarchy_build"
for f in "$seeds/ply"/* "$seeds/obj"/*; do
  [ "$(stat -c %s "$f")" -lt 65536 ] || continue
  obj=0
  [[ "$f" == *.obj ]] && obj=1
  for sets in 0 2 4 6; do  # one, two, three sets a level; sequential
    sel=$(printf '%03o' $((obj | sets)))
    { printf "\\$sel"; cat "$f"; } >"$corpus/fuzz_hierarchy_build/$sel-$(basename "$f")"
  done
done

# What earlier runs grew, minimised (libFuzzer's -merge=1) where it stayed small.
for t in "${all_targets[@]}"; do
  if [ -d "$root/tests/fuzz/corpus/$t" ]; then
    mkdir -p "$corpus/$t"
    cp -R "$root/tests/fuzz/corpus/$t/." "$corpus/$t/"
  fi
done

# Dictionaries of the formats' keywords (libFuzzer -dict), so mutations speak them.
dicts="$build/dict"
mkdir -p "$dicts"
words_ply='ply format ascii binary_little_endian binary_big_endian 1.0 comment obj_info element vertex face
  property list char uchar short ushort int uint float double int8 uint8 int16 uint16 int32 uint32 float32
  float64 x y z vertex_indices vertex_index end_header nan inf -inf 1e39 -0 4294967295 2147483648'
words_obj='v f vt vn vp g o s l usemtl mtllib / // -1 -2 0 nan inf 1e39 9223372036854775807 -9223372036854775808'
words_stl='solid endsolid facet normal outer loop vertex endloop endfacet nan inf 1e39'
write_dict() {  # write_dict FILE WORDS...
  local file="$1" w
  shift
  {
    # Line ends, blanks, float NaN / infinity / FLT_MAX (little-endian), all-ones, zstd magic.
    cat <<'EOF'
"\x0A"
"\x0D\x0A"
"\x20"
"\x09"
"\x00\x00\x00\x00"
"\xFF\xFF\xFF\xFF"
"\x00\x00\xC0\x7F"
"\x00\x00\x80\x7F"
"\xFF\xFF\x7F\x7F"
"\x28\xB5\x2F\xFD"
"\x50\x2A\x4D\x18"
"\x0D"
"\xEF\xBB\xBF"
EOF
    for w in "$@"; do printf '"%s"\n' "$w"; done
  } >"$file"
}
write_dict "$dicts/fuzz_ply_reader.dict" $words_ply
write_dict "$dicts/fuzz_obj_reader.dict" $words_obj
write_dict "$dicts/fuzz_stl_reader.dict" $words_stl
words_off="OFF COFF NOFF CNOFF STOFF STCNOFF 4OFF nOFF BINARY # 0 1 3 4 255 1.5 -1 1e30 nan"
write_dict "$dicts/fuzz_off_reader.dict" $words_off
# glb: the magic and chunk types, and the JSON's names.
words_glb='glTF JSON asset version 2.0 scene scenes nodes mesh meshes primitives attributes POSITION NORMAL
  TEXCOORD_0 COLOR_0 indices mode accessors bufferView bufferViews buffer buffers byteOffset byteLength
  byteStride componentType count type SCALAR VEC2 VEC3 VEC4 normalized sparse uri matrix translation rotation
  scale children extensionsRequired 5120 5121 5122 5123 5125 5126 4294967295'
write_dict "$dicts/fuzz_glb_reader.dict" $words_glb
cat >>"$dicts/fuzz_glb_reader.dict" <<'EOF'
"glTF\x02\x00\x00\x00"
"JSON"
"BIN\x00"
EOF
# gzip: the magic, the deflate method and flag bytes, a stored block's header.
write_dict "$dicts/fuzz_gzip_input.dict" $words_obj
cat >>"$dicts/fuzz_gzip_input.dict" <<'EOF'
"\x1F\x8B\x08\x00"
"\x1F\x8B\x08\x08"
"\x01\x00\x00\xFF\xFF"
"\x03\x00"
EOF
write_dict "$dicts/fuzz_simplify.dict" $words_ply $words_obj $words_stl $words_off
write_dict "$dicts/fuzz_hierarchy_build.dict" $words_ply $words_obj
# .4k: the magic, the versions, a swap's head, a removal's, attribute types with a
# name, and the attribute names the writers use.
write_dict "$dicts/fuzz_hierarchy_file.dict" red green blue nx ny nz quality u v
cat >>"$dicts/fuzz_hierarchy_file.dict" <<'EOF'
"oocs-4k\x0A"
"\x01\x00\x00\x00"
"\x02\x00\x00\x00"
"\x80"
"\x04"
"\x01\x00\x03\x00red"
"\x06\x00\x02\x00nx"
"\x07\x00\x01\x00q"
EOF

flock -u 9
exec 9>&-

# --- runs ---------------------------------------------------------------------------
mkdir -p "$build/logs"
found=0
printf '%-18s %12s %10s %8s  %s\n' target executions cpu_s wall_s result
for t in "${targets[@]}"; do
  art="$build/artifacts/$t"
  rm -rf "$art" "$build/tmp/$t"
  mkdir -p "$art" "$build/tmp/$t"
  log="$build/logs/$t.log"
  : >"$log"
  extra=()
  [ "$t" = fuzz_simplify ] || [ "$t" = fuzz_hierarchy_build ] && extra=(-max_len=65537)
  timefile="$build/logs/$t.time"
  part="$build/logs/$t.part"
  # libFuzzer's -timeout counts wall time, so a run at low priority beside other work
  # can save a timeout that is only the fuzzer starved of CPU. Each timeout is replayed
  # alone; one that then finishes in under 10 s of CPU time is no finding, and its file
  # is renamed starved-* (kept for a look). A replay cut off at 60 s stays a finding.
  # libFuzzer stops at its first timeout (exit 70): a run stopped by a starved one
  # found nothing, and it goes on for the wall time left (a minute or more), so that a
  # long run in the background is not cut short by one busy moment beside it. The
  # ledger's row sums the parts.
  left="$seconds" wall_sum=0 cpu_sum=0 execs_sum=0 stopped_starved=0
  while :; do
    set +e
    TIMEFORMAT='%R %U %S'
    { time TMPDIR="$build/tmp/$t" "$build/$t" -max_total_time="$left" -timeout=10 -rss_limit_mb=2048 \
        -artifact_prefix="$art/" -print_final_stats=1 -dict="$dicts/$t.dict" "${extra[@]}" "$corpus/$t" >"$part" 2>&1; } \
      2>"$timefile"
    rc=$?
    set -e
    cat "$part" >>"$log"
    # Executions: the final statistics, or after a crash the last status line ("#N ...").
    execs=$(awk '/^stat::number_of_executed_units:/ { s = $2 } /^#[0-9]+/ { n = substr($1, 2) }
                 END { print (s != "" ? s : (n != "" ? n : 0)) }' "$part")
    wall=0 user=0 sys=0
    read -r wall user sys <"$timefile" || true
    wall_sum=$(awk "BEGIN { printf \"%.1f\", $wall_sum + $wall }")
    cpu_sum=$(awk "BEGIN { printf \"%.1f\", $cpu_sum + $user + $sys }")
    execs_sum=$((execs_sum + execs))
    starved=0
    for f in "$art"/timeout-*; do
      [ -e "$f" ] || continue
      set +e
      { TIMEFORMAT='%U %S'; time timeout 60 "$build/$t" "$f" >/dev/null 2>&1; } 2>"$build/logs/$t.replay"
      replay_rc=$?
      set -e
      ru=0 rs=0
      read -r ru rs <"$build/logs/$t.replay" || true
      if [ "$replay_rc" -eq 0 ] && awk "BEGIN { exit !($ru + $rs < 10) }"; then
        mv "$f" "$art/starved-${f##*/timeout-}"
        starved=1
        echo "fuzz.sh: ${f##*/} replayed alone in $(awk "BEGIN { print $ru + $rs }") s of CPU: starved, not a hang" >>"$log"
      fi
    done
    stopped_starved=0
    [ "$rc" -eq 70 ] && [ "$starved" -eq 1 ] && stopped_starved=1
    left=$(awk "BEGIN { printf \"%d\", $seconds - $wall_sum }")
    if [ "$stopped_starved" -eq 1 ] && [ "$left" -ge 60 ]; then
      echo "fuzz.sh: going on after the starved timeout, $left s of wall time left" >>"$log"
      continue
    fi
    break
  done
  rm -rf "$build/tmp/$t" "$part"
  wall="$wall_sum" cpu="$cpu_sum" execs="$execs_sum"
  artifacts=$(find "$art" -maxdepth 1 -type f \( -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' -o -name 'oom-*' \) \
    -printf '%f ' | sed 's/ $//')
  if [ -n "$artifacts" ]; then
    result="FOUND: $artifacts (see $log)"
    found=1
  elif [ "$stopped_starved" -eq 1 ]; then
    result="nothing found (stopped early by a starved timeout, see $log)"
  elif [ "$rc" -ne 0 ]; then
    result="FAILED: exit $rc without an artifact (see $log)"
    found=1
  else
    result="nothing found"
  fi
  printf '%-18s %12s %10s %8.1f  %s\n' "$t" "$execs" "$cpu" "$wall" "$result"
  if [ -n "$ledger" ]; then
    [ -s "$ledger" ] ||
      printf 'date\tcommit\ttarget\twall_seconds\tcpu_seconds\texecutions\tfindings\n' >"$ledger"
    commit=$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo '?')
    [ -n "$(git -C "$root" status --porcelain -- src include 2>/dev/null)" ] && commit="$commit+"
    findings="${artifacts:--}"
    [ -z "$artifacts" ] && [ "$rc" -ne 0 ] && [ "$stopped_starved" -eq 0 ] && findings="exit-$rc"
    printf '%s\t%s\t%s\t%.1f\t%s\t%s\t%s\n' "$(date -u +%Y-%m-%dT%H:%M:%SZ)" "$commit" "$t" "$wall" "$cpu" "$execs" \
      "${findings// /,}" >>"$ledger"
    "$root/scripts/fuzz-hours.sh" --update
  fi
done
exit "$found"
