#!/usr/bin/env bash
# Corpus benchmark (docs/benchmarks.md, "Preprocessing"; history: docs/benchmarks-history.md,
# "Real meshes"): runs `tetseg build` over every OFF, PLY,
# OBJ and STL surface of a folder, once per repair mode, with a time limit per mesh, and prints
# per mesh the exit code, the failing stage and message, the repairs (and the repair auto
# used), the deviation (two-sided Hausdorff distance, of the diagonal), the surface triangles,
# clusters and wall time, then totals per mode with the median and 90th percentile of the
# deviation (the larger of the two sides) over the meshes built.
#
# Usage: scripts/bench-corpus.sh BUILD_DIR [MESH_DIR] [--modes fix,wrap] [--limit 180]
#                                [--jobs 1] [--smallest N]
#   BUILD_DIR   a configured build with tools/tetseg built (and, for the default MESH_DIR, the
#               libcgal-demo meshes the build unpacks into BUILD_DIR/test-data/cgal/data/meshes)
#   --modes     comma-separated --repair modes (default auto: tetseg's default)
#   --limit     seconds per mesh and mode (timeout; exit 124 = over the limit; the build's
#               own --time-limit, exit 5, is left at its default)
#   --jobs      meshes run at once (default 1: the timings are then comparable)
#   --smallest  only the N smallest files (by bytes), for a quick subset
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib/bench-common.sh"

usage() {
  sed -n '/^# Usage:/,/^#   --smallest/p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
}

build=""
mesh_dir=""
modes="auto"
limit=180
jobs=1
smallest=0
while [ $# -gt 0 ]; do
  case "$1" in
    --modes) modes=${2:?}; shift 2 ;;
    --limit) limit=${2:?}; shift 2 ;;
    --jobs) jobs=${2:?}; shift 2 ;;
    --smallest) smallest=${2:?}; shift 2 ;;
    -h | --help) usage ;;
    -*) echo "bench-corpus.sh: unknown option $1" >&2; usage ;;
    *)
      if [ -z "$build" ]; then build=$1
      elif [ -z "$mesh_dir" ]; then mesh_dir=$1
      else usage; fi
      shift ;;
  esac
done
[ -n "$build" ] || usage
tetseg="$(cd "$build" && pwd)/tools/tetseg"
bench_require_tools "$build" tetseg
mesh_dir=${mesh_dir:-$build/test-data/cgal/data/meshes}
[ -d "$mesh_dir" ] || { echo "bench-corpus.sh: no mesh folder $mesh_dir" >&2; exit 1; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# The meshes, smallest first when --smallest is given, else by name.
find -L "$mesh_dir" -maxdepth 1 -type f \( -iname '*.off' -o -iname '*.ply' -o -iname '*.obj' \
  -o -iname '*.stl' \) -printf '%s %p\n' |
  sort -n | { if [ "$smallest" -gt 0 ]; then head -n "$smallest"; else cat; fi; } |
  cut -d' ' -f2- | sort >"$work/list"

# One run: writes one tab-separated line to $work/rows/<mode>.<n>.
run_one() {
  local mode=$1 n=$2 mesh=$3
  local out="$work/out.$mode.$n"
  local start end code
  start=$(date +%s.%N)
  set +e
  timeout "$limit" "$tetseg" build "$mesh" -o "$out.tetseg" --report "$out.json" --repair "$mode" \
    >"$out.stdout" 2>"$out.stderr"
  code=$?
  set -e
  end=$(date +%s.%N)
  python3 - "$mode" "$mesh" "$code" "$start" "$end" "$out" >"$work/rows/$mode.$n" <<'PY'
import json, os, re, sys
mode, mesh, code, start, end, out = sys.argv[1:]
code = int(code)
stderr = open(out + ".stderr", errors="replace").read()
order = ["read", "tetrahedralize", "surface", "charge", "equalize", "segmentation",
         "refinement", "detectors", "bvh", "write"]
done = [m.group(1) for m in re.finditer(r"^tetseg: (\w+) +[0-9.]+ s ", stderr, re.M)]
stage = message = repairs = hausdorff = triangles = clusters = ""
if code == 0:
    report = json.load(open(out + ".json"))
    repairs = "; ".join("%s %s" % (v, k) for k, v in report.get("repairs", {}).items())
    if report.get("fallback_reason"):
        repairs = "auto: wrap (%s)%s" % (report["fallback_reason"][:80].replace("\t", " "),
                                         "; " + repairs if repairs else "")
    h = report.get("hausdorff")
    if h:
        hausdorff = "%.2g/%.2g" % (h["input_to_mesh"], h["mesh_to_input"])
    triangles = str(report["counts"]["surface_triangles"])
    clusters = str(report["counts"]["clusters"])
else:
    later = [s for s in order if s not in done]
    stage = later[0] if later else "?"
    if code == 124:
        stage, message = stage + " (time limit)", "over the time limit"
    elif code > 128:
        message = "crash: signal %d" % (code - 128)
    else:
        errors = [l for l in stderr.splitlines() if l.startswith("tetseg: error:")]
        lines = errors or stderr.strip().splitlines() or [""]
        message = lines[-1]
        message = message.replace("tetseg: error: ", "").replace(mesh + ": ", "")
        message = message.replace("\t", " ")[:200]
        m = re.match(r"[^:]+: (tetrahedralize|read):", message)
        if m:
            stage = m.group(1)
for suffix in (".tetseg", ".json"):
    if os.path.exists(out + suffix):
        os.remove(out + suffix)
print("\t".join([mode, os.path.basename(mesh), str(code), stage, message, repairs, hausdorff,
                 triangles, clusters, "%.1f" % (float(end) - float(start))]))
PY
}
export -f run_one
export work limit tetseg
mkdir -p "$work/rows"

echo "# tetseg build over $(wc -l <"$work/list") meshes of $mesh_dir; modes $modes; limit ${limit}s; jobs $jobs"
echo "# $(bench_machine "$build")"
printf 'mode\tmesh\texit\tfailed stage\tmessage\trepairs\tdeviation (in->mesh/mesh->in, of diagonal)\ttriangles\tclusters\tseconds\n'
for mode in ${modes//,/ }; do
  awk -v m="$mode" '{ printf "%s %d %s\n", m, NR, $0 }' "$work/list"
done | xargs -P "$jobs" -n 3 bash -c 'run_one "$@"' _  # (mesh paths without spaces)
for mode in ${modes//,/ }; do
  ls "$work/rows" | grep "^$mode\." | sort -t. -k2 -n | while read -r f; do cat "$work/rows/$f"; done
done | tee "$work/all"
echo
echo "# totals per mode: built, failed (exit 3), refused at the build's --time-limit (5), over"
echo "# the script's limit (124), crashed (signal), other; deviation of the built: median, 90th"
echo "# percentile (the larger side, of the diagonal; nearest rank); wrapped by auto: how many"
for mode in ${modes//,/ }; do
  python3 - "$mode" "$work/all" <<'PY'
import math, sys
mode, path = sys.argv[1:]
rows = [l.rstrip("\n").split("\t") for l in open(path)]
rows = [r for r in rows if r[0] == mode]
codes = [int(r[2]) for r in rows]
deviation = sorted(max(map(float, r[6].split("/"))) for r in rows if r[2] == "0" and r[6])
def rank(q):
    return deviation[max(0, math.ceil(q * len(deviation)) - 1)] if deviation else float("nan")
wrapped = sum(1 for r in rows if r[5].startswith("auto: wrap"))
print("%s: %d meshes, %d built, %d failed, %d time limit, %d over the limit, %d crashed, "
      "%d other; %.0f s; deviation median %.3g, 90th percentile %.3g; %d wrapped by auto" % (
          mode, len(rows), codes.count(0), codes.count(3), codes.count(5), codes.count(124),
          sum(c > 128 for c in codes), sum(c not in (0, 3, 5, 124) and c <= 128 for c in codes),
          sum(float(r[9]) for r in rows), rank(0.5), rank(0.9), wrapped))
PY
done
