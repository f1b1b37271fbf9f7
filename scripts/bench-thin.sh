#!/usr/bin/env bash
# Thin and multi-part bodies (docs/benchmarks.md, "Scenes of several bodies"; history:
# docs/benchmarks-history.md, "Thin and multi-part bodies (issue 13)"):
# makes the thin scenes (TETSEG_SCENES=thin scripts/make-scenes.sh), then prints per shape the
# build figures (time, components, clusters, detectors inside tets, overlap-only clusters) and
# the scene table of `tetseg-bench scene` (per-step time by stage, contacts, missed contacts
# against the brute-force oracle).
#
#   scripts/bench-thin.sh [BUILD_DIR] [OUT_DIR]      (BUILD_DIR default: ./build)
#
# Needs tetseg, tetseg-dump, tetseg-sim and tetseg-bench built in BUILD_DIR (Release). About
# 10 minutes of CPU on 2 cores (the twisted mat is most of it).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib/bench-common.sh"
repo=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$repo/build}" && pwd)
out=${2:-$build/scenes}
bench_require_tools "$build" tetseg tetseg-dump tetseg-sim tetseg-bench
echo "== $(bench_machine "$build")"
TETSEG_SCENES=thin "$repo/scripts/make-scenes.sh" "$build" "$out"
cd "$out"
echo "| shape | nodes | interior nodes | surface triangles | components | build s | clusters | detectors inside tets | overlap-only | lowest rest visibility |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for shape in mat plate bar torus tori; do
  "$build/tools/tetseg-dump" --json "$shape.tetseg" > "$shape.dump.json"
  python3 - "$shape" <<'PY'
import json, sys
s = sys.argv[1]
r = json.load(open(s + ".build.json"))
d = json.load(open(s + ".dump.json"))
c = r["counts"]
inside = sum(1 for k in d["clusters"] if k["detector"].get("tet", None) is not None)
flagged = sum(1 for k in d["clusters"] if k["overlap_only"])
lowest = min(k["rest_positive_fraction"] for k in d["clusters"])
print("| %s | %d | %d | %d | %d | %.2f | %d | %d | %d | %.3f |" % (
    s, c["nodes"], c["interior_nodes"], c["surface_triangles"], c["components"],
    r["seconds"]["total"], c["clusters"], inside, flagged, lowest))
PY
done
scenes=()
for name in mat-drape plate-drape mat-twist bar-drape torus-drop tori-drop; do
  scenes+=("$name" "$name.tsscene")
done
"$build/tools/tetseg-bench" scene "${scenes[@]}" --repeat 1
