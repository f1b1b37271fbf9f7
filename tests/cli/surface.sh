#!/usr/bin/env bash
# Surface bodies (asset format 1.2) in the tools: tetseg-dump shows the body kind, detector
# form, terms and bone names of the golden 1.2 assets; tetseg-ccd frames --asset culls a
# frame pair with the asset's clusters and detectors, finds the contacts the plain soup path
# finds first, and refuses frames whose vertices or faces are not the asset's.
# needs: bench
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.bash"  # $bin, $work, fail, expect_exit
src=${TETSEG_SOURCE_DIR:?}
weights=$src/tests/golden/asset-v1.2.tetseg
bones=$src/tests/golden/asset-v1.2-bones.tetseg

# tetseg-dump: text and JSON.
"$bin/tetseg-dump" "$weights" > w.txt
grep -q "format 1.2" w.txt || fail "dump: version: $(cat w.txt)"
grep -q "^  body  *surface$" w.txt || fail "dump: body kind: $(cat w.txt)"
grep -q "^  detector form  *surface-weights$" w.txt || fail "dump: form: $(cat w.txt)"
grep -q "detector terms  *8 (3 to 5 per cluster" w.txt || fail "dump: term summary: $(cat w.txt)"
grep -q "weights n0:0.125 n2:0.125 n1:0.125 n3:0.125 (+1 terms) at (0, 0, 0.5)" w.txt ||
  fail "dump: cluster 0 detector: $(cat w.txt)"
"$bin/tetseg-dump" "$bones" > b.txt
grep -q '^  bones  *3: 0="root" 1="spine" 2="head"$' b.txt || fail "dump: bone names: $(cat b.txt)"
# The weights golden maps 9 file vertices (seam copies) onto its 7 nodes; the bones one has no map.
grep -q "^  source vertices  *9 mapped onto 7 nodes" w.txt || fail "dump: source vertex map: $(cat w.txt)"
grep -q "^  source vertices  *none mapped" b.txt || fail "dump: no source vertex map: $(cat b.txt)"
"$bin/tetseg-dump" "$weights" --json > w.json
grep -q '"source_vertices": 9, "source_vertex_map": true' w.json || fail "dump --json: map: $(cat w.json)"
grep -q "bones 1:0.75 2:0.25 at (0, 0, 0.5)" b.txt || fail "dump: bone detector: $(cat b.txt)"
grep -q "overlap-only  bones none at (0, 0, -0.5)" b.txt || fail "dump: overlap-only cluster: $(cat b.txt)"
"$bin/tetseg-dump" "$bones" --json > b.json
grep -q '"body": "surface"' b.json || fail "dump --json: body: $(cat b.json)"
grep -q '"detector_form": "bones"' b.json || fail "dump --json: form: $(cat b.json)"
grep -q '"source_vertices": 7, "source_vertex_map": false' b.json || fail "dump --json: no map: $(cat b.json)"
grep -q '"bone_names": \["root", "spine", "head"\]' b.json || fail "dump --json: bones: $(cat b.json)"
grep -q '"detector": {"form": "bones", "terms": \[\[1, 0.75\], \[2, 0.25\]\], "position": \[0, 0, 0.5\]}' b.json ||
  fail "dump --json: detector: $(cat b.json)"
"$bin/tetseg-dump" "$weights" --vtu w.vtu --ply w.ply > /dev/null
grep -q "<VTKFile" w.vtu || fail "dump --vtu of a surface asset"
grep -q "^ply" w.ply || fail "dump --ply of a surface asset"
"$bin/tetseg-render" "$bones" -o b.png --width 64 --height 48 --detectors
[ "$(head -c 4 b.png | tail -c 3)" = "PNG" ] || fail "tetseg-render of a surface asset: no PNG"

# The golden octahedron's frames: its 7 vertices (the 7th used by no face) and 8 triangles;
# the top vertex 4 falls through the lower half, past the detector of the upper cluster.
ply() {  # ply FILE TOP_X TOP_Y TOP_Z [FACES...]: the octahedron with vertex 4 at TOP
  local file=$1 x=$2 y=$3 z=$4
  shift 4
  local faces=("$@")
  {
    printf 'ply\nformat ascii 1.0\nelement vertex 7\nproperty double x\nproperty double y\nproperty double z\n'
    printf 'element face %d\nproperty list uchar int vertex_indices\nend_header\n' "${#faces[@]}"
    printf '1 0 0\n-1 0 0\n0 1 0\n0 -1 0\n%s %s %s\n0 0 -1\n3 3 3\n' "$x" "$y" "$z"
    for f in "${faces[@]}"; do printf '3 %s\n' "$f"; done
  } > "$file"
}
faces=("0 2 4" "2 1 4" "1 3 4" "3 0 4" "2 0 5" "1 2 5" "3 1 5" "0 3 5")
ply t0.ply 0 0 1 "${faces[@]}"
ply t1.ply 0.1 0.05 -2 "${faces[@]}"
"$bin/tetseg-ccd" frames t0.ply t1.ply 2>/dev/null > soup.txt
[ -s soup.txt ] || fail "the soup path finds no contact"
grep -q '^vf 4 2 0 5 ' soup.txt || fail "soup: vertex 4 through face 2 0 5 not found: $(cat soup.txt)"
first=$(sort -g -k6 soup.txt | head -1 | cut -d' ' -f1-5)
for asset in "$weights" "$bones"; do
  "$bin/tetseg-ccd" frames t0.ply t1.ply --asset "$asset" 2>err.txt > asset.txt
  grep -q "rvbc with the asset's clusters" err.txt || fail "--asset: not culled by the asset: $(cat err.txt)"
  # Every contact reported is a soup contact at the same time, and the earliest is found.
  while read -r line; do
    grep -qxF -- "$line" soup.txt || fail "--asset ($asset): '$line' is not a soup contact"
  done < asset.txt
  grep -q "^$first " asset.txt || fail "--asset ($asset): the earliest contact '$first' is missing: $(cat asset.txt)"
done
echo "frames --asset: $(wc -l < asset.txt) of $(wc -l < soup.txt) soup contacts, earliest '$first' found"

# tetseg-run over the same step as a frame sequence: both surface assets give brute force's
# earliest contact; the bones asset runs with its detectors at rest (said on stderr).
"$bin/tetseg-frames" step.tsf t0.ply t1.ply 2>/dev/null
"$bin/tetseg-run" "$weights" step.tsf --mode brute --json > brute.json
earliest=$(grep -o '"earliest_toi": [0-9.e-]*' brute.json)
[ -n "$earliest" ] || fail "tetseg-run brute: no contact: $(cat brute.json)"
for asset in "$weights" "$bones"; do
  "$bin/tetseg-run" "$asset" step.tsf --json > run.json 2> run.err
  grep -qF "$earliest" run.json || fail "tetseg-run ($asset): not brute force's $earliest: $(cat run.json)"
done
grep -q "detectors carried by bones stay at their rest positions" run.err ||
  fail "tetseg-run: no note on the bones asset: $(cat run.err)"

# Frames that are not the asset's: refused with the reason, exit 3.
ply six.ply 0 0 1 "${faces[@]}"
sed -i 's/^element vertex 7$/element vertex 6/; /^3 3 3$/d' six.ply
ply six1.ply 0 0 -1 "${faces[@]}"
sed -i 's/^element vertex 7$/element vertex 6/; /^3 3 3$/d' six1.ply
expect_exit 3 "six.ply: 6 vertices, the asset .* has 7 nodes" -- "$bin/tetseg-ccd" frames six.ply six1.ply --asset "$weights"
# A frame over the 9 file vertices the weights golden was read from (its map): named as such.
{
  printf 'ply\nformat ascii 1.0\nelement vertex 9\nproperty double x\nproperty double y\nproperty double z\n'
  printf 'element face 1\nproperty list uchar int vertex_indices\nend_header\n'
  printf '0 0 1\n1 0 0\n-1 0 0\n0 1 0\n0 -1 0\n0 0 1\n0 0 -1\n3 3 3\n1 0 0\n3 1 2 3\n'
} > nine.ply
expect_exit 3 "nine.ply: 9 vertices, the asset .* has 7 nodes .*input file's vertices, which the asset merged" -- "$bin/tetseg-ccd" frames nine.ply nine.ply --asset "$weights"
swapped=("2 0 4" "2 1 4" "1 3 4" "3 0 4" "2 0 5" "1 2 5" "3 1 5" "0 3 5")
ply s0.ply 0 0 1 "${swapped[@]}"
ply s1.ply 0 0 -1 "${swapped[@]}"
expect_exit 3 "s0.ply: face 0 differs from triangle 0 of the asset" -- "$bin/tetseg-ccd" frames s0.ply s1.ply --asset "$weights"
ply f0.ply 0 0 1 "${faces[@]:0:7}"
ply f1.ply 0 0 -1 "${faces[@]:0:7}"
expect_exit 3 "f0.ply: 7 faces, the asset .* has 8 triangles" -- "$bin/tetseg-ccd" frames f0.ply f1.ply --asset "$weights"
expect_exit 3 "tetseg-ccd: error: missing.tetseg: " -- "$bin/tetseg-ccd" frames t0.ply t1.ply --asset missing.tetseg
expect_exit 2 "" -- "$bin/tetseg-ccd" frames t0.ply t1.ply --asset "$weights" --brute
echo "ok"
