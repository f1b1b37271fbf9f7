#!/usr/bin/env bash
# End to end: tetseg-scene -> tetseg-run in every mode and query (JSON shape, agreement of the
# modes on "any" and on the earliest time of impact), tetseg-frames from .obj/.ply files,
# exit codes on bad input.
# needs: bench
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.bash"

expect_exit 0 "Usage" -- "$bin/tetseg-run" --help
expect_exit 0 "tetseg-run 0.1" -- "$bin/tetseg-run" --version
expect_exit 2 "" -- "$bin/tetseg-run"
expect_exit 2 "" -- "$bin/tetseg-run" a b --mode fast
expect_exit 3 "tetseg-run: error: missing.tetseg: " -- "$bin/tetseg-run" missing.tetseg missing.tsf

"$bin/tetseg-scene" dumbbell d.tetseg d.tsf --segments 16 --rings 20 --frames 10 --obj-dir . 2>/dev/null
"$bin/tetseg-scene" sphere s.tetseg s.tsf --segments 12 --rings 8 --frames 4 2>/dev/null
expect_exit 3 "has .* nodes, the asset has" -- "$bin/tetseg-run" d.tetseg s.tsf
printf 'TSFRAMES\001\000\000\000' > short.tsf
expect_exit 3 "tetseg-run: error: short.tsf: too short" -- "$bin/tetseg-run" d.tetseg short.tsf

for mode in rvbc bvh brute; do
  for query in any earliest all; do
    "$bin/tetseg-run" d.tetseg d.tsf --mode "$mode" --query "$query" --json > "$mode-$query.json"
  done
done
python3 - <<'PY'
import json, sys
def load(m, q): return json.load(open(f"{m}-{q}.json"))
for m in ("rvbc", "bvh", "brute"):
    for q in ("any", "earliest", "all"):
        d = load(m, q)
        assert set(d) == {"mode", "query", "frames", "mean_ms"}, d.keys()
        assert d["mode"] == m and d["query"] == q
        assert set(d["mean_ms"]) == {"refit", "classify", "traversal", "tests", "total"}
        assert len(d["frames"]) == 9
        for i, f in enumerate(d["frames"]):
            assert set(f) == {"frame", "any", "earliest_toi", "contacts"} and f["frame"] == i
            if q == "all": assert isinstance(f["contacts"], int) and f["any"] == (f["contacts"] > 0)
            if q != "any": assert (f["earliest_toi"] is None) == (not f["any"])
brute = load("brute", "all")["frames"]
assert any(f["any"] for f in brute), "the scene must reach a contact"
first = next(i for i, f in enumerate(brute) if f["any"])
for m in ("rvbc", "bvh"):
    for q in ("any", "earliest", "all"):
        fr = load(m, q)["frames"]
        # Up to the first contact (after it the start state may be self-intersecting).
        for i in range(first + 1):
            assert fr[i]["any"] == brute[i]["any"], (m, q, i)
        if q != "any":
            assert abs(fr[first]["earliest_toi"] - brute[first]["earliest_toi"]) < 1e-9, (m, q)
PY

# Frame files from meshes: the .obj frames written by tetseg-scene give the same bytes.
"$bin/tetseg-frames" fromobj.tsf frame_000*.obj 2>/dev/null
cmp fromobj.tsf d.tsf || fail "frames from .obj differ from the generated frames"
# A .ply (ascii) and a Medit .mesh with the same vertices convert to the same positions.
python3 - <<'PY'
v = [l.split()[1:] for l in open("frame_0000.obj") if l.startswith("v ")]
with open("f0.ply", "w") as out:
    out.write(f"ply\nformat ascii 1.0\nelement vertex {len(v)}\nproperty double x\nproperty double y\nproperty double z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n")
    for p in v: out.write(" ".join(p) + "\n")
PY
python3 - <<'PY'
v = [l.split()[1:] for l in open("frame_0001.obj") if l.startswith("v ")]
with open("f1.mesh", "w") as out:
    out.write(f"MeshVersionFormatted 2\nDimension 3\nVertices\n{len(v)}\n")
    for p in v: out.write(" ".join(p) + " 0\n")
    out.write("End\n")
PY
"$bin/tetseg-frames" ply.tsf f0.ply f1.mesh 2>/dev/null
# Binary little-endian PLY with an extra float property and a face element.
python3 - <<'PY'
import struct
v = [[float(x) for x in l.split()[1:]] for l in open("frame_0000.obj") if l.startswith("v ")]
with open("f0b.ply", "wb") as out:
    out.write(f"ply\nformat binary_little_endian 1.0\nelement vertex {len(v)}\nproperty float q\nproperty double x\nproperty double y\nproperty double z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n".encode())
    for p in v: out.write(struct.pack("<f3d", 0.5, *p))
PY
"$bin/tetseg-frames" plyb.tsf f0b.ply f1.mesh 2>/dev/null
cmp plyb.tsf ply.tsf || fail "frames from binary .ply differ"
"$bin/tetseg-frames" obj.tsf frame_0000.obj frame_0001.obj 2>/dev/null
cmp ply.tsf obj.tsf || fail "frames from .ply differ from .obj"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' > tri.obj
expect_exit 3 "has 3 vertices, the first frame has" -- "$bin/tetseg-frames" bad.tsf frame_0000.obj f0.ply tri.obj
echo "v 1 2" > broken.obj
expect_exit 3 "tetseg-frames: error: broken.obj: " -- "$bin/tetseg-frames" bad.tsf broken.obj
[ ! -e bad.tsf ] || fail "a failed conversion left an output file"
echo "run: all checks passed"
