#!/usr/bin/env bash
# tetseg-bench table on tiny scenes: a generated dumbbell sequence that reaches contacts
# (tetseg-scene) and a short tetseg-sim drop. Every mode must report every contact that brute
# force finds at the earliest time of impact of each step (missed 0, any and earliest toi
# agree) on every step with an intersection-free start; bvh and cone must find all of them
# (the cone mode culls only patches proven embedded for the whole step).
# needs: preprocess
# needs: bench
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.bash"

"$bin/tetseg-scene" dumbbell d.tetseg d.tsf --segments 16 --rings 20 --frames 12 2>/dev/null
"$bin/tetseg" generate dumbbell --size 0.4 -o s.mesh 2>/dev/null
"$bin/tetseg" build s.mesh -o s.tetseg -q
"$bin/tetseg-sim" s.mesh s.tetseg -o s.tsf --frames 30 --substeps 4 --dt 0.02 --drop 0.1 \
  --tilt-y 75 --edge-compliance 5e-3 2>/dev/null

"$bin/tetseg-bench" table scene d.tetseg d.tsf sim s.tetseg s.tsf --repeat 1 --openmp --json \
  > table.json 2>/dev/null || fail "tetseg-bench table reported missed contacts"
python3 - <<'PY'
import json
d = json.load(open("table.json"))
assert d["all_contacts_found"] is True
rows = d["rows"]
assert {(r["scene"], r["mode"], r["openmp"]) for r in rows} == {
    (s, m, o) for s in ("scene", "sim") for m in ("rvbc", "bvh", "cone") for o in (False, True)} | {
    ("scene", "brute", False), ("sim", "brute", False)}, rows
for r in rows:
    assert r["missed"] == 0 and r["any_mismatch"] == 0 and r["toi_later"] == 0, r
    assert not r["truncated"]
    assert r["total_ms"] > 0 and r["total_cpu_ms"] >= 0
brute = {r["scene"]: r for r in rows if r["mode"] == "brute"}
assert brute["scene"]["contacts"] > 0, "the generated scene must reach contacts"
assert brute["scene"]["compared"] >= 8, brute["scene"]
for r in rows:
    # Same elementary tests on the same steps: bvh finds every contact; rvbc never more.
    if r["mode"] in ("bvh", "cone"):
        assert abs(r["contacts"] - brute[r["scene"]]["contacts"]) < 1e-12, r
        assert r["later_missed"] == 0, r
    assert r["contacts"] <= brute[r["scene"]]["contacts"] + 1e-12, r
    assert r["extra"] == 0, r
    if r["mode"] == "rvbc":
        assert r["orientation_ms"] > 0
PY
"$bin/tetseg-bench" table scene d.tetseg d.tsf --repeat 1 --modes rvbc > table.md 2>/dev/null
grep -q "| scene | rvbc | 11 (8) |" table.md || { cat table.md >&2; fail "markdown table"; }
grep -q "contacts at the earliest toi found by every mode: yes" table.md || fail "summary line"
set +e; "$bin/tetseg-bench" table scene d.tetseg > /dev/null 2>&1; rc=$?; set -e
[ "$rc" -eq 2 ] || fail "incomplete scene triple exited $rc"
set +e; "$bin/tetseg-bench" table scene d.tetseg missing.tsf > /dev/null 2>&1; rc=$?; set -e
[ "$rc" -eq 3 ] || fail "missing frames exited $rc"
echo "bench: ok"
