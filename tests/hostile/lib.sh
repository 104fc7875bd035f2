# Purpose: shared set-up of the tests/hostile scripts: arguments, a valid base pipeline, and the CLI test helpers.
# Usage: source "$(dirname "$0")/lib.sh" from a script called as <script> TF PLUGINS HOSTILE_PLUGINS INPUTS.
TF=$1
PLUGINS=$2
HOSTILE=$3
INPUTS=$4
source "$(dirname "${BASH_SOURCE[0]}")/../cli/lib.sh"
# Only what a test passes explicitly is searched for plugins.
unset TRACKFLOW_PLUGIN_PATH

# A valid pipeline (5 s at 10 Hz, 2 runs); each case breaks one thing in a copy.
base() { base_pipeline hostile 2; }

# expect_no <what> <regex> <file>: the file must not match (e.g. no NaN written).
expect_no() {
  if grep -Eq -- "$2" "$3"; then
    grep -Em3 -- "$2" "$3" >&2
    fail "$1: '$3' matches /$2/"
  fi
  checks=$((checks + 1))
  echo "ok: $1"
}
