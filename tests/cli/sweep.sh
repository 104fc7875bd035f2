#!/usr/bin/env bash
# Purpose: `trackflow sweep` runs the whole grid, writes a deterministic table, and rejects bad axes and metrics.
set -u
TF=$1
ROOT=$4
source "$(dirname "$0")/lib.sh"
P="$ROOT/pipelines/quickstart.yaml"

sweep() { "$TF" sweep "$P" --param kf.q=0,0.1,10 --param radar.sigma_range="5 m,20 m" --runs 6 --out "$TMP/out" "$@"; }
sweep --threads 1 --csv "$TMP/t1.csv" > "$TMP/t1.log" 2>&1 || fail "sweep failed: $(cat "$TMP/t1.log")"
sweep --threads 2 --csv "$TMP/t2.csv" > "$TMP/t2.log" 2>&1 || fail "sweep failed: $(cat "$TMP/t2.log")"
[ "$(wc -l < "$TMP/t1.csv")" -eq 7 ] || fail "expected a header and 6 grid rows: $(cat "$TMP/t1.csv")"
head -1 "$TMP/t1.csv" | grep -qx 'kf.q_m2_per_s3,radar.sigma_range_m,score.position_rmse_m,score.velocity_rmse_m_per_s,score.anees' ||
  fail "unexpected header: $(head -1 "$TMP/t1.csv")"
cmp "$TMP/t1.csv" "$TMP/t2.csv" || fail "sweep table differs between 1 and 2 threads"
echo "ok: 3 x 2 grid, 6 rows, identical with 1 and 2 threads"
checks=$((checks + 1))
# Axis values are numbers in SI ("5 m" -> 5), never text with a unit.
awk -F, 'NR>1 && ($1 !~ /^[0-9.e+-]+$/ || $2 !~ /^[0-9.e+-]+$/) { exit 1 }' "$TMP/t1.csv" ||
  fail "axis values are not plain SI numbers: $(cat "$TMP/t1.csv")"
echo "ok: axis values are SI numbers, units in the header"
checks=$((checks + 1))
# Larger measurement noise must give a larger position RMSE at the same q (common random numbers).
awk -F, 'NR>1 { r[$1 "," $2] = $3 } END { if (!(r["0,20"] > r["0,5"] && r["10,20"] > r["10,5"])) exit 1 }' "$TMP/t1.csv" ||
  fail "position RMSE does not grow with sigma_range: $(cat "$TMP/t1.csv")"
echo "ok: position RMSE grows with sigma_range at each q"
checks=$((checks + 1))

# Units are converted: 0.02 km is 20 m; a list-valued axis stays text, quoted per RFC 4180.
"$TF" sweep "$P" --param radar.sigma_range="0.02 km,30 m" --param 'truth.initial_position=[6 km, 8 km, 1 km]' --runs 2 \
  --out "$TMP/out" --csv "$TMP/u.csv" --report "$TMP/sweep.html" > "$TMP/u.log" 2>&1 || fail "sweep failed: $(cat "$TMP/u.log")"
sed -n 2p "$TMP/u.csv" | grep -q '^20,"\[6 km, 8 km, 1 km\]",' || fail "unexpected row: $(cat "$TMP/u.csv")"
echo "ok: 0.02 km written as 20 (m); a list value quoted"
checks=$((checks + 1))
grep -q 'data-title="score.position_rmse against radar.sigma_range"' "$TMP/sweep.html" ||
  fail "sweep --report lacks the metric-against-parameter plot"
echo "ok: sweep --report plots each metric against the swept parameter"
checks=$((checks + 1))

expect_run "chosen metrics only" 0 "kf.q +score.anis" -- "$TF" sweep "$P" --param kf.q=0,1 --runs 2 --metric score.anis --out "$TMP/out"
expect_run "an unknown metric is an error listing what exists" 2 "no such metric \(did you mean 'position_rmse'\?\)" -- \
  "$TF" sweep "$P" --param kf.q=0,1 --runs 2 --metric score.position_rmsee --out "$TMP/out"
expect_run "a bad grid value names the grid point" 2 "parameter 'q'.*'fast' is not a number.*grid point kf.q=fast" -- \
  "$TF" sweep "$P" --param kf.q=0,fast --runs 2 --out "$TMP/out"
expect_run "sweep without --param" 2 "needs at least one --param" -- "$TF" sweep "$P"
expect_run "sweep --help explains the grid" 0 "Cartesian product" -- "$TF" sweep --help
"$TF" sweep "$P" -q --param kf.q=0,1 --runs 2 --csv "$TMP/q.csv" --out "$TMP/out" > "$TMP/quiet.txt" 2>&1 || fail "sweep -q failed"
head -1 "$TMP/quiet.txt" | grep -Eq "^kf.q +score" || fail "sweep -q: the table is not the first line: $(head -2 "$TMP/quiet.txt")"
[ "$(wc -l < "$TMP/quiet.txt")" -eq 3 ] || fail "sweep -q prints more than the table: $(cat "$TMP/quiet.txt")"
echo "ok: sweep -q prints only the table (issue 26)"
checks=$((checks + 1))

# Issue 26: --zip ties the lists. A two-filter study, one q for both filters: 4 points, not 16,
# each row with the same q for both; the report plots both filters' metrics against that q
# (one axis, named by both), and the pipeline table marks q as swept, not fixed.
S="$3/two_filter_study.yaml"
zip_sweep() { "$TF" sweep "$S" --param kf.q=0.1,1,10,100 --param ekf.q=0.1,1,10,100 --out "$TMP/out" "$@"; }
zip_sweep --zip --csv "$TMP/zip.csv" --report "$TMP/zip.html" -m kf_score.position_rmse -m ekf_score.position_rmse \
  > "$TMP/zip.log" 2>&1 || fail "sweep --zip failed: $(cat "$TMP/zip.log")"
[ "$(wc -l < "$TMP/zip.csv")" -eq 5 ] || fail "sweep --zip: expected a header and 4 rows: $(cat "$TMP/zip.csv")"
awk -F, 'NR>1 && $1 != $2 { exit 1 }' "$TMP/zip.csv" || fail "sweep --zip: a row with two different q: $(cat "$TMP/zip.csv")"
awk -F, 'NR>1 { q[NR] = $1 } END { if (q[2] != 0.1 || q[3] != 1 || q[4] != 10 || q[5] != 100) exit 1 }' "$TMP/zip.csv" ||
  fail "sweep --zip: q is not 0.1, 1, 10, 100 in order: $(cat "$TMP/zip.csv")"
grep -q "4 grid points (zipped)" "$TMP/zip.log" || fail "sweep --zip does not say it is zipped: $(cat "$TMP/zip.log")"
echo "ok: --zip: 4 points for two filters' q, the same q in each row"
checks=$((checks + 1))
for m in kf_score.position_rmse ekf_score.position_rmse; do
  grep -q "data-title=\"$m against kf.q = ekf.q\"" "$TMP/zip.html" || fail "sweep --zip report: no plot of $m against kf.q = ekf.q"
done
grep -q '<b>swept:</b> <code>q</code>' "$TMP/zip.html" || fail "sweep report: the swept q is not marked as swept"
echo "ok: the zipped report plots each filter's metric against the tied q and marks q as swept"
checks=$((checks + 1))
# The metrics really move with q (a report of four equal numbers would also pass the above).
awk -F, 'NR>1 { v[$3] = 1 } END { n = 0; for (k in v) n++; if (n < 3) exit 1 }' "$TMP/zip.csv" ||
  fail "kf position RMSE does not change with q: $(cat "$TMP/zip.csv")"
echo "ok: the metrics change along the tied q"
checks=$((checks + 1))
zip_sweep -q --csv "$TMP/product.csv" > /dev/null 2>&1 || fail "the product sweep failed"
[ "$(wc -l < "$TMP/product.csv")" -eq 17 ] || fail "without --zip: expected 16 rows: $(wc -l < "$TMP/product.csv")"
echo "ok: without --zip the same lists are the 16-point product"
checks=$((checks + 1))
# A product over kf.q alone cannot change ekf's metrics: they are listed, not plotted flat.
"$TF" sweep "$S" --param kf.q=0.1,10 --out "$TMP/out" -m kf_score.position_rmse -m ekf_score.position_rmse \
  --report "$TMP/one.html" > "$TMP/one.log" 2>&1 || fail "sweep failed: $(cat "$TMP/one.log")"
grep -q 'data-title="kf_score.position_rmse against kf.q"' "$TMP/one.html" || fail "no plot of kf's metric against kf.q"
grep -q 'data-title="ekf_score.position_rmse against' "$TMP/one.html" && fail "ekf's metric, which kf.q cannot change, is plotted"
grep -q 'so not plotted: ekf_score.position_rmse = ' "$TMP/one.html" || fail "ekf's unchanged metric is not listed as constant"
echo "ok: a metric no swept parameter changes is listed, not plotted"
checks=$((checks + 1))
expect_run "--zip with lists of different lengths" 2 "--zip: every --param list must have the same length; kf.q has 2 values, ekf.q has 3" -- \
  "$TF" sweep "$S" --param kf.q=1,2 --param ekf.q=1,2,3 --zip --out "$TMP/out"
expect_run "sweep --help explains --zip" 0 "with --zip the lists move together" -- "$TF" sweep --help
# A --param path into a list of records: the turn's rate, swept.
"$TF" sweep "$S" -q --param 'truth.segments[1].turn_rate=1 deg/s,6 deg/s' --out "$TMP/out" --csv "$TMP/turn.csv" \
  -m kf_score.position_rmse > "$TMP/turn.log" 2>&1 || fail "sweep over segments[1].turn_rate failed: $(cat "$TMP/turn.log")"
awk -F, 'NR==2 { a = $2 } NR==3 { b = $2 } END { if (!(b > a)) exit 1 }' "$TMP/turn.csv" ||
  fail "a sharper turn does not give a larger RMSE at q = 1: $(cat "$TMP/turn.csv")"
head -1 "$TMP/turn.csv" | grep -q '^truth.segments\[1\].turn_rate_rad_per_s,' || fail "turn-rate column header: $(head -1 "$TMP/turn.csv")"
echo "ok: --param truth.segments[1].turn_rate sweeps the second segment's turn (the sharper, the larger the RMSE)"
checks=$((checks + 1))
finish
