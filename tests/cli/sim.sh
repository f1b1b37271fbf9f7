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

# Recorded queries: the substeps with contact as frame pairs, the main frames unchanged; each
# pair's end penetrates (the scene oracle finds contacts) and every mode finds the earliest ones.
"$sim" d.mesh d.tetseg -o q.tsf --frames 150 "${args[@]}" --json --record-queries q.queries.tsf \
  --record-every 3 > q.json
cmp a.tsf q.tsf || fail "recording the queries changed the frames"
python3 - <<'PY'
import json, os
d = json.load(open("q.json"))
n = d["queries_recorded"]
assert n == (d["substeps_with_contact"] + 2) // 3 and n > 0, d
assert os.path.getsize("q.queries.tsf") == 24 + 24 * d["nodes"] * 2 * n, d
PY
"$bin/tetseg-bench" table d d.tetseg q.queries.tsf --pairs --modes rvbc,bvh,cone,brute \
  --repeat 1 --json > qt.json || fail "a mode missed a contact on the recorded queries"
python3 - <<'PY'
import json
rows = json.load(open("qt.json"))["rows"]
brute = [r for r in rows if r["mode"] == "brute"][0]
assert brute["contacts"] > 0 and brute["compared"] == brute["steps"], brute
for r in rows:  # every mode, brute included, against the scene oracle
    assert r["missed"] == 0 and r["any_mismatch"] == 0 and r["toi_later"] == 0, r
    assert r["extra"] == 0, r
PY
"$sim" d.mesh d.tetseg -o x.tsf --frames 2 --substeps 1 --dt 0.005 --drop 1 \
  --record-queries xq.tsf 2>err.txt && fail "no query to record: must fail"
grep -q "xq.tsf" err.txt || fail "the error must name the queries file"
[ ! -e x.tsf ] && [ ! -e xq.tsf ] || fail "output written although no query was recorded"
expect_exit 2 "" -- "$bin/tetseg-bench" table d d.tetseg q.queries.tsf --pairs --stride 2
"$sim" d.mesh d.tetseg -o odd.tsf --frames 3 "${args[@]}" 2>/dev/null
expect_exit 3 "even frame count" -- "$bin/tetseg-bench" table d d.tetseg odd.tsf --pairs --no-truth
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
