#!/usr/bin/env bash
# Benchmark of the elementary CCD tests (docs/benchmarks.md, "Elementary CCD"; history:
# docs/benchmarks-history.md, "Elementary CCD tests"): builds
# tetseg-ccd in Release and runs it on the reference queries (conservative runtime test and the
# non-conservative fast-cubic baseline), then on whole scalable-CCD frames.
# Usage: scripts/bench-ccd.sh [build-dir]   (default build-bench-ccd; data from ../shared)
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib/bench-common.sh"
cd "$(dirname "$0")/.."
build=${1:-build-bench-ccd}
data=${TETSEG_SHARED_DIR:-$PWD/../shared}/data/ccd-queries
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DTETSEG_BUILD_PREPROCESS=OFF \
  -DTETSEG_BUILD_TESTS=OFF >/dev/null
cmake --build "$build" --target tetseg-ccd -j 2 >/dev/null
tool="$build/tools/tetseg-ccd"
[ -d "$data/sample-queries" ] || { echo "reference data not found under $data" >&2; exit 1; }

echo "== $(bench_machine "$build")"
for method in conservative fast-cubic; do
  echo "== reference queries, --method $method (3 runs; mean CPU time of the test calls per query)"
  for run in 1 2 3; do
    "$tool" queries "$data/sample-queries" --method "$method" | tail -2 | sed "s/^/run $run: /"
  done
done
echo "== per-scene table (conservative)"
"$tool" queries "$data/sample-queries"

echo "== whole frames: the runtime scene, then the sort-and-sweep baseline (same tests);"
echo "   user CPU and wall seconds including PLY reading, then the tool's own CPU and counts"
for scene in "cloth-funnel 227 228" "rod-twist 3036 3037" "cloth-ball cloth_ball92 cloth_ball93"; do
  set -- $scene
  dir="$data/sample-scalable-ccd-data/$1/frames"
  [ -f "$dir/$2.ply" ] || continue
  for broad in "" --sweep; do
    TIMEFORMAT="%U s user, %R s wall"
    { time "$tool" frames "$dir/$2.ply" "$dir/$3.ply" $broad 2>"$build/stderr.txt" |
        wc -l > "$build/contacts.txt"; } 2> "$build/time.txt"
    echo "$1 ${broad:-(scene)}: $(cat "$build/contacts.txt") contacts, $(cat "$build/time.txt")"
    tail -1 "$build/stderr.txt" | sed 's/^/  /'
  done
done
