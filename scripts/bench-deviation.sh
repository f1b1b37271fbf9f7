#!/usr/bin/env bash
# Deviation trade-off (docs/benchmarks.md, "Deviation against surface triangles and step time";
# issue 28, item 5): for each mesh and each --max-deviation D, builds the asset with the default
# options but D, and prints the measured deviation (two-sided Hausdorff distance, of the
# bounding-box diagonal), the surface triangles, the build's wall time and the collider's mean
# time per step (tetseg-run, rvbc, all contacts) on a 20-frame tetseg-sim drop of that mesh.
#
# Usage: scripts/bench-deviation.sh BUILD_DIR [--deviations 0.01,0.004,0.002,0.001] [MESH...]
#   BUILD_DIR     a configured build with the tetseg, tetseg-sim and tetseg-run targets built
#                 (and, for the default meshes, the libcgal-demo meshes it unpacks)
#   --deviations  comma-separated --max-deviation values
#   MESH...       surface files (default: elephant.off, fandisk.off and cow.off of libcgal-demo:
#                 organic, sharp CAD, self-intersecting so wrapped by --repair auto)
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib/bench-common.sh"

usage() {
  sed -n '/^# Usage:/,/^#                 organic/p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
}

build=""
deviations="0.01,0.004,0.002,0.001"
meshes=()
while [ $# -gt 0 ]; do
  case "$1" in
    --deviations) deviations=${2:?}; shift 2 ;;
    -h | --help) usage ;;
    -*) echo "bench-deviation.sh: unknown option $1" >&2; usage ;;
    *) if [ -z "$build" ]; then build=$1; else meshes+=("$1"); fi; shift ;;
  esac
done
[ -n "$build" ] || usage
tools="$(cd "$build" && pwd)/tools"
bench_require_tools "$build" tetseg tetseg-sim tetseg-run
if [ ${#meshes[@]} -eq 0 ]; then
  data="$build/test-data/cgal/data/meshes"
  meshes=("$data/elephant.off" "$data/fandisk.off" "$data/cow.off")
fi

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

echo "# tetseg build --max-deviation D (other options default), then a 20-frame tetseg-sim drop and"
echo "# tetseg-run (rvbc, all contacts) on its asset"
echo "# $(bench_machine "$build")"
echo "| mesh | D | repair | deviation in->mesh | mesh->in | excess | surface triangles | build s | step ms (mean) |"
echo "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"
for mesh in "${meshes[@]}"; do
  name=$(basename "$mesh")
  for d in ${deviations//,/ }; do
    start=$(date +%s.%N)
    "$tools/tetseg" build "$mesh" -o "$work/a.tetseg" --report "$work/r.json" --max-deviation "$d" \
      >/dev/null 2>"$work/build.err" || { echo "| $name | $d | build failed: $(tail -1 "$work/build.err") |"; continue; }
    end=$(date +%s.%N)
    # The same tets as a tet mesh (meshing is sequential and deterministic), for the simulator.
    "$tools/tetseg" tetrahedralize "$mesh" -o "$work/m.mesh" --max-deviation "$d" >/dev/null 2>&1
    "$tools/tetseg" build "$work/m.mesh" -o "$work/m.tetseg" >/dev/null 2>&1
    "$tools/tetseg-sim" "$work/m.mesh" "$work/m.tetseg" --frames 20 -o "$work/f.tsf" >/dev/null 2>&1
    "$tools/tetseg-run" "$work/m.tetseg" "$work/f.tsf" --json >"$work/run.json"
    python3 - "$name" "$d" "$work/r.json" "$work/run.json" "$start" "$end" <<'PY'
import json, sys
name, d, report, run, start, end = sys.argv[1:]
r = json.load(open(report))
h = r["hausdorff"]
step = json.load(open(run))["mean_ms"]["total"]
repair = r.get("repair_used", "")
print("| %s | %s | %s | %.3g | %.3g | %.3g | %d | %.1f | %.3f |" % (
    name, d, repair, h["input_to_mesh"], h["mesh_to_input"], r.get("deviation_excess", 0.0),
    r["counts"]["surface_triangles"], float(end) - float(start), step))
PY
  done
done
