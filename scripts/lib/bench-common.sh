# shellcheck shell=bash
# Sourced by scripts/bench-*.sh and scripts/make-scenes.sh (not run itself): the checks and the
# machine line every benchmark shares. Messages start with the name of the script sourcing it.

bench_script=$(basename "$0" .sh)
bench_repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)

# bench_require_tools BUILD_DIR TOOL...: each TOOL is built in BUILD_DIR/tools; else exits 1
# naming the missing ones and the command that builds them.
bench_require_tools() {
  local build=$1 tool missing=()
  shift
  for tool in "$@"; do
    [ -x "$build/tools/$tool" ] || missing+=("$tool")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "$bench_script: not built in $build/tools: ${missing[*]}" \
    "(cmake --build $build --target ${missing[*]})" >&2
  exit 1
}

# bench_require_scenes FILE...: each recorded scene file (scripts/make-scenes.sh) exists; else
# exits 1 naming the first missing one.
bench_require_scenes() {
  local file
  for file in "$@"; do
    [ -f "$file" ] || { echo "$bench_script: $file missing: run scripts/make-scenes.sh" >&2; exit 1; }
  done
}

# bench_machine [BUILD_DIR]: "machine: <cores> cores, <CPU model>, load average <1 5 15 min>,
# <UTC date and time>, commit <hash>", the line every benchmark prints with its figures
# (docs/benchmarks.md). The commit is that of the sources BUILD_DIR was configured from, or
# of this repository.
bench_machine() {
  local source_dir=$bench_repo
  if [ -n "${1:-}" ] && [ -f "$1/CMakeCache.txt" ]; then
    source_dir=$(sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' "$1/CMakeCache.txt")
  fi
  echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)," \
    "load average $(cut -d' ' -f1-3 /proc/loadavg), $(date -u '+%Y-%m-%d %H:%M UTC')," \
    "commit $(git -C "$source_dir" rev-parse --short HEAD 2>/dev/null || echo unknown)"
}
