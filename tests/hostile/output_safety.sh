#!/usr/bin/env bash
# Purpose: outputs cannot be redirected or corrupted (issue 27): no write through a symlink inside --out, an --out in use refused, two outputs naming one file refused, no truncated file under a real name on a full disk, --metrics-json checked by creating it.
set -u
source "$(dirname "$0")/lib.sh"
# OUTPUT_SAFETY_KEEP_GOING=1: go on after a failed check and count them (to see every case fail
# on an old build); the default stops at the first, as every hostile script does.
if [ "${OUTPUT_SAFETY_KEEP_GOING:-0}" = 1 ]; then
  failed=0
  fail() { echo "FAIL: $*" >&2; failed=$((failed + 1)); }
  finish() { echo "keep-going mode: $failed failed check(s)"; [ "$failed" -eq 0 ]; }
fi

# A repository as an attacker ships it: pipeline.yaml and links inside its default --out
# (out/<pipeline name>); the victims live outside, and every file outside --out must stay as it was.
base > "$TMP/p.yaml"
REPO="$TMP/repo"
mkdir -p "$REPO/out/hostile" "$TMP/victims/elsewhere"
for v in csv partial report series sub; do printf 'precious %s\n' "$v" > "$TMP/victims/$v"; done
printf 'precious t.csv\n' > "$TMP/victims/elsewhere/t.csv"
printf 'precious t.csv in out\n' > "$REPO/out/t.csv"
# Checksums of every file outside the output folder under test ($1): the victims, the repository.
outside_sums() { (cd "$TMP" && find . -path "./$1" -prune -o -type f -print | sort | xargs -r sha256sum); }

{ base; printf '  - { id: log, type: sink.csv, inputs: [kf, truth], params: { path: tracks.csv } }\n'; } > "$REPO/pipeline.yaml"
ln -s "$TMP/victims/partial" "$REPO/out/hostile/tracks.csv.partial"
ln -s "$TMP/victims/report" "$REPO/out/hostile/report.html"
ln -s "$TMP/victims/series" "$REPO/out/hostile/score.ensemble.csv"
before=$(outside_sums repo/out/hostile)
expect_run "a report run beside links at tracks.csv.partial, report.html and a series file" 0 "wrote out/hostile/report.html" \
  -- bash -c "cd '$REPO' && '$TF' report pipeline.yaml"
after=$(outside_sums repo/out/hostile)
[ "$before" = "$after" ] || fail "a file outside --out changed: $(diff <(echo "$before") <(echo "$after") | head -5)"
echo "ok: ... no file outside --out changed (the links are not written through)"
checks=$((checks + 1))
[ -L "$REPO/out/hostile/report.html" ] && fail "report.html is still the link"
[ -L "$REPO/out/hostile/score.ensemble.csv" ] && fail "score.ensemble.csv is still the link"
grep -q '^run,time_s,' "$REPO/out/hostile/tracks.csv" || fail "tracks.csv is not the sink's file"
echo "ok: ... the report and the series file replace the links, tracks.csv is written"
checks=$((checks + 1))

# A link at the sink's final name: replaced by the rename, the victim untouched.
rm -f "$REPO/out/hostile/tracks.csv"
ln -s "$TMP/victims/csv" "$REPO/out/hostile/tracks.csv"
before=$(outside_sums repo/out/hostile)
expect_run "a link at the sink's own file name" 0 "rows" -- bash -c "cd '$REPO' && '$TF' run pipeline.yaml"
[ "$before" = "$(outside_sums repo/out/hostile)" ] || fail "the link at tracks.csv was written through"
echo "ok: ... is replaced, not written through"
checks=$((checks + 1))

# A symlinked subfolder (path: sub/t.csv, sub -> .. and sub -> elsewhere): refused, nothing written.
{ base; printf '  - { id: log, type: sink.csv, inputs: [kf, truth], params: { path: sub/t.csv } }\n'; } > "$REPO/sub.yaml"
ln -s .. "$REPO/out/hostile/sub"
before=$(outside_sums repo/out/hostile)
expect_run "path: sub/t.csv with sub -> .. inside --out is refused" 2 "node 'log': cannot write 'out/hostile/sub/t.csv': 'out/hostile/sub' is a symbolic link" \
  -- bash -c "cd '$REPO' && '$TF' run sub.yaml"
rm "$REPO/out/hostile/sub"
ln -s "$TMP/victims/elsewhere" "$REPO/out/hostile/sub"
expect_run "... and with sub -> a folder elsewhere" 2 "is a symbolic link" -- bash -c "cd '$REPO' && '$TF' run sub.yaml"
[ "$before" = "$(outside_sums repo/out/hostile)" ] || fail "a write went through the symlinked subfolder"
echo "ok: ... nothing outside --out was written"
checks=$((checks + 1))
leftovers=$(find "$TMP" -name '*.partial' -type f)
[ -z "$leftovers" ] || fail "temporaries left behind: $leftovers"
echo "ok: no temporary is left anywhere"
checks=$((checks + 1))

# The folders trackflow names itself: the default out/<name> beneath the current folder, sweep-<i>.
mkdir -p "$TMP/repo2" "$TMP/victims/home"
ln -s "$TMP/victims/home" "$TMP/repo2/out"
cp "$REPO/pipeline.yaml" "$TMP/repo2/"
expect_run "a default --out through a link (out -> elsewhere) is refused" 2 "the default --out 'out/hostile': 'out' is a symbolic link" \
  -- bash -c "cd '$TMP/repo2' && '$TF' run pipeline.yaml"
mkdir -p "$TMP/sw"
ln -s "$TMP/victims/home" "$TMP/sw/sweep-1"
expect_run "a sweep-<i> folder that is a link is refused" 2 "'$TMP/sw/sweep-1' is a symbolic link" \
  -- "$TF" sweep "$REPO/pipeline.yaml" --param kf.q=0,1 --runs 1 --out "$TMP/sw"
[ -z "$(ls -A "$TMP/victims/home")" ] || fail "a file was written through out or sweep-1: $(ls -A "$TMP/victims/home")"
echo "ok: ... nothing was written there"
checks=$((checks + 1))

# An --out in use by another running trackflow is refused; the first run's file is whole.
{ base | sed 's/runs: 2/runs: 100000/'; printf '  - { id: log, type: sink.csv, inputs: [kf, truth] }\n'; } > "$TMP/long.yaml"
"$TF" run "$TMP/long.yaml" --out "$TMP/shared" --no-progress > "$TMP/first.txt" 2>&1 &
first=$!
for _ in $(seq 100); do [ -d "$TMP/shared" ] && break; sleep 0.1; done
sleep 0.3
expect_run "a second run into an --out in use is refused" 2 "'$TMP/shared' is in use by another running trackflow" \
  -- "$TF" run "$TMP/long.yaml" --out "$TMP/shared" --runs 3
kill "$first" 2>/dev/null
wait "$first" 2>/dev/null
# Two runs of different seeds one after the other into one folder: each file is one run's whole file.
"$TF" run "$TMP/long.yaml" --out "$TMP/shared2" --runs 3 --seed 5 > /dev/null 2>&1 || fail "seed 5 run failed"
cp "$TMP/shared2/log.csv" "$TMP/seed5.csv"
"$TF" run "$TMP/long.yaml" --out "$TMP/shared2" --runs 3 --seed 6 > /dev/null 2>&1 || fail "seed 6 run failed"
cmp -s "$TMP/shared2/log.csv" "$TMP/seed5.csv" && fail "the second run did not replace log.csv"
[ "$(wc -l < "$TMP/shared2/log.csv")" = "$(wc -l < "$TMP/seed5.csv")" ] || fail "log.csv of seed 6 is not whole"
echo "ok: ... and one after the other each leaves one whole file"
checks=$((checks + 1))

# Two outputs of one run naming one file: refused at validate and before the runs.
{ base; printf '  - { id: a, type: sink.csv, inputs: [kf] }\n  - { id: b, type: sink.csv, inputs: [kf, truth], params: { path: a.csv } }\n'; } > "$TMP/twice.yaml"
expect_run "two sink.csv with one path are refused at validate" 2 "nodes 'a' and 'b' both write 'a.csv'" -- "$TF" validate "$TMP/twice.yaml"
expect_run "... and at run" 2 "nodes 'a' and 'b' both write 'a.csv'" -- "$TF" run "$TMP/twice.yaml" --out "$TMP/c1"
{ base; printf '  - { id: a, type: sink.csv, inputs: [kf], params: { path: sub/../a.csv } }\n  - { id: b, type: sink.csv, inputs: [kf], params: { path: ./a.csv } }\n'; } > "$TMP/twice2.yaml"
expect_run "... also when spelled differently" 2 "both write 'a.csv'" -- "$TF" validate "$TMP/twice2.yaml"
{ base; printf '  - { id: log, type: sink.csv, inputs: [kf], params: { path: report.html } }\n'; } > "$TMP/rep.yaml"
expect_run "a sink.csv path equal to the default report is refused before the runs" 2 \
  "node 'log': its file '$TMP/c2/report.html' is also the file of the report" -- "$TF" report "$TMP/rep.yaml" --out "$TMP/c2"
expect_run "... and to --report" 2 "node 'log': its file .* is also the file of the report; give one of them another name" \
  -- "$TF" run "$TMP/rep.yaml" --out "$TMP/c3" --report "$TMP/c3/report.html"
expect_run "a sink.csv path equal to --metrics-json is refused" 2 "node 'log': its file .*report.html' is also the file of --metrics-json" \
  -- "$TF" run "$TMP/rep.yaml" --out "$TMP/c4" --metrics-json "$TMP/c4/report.html"
{ base; printf '  - { id: log, type: sink.csv, inputs: [kf], params: { path: score.ensemble.csv } }\n'; } > "$TMP/ser.yaml"
expect_run "a sink.csv path equal to a series file is refused with --series" 2 \
  "node 'log': its file .*score.ensemble.csv' is a name of the series files of node 'score'" -- "$TF" run "$TMP/ser.yaml" --out "$TMP/c5" --series
expect_run "--report equal to --metrics-json is refused" 2 "--report and --metrics-json both name" \
  -- "$TF" run "$TMP/p.yaml" --out "$TMP/c6" --report "$TMP/x.html" --metrics-json "$TMP/x.html"
for d in c1 c2 c3 c4 c5 c6; do [ -e "$TMP/$d" ] && [ -n "$(ls -A "$TMP/$d")" ] && fail "a refused run wrote into $d: $(ls -A "$TMP/$d")"; done
echo "ok: ... and the refused runs wrote nothing"
checks=$((checks + 1))

# A full disk (RLIMIT_FSIZE, 50 kB): exit 2 naming EFBIG, no truncated file under a real name,
# an earlier complete file under that name as it was, no temporary left.
"$TF" report "$TMP/p.yaml" --out "$TMP/full" > /dev/null 2>&1 || fail "a report run failed"
report_sum=$(sha256sum < "$TMP/full/report.html")
expect_run "a report past RLIMIT_FSIZE is exit 2, not SIGXFSZ" 2 "report.html': File too large" \
  -- bash -c "ulimit -f 50; exec '$TF' report '$TMP/p.yaml' --out '$TMP/full' --seed 9"
[ "$(sha256sum < "$TMP/full/report.html")" = "$report_sum" ] || fail "report.html was truncated or replaced by a partial one"
{ base | sed 's/runs: 2/runs: 20/'; printf '  - { id: log, type: sink.csv, inputs: [kf, truth] }\n'; } > "$TMP/rows.yaml"
expect_run "a sink.csv past RLIMIT_FSIZE is exit 2" 2 "log.csv': File too large" \
  -- bash -c "ulimit -f 50; exec '$TF' run '$TMP/rows.yaml' --out '$TMP/full2'"
[ -e "$TMP/full2/log.csv" ] && fail "a truncated log.csv is left"
expect_run "--metrics-json past RLIMIT_FSIZE is exit 2" 2 "metrics JSON '$TMP/m.json': File too large" \
  -- bash -c "ulimit -f 0; exec '$TF' run '$TMP/p.yaml' --out '$TMP/full3' --metrics-json '$TMP/m.json'"
[ -e "$TMP/m.json" ] && fail "a truncated m.json is left"
leftovers=$(find "$TMP/full" "$TMP/full2" "$TMP" -maxdepth 1 -name '*.partial')
[ -z "$leftovers" ] || fail "temporaries left on a full disk: $leftovers"
echo "ok: ... no truncated file and no temporary left"
checks=$((checks + 1))

# A folder where no file can be created is refused before the runs.
expect_run "--metrics-json /proc/nope.json is refused before the runs" 2 "--metrics-json: cannot write '/proc/nope.json'" \
  -- "$TF" run "$TMP/p.yaml" --out "$TMP/proc" --metrics-json /proc/nope.json
"$TF" run "$TMP/p.yaml" --out "$TMP/proc" --metrics-json /proc/nope.json > "$TMP/stdout.txt" 2>/dev/null
expect_no "... and nothing ran" "pipeline hostile|measurements processed" "$TMP/stdout.txt"
finish
