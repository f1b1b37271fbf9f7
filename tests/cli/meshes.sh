#!/usr/bin/env bash
# Surfaces and tet meshes as users have them: polygonal OFF solids (the 5-vertex pyramid and
# the 6-quad cube once died of SIGFPE in Mesh_3), binary Gmsh in and out, and hostile files:
# every run exits 0 or 3, an error names the file, and a failed run leaves no output.
# needs: preprocess
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.bash"

cat >pyramid.off <<'EOF'
OFF
5 5 0
-1 -0.5 -0.5
-1 -0.5  0.5
-1 0.5  0.5
-1 0.5  -0.5
1 0 0
3  1 0 4
3  2 1 4
3  3 2 4
3  0 3 4
4  0 1 2 3
EOF
cat >cube.off <<'EOF'
OFF
8 6 0
0 0 0
1 0 0
1 1 0
0 1 0
0 0 1
1 0 1
1 1 1
0 1 1
4 0 3 2 1
4 4 5 6 7
4 0 1 5 4
4 1 2 6 5
4 2 3 7 6
4 3 0 4 7
EOF

# The polygonal solids build with default options.
expect_exit 0 "tetseg: done" -- "$bin/tetseg" build pyramid.off -o pyramid.tetseg --clusters single
expect_exit 0 "tetseg: done" -- "$bin/tetseg" build cube.off -o cube.tetseg --clusters single
"$bin/tetseg-dump" pyramid.tetseg >/dev/null

# Binary Gmsh 4.1 out and back in; --binary and --gmsh22 exclude each other.
"$bin/tetseg" tetrahedralize cube.off -o cube.msh --binary --facet-size 0.2 2>/dev/null
head -c 20 cube.msh | grep -q '4.1 1 8' || fail "cube.msh is not binary Gmsh 4.1"
"$bin/tetseg" tetrahedralize cube.off -o cube_ascii.msh --facet-size 0.2 2>/dev/null
expect_exit 0 "tetseg: done" -- "$bin/tetseg" build cube.msh -o from_binary.tetseg --clusters single
"$bin/tetseg" build cube_ascii.msh -o from_ascii.tetseg --clusters single -q
expect_exit 2 "" -- "$bin/tetseg" tetrahedralize cube.off -o x.msh --binary --gmsh22
[ ! -e x.msh ] || fail "a usage error left a mesh"

# --repair auto (the default) fixes a duplicated face and says so; --repair none refuses it.
{ cat cube.off; echo "4 0 3 2 1"; } | sed 's/^8 6 0$/8 7 0/' >cube_dup.off
expect_exit 0 "tetseg: repaired cube_dup.off: 2 duplicate triangles removed" -- \
  "$bin/tetseg" tetrahedralize cube_dup.off -o dup.mesh --facet-size 0.25 --no-optimize
expect_exit 3 "tetseg: error: cube_dup.off: surface has [0-9]* non-manifold edges" -- \
  "$bin/tetseg" tetrahedralize cube_dup.off -o dup2.mesh --repair none
[ ! -e dup2.mesh ] || fail "a refused surface left a mesh"
expect_exit 2 "repair" -- "$bin/tetseg" build cube.off -o x.tetseg --repair bogus

# --repair none: build accepts and refuses exactly the surfaces tetrahedralize does (both run
# tetrahedralize's checks, once). Two cubes touching at one corner (a pinched vertex, as in
# modelled meshes) are accepted by both; without its top the cube is refused by both.
cat >pinch.off <<'EOF'
OFF
15 12 0
0 0 0
1 0 0
1 1 0
0 1 0
0 0 1
1 0 1
1 1 1
0 1 1
2 1 1
2 2 1
1 2 1
1 1 2
2 1 2
2 2 2
1 2 2
4 0 3 2 1
4 4 5 6 7
4 0 1 5 4
4 1 2 6 5
4 2 3 7 6
4 3 0 4 7
4 6 10 9 8
4 11 12 13 14
4 6 8 12 11
4 8 9 13 12
4 9 10 14 13
4 10 6 11 14
EOF
pinch_options=(--repair none --facet-size 0.2 --no-optimize)
expect_exit 0 "" -- "$bin/tetseg" tetrahedralize pinch.off -o pinch.mesh "${pinch_options[@]}"
expect_exit 0 "tetseg: done" -- \
  "$bin/tetseg" build pinch.off -o pinch.tetseg --clusters single "${pinch_options[@]}"
"$bin/tetseg-dump" pinch.tetseg --json | grep -q '"components": 2' || fail "pinch: not two bodies"
head -n 10 cube.off | sed 's/^8 6 0$/8 5 0/' >open.off
tail -n 5 cube.off >>open.off
for command in "tetrahedralize open.off -o open.mesh" "build open.off -o open.tetseg"; do
  expect_exit 3 "tetseg: error: open.off: surface is not closed" -- \
    "$bin/tetseg" $command --repair none
done

# The repairs go to the report and the provenance.
"$bin/tetseg" build cube_dup.off -o dup.tetseg --clusters single --facet-size 0.25 -q \
  --report dup.json
grep -q '"duplicate triangles removed": 2' dup.json || fail "the report lacks the repair"
grep -q '"hausdorff": {"input_to_mesh": ' dup.json || fail "the report lacks the distance"
"$bin/tetseg-dump" dup.tetseg | grep -q 'repairs.duplicate_triangles_removed *2' ||
  fail "the provenance lacks the repair"

# A cube without one face: fix fills the hole; auto, by default, wraps it instead (the patch is
# 1/6 of the area and 0.29 of the diagonal from the input, over --max-deviation 0.01), and fills
# it within --max-deviation 0.5. A tube with 2 x 1001 border edges (over fix's 1000): fix names
# it and points to wrap. A tube with 2 x 80: fix fills its ends, but auto wraps it (the patches
# are 20 % of the area, 0.2 of the diagonal from the input). Wrap (alpha larger than the hole)
# closes a hole.
sed -e 's/^8 6 0$/8 5 0/' -e '/^4 2 3 7 6$/d' cube.off >holed.off
expect_exit 0 "tetseg: repaired holed.off: 1 holes filled" -- \
  "$bin/tetseg" build holed.off -o filled.tetseg --clusters single --facet-size 0.25 --no-optimize \
  --repair fix
expect_exit 0 "auto wrapped the surface, as fix left: tetrahedralize: the holes filled by fix (17 % of the area) lie 0.2[89] of the diagonal" -- \
  "$bin/tetseg" build holed.off -o filled.tetseg --clusters single --facet-size 0.25 --no-optimize
expect_exit 0 "tetseg: repaired holed.off: 1 holes filled" -- \
  "$bin/tetseg" build holed.off -o filled.tetseg --clusters single --facet-size 0.25 --no-optimize \
  --max-deviation 0.5
# Two halves of the cube whose 8 seam edges have duplicated vertices (bottom, top and front
# on vertices 0-7; right, back and left on copies 8-15): the reader merges vertices by exact
# position, so the seam is closed as read and builds even with --repair none (stitching of
# borders that stay separate after reading is tested in tests/preprocess/repair_test.cpp).
{ sed -n '1,10p' cube.off | sed 's/^8 6 0$/16 6 0/'; sed -n '3,10p' cube.off
  printf '4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 9 10 14 13\n4 10 11 15 14\n4 11 8 12 15\n'; } >halves.off
expect_exit 0 "tetseg: read .* 8 vertices, 12 triangles" -- \
  "$bin/tetseg" build halves.off -o halves.tetseg --clusters single --repair none
tube() {
  python3 -c '
import math, sys
n = int(sys.argv[1])
print("OFF\n%d %d 0" % (2 * n, 2 * n))
for z in (0, 2):
    for i in range(n):
        print(0.5 * math.cos(2 * math.pi * i / n), 0.5 * math.sin(2 * math.pi * i / n), z)
for i in range(n):
    j = (i + 1) % n
    print(3, i, j, j + n)
    print(3, i, j + n, i + n)' "$1"
}
tube 1001 >wide.off
expect_exit 3 "tetseg: error: wide.off: surface is not closed (2002 border edges.*left after --repair fix; --repair wrap" -- \
  "$bin/tetseg" build wide.off -o wide.tetseg --clusters single --repair fix
[ ! -e wide.tetseg ] || fail "a refused surface left an asset"
tube 80 >tube.off
# --repair auto (the default) wraps what fix leaves and says why: stderr, report, provenance;
# the deviation is in the provenance of every build.
expect_exit 0 "tetseg: note: tube.off: --repair auto wrapped the surface, as fix left: .*the holes filled by fix (20 % of the area)" -- \
  "$bin/tetseg" build tube.off -o tube.tetseg --clusters single --report tube.json
grep -q '"repair_used": "wrap"' tube.json || fail "the report lacks the repair used"
grep -q '"fallback_reason": ".*the holes filled by fix' tube.json || fail "the report lacks the reason"
"$bin/tetseg-dump" tube.tetseg >tube.txt
grep -q 'meshing.repair_used *wrap' tube.txt || fail "the provenance lacks the repair used"
grep -q 'meshing.fallback_reason *.*the holes filled by fix' tube.txt ||
  fail "the provenance lacks the reason"
grep -q 'deviation.asset_to_input_absolute' tube.txt || fail "the provenance lacks the deviation"
expect_exit 0 "tetseg: repaired holed.off: [0-9]* surface replaced by an alpha wrap" -- \
  "$bin/tetseg" build holed.off -o holed.tetseg --clusters single --repair wrap --wrap-alpha 0.5 \
  --facet-size 0.2 --no-optimize --report holed.json
grep -q '"surface replaced by an alpha wrap of this many triangles": [1-9]' holed.json ||
  fail "the report lacks the wrap"
"$bin/tetseg-dump" holed.tetseg | grep -q 'meshing.wrap_alpha *0.5' ||
  fail "the provenance lacks the wrap options"
expect_exit 2 "wrap-alpha" -- "$bin/tetseg" build holed.off -o x.tetseg --repair wrap --wrap-alpha 0
# A flat sheet encloses nothing: wrap meshes it as a slab (2 x --wrap-sheet-offset thick) and
# reports it (stderr, report, provenance); the option is range-checked.
printf 'OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n' >sheet.off
expect_exit 0 "tetseg: repaired sheet.off: .*400 surface wrapped as a slab" -- \
  "$bin/tetseg" build sheet.off -o sheet.tetseg --clusters single --repair wrap \
  --wrap-sheet-offset 0.02 --report sheet.json
grep -q '"surface wrapped as a slab this many ten thousandths of the diagonal thick": 400' sheet.json ||
  fail "the report lacks the slab"
"$bin/tetseg-dump" sheet.tetseg | grep -q 'meshing.wrap_sheet_offset *0.02' ||
  fail "the provenance lacks the sheet offset"
"$bin/tetseg-dump" sheet.tetseg | grep -q 'repairs.surface_wrapped_as_a_slab' ||
  fail "the provenance lacks the slab repair"
expect_exit 2 "wrap-sheet-offset" -- "$bin/tetseg" build sheet.off -o x.tetseg --repair wrap \
  --wrap-sheet-offset 2

# Hostile variants of each kind of file: truncations, huge and negative counts, NaN, byte
# flips. The small facet size bounds the time of those that still read.
python3 - <<'PY'
import random, struct
random.seed(7)
files = {"pyramid.off": open("pyramid.off", "rb").read(),
         "cube.msh": open("cube.msh", "rb").read(),
         "cube_ascii.msh": open("cube_ascii.msh", "rb").read()}
ply = (b"ply\nformat binary_little_endian 1.0\nelement vertex 5\nproperty float x\n"
       b"property float y\nproperty float z\nelement face 5\n"
       b"property list uchar int vertex_indices\nend_header\n")
for p in [(-1, -.5, -.5), (-1, -.5, .5), (-1, .5, .5), (-1, .5, -.5), (1, 0, 0)]:
    ply += struct.pack("<3f", *p)
for f in [(1, 0, 4), (2, 1, 4), (3, 2, 4), (0, 3, 4), (0, 1, 2, 3)]:
    ply += struct.pack("<B", len(f)) + struct.pack("<%di" % len(f), *f)
files["pyramid.ply"] = ply
n = 0
def emit(name, data):
    global n
    stem, ext = name.rsplit(".", 1)
    open("hostile%03d_%s.%s" % (n, stem, ext), "wb").write(data)
    n += 1
for name, data in files.items():
    for cut in (0, 3, len(data) // 4, len(data) // 2, len(data) - 20):
        emit(name, data[:cut])
    for _ in range(8):
        d = bytearray(data)
        for _ in range(3):
            d[random.randrange(len(d))] = random.choice(b"09-.e \n$\x00\xff")
        emit(name, bytes(d))
text = files["pyramid.off"].decode()
for bad in ("5 99999999999 0", "-5 5 0", "2147483647 5 0", "5 5 0\n-1 nan -0.5"):
    emit("pyramid.off", text.replace("5 5 0", bad, 1).encode())
emit("pyramid.off", text.replace("4  0 1 2 3", "2000000000  0 1 2 3").encode())
for bad in (b"element vertex 99999999999", b"element vertex -3"):
    emit("pyramid.ply", ply.replace(b"element vertex 5", bad))
d = bytearray(ply)
at = ply.index(b"end_header\n") + 11 + 4
d[at:at + 4] = struct.pack("<f", float("nan"))
emit("pyramid.ply", bytes(d))
msh = files["cube.msh"]
at = msh.index(b"$Nodes\n") + 7 + 8
emit("cube.msh", msh[:at] + b"\xff" * 8 + msh[at + 8:])
PY
count=0
for f in hostile*; do
  count=$((count + 1))
  set +e
  "$bin/tetseg" build "$f" -o "$f.tetseg" --clusters single --facet-size 0.25 -q >out.txt 2>err.txt
  code=$?
  set -e
  case $code in
    0) [ -s "$f.tetseg" ] || fail "$f: exit 0 without an asset" ;;
    3) grep -q "tetseg: error: $f: " err.txt || { cat err.txt >&2; fail "$f: message does not name the file"; }
       [ ! -e "$f.tetseg" ] || fail "$f: a failed build left an asset" ;;
    *) cat err.txt >&2; fail "$f: exit $code (expected 0 or 3)" ;;
  esac
done
[ "$count" -ge 50 ] || fail "only $count hostile files"
echo "meshes.sh: all checks passed ($count hostile files)"
