#!/usr/bin/env bash
# tetseg-bench-charge: exit codes and messages of docs/cli.md (run_tool), checked before any
# solve starts; one small ellipsoid run for the table.
# needs: preprocess
# needs: bench
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.bash"
tool="$bin/tetseg-bench-charge"

expect_exit 0 "tetseg-bench-charge 0.1" -- "$tool" --version
expect_exit 0 "Usage" -- "$tool" --help
# Usage errors name the option and the entry.
expect_exit 2 "tetseg-bench-charge: error: --solvers magic: unknown solver 'magic'" -- \
  "$tool" --solvers magic
expect_exit 2 "--solvers fast:abc: bad order 'abc'" -- "$tool" --solvers fast:abc
expect_exit 2 "--solvers gmres@2: tolerance" -- "$tool" --solvers gmres@2
expect_exit 2 "2k not in" -- "$tool" --sizes 2k
# A real mesh named on the command line must read: missing and malformed files name the file.
expect_exit 3 "tetseg-bench-charge: error: $PWD/missing.off: cannot open" -- \
  "$tool" --mesh-dir "$PWD" --real missing.off --sizes 1k --no-reference
printf 'OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n' > bad.off
expect_exit 3 "tetseg-bench-charge: error: $PWD/bad.off: " -- \
  "$tool" --mesh-dir "$PWD" --real bad.off --sizes 1k --no-reference
# Nothing was solved before the errors above: no table on stdout.
[ ! -s out.txt ] || fail "a rejected run printed a table"
# --real none: ellipsoids only, whatever --mesh-dir holds.
"$tool" --mesh-dir "$PWD" --real none --sizes 1k --solvers direct --no-reference > none.md
[ "$(grep -c '^| ellipsoid' none.md)" -eq 1 ] && ! grep -q "none" none.md ||
  { cat none.md >&2; fail "--real none"; }

# A run: the 980-triangle ellipsoid and a small real mesh (an octahedron), direct solver.
printf 'OFF\n6 8 0\n1 0 0\n-1 0 0\n0 1 0\n0 -1 0\n0 0 1\n0 0 -1\n' > octa.off
printf '3 0 2 4\n3 2 1 4\n3 1 3 4\n3 3 0 4\n3 2 0 5\n3 1 2 5\n3 3 1 5\n3 0 3 5\n' >> octa.off
"$tool" --mesh-dir "$PWD" --real octa.off --sizes 1k --solvers direct --no-reference \
  > table.md 2> err.txt || { cat err.txt >&2; fail "the small run failed"; }
grep -q "^| ellipsoid 1:0.6:0.3 | 980 | direct |" table.md || { cat table.md >&2; fail "no ellipsoid row"; }
grep -q "^| octa.off | 8 | direct |" table.md || { cat table.md >&2; fail "no real-mesh row"; }
echo "bench_charge: ok"
