#!/usr/bin/env bash
# The generated skinned character (tetseg-character) and `tetseg build --body surface
# --detectors skin`: outputs, determinism, refusals (issue 29).
# needs: preprocess
# needs: bench
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.bash"

expect_exit 2 "" -- "$bin/tetseg-character"
expect_exit 2 "" -- "$bin/tetseg-character" -o x --bones 0
"$bin/tetseg-character" -o tube --frames 9 >/dev/null
"$bin/tetseg-character" -o again --frames 9 >/dev/null
for f in gltf tsf bones.tsf; do
  [ -s "tube.$f" ] || fail "no tube.$f"
  cmp -s "tube.$f" "again.$f" || fail "tetseg-character is not deterministic ($f)"
done
python3 - tube.tsf tube.bones.tsf <<'PY'
import struct, sys
def header(path):
    data = open(path, "rb").read()
    assert data[:8] == b"TSFRAMES", path
    nodes, frames = struct.unpack("<II", data[12:20])
    assert len(data) == 24 + 24 * nodes * frames, path
    return nodes, frames, data
nodes, frames, surface = header(sys.argv[1])
bones, bone_frames, matrices = header(sys.argv[2])
assert frames == bone_frames == 9 and bones == 4 * 4, (frames, bone_frames, bones)
# Frame 0 is the rest pose: every skinning matrix is the identity.
first = struct.unpack("<48d", matrices[24:24 + 48 * 8])
assert first == (1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0) * 4, first
PY

"$bin/tetseg" build tube.gltf --body surface --detectors skin -o skin.tetseg --report skin.json \
  2>build.txt
grep -q "tetseg: skin .* 4 bones" build.txt || fail "no skin stage"
"$bin/tetseg" build tube.gltf --body surface --detectors skin -o skin2.tetseg -q
cmp -s skin.tetseg skin2.tetseg || fail "the skinned build is not deterministic"
"$bin/tetseg-dump" skin.tetseg --json >dump.json
python3 - dump.json skin.json <<'PY'
import json, sys
dump, report = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
assert report["body"] == "surface" and report["detectors"] == "skin", report
assert dump["format_version"] == "1.2", dump["format_version"]
assert dump["provenance"]["options"]["detectors"] == "skin", dump["provenance"]
assert dump["nodes"] == report["counts"]["nodes"] == 1322, dump["nodes"]
PY

# Refusals: no skin in the file (exit 3, naming it); skin without a surface body (exit 2).
sed 's/,"skin":0//' tube.gltf >bare.gltf
expect_exit 3 "tetseg: error: bare.gltf: .*has no bones" -- \
  "$bin/tetseg" build bare.gltf --body surface --detectors skin -o bare.tetseg
[ ! -e bare.tetseg ] || fail "a refused build left an asset"
expect_exit 2 "needs --body surface" -- \
  "$bin/tetseg" build tube.gltf --detectors skin -o tet.tetseg

# tetseg-bench table poses the bone-carried detectors from the --bones file: 0 missed.
"$bin/tetseg-bench" table tube skin.tetseg tube.tsf --bones tube.bones.tsf --modes rvbc,bvh \
  --repeat 1 --json >table.json
python3 - table.json <<'PY'
import json, sys
rows = json.load(open(sys.argv[1]))["rows"]
assert [r["mode"] for r in rows] == ["rvbc", "bvh"], rows
assert all(r["steps"] == 8 and r["compared"] == 8 and r["missed"] == 0 and r["extra"] == 0
           for r in rows), rows
PY
expect_exit 2 "give --bones" -- "$bin/tetseg-bench" table tube skin.tetseg tube.tsf --repeat 1
"$bin/tetseg" build tube.gltf --body surface -o weights.tetseg -q
expect_exit 2 "more --bones files" -- "$bin/tetseg-bench" table tube weights.tetseg tube.tsf \
  --bones tube.bones.tsf --repeat 1
expect_exit 3 "tube.tsf: expected 4 bones" -- "$bin/tetseg-bench" table tube skin.tetseg \
  tube.tsf --bones tube.tsf --repeat 1
