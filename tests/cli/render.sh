#!/usr/bin/env bash
# Pictures for people: tetseg-render (PNG) and tetseg-dump --vtu/--ply on the golden asset and
# on hand-written PLY files; PNGs are decoded independently (python zlib) and checked.
set -euo pipefail
src=${TETSEG_SOURCE_DIR:?}
source "$(dirname "${BASH_SOURCE[0]}")/common.bash"

golden=$src/tests/golden/asset-v1.0.tetseg
expect_exit 0 "Usage" -- "$bin/tetseg-render" --help
expect_exit 2 "" -- "$bin/tetseg-render" "$golden"
expect_exit 2 "" -- "$bin/tetseg-render" "$golden" -o x.png --width 3
expect_exit 3 "tetseg-render: error: missing.tetseg: " -- "$bin/tetseg-render" missing.tetseg -o x.png
[ ! -e x.png ] || fail "a failed render left a file"
expect_exit 4 "tetseg-render: error: nodir/x.png" -- "$bin/tetseg-render" "$golden" -o nodir/x.png

# decode FILE: pixels of a PNG decoded independently (python zlib; the five PNG row filters),
# after checking signature, chunk CRCs, IHDR and the zlib stream (with its Adler-32).
cat > png.py <<'PY'
import struct, zlib
def decode(path):
    d = open(path, "rb").read()
    assert d[:8] == b"\x89PNG\r\n\x1a\n", "signature"
    pos, idat, ihdr = 8, b"", None
    while pos < len(d):
        n, = struct.unpack(">I", d[pos:pos + 4])
        kind, body = d[pos + 4:pos + 8], d[pos + 8:pos + 8 + n]
        crc, = struct.unpack(">I", d[pos + 8 + n:pos + 12 + n])
        assert zlib.crc32(kind + body) & 0xffffffff == crc, "CRC of %r" % kind
        if kind == b"IHDR": ihdr = body
        if kind == b"IDAT": idat += body
        pos += 12 + n
    w, h, depth, ctype, comp, filt, lace = struct.unpack(">IIBBBBB", ihdr)
    assert (depth, ctype, comp, filt, lace) == (8, 2, 0, 0, 0), "IHDR"
    raw = zlib.decompress(idat)
    assert len(raw) == h * (3 * w + 1), "size"
    rows = []
    for y in range(h):
        f, line = raw[y * (3 * w + 1)], bytearray(raw[y * (3 * w + 1) + 1:(y + 1) * (3 * w + 1)])
        assert f in (0, 1, 2, 3, 4), "filter %d" % f
        prev = rows[-1] if rows else bytes(len(line))
        for x in range(len(line)):
            a = line[x - 3] if x >= 3 else 0
            b, c = prev[x], (prev[x - 3] if x >= 3 else 0)
            if f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                predictor = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            else:
                predictor = (0, a, b, (a + b) // 2)[f]
            line[x] = (line[x] + predictor) & 255
        rows.append(bytes(line))
    return w, h, rows
PY
# checkpng FILE WIDTH HEIGHT MIN_COLOURS: a valid PNG of that size whose corners are background
# and with at least MIN_COLOURS distinct non-background colours.
checkpng() {
  python3 - "$@" <<'PY'
import sys
sys.path.insert(0, ".")
from png import decode
path, w, h, min_colours = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
W, H, rows = decode(path)
assert (W, H) == (w, h), (W, H)
px = lambda x, y: tuple(rows[y][3 * x:3 * x + 3])
for x, y in ((0, 0), (w - 1, 0), (0, h - 1), (w - 1, h - 1)):
    assert px(x, y) == (255, 255, 255), "corner %s" % (px(x, y),)
colours = {px(x, y) for y in range(h) for x in range(w)} - {(255, 255, 255)}
assert len(colours) >= min_colours, "only %d colours" % len(colours)
PY
}

# The golden asset: two clusters, one boundary, detector nodes.
"$bin/tetseg-render" "$golden" -o golden.png --width 160 --height 120 --detectors
checkpng golden.png 160 120 4 || fail "golden.png"
"$bin/tetseg-render" "$golden" -o again.png --width 160 --height 120 --detectors
cmp golden.png again.png || fail "two renders differ"
"$bin/tetseg-render" "$golden" -o side.png --view 0,0,-1 --up 0,1,0 --no-boundaries
checkpng side.png 800 600 1 || fail "side.png"

# The compressed and the stored encodings hold the same pixels; compression pays.
"$bin/tetseg-render" "$golden" -o side_stored.png --view 0,0,-1 --up 0,1,0 --no-boundaries --png-stored
python3 - side.png side_stored.png <<'PY'
import os, sys
sys.path.insert(0, ".")
from png import decode
a, b = decode(sys.argv[1]), decode(sys.argv[2])
assert a == b, "pixels differ between encodings"
assert os.path.getsize(sys.argv[1]) * 5 < os.path.getsize(sys.argv[2]), "no compression"
# Looking down -z at the octahedron shows only the upper cluster (0): palette colour 0,
# (31, 119, 180), shaded by a factor in [0.45, 1]; nothing of the lower one.
w, h, rows = a
r, g, b = rows[h // 2][3 * (w // 2):3 * (w // 2) + 3]
assert b > g > r and 0.45 * 180 - 2 <= b <= 181, (r, g, b)
PY

# tetseg-dump --vtu / --ply: counts match the asset (8 triangles, 1 loop of 4 nodes, 2 clusters).
"$bin/tetseg-dump" "$golden" --vtu golden.vtu --ply golden.ply >/dev/null
python3 - golden.vtu golden.ply <<'PY'
import sys
import xml.etree.ElementTree as ET
piece = ET.parse(sys.argv[1]).getroot().find("UnstructuredGrid/Piece")
assert piece.get("NumberOfCells") == "11", piece.get("NumberOfCells")
arrays = {a.get("Name"): a.text.split() for a in piece.iter("DataArray") if a.get("Name")}
assert arrays["types"] == ["5"] * 8 + ["4"] + ["1"] * 2, arrays["types"]
assert arrays["cluster"][:8].count("0") == 4 and arrays["cluster"][:8].count("1") == 4
assert arrays["offsets"][-1] == str(len(arrays["connectivity"]))
conn = arrays["connectivity"][24:29]
assert conn[0] == conn[-1] and len(set(conn)) == 4, conn  # a closed loop of 4 nodes
lines = open(sys.argv[2]).read().split("\n")
assert lines[0] == "ply" and "element face 8" in lines and "element edge 4" in lines
body = lines[lines.index("end_header") + 1:]
faces = [l.split() for l in body[6:14]]
assert all(f[0] == "3" and len(f) == 8 for f in faces)
assert {f[7] for f in faces} == {"0", "1"}
PY

# A PLY with face colours and a face scalar, as `tetseg charge -o x.ply` writes: a cube.
cat > cube.ply <<'EOF'
ply
format ascii 1.0
element vertex 8
property float x
property float y
property float z
element face 6
property list uchar int vertex_indices
property uchar red
property uchar green
property uchar blue
property float charge
end_header
0 0 0
0 0 1
0 1 0
0 1 1
1 0 0
1 0 1
1 1 0
1 1 1
4 0 2 6 4 255 0 0 0.1
4 1 5 7 3 0 255 0 0.5
4 0 4 5 1 0 0 255 1.0
4 2 3 7 6 255 255 0 2.0
4 0 1 3 2 0 255 255 3.0
4 4 6 7 5 255 0 255 4.0
EOF
"$bin/tetseg-render" cube.ply -o cube.png --width 64 --height 64
checkpng cube.png 64 64 3 || fail "cube.png"
"$bin/tetseg-render" cube.ply -o charge.png --width 64 --height 64 --scalar charge
checkpng charge.png 64 64 3 || fail "charge.png"
cmp -s cube.png charge.png && fail "--scalar did not change the colours"
expect_exit 3 "no property 'density'" -- "$bin/tetseg-render" cube.ply -o x.png --scalar density
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n' >bad.ply
expect_exit 3 "tetseg-render: error: bad.ply: PLY" -- "$bin/tetseg-render" bad.ply -o x.png
printf 'ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nend_header\n' >huge.ply
expect_exit 3 "tetseg-render: error: huge.ply: PLY" -- "$bin/tetseg-render" huge.ply -o x.png
[ ! -e x.png ] || fail "a failed render left a file"

# An asset without rest positions cannot be drawn: exit 3 with a clear message.
if [ -x "$bin/tetseg" ]; then
  "$bin/tetseg" generate sphere -o sphere.mesh --size 0.5 2>/dev/null
  "$bin/tetseg" build sphere.mesh -o bare.tetseg --clusters single --no-rest-positions -q
  expect_exit 3 "no rest positions" -- "$bin/tetseg-render" bare.tetseg -o x.png
  expect_exit 3 "no rest positions" -- "$bin/tetseg-dump" bare.tetseg --vtu x.vtu
  [ ! -e x.png ] && [ ! -e x.vtu ] || fail "a failed output left a file"
else
  echo "WARN: tetseg not built; the no-rest-positions case is not checked"
fi
echo "render: ok"
