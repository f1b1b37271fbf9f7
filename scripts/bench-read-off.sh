#!/usr/bin/env bash
# Reading and writing at a million triangles (docs/benchmarks-history.md, "Reading a 1.3 M-triangle
# OFF"): writes a torus of 1,310,720 triangles as plain ASCII OFF (70 MB, in the scratch
# directory), then runs `tetseg charge` on it with one GMRES iteration (the charge is not the
# point here) for each tetseg binary given, twice, alternating, and prints the reading stage
# (read + validate), the charge and the whole run (the rest is mostly writing the CSV).
# Usage: scripts/bench-read-off.sh [tetseg binary ...]   (default build/tools/tetseg)
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib/bench-common.sh"
cd "$(dirname "$0")/.."
binaries=("$@")
[ ${#binaries[@]} -gt 0 ] || binaries=(build/tools/tetseg)
scratch=${TMPDIR:-/tmp}/tetseg-bench-read-off
mkdir -p "$scratch"
off=$scratch/torus.off
if [ ! -f "$off" ]; then
  python3 - "$off" <<'PY'
import math, sys
nu, nv, big, small = 1024, 640, 1.0, 0.3
with open(sys.argv[1], "w") as f:
    f.write(f"OFF\n{nu * nv} {2 * nu * nv} 0\n")
    for i in range(nu):
        u = 2 * math.pi * i / nu
        for j in range(nv):
            v = 2 * math.pi * j / nv
            r = big + small * math.cos(v)
            f.write(f"{r * math.cos(u)!r} {r * math.sin(u)!r} {small * math.sin(v)!r}\n")
    at = lambda i, j: (i % nu) * nv + (j % nv)
    for i in range(nu):
        for j in range(nv):
            a, b, c, d = at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)
            f.write(f"3 {a} {b} {c}\n3 {a} {c} {d}\n")
PY
fi
echo "== $(bench_machine)"
echo "| binary | read + validate s | charge s | whole run s |"
echo "|---|---|---|---|"
for round in 1 2; do
  for bin in "${binaries[@]}"; do
    start=$(date +%s.%N)
    "$bin" charge "$off" -o "$scratch/out.csv" --max-iterations 1 2>"$scratch/log.txt"
    end=$(date +%s.%N)
    # Stage lines: "tetseg: read   0.12 s  ..." (since issue 27), "tetseg: reading x ... 0.12 s" before.
    read_s=$(sed -n -e 's/^tetseg: reading .* \.\.\. \([0-9.]*\) s.*/\1/p' \
      -e 's/^tetseg: read  *\([0-9.]*\) s .*/\1/p' "$scratch/log.txt")
    charge_s=$(sed -n -e 's/^tetseg: charge \.\.\. \([0-9.]*\) s.*/\1/p' \
      -e 's/^tetseg: charge  *\([0-9.]*\) s .*/\1/p' "$scratch/log.txt")
    awk -v b="$bin" -v r="$read_s" -v c="$charge_s" -v s="$start" -v e="$end" \
      'BEGIN { printf "| %s | %s | %s | %.2f |\n", b, r, c, e - s }'
  done
done
