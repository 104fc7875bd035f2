#!/usr/bin/env bash
# Purpose: renders the quickstart's HTML report and a two-filter study's in headless Chromium and checks that every plot was drawn with all its series, points, bands and rules, and that the filters share one consistency plot; skipped (exit 77) without a browser.
# Usage: browser.sh TRACKFLOW ROOT OUTDIR  (OUTDIR keeps the report, its DOM and the screenshot)
set -u
TF=$1
ROOT=$2
OUT=$3
HERE=$(cd "$(dirname "$0")" && pwd)
passed=0
fail() {
  echo "FAIL: $*" >&2
  exit 1
}
ok() {
  echo "ok: $*"
  passed=$((passed + 1))
}

BROWSER=""
for b in chromium chromium-browser google-chrome; do
  if command -v "$b" > /dev/null 2>&1; then
    BROWSER=$(command -v "$b")
    break
  fi
done
if [ -z "$BROWSER" ]; then
  echo "SKIPPED: no Chromium installed, the report was not rendered (apt-get install chromium; 'bash setup.sh test' installs it)"
  exit 77
fi

rm -rf "$OUT"
mkdir -p "$OUT"
PROFILE=$(mktemp -d)
trap 'rm -rf "$PROFILE"' EXIT
# The browser runs offline: no network flags, and the page must not need any.
chrome() {
  "$BROWSER" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking \
    --disable-component-update --disable-sync --user-data-dir="$PROFILE" --virtual-time-budget=30000 "$@" 2> "$OUT/chromium.log"
}

# render PIPELINE NAME MIN_CHARTS: `trackflow report` of PIPELINE into $OUT/NAME, rendered; every
# chart must have drawn exactly what its data hold (lines, points, bands, symbols, rules), at a
# visible size. Sets HTML and COUNTS for `need`.
render() {
  local pipeline=$1 name=$2 min_charts=$3
  mkdir -p "$OUT/$name"
  "$TF" report "$pipeline" --threads 2 --no-progress --out "$OUT/$name/out" > "$OUT/$name/report.log" 2>&1 ||
    fail "trackflow report $pipeline failed: $(cat "$OUT/$name/report.log")"
  HTML="$OUT/$name/out/report.html"
  [ -s "$HTML" ] || fail "no report written for $pipeline"
  # A copy with the counting script before </body>: it waits until the report's own script
  # says every chart has rendered, then counts what the SVG holds.
  local line
  line=$(grep -n '^</body>$' "$HTML" | tail -1 | cut -d: -f1)
  [ -n "$line" ] || fail "the report has no </body> line"
  {
    head -n $((line - 1)) "$HTML"
    echo "<script>"
    cat "$HERE/count_marks.js"
    echo "</script>"
    tail -n +"$line" "$HTML"
  } > "$OUT/$name/counted.html"
  chrome --dump-dom "$OUT/$name/counted.html" > "$OUT/$name/dom.html" || fail "chromium --dump-dom failed: $(tail -5 "$OUT/chromium.log")"
  COUNTS="$OUT/$name/counts.txt"
  sed -n '/<pre id="tf-count">rendered/,/^end/p' "$OUT/$name/dom.html" | sed 's/<pre id="tf-count">//' > "$COUNTS"
  grep -q '^end' "$COUNTS" || fail "$name: the charts never finished rendering (no count in the DOM); see $OUT/chromium.log"
  local charts rendered failed
  charts=$(grep -c '<div class="chart"' "$HTML")
  read -r _ rendered _ failed < <(head -1 "$COUNTS")
  [ "$failed" = 0 ] || fail "$name: $failed chart(s) failed to render: $(grep -o 'plot failed[^<]*' "$OUT/$name/dom.html" | head -3)"
  [ "$rendered" = "$charts" ] || fail "$name: $rendered of $charts charts rendered"
  [ "$charts" -ge "$min_charts" ] || fail "$name: expected at least $min_charts charts, found $charts"
  ok "$name: $rendered of $charts charts rendered, none failed"
  while read -r tag id want_lines lines want_points points want_areas areas want_symbols symbols w h title want_rules rules; do
    [ "$tag" = chart ] || continue
    [ "$lines" = "$want_lines" ] || fail "$id ($title): $lines line series drawn, $want_lines expected"
    [ "$points" = "$want_points" ] || fail "$id ($title): $points line points drawn, $want_points expected"
    [ "$areas" = "$want_areas" ] || fail "$id ($title): $areas band areas drawn, $want_areas expected"
    [ "$symbols" = "$want_symbols" ] || fail "$id ($title): $symbols symbols drawn, $want_symbols expected"
    [ "$rules" = "$want_rules" ] || fail "$id ($title): $rules rules drawn, $want_rules expected"
    [ $((lines + areas + symbols)) -gt 0 ] || fail "$id ($title) is empty"
    [ "$w" -gt 300 ] && [ "$h" -gt 80 ] || fail "$id ($title) is only ${w}x${h} px"
  done < "$COUNTS"
  ok "$name: every chart drew all its lines, points, bands, symbols and rules"
}

render "$ROOT/pipelines/quickstart.yaml" quickstart 7

# The plots the issue asks for, with their content: quickstart has one filter and 601 steps.
need() {  # need TITLE MIN_LINES MIN_POINTS MIN_AREAS MIN_SYMBOLS [MIN_RULES]
  local row
  row=$(awk -v t="$1" '$1 == "chart" && $13 == t' "$COUNTS")
  [ -n "$row" ] || fail "no chart titled '$1' (charts: $(awk '$1 == "chart" { printf "%s ", $13 }' "$COUNTS"))"
  read -r _ _ _ l _ p _ a _ s _ _ _ _ r <<< "$row"
  [ "$l" -ge "$2" ] && [ "$p" -ge "$3" ] && [ "$a" -ge "$4" ] && [ "$s" -ge "$5" ] && [ "$r" -ge "${6:-0}" ] ||
    fail "'$1' has $l lines, $p points, $a areas, $s symbols, $r rules; expected at least $2, $3, $4, $5, ${6:-0}"
  ok "'$1' holds at least $2 series, $3 points, $4 bands, $5 symbols, ${6:-0} rules"
}
need pipeline 4 8 0 5                                             # 5 nodes, 4 arrows
need position_RMSE_against_time 2 1100 0 0                        # kf and the measurements
need velocity_RMSE_against_time 1 550 0 0
need ANEES_against_time 1 550 1 0                                 # value inside its shaded band
need ANIS_against_time 1 550 1 0
need "ground_track_(east-north)" 2 1100 0 550                     # truth and kf; measurements as symbols
need altitude_against_time 2 1100 0 550
# A fraction of runs that never changes is a line of text, not a flat plot (issue 26).
if grep -q 'data-title="fraction of runs' "$HTML"; then
  need fraction_of_runs_initialised_and_updated_-_kf 1 550 0 0
else
  grep -q 'kf: at every step .* % of the runs (not plotted)' "$HTML" || fail "no fraction plot and no line saying why"
  ok "the constant fractions of runs are one line of text"
fi

chrome --window-size=1100,6400 --screenshot="$OUT/report.png" "$HTML" > /dev/null || fail "screenshot failed"
size=$(stat -c %s "$OUT/report.png" 2> /dev/null || echo 0)
[ "$size" -gt 100000 ] || fail "screenshot $OUT/report.png is only $size bytes"
ok "screenshot $OUT/report.png ($size bytes)"

# Two filters on one target that turns at 10 s (tests/cli/data/two_filter_study.yaml): each
# statistic is one plot with both filters on one scale inside one band, and the plots against
# time mark the turn's onset with a rule (issue 26).
render "$ROOT/tests/cli/data/two_filter_study.yaml" two_filters 6
need ANEES_against_time 2 150 1 0 1
need ANIS_against_time 2 150 1 0 1
need position_RMSE_against_time 2 150 0 0 1
awk '$1 == "chart" && $13 ~ /^AN(EES|IS)_against_time_-_/ { exit 1 }' "$COUNTS" ||
  fail "a consistency plot per filter: the filters share one band and belong on one plot"
ok "no per-filter consistency plots"
grep -q 'inside the band: kf: [0-9]* of [0-9]* steps ([0-9.]* %); ekf: [0-9]* of [0-9]* steps' "$HTML" ||
  fail "the consistency caption does not give each filter's steps inside the band as counts"
ok "the consistency caption counts each filter's steps inside the band"
chrome --window-size=1100,4200 --screenshot="$OUT/two_filters.png" "$HTML" > /dev/null || fail "screenshot failed"
ok "screenshot $OUT/two_filters.png"
echo "$passed passed, 0 failed"
