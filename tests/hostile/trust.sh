#!/usr/bin/env bash
# Purpose: opening a pipeline from someone else runs no code, replaces no built-in type, writes nothing outside --out and quotes no file content beyond the offending token.
set -u
source "$(dirname "$0")/lib.sh"

IMP="$HOSTILE/impostor"
[ -f "$IMP/tfplugin_test_impostor.so" ] || fail "the test plugin is not built"
export TRACKFLOW_TEST_MARKER="$TMP/marker"

# plugin_paths: in the file is refused unless the command line says so; nothing is loaded.
{ base | sed "s|runs: 2 }|runs: 2, plugin_paths: [$IMP] }|"; } > "$TMP/paths.yaml"
expect_run "a pipeline's plugin_paths: is refused (validate)" 2 \
  "paths.yaml:1:[0-9]+: this pipeline asks to load plugins from $IMP \(plugin_paths:\); a pipeline file cannot make trackflow run code" \
  -- "$TF" validate "$TMP/paths.yaml"
[ -e "$TMP/marker" ] && fail "validate loaded the plugin named by plugin_paths: (its code ran)"
echo "ok: and the plugin's code did not run"
expect_run "... and by run and sweep" 2 "cannot make trackflow run code" -- "$TF" run "$TMP/paths.yaml" --out "$TMP/o"
expect_run "... (sweep)" 2 "cannot make trackflow run code" -- "$TF" sweep "$TMP/paths.yaml" --param kf.q=0,1
[ -e "$TMP/marker" ] && fail "run or sweep loaded the plugin named by plugin_paths:"
printf 'plugin_paths: [%s]\n' "$IMP" > "$TMP/top.yaml"; base >> "$TMP/top.yaml"
expect_run "a top-level plugin_paths: too" 2 "top.yaml:1:15: this pipeline asks to load plugins" -- "$TF" validate "$TMP/top.yaml"
expect_run "--trust-plugin-paths loads them" 0 "ok" -- "$TF" validate "$TMP/paths.yaml" --trust-plugin-paths
[ -e "$TMP/marker" ] || fail "--trust-plugin-paths did not load the folder"
echo "ok: and then the plugin was loaded"
rm -f "$TMP/marker"

# A plugin folder cannot silently replace a built-in type.
expect_run "a plugin declaring filter.kalman does not replace the built-in one" 0 \
  "filter.kalman \(filter, from $PLUGINS/tfplugin_filter_kalman.so\)" \
  -- "$TF" describe filter.kalman --plugin-path "$IMP"
expect_run "... it is named in a warning with the way to ask for it" 0 \
  "tfplugin_test_impostor.so: register: type 'filter.kalman' already provided by .*tfplugin_filter_kalman.so \(kept that one; it is built in: pass --replace-type filter.kalman" \
  -- "$TF" describe filter.kalman --plugin-path "$IMP"
base > "$TMP/p.yaml"
expect_run "... the run uses the built-in filter" 0 "position_rmse" -- "$TF" run "$TMP/p.yaml" --plugin-path "$IMP" --out "$TMP/o"
expect_run "--replace-type filter.kalman uses the plugin's" 0 "impostor +1" \
  -- "$TF" run "$TMP/p.yaml" --plugin-path "$IMP" --replace-type filter.kalman --out "$TMP/o"
expect_run "... and plugins lists it once, from the plugin" 0 "tfplugin_test_impostor.so" \
  -- "$TF" plugins --plugin-path "$IMP" --replace-type filter.kalman
n=$("$TF" plugins --json --plugin-path "$IMP" --replace-type filter.kalman | grep -c '"type": "filter.kalman"')
[ "$n" -eq 1 ] || fail "filter.kalman is listed $n times after --replace-type"

# Sinks write under --out only.
{ base; printf '  - { id: log, type: sink.csv, inputs: [kf, truth], params: { path: %s } }\n' "$TMP/elsewhere/x.csv"; } > "$TMP/abs.yaml"
expect_run "an absolute sink.csv path is refused at validate time, at its line" 2 \
  "abs.yaml:23:[0-9]+: node 'log': parameter 'path': '$TMP/elsewhere/x.csv' is an absolute path; sinks write under --out \(pass --allow-outside-out" \
  -- "$TF" validate "$TMP/abs.yaml"
{ base; printf '  - { id: log, type: sink.csv, inputs: [kf, truth], params: { path: sub/../../../x.csv } }\n'; } > "$TMP/up.yaml"
expect_run "a path that climbs out of --out is refused" 2 "'sub/../../../x.csv' leaves the output folder" \
  -- "$TF" run "$TMP/up.yaml" --out "$TMP/o/deep"
[ -e "$TMP/x.csv" ] || [ -e "$TMP/o/x.csv" ] && fail "the refused path was written anyway"
expect_run "--allow-outside-out lets the user write there" 0 "wrote $TMP/elsewhere/x.csv" \
  -- "$TF" run "$TMP/abs.yaml" --allow-outside-out --out "$TMP/o"
[ -s "$TMP/elsewhere/x.csv" ] || fail "--allow-outside-out did not write the file"
{ base | sed 's/name: hostile/name: \/etc/'; } > "$TMP/name.yaml"
expect_run "a pipeline name cannot move the default output folder" 2 "name '/etc' must be" -- "$TF" validate "$TMP/name.yaml"

# A data path pointing at a file that is not a log: no line of it in the message.
for target in "$INPUTS/passwd_like.csv" /etc/passwd; do
  printf 'pipeline: {name: peek, runs: 1}\nnodes:\n  - {id: r, type: source.csv, params: {path: %s}}\n' "$target" > "$TMP/peek.yaml"
  expect_run "source.csv on $target says it is no log" 2 "does not look like a header of column names" -- "$TF" validate "$TMP/peek.yaml"
  out=$("$TF" validate "$TMP/peek.yaml" 2>&1)
  if printf '%s' "$out" | grep -q 'root:\|/bin/\|daemon'; then fail "the message quotes the file: $out"; fi
  echo "ok: and quotes none of it"
done
finish
