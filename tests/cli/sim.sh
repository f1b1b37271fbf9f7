#!/usr/bin/env bash
# End to end: tetseg generate -> tetseg build -> tetseg-sim on a coarse soft dumbbell that
# folds onto itself. Checks with brute force (tetseg-bench check) that no written frame
# self-intersects and no step has a contact, that the same run without self-contact handling
# does intersect (so the check can fail), that contacts were resolved, that two runs are
# byte-identical, and the exit codes on bad input.
# needs: preprocess
# needs: bench
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.bash"

sim="$bin/tetseg-sim"
"$bin/tetseg" generate dumbbell --size 0.4 -o d.mesh 2>/dev/null
"$bin/tetseg" build d.mesh -o d.tetseg -q
args=(--substeps 1 --dt 0.005 --drop 0.1 --tilt-y 75 --edge-compliance 5e-3)

"$sim" d.mesh d.tetseg -o a.tsf --frames 150 "${args[@]}" --json > a.json
"$sim" d.mesh d.tetseg -o b.tsf --frames 150 "${args[@]}" --json > b.json
cmp a.tsf b.tsf || fail "two runs differ"
cmp a.json b.json || fail "two runs report different counters"
python3 - <<'PY'
import json, os
d = json.load(open("a.json"))
assert d["frames"] == 150 and d["substeps"] == 149, d
assert d["contacts_resolved"] > 0, "the dumbbell must fold onto itself: %s" % d
assert d["ground_contacts"] > 0, d
assert os.path.getsize("a.tsf") == 24 + 24 * d["nodes"] * 150
PY

# Every substep is a written step here (--substeps 1): brute force finds no contact in any
# step and no frame self-intersects.
"$bin/tetseg-bench" check d.tetseg a.tsf > check.txt || { cat check.txt >&2; fail "frames not clean"; }
grep -q "self-intersecting frames 0, steps with contacts 0" check.txt || fail "check output"

# Without self-contact handling the same drop intersects itself: the check can fail.
"$sim" d.mesh d.tetseg -o n.tsf --frames 150 "${args[@]}" --no-self-contact 2>/dev/null
set +e; "$bin/tetseg-bench" check d.tetseg n.tsf > checkn.txt; rc=$?; set -e
[ "$rc" -eq 1 ] || fail "check of an intersecting sequence exited $rc"

# The bvh mode in the simulator gives clean frames as well.
"$sim" d.mesh d.tetseg -o c.tsf --frames 60 "${args[@]}" --mode bvh 2>/dev/null
"$bin/tetseg-bench" check d.tetseg c.tsf > /dev/null || fail "bvh-mode frames not clean"

# A mat one tet thick twisted by its ends wraps into itself; with one substep per frame every
# written step is collision-free, against brute force over the whole scene.
"$bin/tetseg" generate mat --resolution 10 -o m.mesh 2>/dev/null
"$bin/tetseg" build m.mesh -o m.tetseg -q
"$sim" m.mesh m.tetseg --drop 1 --twist 1500 --substeps 1 --frames 40 -o m.tsf \
  --scene m.tsscene --json >m.json
python3 -c 'import json; c = json.load(open("m.json")); assert c["substeps_with_contact"] > 0, c'
"$bin/tetseg-bench" scene m m.tsscene --expect-clean --repeat 1 >/dev/null 2>&1 ||
  fail "twisted mat frames not clean"

expect_exit 0 "Usage" -- "$sim" --help
expect_exit 2 "" -- "$sim" d.mesh d.tetseg
expect_exit 3 "tetseg-sim: error: missing.mesh" -- "$sim" missing.mesh d.tetseg -o x.tsf
"$bin/tetseg" generate sphere --size 0.3 -o s.mesh 2>/dev/null
expect_exit 3 "nodes, the tet mesh" -- "$sim" s.mesh d.tetseg -o x.tsf
[ ! -e x.tsf ] || fail "output written on error"
echo "sim: ok"
