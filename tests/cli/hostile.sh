#!/usr/bin/env bash
# needs: preprocess
# Hostile geometry (issue 28, "every input ends"): small closed surfaces with extreme aspect
# ratios, slivers, spikes, near-coincident vertices and huge or tiny coordinates. Each
# `tetseg build` with the default options must end within 60 s (a `timeout` of 60 s here; the
# build's own --time-limit and Mesh_3 bounds are what make it end) with exit 0, or with a
# documented refusal (3: the input cannot be meshed, the message naming the stage; 5: the time
# limit) and no asset written. And --time-limit is honoured: a build given 0.01 s is refused
# with exit 5 and the stage named, nothing written.
set -euo pipefail
. "$(dirname "$0")/common.bash"

# tet NAME P0 P1 P2 P3: a tetrahedron as OFF, outward whatever the corners' order.
tet() {
  python3 - "$@" <<'PY'
import sys
name, *corners = sys.argv[1:]
p = [tuple(map(float, c.split(","))) for c in corners]
def sub(a, b): return tuple(x - y for x, y in zip(a, b))
def det(a, b, c):
    return (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0]))
faces = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
if det(sub(p[1], p[0]), sub(p[2], p[0]), sub(p[3], p[0])) < 0:
    faces = [(a, c, b) for a, b, c in faces]
with open(name, "w") as f:
    f.write("OFF\n4 4 0\n")
    for q in p: f.write("%.17g %.17g %.17g\n" % q)
    for t in faces: f.write("3 %d %d %d\n" % t)
PY
}

cases=()
# Needles: one long edge, aspect ratio 1 to 10^4 (L = 160 ran over 5 minutes before).
for L in 1 10 160 1000 10000; do tet "needle$L.off" 0,0,0 1,0,0 "0,$L,0" 0,0,1; cases+=("needle$L.off"); done
# Slivers: a flat tetrahedron, height 1e-2 and 1e-4 of its width.
for h in 1e-2 1e-4; do tet "sliver$h.off" 0,0,0 1,0,0 0,1,0 "0.3,0.3,$h"; cases+=("sliver$h.off"); done
# A spike: a long thin pyramid tip on a unit base.
tet spike.off 0,0,0 1,0,0 0.5,0.9,0 0.5,0.3,1000; cases+=(spike.off)
# Huge and tiny coordinates, and near-coincident vertices (the fourth 1e-9 from the first).
tet huge.off 1e12,1e12,1e12 1.1e12,1e12,1e12 1e12,1.1e12,1e12 1e12,1e12,1.1e12; cases+=(huge.off)
tet tiny.off 0,0,0 1e-12,0,0 0,1e-12,0 0,0,1e-12; cases+=(tiny.off)
tet coincident.off 0,0,0 1,0,0 0,1,0 1e-9,1e-9,1e-9; cases+=(coincident.off)

for mesh in "${cases[@]}"; do
  set +e
  timeout 60 "$bin/tetseg" build "$mesh" -o "$mesh.tetseg" --clusters single -q >out.txt 2>err.txt
  code=$?
  set -e
  case $code in
    0) [ -s "$mesh.tetseg" ] || fail "$mesh: exit 0 without an asset" ;;
    3 | 5)
      grep -q "tetseg: error: $mesh: " err.txt || { cat err.txt >&2; fail "$mesh: refusal without the file named"; }
      [ ! -e "$mesh.tetseg" ] || fail "$mesh: refused but an asset was written" ;;
    124) fail "$mesh: still running after 60 s" ;;
    *) cat err.txt >&2; fail "$mesh: exit $code (a crash or an undocumented code)" ;;
  esac
  echo "$mesh: exit $code $(head -c 200 err.txt | tr '\n' ' ')"
done
# None of them may leave a temporary file behind.
if ls ./*.tmp* 2>/dev/null | grep -q .; then fail "a temporary file was left"; fi

# --time-limit: refused with exit 5, the stage named, nothing written; range-checked.
"$bin/tetseg" generate sphere -o sphere.mesh 2>/dev/null
"$bin/tetseg" charge sphere.mesh -o ball.ply 2>/dev/null
# (A facet size of 0.01 makes Mesh_3 run for minutes; reading takes milliseconds.)
expect_exit 5 "tetseg: error: ball.ply: time limit of 1 s reached in stage tetrahedralize, in CGAL Mesh_3" -- \
  "$bin/tetseg" build ball.ply -o ball.tetseg --time-limit 1 --facet-size 0.01
[ ! -e ball.tetseg ] || fail "a build over its time limit left an asset"
expect_exit 5 "tetseg: error: ball.ply: tetrahedralize: time limit of 1 s reached in CGAL Mesh_3" -- \
  "$bin/tetseg" tetrahedralize ball.ply -o ball.mesh --time-limit 1 --facet-size 0.01
[ ! -e ball.mesh ] || fail "a tetrahedralisation over its time limit left a mesh"
expect_exit 2 "time-limit" -- "$bin/tetseg" build ball.ply -o ball.tetseg --time-limit -1
# A tet-mesh input: the limit is checked after every stage (the stage named).
expect_exit 5 "tetseg: error: sphere.mesh: time limit of 1e-06 s reached in stage read" -- \
  "$bin/tetseg" build sphere.mesh -o sphere.tetseg --time-limit 0.000001
[ ! -e sphere.tetseg ] || fail "a build over its time limit left an asset"
