#!/usr/bin/env bash
# Quick start, part 1: installs dependencies, builds tetseg, generates a default mesh (a chess
# pawn of revolution, made in code) and runs the whole pipeline on it, then prints a summary
# of the asset. Outputs land in out/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DTETSEG_BUILD_TESTS=OFF
cmake --build build
mkdir -p out
build/tools/tetseg generate pawn -o out/pawn.mesh
build/tools/tetseg build out/pawn.mesh -o out/pawn.tetseg --report out/pawn.report.json
build/tools/tetseg-dump out/pawn.tetseg
