#!/usr/bin/env bash
# Purpose: every ```yaml snippet in README.md, docs/ and examples/ validates (issue 26), and the check can fail.
set -u
TF=$1
PLUGINS=$2
ROOT=$4
source "$(dirname "$0")/lib.sh"
CHECK="$ROOT/tests/support/docs_snippets.py"
command -v python3 > /dev/null && python3 -c 'import yaml' 2> /dev/null ||
  fail "python3 with PyYAML (Debian python3-yaml) is needed: setup.sh test installs it"

expect_run "every docs snippet validates" 0 "snippets validate" -- python3 "$CHECK" "$TF" "$PLUGINS" "$ROOT"
# Teeth: with each snippet's first type misspelt, every one of them must fail its check.
expect_run "every docs snippet fails when corrupted" 0 "snippets fail when corrupted" -- \
  python3 "$CHECK" "$TF" "$PLUGINS" "$ROOT" --corrupt

# A fence without a marker, and a marker naming a missing host, are failures, not skips.
mkdir -p "$TMP/root/docs" "$TMP/root/pipelines"
printf '# t\n\n```yaml\n- { id: a, type: sim.radar }\n```\n' > "$TMP/root/README.md"
printf '<!-- checked: nodes in pipelines/none.yaml -->\n```yaml\n- { id: a, type: sim.radar }\n```\n' > "$TMP/root/docs/x.md"
expect_run "an unmarked fence fails" 1 "README.md:3: a \`\`\`yaml fence without a" -- \
  python3 "$CHECK" "$TF" "$PLUGINS" "$TMP/root"
expect_run "a marker naming a missing host fails" 1 "docs/x.md:2 .*pipelines/none.yaml, which does not exist" -- \
  python3 "$CHECK" "$TF" "$PLUGINS" "$TMP/root"
# No snippet at all: the check ran nothing, which is a failure.
rm "$TMP/root/README.md" "$TMP/root/docs/x.md"; touch "$TMP/root/README.md"
expect_run "no snippet at all fails" 1 "no \`\`\`yaml snippet found" -- python3 "$CHECK" "$TF" "$PLUGINS" "$TMP/root"
finish
