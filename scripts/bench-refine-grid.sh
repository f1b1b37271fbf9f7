#!/usr/bin/env bash
# The refinement-defaults grid of docs/benchmarks-history.md ("Refinement defaults after the seam
# rule"): for each scene, assets built with --refine-gain G x --refine-visibility V, then one
# `tetseg-bench table` over all of them on the scene's frames (rvbc, single thread, timings
# only, fastest of 3 runs per step), twice. Prints "scene variant:clusters/pairs/cpu-ms ...".
#
#   scripts/bench-refine-grid.sh [BUILD_DIR] [SCENE_DIR]    (defaults: ./build, BUILD_DIR/scenes)
#
# Needs the scenes of scripts/make-scenes.sh (NAME.mesh and NAME.tsf). About a minute.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib/bench-common.sh"
repo=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$repo/build}" && pwd)
scenes=${2:-$build/scenes}
bench_require_tools "$build" tetseg tetseg-bench
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "== $(bench_machine "$build")"
gains="0.25 0.5 1 2"
visibilities="0.97 0.98 0.99"
for s in pawn dumbbell elephant armadillo dino; do
  bench_require_scenes "$scenes/$s.tsf"
  args=()
  for g in $gains; do
    for v in $visibilities; do
      "$build/tools/tetseg" build "$scenes/$s.mesh" -o "$work/$s-g$g-v$v.tetseg" -q \
        --refine-gain "$g" --refine-visibility "$v"
      args+=("g$g-v$v" "$work/$s-g$g-v$v.tetseg" "$scenes/$s.tsf")
    done
  done
  for run in 1 2; do
    "$build/tools/tetseg-bench" table "${args[@]}" --modes rvbc --repeat 3 --no-truth --json \
      2>/dev/null | python3 -c "
import json, sys
rows = json.load(sys.stdin)['rows']
print('$s', ' '.join('%s:%d/%.0f/%.3f' % (r['scene'], r['clusters'], r['triangle_pairs'],
                                         r['total_cpu_ms']) for r in rows))"
  done
done
