#!/usr/bin/env bash
# Purpose: number formatting measured from outside (issue 20), two builds taking turns: the HTML report's extra CPU on a 21 600-step pipeline, and sink.csv's CPU per row in the quickstart.
# Usage: bench/number_format.sh OLD_TRACKFLOW NEW_TRACKFLOW [REPEATS]
#   e.g. bench/number_format.sh /work/main/build/bin/trackflow build/bin/trackflow 3
# CPU seconds (user + sys, GNU time) of each command, the median of REPEATS, the builds alternating
# so other load on the machine affects both alike; single thread. Also checks that both builds
# write the same report.html (apart from --out and the elapsed time), series CSVs and sink.csv file.
#   report: `trackflow report` minus `trackflow run` of pipelines/launch_normal_noise.yaml
#     (10 runs x 21 600 steps, 4 filters): the series CSVs, the track and the HTML page.
#   sink.csv: pipelines/quickstart.yaml with a sink.csv node on the filter and the truth (200 x
#     600 = 120 000 rows), minus the quickstart without it, per row.
set -eu
cd "$(dirname "$0")/.."
OLD=$1
NEW=$2
REPEATS=${3:-3}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
LAUNCH=pipelines/launch_normal_noise.yaml
cp pipelines/quickstart.yaml "$OUT/plain.yaml"
awk '/^expect:/ { print "  - { id: log, type: sink.csv, inputs: [kf, truth] }\n" } { print }' \
  pipelines/quickstart.yaml > "$OUT/with_csv.yaml"

cpu() {  # cpu COMMAND...: CPU seconds (user + sys)
  /usr/bin/time -f '%U %S' -o "$OUT/time" "$@" > /dev/null 2> "$OUT/stderr" || { cat "$OUT/stderr" >&2; exit 1; }
  awk '{ printf "%.2f\n", $1 + $2 }' "$OUT/time"
}
median() { sort -n | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }

declare -A t
for _ in $(seq "$REPEATS"); do
  for b in old new; do
    tf=$OLD
    [ "$b" = new ] && tf=$NEW
    t[$b.run]+="$(cpu "$tf" run "$LAUNCH" --no-progress -q -o "$OUT/$b.run") "
    t[$b.report]+="$(cpu "$tf" report "$LAUNCH" --no-progress -q -o "$OUT/$b.report") "
    t[$b.plain]+="$(cpu "$tf" run "$OUT/plain.yaml" --no-progress -q -o "$OUT/$b.plain") "
    t[$b.csv]+="$(cpu "$tf" run "$OUT/with_csv.yaml" --no-progress -q -o "$OUT/$b.csv") "
  done
done
m() { printf '%s\n' ${t[$1]} | median; }
rows=$(($(wc -l < "$OUT/new.csv/log.csv") - 1))
echo "$(nproc) cores, load $(uptime | sed 's/.*load average: //'); CPU s, median of $REPEATS (all values)"
printf '%-46s %10s %10s\n' "" "old" "new"
for k in run report plain csv; do
  case $k in
    run) label="launch_normal_noise: run" ;;
    report) label="launch_normal_noise: report" ;;
    plain) label="quickstart" ;;
    csv) label="quickstart + sink.csv ($rows rows)" ;;
  esac
  printf '%-46s %10s %10s   (%s| %s)\n' "$label" "$(m old.$k)" "$(m new.$k)" "${t[old.$k]}" "${t[new.$k]}"
done
for b in old new; do
  extra=$(awk -v r="$(m $b.report)" -v n="$(m $b.run)" 'BEGIN { printf "%.2f s (+%.0f %%)", r - n, 100 * (r - n) / n }')
  per_row=$(awk -v c="$(m $b.csv)" -v p="$(m $b.plain)" -v rows="$rows" 'BEGIN { printf "%.2f us", 1e6 * (c - p) / rows }')
  echo "$b: the report adds $extra; sink.csv costs $per_row per row"
done
# The page names its --out folder and the run's elapsed seconds; everything else must match.
for b in old new; do
  sed -E "s#$OUT/$b\.report#OUT#g; s/[0-9.]+ s; ([0-9]+ measurements processed)/T s; \1/" "$OUT/$b.report/report.html" > "$OUT/$b.html"
done
cmp -s "$OUT/old.html" "$OUT/new.html" && echo "report.html: identical (apart from --out and the elapsed time)" ||
  echo "report.html: DIFFERS"
cmp -s "$OUT/old.csv/log.csv" "$OUT/new.csv/log.csv" && echo "log.csv: identical" ||
  echo "log.csv: DIFFERS (expected between builds before and after sink.csv's shortest round-trip default)"
diff -r -q -x report.html "$OUT/old.report" "$OUT/new.report" > /dev/null && echo "series and track CSVs: identical" ||
  echo "series and track CSVs: DIFFER"
