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
"$TF" sweep "$P" --param radar.sigma_range="0.02 km" --param 'truth.initial_position=[6 km, 8 km, 1 km]' --runs 2 \
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
finish
