#!/usr/bin/env bash
# End to end with several bodies: tetseg-sim drops two small soft balls onto each other over a
# still box (and, in a second run, into a bin beside a still sphere) and writes a scene
# description; tetseg-bench scene checks against the brute-force oracle over the whole scene
# that no written frame intersects, no step the simulator accepted (--substeps 1) has a
# contact, and no contact is missed. The same drop without contact handling intersects (the
# check can fail) while the scene still misses none of the oracle's contacts. Also: two runs
# are byte-identical, and bad input exits 2 or 3 naming the problem.
# needs: preprocess
# needs: bench
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.bash"

sim="$bin/tetseg-sim"
bench="$bin/tetseg-bench"
"$bin/tetseg" generate sphere --radius 0.3 --size 0.3 -o b.mesh 2>/dev/null
"$bin/tetseg" build b.mesh -o b.tetseg -q
# Ball 0 lands on the box (top at 0.1), ball 1 falls onto ball 0, off centre.
args=(--body b.mesh,b.tetseg,0.2,0,0 --body b.mesh,b.tetseg,0.9,0.15,0.05
  --box=-0.8,-0.8,-0.05,0.8,0.8,0.1 --obstacle-resolution 4
  --substeps 1 --dt 0.005 --frames 120 --edge-compliance 5e-3)

"$sim" "${args[@]}" -o a.tsf --scene a.tsscene --json > a.json
"$sim" "${args[@]}" -o b.tsf --scene b.tsscene --json > b.json
cmp a.tsf b.tsf || fail "two runs differ"
cmp a.json b.json || fail "two runs report different counters"
python3 - <<'PY'
import json, os
d = json.load(open("a.json"))
assert d["bodies"] == 2 and d["obstacles"] == 1 and d["substeps"] == 119, d
assert d["body_contacts"] > 0, "the balls must touch each other or the box: %s" % d
assert os.path.getsize("a.tsf") == 24 + 24 * d["nodes"] * 120
lines = open("a.tsscene").read().split("\n")
assert lines[:2] == ["tetseg-scene 1", "frames a.tsf"], lines[:2]
assert lines[2].startswith("tet b.tetseg ") and lines[3].startswith("tet b.tetseg "), lines
assert lines[4].startswith("obstacle "), lines[4]
PY

# Every written step is an accepted substep: no frame intersects, brute force finds no contact
# in any step, and the scene misses nothing.
table_ok() {  # table_ok FILE: every row has 0 missed and 0 extra contacts
  python3 - "$1" <<'PY'
import sys
rows = [l.split("|")[1:-1] for l in open(sys.argv[1]) if l.startswith("| ") and "---" not in l]
head = [c.strip() for c in rows[0]]
assert len(rows) > 1, rows
for r in rows[1:]:
    r = dict(zip(head, (c.strip() for c in r)))
    assert int(r["steps"]) == 119 and r["bodies"] == "3", r
    assert r["missed"] == "0" and r["extra"] == "0", r
    print(r["scene"], "brute contacts per step", r["brute contacts"])
PY
}
"$bench" scene drop a.tsscene --expect-clean --repeat 1 > check.txt 2>/dev/null ||
  { cat check.txt >&2; fail "frames not clean"; }
grep -q "drop: intersecting frames 0, steps with brute-force contacts 0" check.txt ||
  fail "check output"
table_ok check.txt > /dev/null

# Without contact handling the balls pass into each other and the box: the check fails, and
# the scene reports every contact the oracle finds.
"$sim" "${args[@]}" --no-self-contact -o n.tsf --scene n.tsscene 2>/dev/null
set +e; "$bench" scene none n.tsscene --expect-clean --repeat 1 > checkn.txt 2>/dev/null; rc=$?
set -e
[ "$rc" -eq 1 ] || fail "check of an intersecting scene exited $rc"
grep -q "none: intersecting frames [1-9]" checkn.txt || fail "no intersecting frame reported"
"$bench" scene none n.tsscene --repeat 1 > tablen.txt 2>/dev/null || fail "missed contacts"
table_ok tablen.txt | grep -qv "brute contacts per step 0.0$" || fail "no contact to compare"

# A bin (open box) and a still sphere, the bvh mode inside the balls: clean as well.
"$sim" --body b.mesh,b.tetseg,0.5,0.5,0 --body b.mesh,b.tetseg,0.3,-0.3,0 --mode bvh \
  --bin=-1,-1,-0.05,1,1,0.6 --sphere=0.5,0,0.2,0.2 --obstacle-resolution 3 \
  --substeps 1 --dt 0.005 --frames 60 --edge-compliance 5e-3 -o s.tsf --scene s.tsscene \
  --json > s.json
"$bench" scene bin s.tsscene --expect-clean --repeat 1 > /dev/null 2>&1 || fail "bin not clean"
python3 -c 'import json; d = json.load(open("s.json")); assert d["body_contacts"] > 0, d'

# Bad input.
expect_exit 2 "no soft body" -- "$sim" -o x.tsf --box=0,0,0,1,1,1
expect_exit 2 "not a number" -- "$sim" --body b.mesh,b.tetseg,0.2 --box=0,0,0,1,1,z -o x.tsf
expect_exit 2 "MIN < MAX" -- "$sim" --body b.mesh,b.tetseg --box=0,0,0,1,0,1 -o x.tsf
expect_exit 3 "missing.tetseg" -- "$sim" --body b.mesh,missing.tetseg -o x.tsf
expect_exit 3 "touches body 1" -- "$sim" --body b.mesh,b.tetseg,0.2,0,0 \
  --body b.mesh,b.tetseg,0.2,0.1,0 -o x.tsf
[ ! -e x.tsf ] || fail "output written on error"
head -n 6 a.tsscene > cut.tsscene
expect_exit 3 "cut.tsscene: line 6: unexpected end" -- "$bench" scene cut cut.tsscene
sed 's/^tet b.tetseg [0-9]*/tet b.tetseg 7/' a.tsscene > wrong.tsscene
expect_exit 3 "node count differs" -- "$bench" scene wrong wrong.tsscene
echo "scene: ok"
