# Sourced by the CLI test scripts (not a test itself): tool folder, a scratch directory that
# is removed on exit, and the two assertions every script uses.
bin=${TETSEG_BIN_DIR:?TETSEG_BIN_DIR must name the folder of the built tools}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"

fail() { echo "FAIL: $*" >&2; exit 1; }

# expect_exit CODE PATTERN -- command...: the command exits with CODE and prints PATTERN
# (grep pattern, on stdout or stderr; "" matches anything).
expect_exit() {
  local code=$1 pattern=$2; shift 3
  set +e; "$@" >out.txt 2>err.txt; local got=$?; set -e
  [ "$got" -eq "$code" ] || { cat err.txt >&2; fail "'$*' exited $got, expected $code"; }
  grep -q -- "$pattern" err.txt out.txt || { cat err.txt >&2; fail "'$*' did not print '$pattern'"; }
}
