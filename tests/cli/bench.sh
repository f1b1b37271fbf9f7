#!/usr/bin/env bash
# tetseg-bench table on tiny scenes: a generated dumbbell sequence that reaches contacts
# (tetseg-scene) and a short tetseg-sim drop. Every mode, brute included, must report every
# contact that the scene oracle (tetseg/testing/scene_oracle.hpp) finds at the earliest time of
# impact of each step (missed 0, any and earliest toi agree) and nothing outside the oracle's
# contacts (extra 0) on every step with an intersection-free start; brute, bvh and cone must
# find all of them (the cone mode culls only patches proven embedded for the whole step).
# needs: preprocess
# needs: bench
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.bash"

expect_exit 0 "tetseg-bench 0.1" -- "$bin/tetseg-bench" --version
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
    (s, m, o) for s in ("scene", "sim") for m in ("rvbc", "bvh", "cone", "brute")
    for o in (False, True)}, rows
for r in rows:
    assert r["missed"] == 0 and r["any_mismatch"] == 0 and r["toi_later"] == 0, r
    assert r["extra"] == 0, r  # nothing outside the oracle's contacts
    assert not r["truncated"]
    assert "total_ms" in r and "orientation_ms" in r  # timings are reported, never judged
bvh = {r["scene"]: r for r in rows if r["mode"] == "bvh" and not r["openmp"]}
assert bvh["scene"]["contacts"] > 0, "the generated scene must reach contacts"
assert bvh["scene"]["compared"] >= 8, bvh["scene"]
for r in rows:
    # brute, bvh and cone find every oracle contact; rvbc those at the earliest toi.
    if r["mode"] in ("brute", "bvh", "cone"):
        assert r["later_missed"] == 0, r
        assert abs(r["contacts"] - bvh[r["scene"]]["contacts"]) < 1e-12, r
    assert r["contacts"] <= bvh[r["scene"]]["contacts"] + 1e-12, r
PY
"$bin/tetseg-bench" table scene d.tetseg d.tsf --repeat 1 --modes rvbc > table.md 2>/dev/null
grep -q "| scene | rvbc | 11 (8) |" table.md || { cat table.md >&2; fail "markdown table"; }
grep -q "contacts at the earliest toi found by every mode, none outside the oracle's: yes" table.md || fail "summary line"
set +e; "$bin/tetseg-bench" table scene d.tetseg > /dev/null 2>&1; rc=$?; set -e
[ "$rc" -eq 2 ] || fail "incomplete scene triple exited $rc"
set +e; "$bin/tetseg-bench" table scene d.tetseg missing.tsf > /dev/null 2>&1; rc=$?; set -e
[ "$rc" -eq 3 ] || fail "missing frames exited $rc"
echo "bench: ok"
