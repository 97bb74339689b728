#!/usr/bin/env bash
# The command line as a newcomer meets it: a mistyped subcommand gets the nearest one,
# an unknown word no false suggestion, and a real subcommand still runs.
# Usage: cli_usage.sh VOLA
set -euo pipefail
vola=$1
source "$(dirname "$0")/lib/cli_test.sh"

expect_suggestion() {  # WORD SUGGESTION
  if "$vola" "$1" a b 2> "$tmp/err.txt"; then fail "'$1' ran"; fi
  grep -q "'$1' is not a vola subcommand; did you mean '$2'?" "$tmp/err.txt" || fail "'$1': $(cat "$tmp/err.txt")"
}
expect_suggestion convrt convert
expect_suggestion tiles tile
expect_suggestion transalte translate
expect_suggestion inf info
if "$vola" xyzzy 2> "$tmp/err.txt"; then fail "'xyzzy' ran"; fi
grep -q "'xyzzy' is not a vola subcommand (vola --help" "$tmp/err.txt" || fail "xyzzy: $(cat "$tmp/err.txt")"
"$vola" info --help > /dev/null || fail "vola info --help failed"
echo "cli usage: ok"
