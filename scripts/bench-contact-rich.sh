#!/usr/bin/env bash
# Contact-rich steps (issue 25; docs/benchmarks.md, "Contact-rich steps"): the recorded
# simulator query steps of scripts/make-scenes.sh and the whole frames of the scalable-CCD
# sample data.
#
#   scripts/bench-contact-rich.sh BUILD_DIR SCENES_DIR [DATA_DIR]
#
# BUILD_DIR: a Release build with tetseg-bench and tetseg-ccd in BUILD_DIR/tools. SCENES_DIR:
# NAME.tetseg and NAME.queries.tsf of armadillo, pawn, elephant, dino, dumbbell. DATA_DIR:
# the ccd-queries folder (default ../shared/data/ccd-queries beside the repository); frames
# missing there are listed as missing. Prints two Markdown tables:
#  1. per scene, ms per step over all steps, each step run 3 times and its fastest run kept:
#     single-thread CPU of step + contacts (into a buffer) for rvbc, cone and bvh, and of
#     step + earliest_toi for rvbc (mean / median over steps), contacts per step, and the
#     wall time of rvbc and bvh contacts with 1 and 2 OpenMP threads (mean / median);
#  2. per frame, the thread CPU seconds of `tetseg-ccd frames` (PLY reading excluded, fastest
#     of 3 runs) and the pairs reported against the frame's exact truth (boxes + mma_bool).
# Timings are CPU time except the thread columns (wall time: CPU time sums the threads).
# To compare with an older build, run the script once per build in the same minutes (a build
# whose tetseg-bench reports no medians prints n/a for them).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib/bench-common.sh"
repo=$(cd "$(dirname "$0")/.." && pwd)
[ $# -ge 2 ] || { echo "usage: $0 BUILD_DIR SCENES_DIR [DATA_DIR]" >&2; exit 2; }
build=$(cd "$1" && pwd)
scenes=$(cd "$2" && pwd)
data=${3:-$repo/../shared/data/ccd-queries}
bench=$build/tools/tetseg-bench
ccd=$build/tools/tetseg-ccd
bench_require_tools "$build" tetseg-bench tetseg-ccd
names=(armadillo pawn elephant dino dumbbell)
for s in "${names[@]}"; do
  bench_require_scenes "$scenes/$s.tetseg" "$scenes/$s.queries.tsf"
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "== $(bench_machine "$build")"
echo "## Recorded steps ($build, $(date -u +%F))"
echo
for s in "${names[@]}"; do
  args=("$s" "$scenes/$s.tetseg" "$scenes/$s.queries.tsf" --pairs --repeat 3 --no-truth --json)
  "$bench" table "${args[@]}" --modes rvbc,cone,bvh > "$work/$s.contacts.json" 2>/dev/null
  "$bench" table "${args[@]}" --modes rvbc --query earliest > "$work/$s.earliest.json" 2>/dev/null
  OMP_NUM_THREADS=2 "$bench" table "${args[@]}" --modes rvbc,bvh --openmp \
    > "$work/$s.threads.json" 2>/dev/null
done
python3 - "$work" "${names[@]}" <<'PY'
import json, sys
work, names = sys.argv[1], sys.argv[2:]
def rows(name, kind):
    return json.load(open(f"{work}/{name}.{kind}.json"))["rows"]
def pick(rs, mode, openmp=False):
    return next(r for r in rs if r["mode"] == mode and r["openmp"] == openmp)
def median(r, key):  # builds before 2026-11-28 report no medians
    return f"{r[key]:.3f}" if key in r else "n/a"
def cpu(r):
    return f"{r['total_cpu_ms']:.3f} / {median(r, 'median_cpu_ms')}"
def wall(r):
    return f"{r['total_ms']:.3f} / {median(r, 'median_total_ms')}"
print("CPU ms per step, mean / median over steps (single thread); wall ms with 1 and 2 threads.")
print()
print("| scene | steps | contacts/step | rvbc | cone | bvh | rvbc earliest_toi "
      "| rvbc 1 thread | rvbc 2 threads | bvh 1 thread | bvh 2 threads |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
for n in names:
    c, e, t = rows(n, "contacts"), rows(n, "earliest"), rows(n, "threads")
    rv = pick(c, "rvbc")
    print(f"| {n} | {rv['steps']} | {rv['contacts']:.0f} | {cpu(rv)} | {cpu(pick(c, 'cone'))} "
          f"| {cpu(pick(c, 'bvh'))} | {cpu(pick(e, 'rvbc'))} "
          f"| {wall(pick(t, 'rvbc'))} | {wall(pick(t, 'rvbc', True))} "
          f"| {wall(pick(t, 'bvh'))} | {wall(pick(t, 'bvh', True))} |")
PY

echo
echo "## Whole frames (tetseg-ccd frames, thread CPU s, PLY reading excluded, fastest of 3)"
echo
echo "| frame | CPU s | pairs reported | true pairs | true pairs not reported | reported, not true |"
echo "| --- | --- | --- | --- | --- | --- |"
frame() {  # name, id, first frame, second frame (file stems)
  local name=$1 id=$2 a=$3 b=$4 dir="$data/sample-scalable-ccd-data/$1"
  if [ ! -f "$dir/frames/$a.ply" ]; then
    echo "| $name | (frames missing in $dir) | | | | |"
    return
  fi
  local best=""
  for _ in 1 2 3; do
    "$ccd" frames "$dir/frames/$a.ply" "$dir/frames/$b.ply" > "$work/found.txt" 2> "$work/err.txt"
    local t
    t=$(sed -n 's/.*CPU \([0-9.]*\) s.*/\1/p' "$work/err.txt")
    best=$(python3 -c "print(min(float('$t'), float('${best:-inf}')))")
  done
  awk '{print $1, $2, $3, $4, $5}' "$work/found.txt" | sort -u > "$work/found"
  : > "$work/truth"
  for kind in vf ee; do
    "$ccd" truth "$dir/frames/$a.ply" "$dir/boxes/$id$kind.json" \
      "$dir/mma_bool/$id${kind}_mma_bool.json" --kind $kind >> "$work/truth"
  done
  sort -u -o "$work/truth" "$work/truth"
  echo "| $name | $best | $(wc -l < "$work/found") | $(wc -l < "$work/truth") |" \
    "$(comm -23 "$work/truth" "$work/found" | wc -l) | $(comm -13 "$work/truth" "$work/found" | wc -l) |"
}
frame cloth-funnel 227 227 228
frame rod-twist 3036 3036 3037
frame cloth-ball 92 cloth_ball92 cloth_ball93
# Not in the stored copy of the data (its README): listed so the table says so.
for name in armadillo-rollers n-body-simulation; do
  [ -d "$data/sample-scalable-ccd-data/$name" ] && echo "| $name | (present: add its frame ids here) | | | | |" ||
    echo "| $name | (not in $data) | | | | |"
done
