#!/usr/bin/env bash
# Surface bodies (issue 29; docs/benchmarks.md, "Surface bodies"): the armadillo and elephant
# scenes as surface bodies against their tet assets, and the public whole frames built as
# surface assets from their first frame.
#
#   scripts/bench-surface-bodies.sh BUILD_DIR SCENES_DIR [DATA_DIR]
#
# BUILD_DIR: a Release build with tetseg, tetseg-bench and tetseg-ccd in BUILD_DIR/tools.
# SCENES_DIR: NAME.tetseg, NAME.tsf and NAME.queries.tsf of armadillo and elephant
# (scripts/make-scenes.sh). DATA_DIR: the ccd-queries folder (default
# ../shared/data/ccd-queries beside the repository).
#  1. Per scene, `tetseg-bench surface` writes the tet asset's rest surface (surface nodes in
#     ascending id) and the scene's frames restricted to those nodes; `tetseg build --body
#     surface` builds the surface asset from that surface; `tetseg-bench table` steps both
#     assets through the same motion (the simulated frames, then the recorded simulator query
#     steps, --pairs), each step 3 times, fastest kept, and compares every mode with the
#     brute-force scene oracle. Printed: CPU ms per step (step + contacts), mean / median over
#     steps, for the tet asset's rvbc and the surface asset's rvbc and bvh (overlap-only
#     culling of the same surface), their ratios, and the contacts missed.
#  2. Per whole frame: `tetseg build FIRST.ply --body surface`, then `tetseg-ccd frames` with
#     and without `--asset` (thread CPU s, PLY reading excluded, fastest of 3) and the pairs
#     each reports against the frame's exact truth (boxes + mma_bool).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib/bench-common.sh"
repo=$(cd "$(dirname "$0")/.." && pwd)
[ $# -ge 2 ] || { echo "usage: $0 BUILD_DIR SCENES_DIR [DATA_DIR]" >&2; exit 2; }
build=$(cd "$1" && pwd)
scenes=$(cd "$2" && pwd)
data=${3:-$repo/../shared/data/ccd-queries}
tetseg=$build/tools/tetseg
bench=$build/tools/tetseg-bench
ccd=$build/tools/tetseg-ccd
bench_require_tools "$build" tetseg tetseg-bench tetseg-ccd
names=(armadillo elephant)
for s in "${names[@]}"; do
  bench_require_scenes "$scenes/$s.tetseg" "$scenes/$s.tsf" "$scenes/$s.queries.tsf"
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "== $(bench_machine "$build")"
echo "## Surface bodies against tet assets ($build, $(date -u +%F), $(nproc) cores)"
echo
for s in "${names[@]}"; do
  "$bench" surface "$scenes/$s.tetseg" "$work/$s.off" "$scenes/$s.tsf" "$work/$s.tsf" \
    "$scenes/$s.queries.tsf" "$work/$s.queries.tsf"
  "$tetseg" build "$work/$s.off" -o "$work/$s-surface.tetseg" --body surface -q \
    --report "$work/$s-surface.build.json"
  "$bench" table "$s" "$scenes/$s.tetseg" "$scenes/$s.tsf" \
    "$s-surface" "$work/$s-surface.tetseg" "$work/$s.tsf" \
    --modes rvbc,bvh --repeat 3 --json > "$work/$s.frames.json" 2>/dev/null
  "$bench" table "$s" "$scenes/$s.tetseg" "$scenes/$s.queries.tsf" \
    "$s-surface" "$work/$s-surface.tetseg" "$work/$s.queries.tsf" \
    --pairs --modes rvbc,bvh --repeat 3 --json > "$work/$s.queries.json" 2>/dev/null
done
python3 - "$work" "${names[@]}" <<'PY'
import json, sys
work, names = sys.argv[1], sys.argv[2:]
def pick(rows, scene, mode):
    return next(r for r in rows if r["scene"] == scene and r["mode"] == mode and not r["openmp"])
def cpu(r):
    return f"{r['total_cpu_ms']:.3f} / {r['median_cpu_ms']:.3f}"
print("CPU ms per step (step + contacts), mean / median over steps; missed: oracle contacts "
      "at a step's earliest toi not reported (tet rvbc / surface rvbc / surface bvh).")
print()
print("| scene | steps | clusters tet / surface | tet rvbc | surface rvbc | surface bvh "
      "| surface rvbc / tet rvbc (mean, median) | surface bvh / surface rvbc (mean, median) "
      "| contacts/step | missed |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
for n in names:
    for kind, label in (("frames", "frames"), ("queries", "recorded steps")):
        rows = json.load(open(f"{work}/{n}.{kind}.json"))["rows"]
        tet, surf, bvh = pick(rows, n, "rvbc"), pick(rows, n + "-surface", "rvbc"), \
            pick(rows, n + "-surface", "bvh")
        ratio = lambda a, b, k: a[k] / b[k]
        missed = f"{tet['missed']} / {surf['missed']} / {bvh['missed']}"
        print(f"| {n} {label} | {surf['steps']} ({surf['compared']} compared) "
              f"| {tet['clusters']} / {surf['clusters']} | {cpu(tet)} | {cpu(surf)} | {cpu(bvh)} "
              f"| {ratio(surf, tet, 'total_cpu_ms'):.2f}x, {ratio(surf, tet, 'median_cpu_ms'):.2f}x "
              f"| {ratio(bvh, surf, 'total_cpu_ms'):.2f}x, {ratio(bvh, surf, 'median_cpu_ms'):.2f}x "
              f"| {surf['contacts']:.2f} | {missed} |")
for n in names:
    report = json.load(open(f"{work}/{n}-surface.build.json"))
    terms = sum(1 for c in report["clusters"] if not c["overlap_only"])
    print(f"\n{n} surface asset: {report['counts']['surface_triangles']} triangles, "
          f"{len(report['clusters'])} clusters ({terms} with detectors), "
          f"build {report['seconds']['total']:.2f} s")
PY

echo
echo "## Whole frames as surface bodies (tetseg-ccd frames, thread CPU s, PLY reading excluded, fastest of 3)"
echo
echo "| frame | build s | clusters (overlap-only) | CPU s without asset | CPU s with asset | pairs reported without / with | true pairs | true pairs not reported without / with |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
fastest() {  # output file, then the tetseg-ccd frames arguments
  local out=$1 best=""
  shift
  for _ in 1 2 3; do
    "$ccd" frames "$@" > "$out" 2> "$work/err.txt"
    local t
    t=$(sed -n 's/.*CPU \([0-9.]*\) s.*/\1/p' "$work/err.txt")
    best=$(python3 -c "print(min(float('$t'), float('${best:-inf}')))")
  done
  echo "$best"
}
frame() {  # name, id, first frame, second frame (file stems)
  local name=$1 id=$2 a=$3 b=$4 dir="$data/sample-scalable-ccd-data/$1"
  if [ ! -f "$dir/frames/$a.ply" ]; then
    echo "| $name | (frames missing in $dir) | | | | | | |"
    return
  fi
  local t0=$dir/frames/$a.ply t1=$dir/frames/$b.ply asset=$work/$name.tetseg
  if ! "$tetseg" build "$t0" -o "$asset" --body surface -q --report "$work/$name.build.json" \
    2> "$work/build-err.txt"; then
    echo "| $name | refused: $(tail -1 "$work/build-err.txt") | | | | | | |"
    return
  fi
  local built clusters plain with
  built=$(python3 -c "import json; print(f\"{json.load(open('$work/$name.build.json'))['seconds']['total']:.1f}\")")
  clusters=$(python3 -c "import json; c = json.load(open('$work/$name.build.json'))['clusters']; print(f\"{len(c)} ({sum(x['overlap_only'] for x in c)})\")")
  plain=$(fastest "$work/plain.txt" "$t0" "$t1")
  with=$(fastest "$work/with.txt" "$t0" "$t1" --asset "$asset")
  awk '{print $1, $2, $3, $4, $5}' "$work/plain.txt" | sort -u > "$work/plain"
  awk '{print $1, $2, $3, $4, $5}' "$work/with.txt" | sort -u > "$work/with"
  : > "$work/truth"
  for kind in vf ee; do
    "$ccd" truth "$t0" "$dir/boxes/$id$kind.json" "$dir/mma_bool/$id${kind}_mma_bool.json" \
      --kind $kind >> "$work/truth"
  done
  sort -u -o "$work/truth" "$work/truth"
  echo "| $name | $built | $clusters | $plain | $with | $(wc -l < "$work/plain") / $(wc -l < "$work/with") |" \
    "$(wc -l < "$work/truth") | $(comm -23 "$work/truth" "$work/plain" | wc -l) / $(comm -23 "$work/truth" "$work/with" | wc -l) |"
}
frame cloth-funnel 227 227 228
frame rod-twist 3036 3036 3037
frame cloth-ball 92 cloth_ball92 cloth_ball93
