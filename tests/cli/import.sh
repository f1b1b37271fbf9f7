#!/usr/bin/env bash
# End-to-end: tetseg generate / tetrahedralize. Exit codes (0 ok, 2 usage, 3 bad input,
# 4 output failed), error message format, outputs, determinism across processes.
# needs: preprocess
set -euo pipefail

tetseg="${TETSEG_BIN_DIR:?}/tetseg"
source "$(dirname "${BASH_SOURCE[0]}")/common.bash"  # $work (the current folder), fail, skip_without_data

# expect_exit <code> <command...>: runs the command, captures stderr in $work/err.
expect_exit() {
  local want="$1"; shift
  set +e
  "$@" 2>"$work/err" >/dev/null
  local got=$?
  set -e
  [[ "$got" == "$want" ]] || { cat "$work/err" >&2; fail "'$*' exited $got, expected $want"; }
}

# Usage errors: exit 2.
expect_exit 2 "$tetseg" generate cube -o x.mesh
expect_exit 2 "$tetseg" generate sphere
expect_exit 2 "$tetseg" generate sphere -o x.vtk
expect_exit 2 "$tetseg" generate sphere -o x.mesh --size -1
expect_exit 2 "$tetseg" generate ellipsoid -o x.mesh --axes 1 2
expect_exit 2 "$tetseg" tetrahedralize
[[ ! -e x.mesh ]] || fail "a usage error left an output"

# Bad input: exit 3 with "tetseg: error: <file>: ...".
printf 'OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 x\n' > bad.off
expect_exit 3 "$tetseg" tetrahedralize bad.off -o out.mesh
grep -q '^tetseg: error: bad.off: ' err || { cat err >&2; fail "no file-named error for bad.off"; }
printf 'OFF\n4 3 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n' > open.off
expect_exit 3 "$tetseg" tetrahedralize open.off -o out.mesh --repair none
grep -q '^tetseg: error: open.off: surface is not closed (3 border edges' err ||
  { cat err >&2; fail "open surface message"; }
expect_exit 3 "$tetseg" tetrahedralize missing.off -o out.mesh
grep -q '^tetseg: error: missing.off: ' err || fail "missing file message"
[[ ! -e out.mesh ]] || fail "a failed run left an output"

# Output failure: exit 4, nothing left behind.
expect_exit 4 "$tetseg" generate sphere --size 0.3 -o "$work/no/such/dir/s.mesh"

# Happy path: every format, stage lines on stderr, no temporary files left.
expect_exit 0 "$tetseg" generate pawn --size 0.5 -o pawn.mesh
grep -q '^tetseg: generate  *[0-9.]* s  pawn: [0-9]* nodes, [0-9]* tets$' err ||
  { cat err >&2; fail "no meshing stage line"; }
head -c 200 pawn.mesh | grep -q 'Vertices' || fail "pawn.mesh is not MEDIT"
expect_exit 0 "$tetseg" generate pawn --size 0.5 -o pawn2.mesh
cmp -s pawn.mesh pawn2.mesh || fail "generate is not deterministic across runs"
expect_exit 0 "$tetseg" generate ellipsoid --axes 1 0.5 0.25 --size 0.5 -o ell.msh
head -n 2 ell.msh | grep -q '^4.1 0 8$' || fail "ell.msh is not Gmsh 4.1"
expect_exit 0 "$tetseg" generate dumbbell --size 0.5 --gmsh22 -o db.msh
head -n 2 db.msh | grep -q '^2.2 0 8$' || fail "db.msh is not Gmsh 2.2"
expect_exit 0 "$tetseg" generate sphere --radius 2 --cell-size 0.5 --no-optimize -o ball.node
[[ -s ball.node && -s ball.ele ]] || fail "TetGen output missing"

# Tetrahedralise a closed surface: an octahedron, and a CGAL demo mesh when available.
printf 'OFF\n6 8 0\n1 0 0\n-1 0 0\n0 1 0\n0 -1 0\n0 0 1\n0 0 -1\n3 0 2 4\n3 2 1 4\n3 1 3 4\n3 3 0 4\n3 2 0 5\n3 1 2 5\n3 3 1 5\n3 0 3 5\n' > octa.off
expect_exit 0 "$tetseg" tetrahedralize octa.off -o octa.mesh
grep -q '^tetseg: validate  *[0-9.]* s  [0-9]* surface triangles' err || { cat err >&2; fail "no validation stage"; }
if [[ -f "${TETSEG_CGAL_MESH_DIR:-/nonexistent}/elephant.off" ]]; then
  expect_exit 0 "$tetseg" tetrahedralize "$TETSEG_CGAL_MESH_DIR/elephant.off" --facet-size 0.05 -o elephant.msh
else
  skip_without_data "CGAL demo mesh elephant.off"
fi

leftovers="$(find . -name '*.tmp*' | head -n 1)"
[[ -z "$leftovers" ]] || fail "temporary file left: $leftovers"
echo "import.sh: all checks passed"
