#!/usr/bin/env bash
# Purpose: each plugin comes from its own .so; removing one removes that type and nothing else, without rebuilding.
set -u
TF=$1
PLUGINS=$2
source "$(dirname "$0")/lib.sh"

mkdir -p "$TMP/plugins"
cp "$PLUGINS"/tfplugin_*.so "$TMP/plugins/"
list() { "$TF" plugins --json --no-default-plugins --plugin-path "$TMP/plugins"; }
types() { list | grep -o '"type": "[a-z_.]*"' | sed 's/"type": //; s/"//g' | sort; }
objects() { list | tr -d '\n' | sed 's/}/}\n/g'; }  # one JSON object of "types" per line

expected="convert.classical filter.kalman sim.radar sim.trajectory sink.csv sink.metrics source.csv"
for t in $expected; do
  types | grep -qx "$t" || fail "type $t not listed by 'trackflow plugins'"
done
echo "ok: all seven first-slice types are listed"
checks=$((checks + 1))

# One file per type among the seven.
for t in $expected; do
  n=$(objects | grep "\"type\": \"$t\"" | grep -o '"file": "[^"]*"' | sort -u | wc -l)
  [ "$n" -eq 1 ] || fail "type $t comes from $n files"
done
files=$(for t in $expected; do objects | grep "\"type\": \"$t\"" | grep -o '"file": "[^"]*"'; done | sort -u | wc -l)
[ "$files" -eq 7 ] || fail "the seven types come from $files files, expected 7"
echo "ok: each of the seven types comes from its own .so"
checks=$((checks + 1))

before=$(types)
rm "$TMP/plugins/tfplugin_sink_csv.so"
after=$(types)
removed=$(comm -23 <(echo "$before") <(echo "$after"))
added=$(comm -13 <(echo "$before") <(echo "$after"))
[ "$removed" = "sink.csv" ] || fail "removing tfplugin_sink_csv.so removed '$removed', expected only sink.csv"
[ -z "$added" ] || fail "removing a plugin added types: $added"
echo "ok: removing tfplugin_sink_csv.so removes sink.csv and nothing else"
checks=$((checks + 1))

# A file that is not a trackflow plugin, and a truncated one, are named with the failing stage.
cp /bin/true "$TMP/plugins/tfplugin_fake.so"
expect_run "a non-library file is refused, naming it" 2 "tfplugin_fake.so: open: " -- \
  "$TF" plugins --no-default-plugins --plugin-path "$TMP/plugins"
rm "$TMP/plugins/tfplugin_fake.so"
cp "$(ldconfig -p | grep -m1 -o '/[^ ]*libm\.so\.6')" "$TMP/plugins/tfplugin_notours.so" 2>/dev/null || cp /lib/x86_64-linux-gnu/libm.so.6 "$TMP/plugins/tfplugin_notours.so"
expect_run "a library without the entry point is 'not a trackflow plugin'" 2 "tfplugin_notours.so: entry: not a trackflow plugin" -- \
  "$TF" plugins --no-default-plugins --plugin-path "$TMP/plugins"
rm "$TMP/plugins/tfplugin_notours.so"
# Plugins built against an older SDK are refused at the "abi" stage, naming both versions, and
# their registration is never run (it traps); the other plugins still load.
for abi in 3 4 5 6 7 8; do
  cp "$PLUGINS/../old-abi-plugins/tfplugin_test_abi$abi.so" "$TMP/plugins/"
  expect_run "an ABI-$abi plugin is refused with a clear message" 2 \
    "tfplugin_test_abi$abi.so: abi: built against plugin ABI $abi \\(SDK 0\\.$abi\\.[01]\\); this trackflow needs ABI 9 \\(SDK 0\\.9\\.[0-9]\\): rebuild the plugin" -- \
    "$TF" plugins --no-default-plugins --plugin-path "$TMP/plugins"
  list | grep -q '"sink.metrics"' || fail "an ABI-$abi plugin in the folder stopped the other plugins from loading"
  rm "$TMP/plugins/tfplugin_test_abi$abi.so"
done
expect_run "an unknown type lists what exists and where it looked" 2 "unknown type 'sink.csv'.*Available: .*sink.metrics.*Searched: $TMP/plugins" -- \
  "$TF" describe sink.csv --no-default-plugins --plugin-path "$TMP/plugins"
finish
