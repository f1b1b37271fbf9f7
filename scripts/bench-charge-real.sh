#!/usr/bin/env bash
# The charge solver at its defaults (`auto` at the automatic tolerance) on real CGAL demo
# surfaces, each as given and 1-to-4 subdivided (docs/benchmarks.md, "Charge density
# (offline)"; history: docs/benchmarks-history.md, "Charge on real meshes"): per mesh and size the iterations, GMRES residual, residual against the exact
# matrix (up to 12k triangles), solve and total seconds (wall) and CPU seconds. Iteration
# counts are deterministic; the times are one run each. About 2 minutes on 2 cores.
# Usage: scripts/bench-charge-real.sh [build-dir] [mesh names]
#        (default build-bench-charge and 16 meshes; e.g. `build elephant dino femur`)
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib/bench-common.sh"
cd "$(dirname "$0")/.."
build=${1:-build-bench-charge}
shift || true
names=${*:-"elephant hand dino armadillo bunny00 camel cow homer knot1 bull femur
            ChineseDragon-10kv eight bones head"}
if [ ! -f "$build/CMakeCache.txt" ]; then
  cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DTETSEG_BUILD_TESTS=OFF >/dev/null
fi
cmake --build "$build" --target tetseg-bench-charge -j 2 >/dev/null
meshes="$build/bench-data/data/meshes"
if [ ! -d "$meshes" ]; then
  if [ ! -f /usr/share/doc/libcgal-dev/data.tar.gz ]; then
    echo "bench-charge-real: needs the libcgal-demo meshes (apt install libcgal-demo)" >&2
    exit 1
  fi
  mkdir -p "$build/bench-data"
  tar xzf /usr/share/doc/libcgal-dev/data.tar.gz -C "$build/bench-data" data/meshes
fi
echo "== $(bench_machine "$build")"
echo "| mesh | N | iterations | residual | exact residual | solve s | total s | CPU s |"
echo "|---|---|---|---|---|---|---|---|"
for name in $names; do
  if [ ! -f "$meshes/$name.off" ]; then
    echo "bench-charge-real: no $meshes/$name.off" >&2
    exit 1
  fi
  # Columns of the bench table: mesh, N, solver, assembly, solve, total, CPU, iterations,
  # residual, exact residual.
  "$build/tools/tetseg-bench-charge" --mesh-dir "$meshes" --real "$name.off" --sizes 5k 20k \
    --solvers auto@auto --no-reference --exact-residual-max 12000 --repeat 1 2>/dev/null |
    awk -F'|' -v name="$name" '$2 ~ name {
      gsub(/ /, "", $3); printf "| %s | %s | %s | %s | %s | %s | %s | %s |\n", name, $3, $9, $10, $11, $6, $7, $8 }' |
    awk -F'|' '!seen[$3]++' | sort -t'|' -k3,3n
done
