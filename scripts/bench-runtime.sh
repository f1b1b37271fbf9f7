#!/usr/bin/env bash
# Per-frame stage times of the collider modes (docs/benchmarks-history.md, "Runtime per-frame"):
# builds tetseg-run and tetseg-scene (Release), generates deforming scenes and runs
# `tetseg-run --json` in rvbc, bvh and brute modes, then prints a Markdown table of the mean
# per-step times (refit, classify, traversal, elementary tests, total) and feature tests.
# Two runs per scene: up to and including the first step with a contact (what a simulator
# steps through before responding: --stop-at-contact) and the whole sequence (later steps
# start interpenetrating and report hundreds of contacts). Brute force is skipped on the
# whole sequence of scenes over 10k triangles (minutes).
# Usage: scripts/bench-runtime.sh [build-dir]   (default build-bench-runtime)
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib/bench-common.sh"
cd "$(dirname "$0")/.."
build=${1:-build-bench-runtime}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DTETSEG_BUILD_TESTS=OFF >/dev/null
cmake --build "$build" -j2 --target tetseg-run tetseg-scene >/dev/null
bin=$build/tools
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# name shape motion segments rings frames
scenes=(
  "dumbbell-3k dumbbell bend 32 48 24"
  "dumbbell-15k dumbbell bend 64 120 24"
  "sphere-8k sphere press 64 64 24"
  "pawn-8k pawn twist 64 64 24"
  "pawn-waves-8k pawn waves 64 64 24"
)
echo "== $(bench_machine "$build")"
echo "| scene | triangles | steps | mode | refit ms | classify ms | traversal ms | tests ms | total ms |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
for entry in "${scenes[@]}"; do
  read -r name shape motion segments rings frames <<<"$entry"
  "$bin/tetseg-scene" "$shape" "$work/$name.tetseg" "$work/$name.tsf" --motion "$motion" \
    --segments "$segments" --rings "$rings" --frames "$frames" 2>"$work/$name.txt"
  tris=$(sed -n 's/.*), \([0-9]*\) triangles.*/\1/p' "$work/$name.txt")
  for span in first all; do
    extra=()
    [ "$span" = first ] && extra=(--stop-at-contact)
    for mode in rvbc bvh brute; do
      # brute force over a whole 15k-triangle sequence takes minutes: first-contact span only
      [ "$mode" = brute ] && [ "$span" = all ] && [ "$tris" -gt 10000 ] && continue
      "$bin/tetseg-run" "$work/$name.tetseg" "$work/$name.tsf" --mode "$mode" --json "${extra[@]}" \
        >"$work/$name-$mode-$span.json"
      python3 - "$work/$name-$mode-$span.json" "$name" "$tris" "$span" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
m = d["mean_ms"]
steps = len(d["frames"])
label = f"{steps} (to first contact)" if sys.argv[4] == "first" else f"{steps} (all)"
print(f"| {sys.argv[2]} | {sys.argv[3]} | {label} | {d['mode']} | {m['refit']:.3f} | {m['classify']:.3f} | "
      f"{m['traversal']:.3f} | {m['tests']:.3f} | {m['total']:.3f} |")
PY
    done
  done
done
