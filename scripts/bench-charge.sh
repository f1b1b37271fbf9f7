#!/usr/bin/env bash
# Benchmark of the charge-density solvers (docs/benchmarks.md, "Charge density (offline)";
# history: docs/benchmarks-history.md, "Charge density"): builds
# tetseg-bench-charge in Release and prints, for ~1k, 5k, 20k and 100k triangles (ellipsoid
# 1:0.6:0.3 and the CGAL demo elephant, 1-to-4 subdivided), each solver's assembly and solve
# time, CPU seconds, iterations, residual (against its own operator and, up to 25k triangles,
# against the exact matrix), peak RSS and error against the analytic density and the best
# reference available. Takes several minutes (the references dominate).
# Usage: scripts/bench-charge.sh [build-dir] [extra tetseg-bench-charge options]
#        (default build-bench-charge; e.g. `--sizes 1k 5k --solvers gmres fast --repeat 5`;
#        solver specs name[/jacobi|block|near|two][@tolerance|@auto][:order[:theta]];
#        `--repeat N` keeps the fastest of N runs)
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib/bench-common.sh"
cd "$(dirname "$0")/.."
build=${1:-build-bench-charge}
shift || true
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DTETSEG_BUILD_TESTS=OFF >/dev/null
cmake --build "$build" --target tetseg-bench-charge -j 2 >/dev/null
meshes="$build/bench-data/data/meshes"
if [ ! -f "$meshes/elephant.off" ] && [ -f /usr/share/doc/libcgal-dev/data.tar.gz ]; then
  mkdir -p "$build/bench-data"
  tar xzf /usr/share/doc/libcgal-dev/data.tar.gz -C "$build/bench-data" data/meshes/elephant.off
fi
echo "== $(bench_machine "$build")"
"$build/tools/tetseg-bench-charge" --mesh-dir "$meshes" "$@"
