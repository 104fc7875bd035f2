#!/usr/bin/env bash
# Purpose: the results table of pipelines/two_station_launch.yaml (docs/two-station-fusion.md): position/velocity RMSE and ANEES of every filter, and the fused filter's per-station mean NIS, as Markdown.
# Usage: bench/two_station_table.sh [TRACKFLOW] [SEED]
#   TRACKFLOW  the CLI (default build/bin/trackflow); SEED the pipeline seed (default: the pipeline's own, 1)
set -eu
cd "$(dirname "$0")/.."
TF=${1:-build/bin/trackflow}
SEED=${2:-1}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
"$TF" run pipelines/two_station_launch.yaml --seed "$SEED" --threads 2 --no-progress --out "$OUT" > "$OUT/summary.txt" || {
  echo "the pipeline failed (see its expect block):" >&2
  tail -30 "$OUT/summary.txt" >&2
  exit 1
}
echo "command: $TF run pipelines/two_station_launch.yaml --seed $SEED --threads 2 (20 runs)"
echo
# The summary prints each node as "<id> (<type>)" followed by indented "name [unit] value" lines.
awk '
  /^[a-z_0-9]+ \(sink\.metrics\)/ { node = $1; sub(/_score$/, "", node); order[++n] = node; next }
  /^[a-z_0-9]+ \(/ { node = ""; filt = $1; next }
  node != "" && $1 == "position_rmse" { pos[node] = $3 }
  node != "" && $1 == "velocity_rmse" { vel[node] = $3 }
  node != "" && $1 == "anees" { anees[node] = $2; band[node] = $6 " " $7 }
  filt != "" && $1 ~ /^nis_mean\./ { nis[filt] = nis[filt] (nis[filt] == "" ? "" : ", ") substr($1, 10) " " $2 }
  END {
    print "| filter | position RMSE [m] | velocity RMSE [m/s] | ANEES | 95 % band (one step) | mean NIS per station |"
    print "|---|---|---|---|---|---|"
    for (i = 1; i <= n; ++i) {
      k = order[i]; f = k; if (f !~ /_ekf$/ && (f "_ekf") in nis) f = f "_ekf"
      printf "| %s | %s | %s | %s | %s | %s |\n", k, pos[k], vel[k], anees[k], band[k], (f in nis ? nis[f] : "")
    }
  }' "$OUT/summary.txt"
