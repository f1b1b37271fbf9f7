#!/usr/bin/env bash
# The skinned character benchmark (docs/benchmarks.md, "Skinned character"): the generated
# character (tetseg-character: a tube on 4 bones, narrowed at the joints, bending until it
# touches itself) at two resolutions, built as a surface body with bone-carried detectors
# (--detectors skin) and with surface-weight detectors (--detectors weights), stepped by
# tetseg-bench table in rvbc and in bvh (overlap-only culling) over every step of its
# sequence, each step against the scene oracle (missed must be 0).
#
#   scripts/bench-skinned.sh BUILD_DIR [OUT_DIR]    (Release build; OUT_DIR default: a temp dir)
#
# Builds the three tools it needs in BUILD_DIR. Single thread; every step is run 3 times and
# its fastest run kept.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib/bench-common.sh"
repo=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:?usage: scripts/bench-skinned.sh BUILD_DIR [OUT_DIR]}" && pwd)
cmake --build "$build" -j 2 --target tetseg tetseg-character tetseg-bench >/dev/null
bin=$build/tools
if [ -n "${2:-}" ]; then
  mkdir -p "$2"
  out=$(cd "$2" && pwd)
else
  out=$(mktemp -d)
  trap 'rm -rf "$out"' EXIT
fi

# name: tetseg-character options
characters=(
  "tube-2.6k:"
  "tube-16k:--around 64 --rings-per-bone 30"
)
for entry in "${characters[@]}"; do
  name=${entry%%:*}
  options=${entry#*:}
  # shellcheck disable=SC2086
  "$bin/tetseg-character" -o "$out/$name" $options >&2
  for form in skin weights; do
    "$bin/tetseg" build "$out/$name.gltf" --body surface --detectors "$form" \
      -o "$out/$name-$form.tetseg" --report "$out/$name-$form.json" -q
    python3 -c 'import json,sys; r=json.load(open(sys.argv[1])); print(sys.argv[2], r["counts"]["surface_triangles"], "triangles,", r["counts"]["clusters"], "clusters")' \
      "$out/$name-$form.json" "$name-$form:" >&2
  done
  "$bin/tetseg-bench" table "$name-skin" "$out/$name-skin.tetseg" "$out/$name.tsf" \
    "$name-weights" "$out/$name-weights.tetseg" "$out/$name.tsf" \
    --bones "$out/$name.bones.tsf" --modes rvbc,bvh --repeat 3 --json >"$out/$name.json"
done
echo "== $(bench_machine "$build")"
# One table: per step, mean and median over steps of the kept run's CPU and wall time.
python3 - "$out" "${characters[@]%%:*}" <<'PY'
import json, sys
out, names = sys.argv[1], sys.argv[2:]
print("| scene | detectors | mode | steps (compared) | CPU ms mean / median | wall ms mean / median "
      "| triangle pairs | contacts | missed | later missed | extra | bvh / rvbc CPU (mean) |")
print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
for name in names:
    rows = json.load(open(f"{out}/{name}.json"))["rows"]
    for r in rows:
        scene, form = r["scene"].rsplit("-", 1)
        bvh = next(o for o in rows if o["scene"] == r["scene"] and o["mode"] == "bvh")
        ratio = f"{bvh['total_cpu_ms'] / r['total_cpu_ms']:.1f}x" if r["mode"] == "rvbc" else ""
        print(f"| {scene} | {'bones' if form == 'skin' else 'surface weights'} | {r['mode']} "
              f"| {r['steps']} ({r['compared']}) "
              f"| {r['total_cpu_ms']:.3f} / {r['median_cpu_ms']:.3f} "
              f"| {r['total_ms']:.3f} / {r['median_total_ms']:.3f} "
              f"| {r['triangle_pairs']:.0f} | {r['contacts']:.1f} | {r['missed']} "
              f"| {r['later_missed']} | {r['extra']} | {ratio} |")
PY
