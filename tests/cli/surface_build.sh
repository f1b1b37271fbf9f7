#!/usr/bin/env bash
# tetseg build --body surface: the input surface kept as it is (vertex count, unused vertices
# and order), the report and dump say so, and bad surfaces and option pairs are refused with
# the reason and the right exit code.
# needs: preprocess
# needs: bench
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.bash"  # $bin, $work, fail, expect_exit

# A closed surface: the boundary of a generated sphere (tetseg-bench surface).
"$bin/tetseg" generate sphere -o sphere.mesh --size 0.6 2>/dev/null
"$bin/tetseg" build sphere.mesh -o sphere.tetseg --clusters single -q
"$bin/tetseg-bench" surface sphere.tetseg sphere.off
# An unwritable output is refused with the file named (exit 4), not a crash.
expect_exit 4 "tetseg-bench: error: no-such-dir/s.off: cannot write" -- \
  "$bin/tetseg-bench" surface sphere.tetseg no-such-dir/s.off
# The same surface with its vertices in reverse order and one unused vertex at the end.
python3 - <<'PY'
lines = open("sphere.off").read().split("\n")
nv, nt = map(int, lines[1].split()[:2])
vertices = lines[2:2 + nv][::-1] + ["9 9 9"]
faces = []
for line in lines[2 + nv:2 + nv + nt]:
    k, a, b, c = map(int, line.split())
    faces.append(f"3 {nv - 1 - a} {nv - 1 - b} {nv - 1 - c}")
open("reversed.off", "w").write(f"OFF\n{nv + 1} {nt} 0\n" + "\n".join(vertices + faces) + "\n")
# One triangle turned the other way round.
a, b, c = faces[0].split()[1:]
open("flipped.off", "w").write(f"OFF\n{nv + 1} {nt} 0\n" + "\n".join(vertices + [f"3 {b} {a} {c}"] + faces[1:]) + "\n")
PY
nodes=$(sed -n 2p reversed.off | cut -d' ' -f1)

"$bin/tetseg" build reversed.off -o surface.tetseg --body surface --report report.json 2>stages.txt
grep -q "^tetseg: tetrahedralize" stages.txt && fail "a surface body was tetrahedralised"
grep -q "^tetseg: detectors .* by weights" stages.txt || fail "detectors stage: $(cat stages.txt)"
grep -q '"body": "surface", "detectors": "weights"' report.json || fail "report: $(head -5 report.json)"
grep -q "\"nodes\": $nodes," report.json || fail "report counts: $(grep counts report.json)"
grep -q '"body": "surface"' report.json || fail "provenance: $(grep options report.json)"
"$bin/tetseg-dump" surface.tetseg > dump.txt
grep -q "^  body  *surface$" dump.txt || fail "dump: $(cat dump.txt)"
"$bin/tetseg-dump" surface.tetseg --json > dump.json
grep -q "\"nodes\": $nodes," dump.json || fail "dump nodes: $(head -c 300 dump.json)"
# The same build twice gives the same bytes.
"$bin/tetseg" build reversed.off -o again.tetseg --body surface -q
cmp -s surface.tetseg again.tetseg || fail "surface body build is not deterministic"

expect_exit 3 "not consistently oriented" -- "$bin/tetseg" build flipped.off -o x.tetseg --body surface
[ ! -e x.tetseg ] || fail "a refused build wrote its output"
expect_exit 3 "builds from a surface file" -- "$bin/tetseg" build sphere.mesh -o x.tetseg --body surface
expect_exit 2 "needs --body surface" -- "$bin/tetseg" build sphere.off -o x.tetseg --detectors weights
expect_exit 2 "" -- "$bin/tetseg" build sphere.off -o x.tetseg --body shell
echo "surface_build: ok"
