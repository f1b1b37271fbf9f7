# Sourced by the CLI test scripts (not a test itself): tool folder, a scratch directory that
# is removed on exit, and the two assertions every script uses.
bin=${TETSEG_BIN_DIR:?TETSEG_BIN_DIR must name the folder of the built tools}
work=$(mktemp -d)
# A script that skipped checks for lack of data (skip_without_data) exits with 77 when everything
# else passed: ctest reports it as skipped (SKIP_RETURN_CODE), never as passed.
skipped_checks=""
on_exit() {
  local status=$?
  rm -rf "$work"
  if [ "$status" -eq 0 ] && [ -n "$skipped_checks" ]; then
    echo "SKIPPED:$skipped_checks" >&2
    exit 77
  fi
}
trap on_exit EXIT
cd "$work"

fail() { echo "FAIL: $*" >&2; exit 1; }

# skip_without_data WHAT: the data for WHAT is missing. Fails when TETSEG_REQUIRE_TEST_DATA=1
# (CI); otherwise records the skip (the script then exits 77) and returns.
skip_without_data() {
  [ "${TETSEG_REQUIRE_TEST_DATA:-0}" != 1 ] || fail "test data missing (required): $*"
  echo "WARN: test data missing: $*: skipped" >&2
  skipped_checks="$skipped_checks $*;"
}

# expect_exit CODE PATTERN -- command...: the command exits with CODE and prints PATTERN
# (grep pattern, on stdout or stderr; "" matches anything).
expect_exit() {
  local code=$1 pattern=$2; shift 3
  set +e; "$@" >out.txt 2>err.txt; local got=$?; set -e
  [ "$got" -eq "$code" ] || { cat err.txt >&2; fail "'$*' exited $got, expected $code"; }
  grep -q -- "$pattern" err.txt out.txt || { cat err.txt >&2; fail "'$*' did not print '$pattern'"; }
}
