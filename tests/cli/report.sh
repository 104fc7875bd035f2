#!/usr/bin/env bash
# Purpose: `trackflow report`, `run --series` and the unit-carrying outputs: self-contained HTML under 5 MB, the multi-target scene picture, per-step series (ANEES in band, mean = summary), metrics JSON, sink.csv covariance, tables.
set -u
TF=$1
PLUGINS=$2
DATA=$3
ROOT=$4
source "$(dirname "$0")/lib.sh"
Q="$ROOT/pipelines/quickstart.yaml"

# --- the report of a paper pipeline: one self-contained file under 5 MB ---------------------
"$TF" report "$ROOT/pipelines/rbs_landing_scn3.yaml" --threads 2 --no-progress --out "$TMP/rbs" > "$TMP/rbs.log" 2>&1 ||
  fail "report of rbs_landing_scn3 failed: $(tail -20 "$TMP/rbs.log")"
H="$TMP/rbs/report.html"
size=$(stat -c %s "$H")
[ "$size" -lt 5000000 ] || fail "report is $size bytes (limit 5 MB)"
if grep -Eiq '<(script|img|iframe)[^>]* src=|<link[^>]* href=' "$H"; then fail "the report loads an external file"; fi
grep -q 'id="tf-charts"' "$H" || fail "no charts in the report"
for t in 'position RMSE against time' 'ANEES against time' 'ANIS against time' \
         'ground track (east-north)' 'altitude against time'; do
  grep -q "data-title=\"$t\"" "$H" || fail "report lacks the plot '$t'"
done
grep -q 'adaptive_r' "$H" || fail "the pipeline section lacks the adapter"
grep -q '>pass<' "$H" || fail "the expect table is missing"
# A single-target pipeline has no tracker: no scene recorder, no multi-target picture.
grep -q 'data-title="scene of run' "$H" && fail "the single-target report draws a multi-target scene"
ls "$TMP/rbs" | grep -q '^report_scene' && fail "the single-target report recorded a scene: $(ls "$TMP/rbs")"
echo "ok: rbs_landing_scn3 report: one file of $size bytes, no external references, the plots and tables"
checks=$((checks + 1))

# --- per-step series: the quickstart's ANEES in its band at >= 90 % of steps, mean = summary --
"$TF" run "$Q" --threads 2 --no-progress --series --out "$TMP/qs" --metrics-json "$TMP/qs.json" > "$TMP/qs.log" 2>&1 ||
  fail "run --series failed: $(cat "$TMP/qs.log")"
S="$TMP/qs/score.ensemble.csv"
head -1 "$S" | grep -q '^time_s,runs_scored,position_rmse_m,velocity_rmse_m_per_s,mean_error_x_m,' ||
  fail "unexpected series header: $(head -1 "$S")"
anees=$(tr -d ' \n' < "$TMP/qs.json" | grep -o '"score":{"position_rmse".*' | grep -o '"anees":{"value":[-0-9.e]*' | cut -d: -f3)
[ -n "$anees" ] || fail "no score.anees in the metrics JSON"
awk -F, -v summary="$anees" '
  NR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; next }
  $col["anees"] != "" {
    v = $col["anees"]; n++; sum += v
    if (v >= $col["anees_band_lo"] && v <= $col["anees_band_hi"]) inside++
  }
  END {
    frac = inside / n; mean = sum / n
    printf "steps %d, inside the band %.4f, series mean %.12g, summary %.12g\n", n, frac, mean, summary
    d = mean - summary; if (d < 0) d = -d
    if (n < 500 || frac < 0.9 || d > 1e-9 * summary) exit 1
  }' "$S" > "$TMP/anees.txt" || fail "ANEES series check: $(cat "$TMP/anees.txt")"
echo "ok: quickstart ANEES series: $(cat "$TMP/anees.txt")"
checks=$((checks + 1))

# --- the series are identical for any thread count ------------------------------------------
# (12 runs: the quickstart's expect block, made for 200, may fail: exit 1 is fine here.)
"$TF" run "$Q" --runs 12 --threads 1 --series --no-progress --out "$TMP/t1" > /dev/null 2>&1; [ $? -le 1 ] || fail "run --threads 1"
"$TF" run "$Q" --runs 12 --threads 2 --series --no-progress --out "$TMP/t2" > /dev/null 2>&1; [ $? -le 1 ] || fail "run --threads 2"
cmp "$TMP/t1/score.ensemble.csv" "$TMP/t2/score.ensemble.csv" || fail "series differ between 1 and 2 threads"
echo "ok: series identical with 1 and 2 threads"
checks=$((checks + 1))

# --- metrics JSON: every metric with its unit, banded ones with their band ---------------------
J=$(tr -d ' \n' < "$TMP/qs.json")
grep -q '"position_rmse":{"value":[0-9.e-]*,"unit":"m"}' <<< "$J" || fail "position_rmse lacks its unit: $J"
grep -q '"velocity_rmse":{"value":[0-9.e-]*,"unit":"m/s"}' <<< "$J" || fail "velocity_rmse lacks its unit"
grep -q '"anees_steps_in_band":{"value":[0-9.e-]*,"unit":"","band_lo":[0-9.e-]*,"band_hi":1.0,"confidence":0.95}' <<< "$J" ||
  fail "anees_steps_in_band lacks its band"
grep -q '"anees":{"value":[0-9.e-]*,"unit":""}' <<< "$J" || fail "anees (the mean) has a band: it has none (issue 25)"
echo "ok: metrics JSON carries units and bands"
checks=$((checks + 1))

expect_run "report --track-run beyond the runs" 2 "track-run 50: there are only 10 runs" -- \
  "$TF" report "$Q" --runs 10 --track-run 50 --out "$TMP/bad"
expect_run "report --help" 0 "self-contained HTML" -- "$TF" report --help

# --- sink.csv: the full covariance, opt-in ------------------------------------------------------
"$TF" run "$DATA/report_csv_covariance.yaml" --no-progress --out "$TMP/cov" > "$TMP/cov.log" 2>&1 ||
  fail "sink.csv full_covariance run failed: $(cat "$TMP/cov.log")"
C="$TMP/cov/tracks.csv"
head -1 "$C" | grep -q ',truth_vz_m_per_s,cov_x_x_m2,cov_x_y_m2,cov_x_z_m2,cov_x_vx_m2_per_s,.*,cov_vy_vz_m2_per_s2,cov_vz_vz_m2_per_s2$' ||
  fail "unexpected header: $(head -1 "$C")"
awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; if (NF != 46) exit 1; next }
  NF != 46 { exit 1 }
  $col["kind"] == "estimate" { n++; s = $col["sigma_x_m"]; c = $col["cov_x_x_m2"]; d = s * s - c; if (d < 0) d = -d
    if (d > 1e-6 * c) exit 1; if ($col["cov_y_vy_m2_per_s"] == "") exit 1 }
  END { if (n < 10) exit 1 }' "$C" || fail "covariance columns: not 46 fields or sigma_x^2 != cov_x_x"
echo "ok: sink.csv full_covariance adds 21 columns, cov_x_x = sigma_x^2"
checks=$((checks + 1))

# --- tables sized from their content ------------------------------------------------------------
"$TF" plugins --no-default-plugins --plugin-path "$PLUGINS" > "$TMP/plugins.txt" 2>&1
grep -Eq '^  convert\.unbiased_modified +converter ' "$TMP/plugins.txt" || fail "plugins table glues the name to the kind"
awk '/^  [a-z]/ { match($0, /^  [^ ]+ +/); print RLENGTH }' "$TMP/plugins.txt" | sort -u | wc -l | grep -qx 1 ||
  fail "plugins: the kind column is not aligned: $(cat "$TMP/plugins.txt")"
echo "ok: plugins table: one kind column, long names kept apart"
checks=$((checks + 1))
for type in sim.trajectory sim.radar filter.ekf; do
  "$TF" describe "$type" --no-default-plugins --plugin-path "$PLUGINS" > "$TMP/d.txt"
  # Parameter rows (after the "parameters" line): the type column starts at one offset.
  awk '/^parameters/ { on = 1; next } on && NF { match($0, /^ +[a-z_0-9]+ +/); print RLENGTH }' "$TMP/d.txt" |
    sort -u | wc -l | grep -qx 1 || fail "describe $type: columns misaligned: $(cat "$TMP/d.txt")"
done
echo "ok: describe aligns long names, nested fields and choice lists"
checks=$((checks + 1))
# --- the report of a multi-target pipeline: trackers are no single track to draw -----------------
# (the track recorder once took the tracker's track sets as input and the report was refused)
"$TF" report "$ROOT/pipelines/crossing_targets.yaml" --runs 4 --threads 2 --no-progress --out "$TMP/mtt" > "$TMP/mtt.log" 2>&1
rc=$?
[ "$rc" -le 1 ] || fail "report of crossing_targets: exit $rc: $(cat "$TMP/mtt.log")"   # 4 runs may fail an expect
[ -s "$TMP/mtt/report.html" ] || fail "report of crossing_targets wrote no report.html: $(cat "$TMP/mtt.log")"
grep -q 'gospa_gnn' "$TMP/mtt/report.html" || fail "the multi-target report lacks sink.gospa's summary"
grep -q 'measurements processed by 0 filters' "$TMP/mtt/report.html" && fail "the multi-target report counts 0 filters"
[ -s "$TMP/mtt/gospa_gnn.gospa.csv" ] || fail "no GOSPA series CSV next to the report"
grep -q 'GOSPA against time' "$TMP/mtt/report.html" || fail "the multi-target report has no GOSPA chart"
grep -q 'GOSPA parts (p-th power) against time - gospa_nn' "$TMP/mtt/report.html" || fail "no GOSPA parts chart per scoring node"
checks=$((checks + 1)); echo "ok: report of a multi-target pipeline (GOSPA summaries, charts and series, no single-track plot)"

# --- the multi-target picture: truth, tracks coloured by id and clutter per scan, per tracker ------
M="$TMP/mtt/report.html"
for tracker in gnn nn; do
  div=$(grep -o "<div class=\"chart\"[^>]*data-title=\"scene of run 0 - $tracker\"[^>]*>" "$M") ||
    fail "the multi-target report has no scene picture for $tracker"
  attr() { grep -o "$1=\"[0-9]*\"" <<< "$div" | grep -o '[0-9]*'; }
  [ "$(attr data-truth-lines)" -eq 6 ] || fail "scene of $tracker: $(attr data-truth-lines) truth lines, not 6: $div"
  [ "$(attr data-track-lines)" -gt 0 ] || fail "scene of $tracker: no track polylines: $div"
  [ "$(attr data-clutter-points)" -gt 0 ] || fail "scene of $tracker: no clutter drawn: $div"
  [ "$(attr data-target-detections)" -gt 0 ] || fail "scene of $tracker: no target detections drawn: $div"
  [ -s "$TMP/mtt/report_scene.tracks-$tracker.csv" ] || fail "no scene series CSV of $tracker's tracks"
done
grep -q 'drawn: every detection of every scan' "$M" || fail "the scene's caption does not say what was drawn"
grep -q '<td><b>report_scene' "$M" && fail "the scene recorder shows in the pipeline table"
checks=$((checks + 1)); echo "ok: multi-target report: a scene per tracker (6 truths, track polylines, clutter, target detections)"

finish
