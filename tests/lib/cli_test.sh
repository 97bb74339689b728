# The preamble every command-line test shares; source it after `set -uo pipefail` (or -euo):
#   source "$(dirname "$0")/../lib/cli_test.sh"
# It gives
#   $tmp        a fresh folder, removed when the test exits;
#   fail MSG    prints "FAIL: MSG" and ends the test with status 1; when the test set
#               keep_going=1 before sourcing, it counts the failure in $failures instead
#               and goes on (the test then ends by checking $failures);
#   skip MSG    the data a test needs is missing: status 77 (ctest's skip), but a failure
#               when CI is set, so that a CI run never passes by skipping.
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() {
  echo "FAIL: $*" >&2
  if [[ ${keep_going:-0} == 1 ]]; then
    failures=$((failures + 1))
    return 0
  fi
  exit 1
}
skip() {
  if [[ -n ${CI:-} ]]; then
    echo "FAIL: $* (CI is set)" >&2
    exit 1
  fi
  echo "SKIP: $*"
  exit 77
}
