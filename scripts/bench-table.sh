#!/usr/bin/env bash
# Regenerates the "Table I", "cluster refinement", "refinement parameters" and "segmentation
# parameters" tables of docs/benchmarks-history.md (the current figures: docs/benchmarks.md).
#
#   scripts/bench-table.sh [BUILD_DIR] [SCENE_DIR]    (defaults: ./build, BUILD_DIR/scenes)
#
# Needs the scenes of scripts/make-scenes.sh (run first, or pass their directory). Release
# build; single thread, plus the runtime's OpenMP option (refit and classification only).
# Every step is run 3 times and its fastest run kept; brute force is the truth (slow: about
# a minute for the pawn).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib/bench-common.sh"
repo=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$repo/build}" && pwd)
scenes=${2:-$build/scenes}
bench_require_tools "$build" tetseg tetseg-bench
bench=$build/tools/tetseg-bench
tetseg=$build/tools/tetseg
bench_require_scenes "$scenes"/{pawn,dumbbell,elephant}.tsf

echo "== $(bench_machine "$build")"
echo "## Table I (tetseg-bench table, $(date -u +%F))"
echo
"$bench" table pawn "$scenes/pawn.tetseg" "$scenes/pawn.tsf" \
  dumbbell "$scenes/dumbbell.tetseg" "$scenes/dumbbell.tsf" \
  elephant "$scenes/elephant.tetseg" "$scenes/elephant.tsf" --repeat 3 --openmp

echo
echo "## Cluster methods (rvbc, single thread; brute force is the truth)"
echo
bench_require_scenes "$scenes"/{armadillo,dino}.tsf
args=()
for s in pawn dumbbell elephant armadillo dino; do
  for c in refined charge single; do
    asset="$scenes/$s-$c.tetseg"; [ "$c" = refined ] && asset="$scenes/$s.tetseg"
    args+=("$s/$c" "$asset" "$scenes/$s.tsf")
  done
done
cluster_json=$(mktemp)
"$bench" table "${args[@]}" --modes rvbc --repeat 3 --json > "$cluster_json"
python3 - "$cluster_json" "$scenes" <<'PY'
import json, sys
rows = [r for r in json.load(open(sys.argv[1]))["rows"] if r["mode"] == "rvbc"]
print("| scene | clusters | count | rest non-positive triangles | negative+uncertain per step | triangle pairs per step | total CPU ms per step | vs charge | missed |")
print("|---|---|---|---|---|---|---|---|---|")
cpu = {r["scene"]: r["total_cpu_ms"] for r in rows}
for r in rows:
    scene, method = r["scene"].split("/")
    suffix = "" if method == "refined" else "-" + method
    report = json.load(open(f"{sys.argv[2]}/{scene}{suffix}.build.json"))
    rest = sum(c["triangles"] * (1 - c["rest_positive_fraction"]) for c in report["clusters"])
    ratio = cpu[f"{scene}/charge"] / r["total_cpu_ms"]
    print(f"| {scene} | {method} | {r['clusters']} | {rest:.0f} | {r['uncertain_negative']:.0f} | "
          f"{r['triangle_pairs']:.0f} | {r['total_cpu_ms']:.4f} | {ratio:.2f}x | {r['missed'] + r['any_mismatch'] + r['toi_later']} |")
PY
rm -f "$cluster_json"

echo
echo "## Segmentation parameters on the pawn scene (rvbc, single thread)"
echo
echo "| alpha | beta divisor | equalisation | clusters | uncertain+negative triangles per step | total CPU ms per step | traversal ms | triangle pairs |"
echo "|---|---|---|---|---|---|---|---|"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
row() {  # row ALPHA BETA EQUALIZATION
  "$tetseg" build "$scenes/pawn.mesh" -o "$work/p.tetseg" -q --report "$work/r.json" \
    --clusters charge --alpha "$1" --beta-divisor "$2" --equalization "$3"
  "$bench" table pawn "$work/p.tetseg" "$scenes/pawn.tsf" --modes rvbc --no-truth --repeat 3 \
    --json > "$work/t.json" 2>/dev/null
  python3 - "$1" "$2" "$3" "$work/r.json" "$work/t.json" <<'PY'
import json, sys
a, b, e, rep, tab = sys.argv[1:]
r = json.load(open(rep)); t = json.load(open(tab))["rows"][0]
clusters = t["clusters"]
print(f"| {a} | {b} | {e} | {clusters} | {t['uncertain_negative']:.0f} | {t['total_cpu_ms']:.4f} | {t['traversal_ms']:.4f} | {t['triangle_pairs']:.0f} |")
PY
}
for alpha in 0.05 0.1 0.2 0.3; do row "$alpha" 400 histogram; done
for beta in 100 1000; do row 0.1 "$beta" histogram; done
for eq in rank log-histogram; do row 0.1 400 "$eq"; done

echo
echo "## Refinement parameters (rvbc, single thread, timings only)"
echo
echo "| scene | variant | clusters | negative+uncertain triangles per step | triangle pairs | total CPU ms per step |"
echo "|---|---|---|---|---|---|"
refine_row() {  # refine_row SCENE LABEL OPTIONS...
  local scene=$1 label=$2; shift 2
  "$tetseg" build "$scenes/$scene.mesh" -o "$work/r.tetseg" -q "$@"
  "$bench" table "$scene" "$work/r.tetseg" "$scenes/$scene.tsf" --modes rvbc --no-truth \
    --repeat 3 --json > "$work/t.json" 2>/dev/null
  python3 - "$scene" "$label" "$work/t.json" <<'PY'
import json, sys
scene, label, tab = sys.argv[1:]
t = json.load(open(tab))["rows"][0]
print(f"| {scene} | {label} | {t['clusters']} | {t['uncertain_negative']:.0f} | {t['triangle_pairs']:.0f} | {t['total_cpu_ms']:.4f} |")
PY
}
for s in pawn elephant armadillo dino; do
  refine_row "$s" "charge" --clusters charge
  refine_row "$s" "refined (defaults)" --clusters refined
  for g in 0.25 1 2 4; do refine_row "$s" "gain $g" --clusters refined --refine-gain "$g"; done
  for v in 0.9 0.95 0.97 0.99; do refine_row "$s" "visibility $v" --clusters refined --refine-visibility "$v"; done
  refine_row "$s" "no merge" --clusters refined --refine-merge false
done
