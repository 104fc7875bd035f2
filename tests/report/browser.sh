#!/usr/bin/env bash
# Purpose: renders the quickstart's HTML report in headless Chromium and checks that every plot was drawn with all its series and points; skipped (exit 77) without a browser.
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
"$TF" report "$ROOT/pipelines/quickstart.yaml" --threads 2 --no-progress --out "$OUT/out" > "$OUT/report.log" 2>&1 ||
  fail "trackflow report failed: $(cat "$OUT/report.log")"
HTML="$OUT/out/report.html"
[ -s "$HTML" ] || fail "no report written"

# The browser runs offline: no network flags, and the page must not need any.
chrome() {
  "$BROWSER" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking \
    --disable-component-update --disable-sync --user-data-dir="$PROFILE" --virtual-time-budget=30000 "$@" 2> "$OUT/chromium.log"
}

# A copy with the counting script before </body>: it waits until the report's own script
# says every chart has rendered, then counts what the SVG holds.
line=$(grep -n '^</body>$' "$HTML" | tail -1 | cut -d: -f1)
[ -n "$line" ] || fail "the report has no </body> line"
{
  head -n $((line - 1)) "$HTML"
  echo "<script>"
  cat "$HERE/count_marks.js"
  echo "</script>"
  tail -n +"$line" "$HTML"
} > "$OUT/counted.html"
chrome --dump-dom "$OUT/counted.html" > "$OUT/dom.html" || fail "chromium --dump-dom failed: $(tail -5 "$OUT/chromium.log")"
sed -n '/<pre id="tf-count">rendered/,/^end/p' "$OUT/dom.html" | sed 's/<pre id="tf-count">//' > "$OUT/counts.txt"
grep -q '^end' "$OUT/counts.txt" || fail "the charts never finished rendering (no count in the DOM); see $OUT/chromium.log"

charts=$(grep -c '<div class="chart"' "$HTML")
read -r _ rendered _ failed < <(head -1 "$OUT/counts.txt")
[ "$failed" = 0 ] || fail "$failed chart(s) failed to render: $(grep -o 'plot failed[^<]*' "$OUT/dom.html" | head -3)"
[ "$rendered" = "$charts" ] || fail "$rendered of $charts charts rendered"
[ "$charts" -ge 9 ] || fail "expected at least 9 charts in the quickstart report, found $charts"
ok "$rendered of $charts charts rendered, none failed"

# Every chart: drawn exactly what its data hold, and something drawn, at a visible size.
while read -r tag id want_lines lines want_points points want_areas areas want_symbols symbols w h title; do
  [ "$tag" = chart ] || continue
  [ "$lines" = "$want_lines" ] || fail "$id ($title): $lines line series drawn, $want_lines expected"
  [ "$points" = "$want_points" ] || fail "$id ($title): $points line points drawn, $want_points expected"
  [ "$areas" = "$want_areas" ] || fail "$id ($title): $areas band areas drawn, $want_areas expected"
  [ "$symbols" = "$want_symbols" ] || fail "$id ($title): $symbols symbols drawn, $want_symbols expected"
  [ $((lines + areas + symbols)) -gt 0 ] || fail "$id ($title) is empty"
  [ "$w" -gt 300 ] && [ "$h" -gt 80 ] || fail "$id ($title) is only ${w}x${h} px"
  ok "$id $title: $lines lines / $points points, $areas areas, $symbols symbols, ${w}x${h} px"
done < "$OUT/counts.txt"

# The plots the issue asks for, with their content: quickstart has one filter and 601 steps.
need() {  # need TITLE MIN_LINES MIN_POINTS MIN_AREAS MIN_SYMBOLS
  local row
  row=$(awk -v t="$1" '$1 == "chart" && $13 == t' "$OUT/counts.txt")
  [ -n "$row" ] || fail "no chart titled '$1'"
  read -r _ _ _ l _ p _ a _ s _ _ _ <<< "$row"
  [ "$l" -ge "$2" ] && [ "$p" -ge "$3" ] && [ "$a" -ge "$4" ] && [ "$s" -ge "$5" ] ||
    fail "'$1' has $l lines, $p points, $a areas, $s symbols; expected at least $2, $3, $4, $5"
  ok "'$1' holds at least $2 series, $3 points, $4 bands, $5 symbols"
}
need pipeline 4 8 0 5                                             # 5 nodes, 4 arrows
need position_RMSE_against_time 2 1100 0 0                        # kf and the measurements
need velocity_RMSE_against_time 1 550 0 0
need ANEES_against_time_-_kf 1 550 1 0                            # value inside its shaded band
need ANIS_against_time_-_kf 1 550 1 0
need "ground_track_(east-north)" 2 1100 0 550                     # truth and kf; measurements as symbols
need altitude_against_time 2 1100 0 550
need fraction_of_runs_initialised_and_updated_-_kf 2 1100 0 0

chrome --window-size=1100,6400 --screenshot="$OUT/report.png" "$HTML" > /dev/null || fail "screenshot failed"
size=$(stat -c %s "$OUT/report.png" 2> /dev/null || echo 0)
[ "$size" -gt 100000 ] || fail "screenshot $OUT/report.png is only $size bytes"
ok "screenshot $OUT/report.png ($size bytes)"
echo "$passed passed, 0 failed"
