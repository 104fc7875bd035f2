#!/usr/bin/env bash
# Purpose: outputs fail loudly: a full disk is not exit 0, output paths are checked before the runs, a failed ensemble leaves no half file, odd plugin files and names do not break commands or JSON.
set -u
source "$(dirname "$0")/lib.sh"

base > "$TMP/p.yaml"
expect_run "--metrics-json on a full disk is exit 2" 2 "error writing metrics JSON '/dev/full': No space left on device" \
  -- "$TF" run "$TMP/p.yaml" --out "$TMP/o" --metrics-json /dev/full
expect_run "stdout on a full disk is exit 2" 2 "cannot write the standard output: No space left on device" \
  -- bash -c "\"$TF\" run \"$TMP/p.yaml\" --out \"$TMP/o\" > /dev/full"
expect_run "... for validate too" 2 "cannot write the standard output" -- bash -c "\"$TF\" validate \"$TMP/p.yaml\" > /dev/full"
expect_run "sweep --csv on a full disk is exit 2" 2 "cannot write '/dev/full': No space left on device" \
  -- "$TF" sweep "$TMP/p.yaml" --param kf.q=0,1 --runs 1 --csv /dev/full --out "$TMP/o"

# Checked before anything runs: nothing of the run is printed.
touch "$TMP/a_file"
expect_run "--metrics-json under a file is refused before the runs" 2 "--metrics-json '$TMP/a_file/m.json': '$TMP/a_file' is not a folder" \
  -- "$TF" run "$TMP/p.yaml" --out "$TMP/o" --metrics-json "$TMP/a_file/m.json"
"$TF" run "$TMP/p.yaml" --out "$TMP/o" --metrics-json "$TMP/a_file/m.json" > "$TMP/stdout.txt" 2>/dev/null
expect_no "... and nothing ran" "pipeline hostile|measurements processed" "$TMP/stdout.txt"
expect_run "--out that is a file is refused before the runs" 2 "--out '$TMP/a_file' exists and is not a folder" \
  -- "$TF" run "$TMP/p.yaml" --out "$TMP/a_file"
expect_run "--report that is a folder is refused before the runs" 2 "--report '$TMP' is a folder, not a file" \
  -- "$TF" run "$TMP/p.yaml" --out "$TMP/o" --report "$TMP"
expect_run "sweep --csv under a file is refused before the grid runs" 2 "--csv '$TMP/a_file/t.csv'" \
  -- "$TF" sweep "$TMP/p.yaml" --param kf.q=0,1 --csv "$TMP/a_file/t.csv"

# A failed ensemble leaves no sink file that looks complete (nor its .partial).
MIS="$HOSTILE/misbehave"
{ base | sed 's/runs: 2/runs: 4/; s/input: cm$/input: bad/'
  printf '  - { id: bad, type: test.misbehave, input: cm, params: { what: throw_std, run: 2 } }\n'
  printf '  - { id: log, type: sink.csv, inputs: [kf, truth] }\n'; } > "$TMP/fails.yaml"
expect_run "an ensemble that fails in run 2" 3 "during run 2 threw" -- "$TF" run "$TMP/fails.yaml" --plugin-path "$MIS" --out "$TMP/failed"
[ -e "$TMP/failed/log.csv" ] && fail "a failed ensemble left log.csv"
[ -e "$TMP/failed/log.csv.partial" ] && fail "a failed ensemble left log.csv.partial"
ls -A "$TMP/failed" | grep -q . && fail "a failed ensemble left files: $(ls -A "$TMP/failed")"
echo "ok: ... leaves no file behind"
checks=$((checks + 1))

# Odd files in a plugin folder.
mkdir -p "$TMP/plugins"
ln -s tfplugin_loop.so "$TMP/plugins/tfplugin_loop.so"
mkfifo "$TMP/plugins/tfplugin_fifo.so"
cp /bin/true "$TMP/plugins/$(printf 'tfplugin_\xff\xfe.so')"
expect_run "a looping symlink and a FIFO named tfplugin_*.so are named load problems" 2 \
  "tfplugin_loop.so: open: cannot resolve the file: Too many levels of symbolic links" -- "$TF" plugins --plugin-path "$TMP/plugins"
expect_run "... the FIFO is not opened (it would block)" 2 "tfplugin_fifo.so: open: not a regular file" -- "$TF" plugins --plugin-path "$TMP/plugins"
expect_run "... and a pipeline still runs beside them" 0 "measurements processed" \
  -- "$TF" run "$TMP/p.yaml" --plugin-path "$TMP/plugins" --out "$TMP/o"
"$TF" plugins --json --plugin-path "$TMP/plugins" > "$TMP/plugins.json" 2>/dev/null
python3 -c "import json,sys; json.load(open(sys.argv[1], encoding='utf-8'))" "$TMP/plugins.json" ||
  fail "plugins --json with a non-UTF-8 file name is not valid JSON"
echo "ok: plugins --json with a non-UTF-8 file name is valid UTF-8 JSON"
checks=$((checks + 1))
"$TF" run "$TMP/p.yaml" --out "$TMP/o" --metrics-json "$TMP/m.json" >/dev/null 2>&1 || fail "metrics run failed"
python3 -c "import json,sys; json.load(open(sys.argv[1], encoding='utf-8'))" "$TMP/m.json" || fail "metrics JSON is invalid"
echo "ok: --metrics-json is valid JSON"
checks=$((checks + 1))
finish
