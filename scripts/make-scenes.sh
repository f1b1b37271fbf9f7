#!/usr/bin/env bash
# Generates the benchmark scenes of docs/benchmarks.md ("Self-collision per frame") and of
# docs/benchmarks-history.md ("Table I", "Cluster refinement"): pawn,
# dumbbell, and the libcgal-demo elephant, armadillo and dino, each an asset (default options)
# plus a tetseg-sim frame sequence of a soft drop onto the ground, and the same mesh's assets
# with the other cluster methods (NAME-charge.tetseg, NAME-single.tetseg); then the scenes with
# several bodies ("Scenes"): a pile of soft balls dropped into a bin, two characters dropped
# on each other, a soft pancake draped over a still sphere, each a frame sequence plus a scene
# description for `tetseg-bench scene` (NAME.tsscene). The single-body scenes also record every
# eighth collision query of the simulator as frame pairs (NAME.queries.tsf, docs/simulation.md,
# "Recording the queries"). Outputs go to OUT_DIR (default
# BUILD_DIR/scenes), never into the repository.
#
#   scripts/make-scenes.sh [BUILD_DIR] [OUT_DIR]      (BUILD_DIR default: ./build)
#
# Then the thin and multi-part bodies of issue 13 ("Thin and multi-part bodies"): structured
# shapes from `tetseg generate` (a 40 x 40 mat, a plate, a bar and a torus one tet thick, two
# interlocked tori in one mesh) draped over a still sphere or dropped, and the mat twisted by
# its ends, each a frame sequence plus a scene description (NAME.tsscene).
#
# Environment: TETSEG_SCENES=multibody makes only the scenes with several bodies, =thin only
# the thin ones;
# TETSEG_PILE_BALLS=N (default 8) balls in the pile, in layers of four (16: the pile of
# docs/benchmarks.md, about 3 minutes more).
# Needs tetseg and tetseg-sim built in BUILD_DIR (Release). A few minutes on 2 cores.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib/bench-common.sh"
repo=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$repo/build}" && pwd)
out=${2:-$build/scenes}
mkdir -p "$out"
out=$(cd "$out" && pwd)
bench_require_tools "$build" tetseg tetseg-sim
tetseg=$build/tools/tetseg
sim=$build/tools/tetseg-sim
cd "$out"

scene() {  # scene NAME SIM-OPTIONS...  (NAME.mesh exists)
  local name=$1; shift
  "$tetseg" build "$name.mesh" -o "$name.tetseg" -q --report "$name.build.json"
  for clusters in charge single; do
    "$tetseg" build "$name.mesh" -o "$name-$clusters.tetseg" -q --clusters "$clusters" \
      --report "$name-$clusters.build.json"
  done
  echo "make-scenes: $name: simulating" >&2
  "$sim" "$name.mesh" "$name.tetseg" -o "$name.tsf" --json "$@" \
    --record-queries "$name.queries.tsf" --record-every 8 > "$name.sim.json"
  echo "make-scenes: $name: $(cat "$name.sim.json")" >&2
}

if [ "${TETSEG_SCENES:-all}" = all ]; then
# Pawn: 5275 nodes, 4942 surface triangles (paper: 3454 vertices, 5130 faces); tilted so it
# falls on its side and the collar bends onto the head and base.
"$tetseg" generate pawn -o pawn.mesh 2>/dev/null
scene pawn --frames 240 --drop 0.5 --tilt-x 50 --edge-compliance 5e-4

# Dumbbell: 1722 surface triangles (paper: 1249 vertices, 1710 faces); dropped nearly upright,
# the bar buckles and the two balls fold onto each other.
"$tetseg" generate dumbbell -o dumbbell.mesh 2>/dev/null
scene dumbbell --frames 240 --drop 0.8 --tilt-y 75 --edge-compliance 5e-4

# Character: the libcgal-demo elephant (paper: Luigi, 2433 vertices, 4014 faces),
# re-meshed by Mesh_3 to 3864 surface triangles; legs, trunk and ears fold onto the body.
tar xzf /usr/share/doc/libcgal-dev/data.tar.gz -O data/meshes/elephant.off > elephant.off
"$tetseg" tetrahedralize elephant.off -o elephant.mesh 2>/dev/null
scene elephant --frames 200 --drop 0.3 --tilt-x 90 --tilt-y 30 --edge-compliance 2e-5 \
  --iterations 3

# Two more libcgal-demo characters for the cluster-refinement comparison (issue 7). The
# armadillo is about 150 units tall: scaled to about 1 so the drop and stiffness match.
tar xzf /usr/share/doc/libcgal-dev/data.tar.gz -O data/meshes/armadillo.off |
  python3 -c '
import sys
lines = [l for l in sys.stdin.read().split("\n") if l.strip() and not l.startswith("#")]
nv = int(lines[1].split()[0])
scaled = [" ".join(repr(float(x) * 0.0066) for x in l.split()[:3]) for l in lines[2:2 + nv]]
print("\n".join(lines[:2] + scaled + lines[2 + nv:]))' > armadillo.off
"$tetseg" tetrahedralize armadillo.off -o armadillo.mesh 2>/dev/null
scene armadillo --frames 200 --drop 0.3 --tilt-x 90 --tilt-y 30 --edge-compliance 2e-5 \
  --iterations 3
tar xzf /usr/share/doc/libcgal-dev/data.tar.gz -O data/meshes/dino.off > dino.off
"$tetseg" tetrahedralize dino.off -o dino.mesh 2>/dev/null
scene dino --frames 200 --drop 0.3 --tilt-x 90 --tilt-y 30 --edge-compliance 2e-5 \
  --iterations 3

fi

multibody() {  # multibody NAME SIM-OPTIONS...: NAME.tsf and NAME.tsscene
  local name=$1; shift
  echo "make-scenes: $name: simulating" >&2
  "$sim" -o "$name.tsf" --scene "$name.tsscene" --json "$@" > "$name.sim.json"
  echo "make-scenes: $name: $(cat "$name.sim.json")" >&2
}

if [ "${TETSEG_SCENES:-all}" != thin ]; then
# Pile: soft balls of radius 0.15 (tetseg generate sphere --size 0.6: 1544 nodes) dropped in
# layers of four, staggered, into a still bin open at the top (its floor just below the
# ground, so the ground plane carries the pile and the walls hold it).
balls=${TETSEG_PILE_BALLS:-8}
"$tetseg" generate sphere --radius 0.15 --size 0.6 -o ball.mesh 2>/dev/null
"$tetseg" build ball.mesh -o ball.tetseg -q
pile=()
for ((i = 0; i < balls; ++i)); do
  layer=$((i / 4))
  pile+=(--body "ball.mesh,ball.tetseg,$(python3 -c "
l, c = $layer, $i % 4
j = 0.05 if l % 2 else -0.05
print('%g,%g,%g' % (0.1 + 0.4 * l, (-0.2 if c % 2 == 0 else 0.2) + j, (-0.2 if c < 2 else 0.2) - j))")")
done
multibody "pile$balls" "${pile[@]}" --bin=-0.45,-0.45,-0.05,0.45,0.45,0.8 --frames 90

# Two characters: a soft dumbbell dropped lengthwise onto the upright pawn, off centre.
[ -f pawn.mesh ] || "$tetseg" generate pawn -o pawn.mesh 2>/dev/null
[ -f dumbbell.mesh ] || "$tetseg" generate dumbbell -o dumbbell.mesh 2>/dev/null
[ -f pawn.tetseg ] || "$tetseg" build pawn.mesh -o pawn.tetseg -q
[ -f dumbbell.tetseg ] || "$tetseg" build dumbbell.mesh -o dumbbell.tetseg -q
multibody characters --body pawn.mesh,pawn.tetseg,0,0,0 \
  --body dumbbell.mesh,dumbbell.tetseg,1.9,0.25,0.1 --frames 120 --edge-compliance 5e-4

# Drape: a soft pancake (ellipsoid 0.6 x 0.6 x 0.06) falling onto a still sphere of radius 0.3.
"$tetseg" generate ellipsoid --axes 0.6 0.6 0.06 -o pancake.mesh 2>/dev/null
"$tetseg" build pancake.mesh -o pancake.tetseg -q
multibody drape --body pancake.mesh,pancake.tetseg,0.7,0,0 --sphere=0,0,0.35,0.3 --frames 120 \
  --edge-compliance 2e-3

fi

if [ "${TETSEG_SCENES:-all}" != multibody ]; then
thin() {  # thin NAME SHAPE GENERATE-OPTIONS -- SIM-OPTIONS...: NAME.tsf and NAME.tsscene
  local name=$1 shape=$2; shift 2
  local gen=()
  while [ "$1" != -- ]; do gen+=("$1"); shift; done
  shift
  "$tetseg" generate "$shape" "${gen[@]}" -o "$shape.mesh" 2>/dev/null
  "$tetseg" build "$shape.mesh" -o "$shape.tetseg" -q --report "$shape.build.json"
  multibody "$name" --body "$shape.mesh,$shape.tetseg" "$@"
}
# Mats and plates: 1 x 1, one (mat) or three (plate) tets thick, over a sphere of radius 0.3.
thin mat-drape mat -- --sphere=0.5,0.5,0.3,0.3 --drop 0.65 --frames 60
thin plate-drape plate -- --sphere=0.5,0.5,0.3,0.3 --drop 0.65 --frames 60
# The mat held 1 above the ground by its ends (5% of its length each), which turn 480 degrees
# per second against each other: it sags and wraps into itself.
thin mat-twist mat -- --drop 1.0 --twist 480 --frames 90
# A bar (1 long, one tet thick) over the sphere; a torus (radius 1, one tet thick) over a
# sphere of radius 1.1 mostly below the ground.
thin bar-drape bar -- --sphere=0.5,0.0125,0.3,0.15 --drop 0.5 --frames 60
thin torus-drop torus -- --sphere=0,0,-0.5,1.1 --drop 0.7 --tilt-x 20 --frames 60
# Two interlocked tori in one mesh (one body, two components), tilted: the upper link falls
# into the lower one, which lands on the ground.
thin tori-drop tori -- --drop 0.1 --tilt-x 60 --frames 60
fi

echo "make-scenes: done: $out/{pawn,dumbbell,elephant,armadillo,dino}{,-charge,-single}.tetseg and .tsf, {pile${balls:-N},characters,drape,mat-drape,plate-drape,mat-twist,bar-drape,torus-drop,tori-drop}.tsscene and .tsf" >&2
