#!/usr/bin/env bash
# Purpose: docs/plugins.md is what `trackflow describe --all --markdown` prints for the plugins in this tree.
set -u
TF=$1
PLUGINS=$2
ROOT=$4
source "$(dirname "$0")/lib.sh"
"$TF" describe --all --markdown --no-default-plugins --plugin-path "$PLUGINS" > "$TMP/plugins.md" || fail "describe --all failed"
if ! diff -u "$ROOT/docs/plugins.md" "$TMP/plugins.md" > "$TMP/diff"; then
  head -40 "$TMP/diff" >&2
  fail "docs/plugins.md is out of date: regenerate with: build/bin/trackflow describe --all --markdown > docs/plugins.md"
fi
echo "ok: docs/plugins.md matches the plugins' declarations"
checks=1
finish
