# Purpose: shared helpers of the CLI test scripts: expect an exit code and text in the output.
# Usage in a script: source "$(dirname "$0")/lib.sh"; then call expect_run.
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
checks=0

fail() {
  echo "FAIL: $*" >&2
  exit 1
}

# expect_run <what> <expected exit code> <regex that stdout+stderr must match> -- command...
expect_run() {
  local what=$1 code=$2 pattern=$3
  shift 4
  local out rc
  out=$("$@" 2>&1)
  rc=$?
  if [ "$rc" -ne "$code" ]; then
    printf '%s\n' "$out" >&2
    fail "$what: exit code $rc, expected $code"
  fi
  if ! printf '%s\n' "$out" | grep -Eq -- "$pattern"; then
    printf '%s\n' "$out" >&2
    fail "$what: output does not match /$pattern/"
  fi
  checks=$((checks + 1))
  echo "ok: $what"
}

finish() {
  echo "$checks passed, 0 failed"
}
