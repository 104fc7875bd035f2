#!/usr/bin/env bash
# Purpose: an MPI job (mpirun --oversubscribe -np 3, threads per process; also with rank 0's window of runs ahead of the oldest unmerged one at 1) gives byte-identical outputs to one process with --threads 1 — metrics JSON, summary, series CSV, report series and track, sweep table — for EVERY pipeline in pipelines/ (so a plugin added later without RunResultCodec fails here: the MPI engine refuses it) and for sink.csv with runs large enough to spill, and a failing run stops the job naming the rank and the run.
# Skipped (exit 77) when this trackflow was built without MPI or mpirun is not installed.
set -u
TF=$1
PLUGINS=$2
DATA=$3
ROOT=$4
source "$(dirname "$0")/lib.sh"

"$TF" --version | grep -q "MPI" || { echo "skipped: trackflow built without MPI"; exit 77; }
command -v mpirun > /dev/null || { echo "skipped: mpirun not found (openmpi-bin)"; exit 77; }
MPIRUN=(mpirun --oversubscribe -np 3)
# Under `setup.sh sanitize`: Open MPI frees neither its MCA components nor its reduction ops at
# MPI_Finalize, which LeakSanitizer reports in every process. Leak checks are off in this script
# only (every other test keeps them); its processes keep ASan's and UBSan's other checks.
if [ -n "${TRACKFLOW_SANITIZE:-}" ]; then export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"; fi
[ "$(id -u)" -eq 0 ] && MPIRUN+=(--allow-run-as-root)
TEST_PLUGINS="$PLUGINS/../test-plugins"
cd "$TMP"

# The summary without what differs between any two runs: wall time, rates, threads, MPI note, paths.
summary() { grep -vE '^  [0-9]+ runs?, |measurements processed:|source items:|^\(runs shared by|^ *wrote ' "$1"; }
same_dir() {  # every file of $1 byte-identical in $2, and nothing else there
  local a=$1 b=$2 n=0 f
  shopt -s nullglob
  for f in "$a"/*; do
    cmp -s "$f" "$b/$(basename "$f")" || fail "$(basename "$f") differs between one process and the MPI job"
    n=$((n + 1))
  done
  [ "$(ls -A "$b" 2> /dev/null | wc -l)" -eq "$n" ] || fail "the MPI job wrote other files than one process ($(ls "$b"))"
  echo "$n"
}

P="$DATA/mpi_pipeline.yaml"
"$TF" run "$P" --threads 1 --no-progress --series --out one --metrics-json one.json > one.log 2>&1 || fail "one process: $(cat one.log)"
"${MPIRUN[@]}" "$TF" run "$P" --threads 2 --no-progress --series --out job --metrics-json job.json > job.log 2>&1 ||
  fail "mpirun: $(cat job.log)"
grep -q "runs shared by 3 MPI processes, 2 threads each" job.log || fail "the MPI job did not run as 3 processes: $(cat job.log)"
cmp one.json job.json || fail "metrics JSON differs between one process and the MPI job"
checks=$((checks + 1)); echo "ok: metrics JSON byte-identical (mpirun -np 3 --threads 2 against --threads 1)"
n=$(same_dir one job); checks=$((checks + 1)); echo "ok: $n series CSV files byte-identical"
diff <(summary one.log) <(summary job.log) || fail "summary differs"
checks=$((checks + 1)); echo "ok: summary identical (all but the timing line)"

# Rank 0 hands out runs at most a window ahead of the oldest run not merged (as the threaded
# engine's workers), so a slow run cannot make finished ones pile up there. With a window of 1
# nearly every request waits for a merge: the same bytes, and no process waits forever.
TRACKFLOW_MPI_WINDOW=1 "${MPIRUN[@]}" "$TF" run "$P" --threads 2 --no-progress --series --out w1 --metrics-json w1.json > w1.log 2>&1 ||
  fail "mpirun with a window of 1: $(cat w1.log)"
cmp one.json w1.json || fail "metrics JSON differs with a window of 1"
n=$(same_dir one w1)
diff <(summary one.log) <(summary w1.log) || fail "summary differs with a window of 1"
checks=$((checks + 1)); echo "ok: window of 1 run: metrics JSON, summary and $n series files identical"

# The report: series and the recorded track of one run through the engine on rank 0.
"$TF" report "$P" --threads 1 --no-progress --out rone --track-run 5 > rone.log 2>&1 || fail "report, one process: $(cat rone.log)"
"${MPIRUN[@]}" "$TF" report "$P" --threads 1 --no-progress --out rjob --track-run 5 > rjob.log 2>&1 ||
  fail "report under mpirun: $(cat rjob.log)"
for f in rone/*.csv; do cmp "$f" "rjob/$(basename "$f")" || fail "report file $(basename "$f") differs"; done
# The HTML embeds the command line (and so the output folder) and the wall time: compare it
# with those two lines removed.
html() { grep -v -e 'rone' -e 'rjob' -e 'runs, seed .* s; ' "$1"; }
cmp <(html rone/report.html) <(html rjob/report.html) || fail "report.html differs beyond its command line and time"
checks=$((checks + 1)); echo "ok: report series and HTML identical under mpirun"

# A sweep: each point's runs shared by the processes.
S=("$P" --param "kf.q=1 m2/s3,5 m2/s3,20 m2/s3" --runs 6 --metric kf_score.position_rmse --metric ekf_score.anees)
"$TF" sweep "${S[@]}" --csv sone.csv --out sone > sone.log 2>&1 || fail "sweep, one process: $(cat sone.log)"
"${MPIRUN[@]}" "$TF" sweep "${S[@]}" --threads 2 --csv sjob.csv --out sjob > sjob.log 2>&1 || fail "sweep under mpirun: $(cat sjob.log)"
cmp sone.csv sjob.csv || fail "sweep CSV differs"
diff <(grep -v '^wrote' sone.log) <(grep -v '^wrote' sjob.log) || fail "sweep table differs"
for i in 0 1 2; do same_dir "sone/sweep-$i" "sjob/sweep-$i" > /dev/null; done
checks=$((checks + 1)); echo "ok: sweep table, CSV and per-point files identical under mpirun"

# A run that fails on whichever process runs it: the job exits 2 naming the rank and the run, once.
boom="node 'boom' \(test.fail_run from [^)]*\)"
expect_run "a failing run stops the job, naming rank, run and node" 2 "data error: rank [0-2]: run 7: $boom: test.fail_run: deliberate failure" -- \
  "${MPIRUN[@]}" "$TF" run "$DATA/mpi_fail.yaml" --threads 2 --no-progress --plugin-path "$TEST_PLUGINS" --out fail
n=$("${MPIRUN[@]}" "$TF" run "$DATA/mpi_fail.yaml" --no-progress --plugin-path "$TEST_PLUGINS" --out fail 2>&1 | grep -c "deliberate failure")
[ "$n" -eq 1 ] || fail "the failure was printed $n times"
checks=$((checks + 1)); echo "ok: printed once"
# A plugin bug (a std::exception) is exit 3 as in one process; merge() runs on rank 0, in run
# order, and a failure there names the node and the run merged, not the run that just finished.
fail_job() { "${MPIRUN[@]}" "$TF" run "$DATA/mpi_fail.yaml" --threads 2 --no-progress --plugin-path "$TEST_PLUGINS" --out fail "$@"; }
expect_run "a plugin bug in a run: exit 3, naming rank, run and node" 3 \
  "internal error: rank [0-2]: $boom during run 7 threw std::logic_error: test.fail_run: deliberate bug" -- fail_job --set boom.kind=bug
expect_run "a DataError in merge() on rank 0: exit 2, naming run and node" 2 \
  "data error: rank 0: run 7: $boom: test.fail_run: deliberate failure" -- fail_job --set boom.during=merge
expect_run "a plugin bug in merge() on rank 0: exit 3, naming node and run" 3 \
  "internal error: rank 0: $boom during run 7 threw std::logic_error" -- fail_job --set boom.during=merge --set boom.kind=bug

# A pipeline the job could not load on every process fails on all of them, printed once.
printf 'pipeline: {name: x}\nnodes:\n  - {id: a, type: no.such}\n' > bad.yaml
expect_run "a bad pipeline under mpirun: exit 2" 2 "bad.yaml:3:[0-9]+: node 'a': unknown type 'no.such'" -- \
  "${MPIRUN[@]}" "$TF" run bad.yaml --no-progress
n=$("${MPIRUN[@]}" "$TF" run bad.yaml --no-progress 2>&1 | grep -c "unknown type")
[ "$n" -eq 1 ] || fail "the error was printed $n times"
checks=$((checks + 1)); echo "ok: printed once"

# sink.csv: each run's rows cross the processes as bytes (RunResultCodec); the file is identical.
D="$DATA/determinism.yaml"
"$TF" run "$D" --no-progress --out cone > cone.log 2>&1 || fail "determinism.yaml, one process: $(cat cone.log)"
"${MPIRUN[@]}" "$TF" run "$D" --threads 2 --no-progress --out cjob > cjob.log 2>&1 || fail "sink.csv under mpirun: $(cat cjob.log)"
cmp cone/tracks.csv cjob/tracks.csv || fail "sink.csv output differs under mpirun"
checks=$((checks + 1)); echo "ok: sink.csv byte-identical under mpirun"
# Runs of ~6 MB of rows each: spilled to a temporary file where they run and again where rank 0
# receives them (not held in memory while they wait to be merged in run order).
L="$DATA/mpi_csv_large.yaml"
"$TF" run "$L" --no-progress --out lone --metrics-json lone.json > lone.log 2>&1 || fail "mpi_csv_large.yaml, one process: $(cat lone.log)"
"${MPIRUN[@]}" "$TF" run "$L" --no-progress --out ljob --metrics-json ljob.json > ljob.log 2>&1 ||
  fail "mpi_csv_large.yaml under mpirun: $(cat ljob.log)"
[ "$(stat -c %s lone/rows.csv)" -gt $((4 * 9 * 1024 * 1024 / 2)) ] || fail "mpi_csv_large.yaml: runs too small to spill ($(stat -c %s lone/rows.csv) bytes)"
cmp lone/rows.csv ljob/rows.csv || fail "sink.csv output of large runs differs under mpirun"
cmp lone.json ljob.json || fail "metrics JSON of mpi_csv_large.yaml differs under mpirun"
[ -z "$(ls -A ljob | grep -v '^rows.csv$')" ] || fail "temporary files left in the output folder: $(ls -A ljob)"
checks=$((checks + 1)); echo "ok: sink.csv with spilled runs ($(stat -c %s lone/rows.csv) bytes) byte-identical under mpirun"

# Every pipeline of the repository, with fewer runs (at least 4, so that runs of every process
# are merged on rank 0): exit code, summary, metrics JSON and every file under --out (series CSV,
# sink files) identical. A node whose plugin lacks RunResultCodec makes the MPI job refuse the
# pipeline, so a plugin added later without it fails here.
# mpirun's own report of a process that exited non-zero: blocks between lines of dashes.
without_mpirun() { awk '/^-----+$/ { skip = !skip; next } !skip' "$1"; }
runs_for() {
  case "$1" in
    launch_normal_noise | shot_noise | worst_noise | beacon_skin) echo 4 ;;  # long runs (8 000-21 600 steps)
    *) echo 5 ;;
  esac
}
n=0
for P in "$ROOT"/pipelines/*.yaml; do
  name=$(basename "$P" .yaml)
  R=$(runs_for "$name")
  "$TF" run "$P" --runs "$R" --threads 1 --no-progress --series --out "pone/$name" --metrics-json "pone/$name.json" \
    > "pone-$name.log" 2> "pone-$name.err"
  rc_one=$?
  "${MPIRUN[@]}" "$TF" run "$P" --runs "$R" --threads 1 --no-progress --series --out "pjob/$name" \
    --metrics-json "pjob/$name.json" > "pjob-$name.log" 2> "pjob-$name.err"
  rc_job=$?
  # With fewer runs some expect checks fail (exit 1): they must fail alike.
  [ "$rc_one" -le 1 ] || fail "$name, one process: exit $rc_one: $(cat "pone-$name.log" "pone-$name.err")"
  [ "$rc_job" -eq "$rc_one" ] ||
    fail "$name under mpirun: exit $rc_job, one process $rc_one: $(cat "pjob-$name.log" "pjob-$name.err")"
  grep -q "runs shared by 3 MPI processes" "pjob-$name.log" || fail "$name did not run as 3 processes: $(cat "pjob-$name.log")"
  cmp "pone/$name.json" "pjob/$name.json" || fail "$name: metrics JSON differs under mpirun"
  diff <(summary "pone-$name.log") <(summary "pjob-$name.log") || fail "$name: summary differs under mpirun"
  diff <(without_mpirun "pone-$name.err") <(without_mpirun "pjob-$name.err") || fail "$name: stderr differs under mpirun"
  # A pipeline whose sinks write nothing (series off) leaves no folder in either case.
  if [ -e "pone/$name" ] || [ -e "pjob/$name" ]; then
    diff -r "pone/$name" "pjob/$name" > /dev/null || fail "$name: files under --out differ: $(diff -rq "pone/$name" "pjob/$name" 2>&1)"
  fi
  n=$((n + 1))
done
[ "$n" -ge 10 ] || fail "only $n pipelines found in $ROOT/pipelines"
checks=$((checks + 1)); echo "ok: all $n pipelines identical under mpirun -np 3 (summary, metrics JSON, files under --out)"

# A sweep of another pipeline (refraction: sim.radar's counters, convert.clark_elevation,
# filter.refraction_ekf, sink.elevation_error), with its per-point files.
S=("$ROOT/pipelines/refraction_bias_estimation.yaml" --param "radar.n0=300,312.5" --runs 4
   --metric ekf_error.max_error --metric clark.corrected --metric radar.refraction_invalid)
"$TF" sweep "${S[@]}" --csv rone.csv --out rsone > rsone.log 2>&1 || fail "refraction sweep, one process: $(cat rsone.log)"
"${MPIRUN[@]}" "$TF" sweep "${S[@]}" --csv rjob.csv --out rsjob > rsjob.log 2>&1 || fail "refraction sweep under mpirun: $(cat rsjob.log)"
cmp rone.csv rjob.csv || fail "refraction sweep CSV differs"
diff <(grep -v '^wrote' rsone.log) <(grep -v '^wrote' rsjob.log) || fail "refraction sweep table differs"
# This pipeline's sinks write no files; if one ever does, they must match as well.
if [ -e rsone ] || [ -e rsjob ]; then diff -r rsone rsjob > /dev/null || fail "refraction sweep files differ: $(diff -rq rsone rsjob)"; fi
[ "$(wc -l < rone.csv)" -eq 3 ] || fail "refraction sweep: expected a header and 2 rows: $(cat rone.csv)"
checks=$((checks + 1)); echo "ok: refraction sweep table and CSV identical under mpirun"
finish
