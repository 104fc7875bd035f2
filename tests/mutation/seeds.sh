#!/usr/bin/env bash
# Purpose: runs every pipeline with --seed 1..10 and requires each to pass its expect block (no bound tuned to one seed).
#
# usage: seeds.sh TRACKFLOW PROJECT_DIR [WORK_DIR]
#   SEEDS="1 2 3 4 5 6 7 8 9 10"   seeds to run
#   SEEDS_JOBS=2                   runs in parallel (each single-threaded)
#   SEEDS_ONLY=name                only this pipeline
# Prints pipeline x seed -> pass / FAIL (the failed checks) and writes WORK_DIR/json/<pipeline>.<seed>.json
# (--metrics-json) for a look at the spread of any metric.
set -u
tf=$1
root=$2
work=${3:-$(mktemp -d)}
seeds=${SEEDS:-1 2 3 4 5 6 7 8 9 10}
jobs=${SEEDS_JOBS:-2}
only=${SEEDS_ONLY:-}
rm -rf "$work/json" "$work/log" "$work/out"
mkdir -p "$work/json" "$work/log" "$work/out"

jobs_list=()
for p in "$root"/pipelines/*.yaml; do
  name=$(basename "$p" .yaml)
  [ -n "$only" ] && [ "$name" != "$only" ] && continue
  for s in $seeds; do jobs_list+=("$name.$s"); done
done

run_one() {
  local job=$1 name=${1%.*} seed=${1##*.}
  "$tf" run "$root/pipelines/$name.yaml" --seed "$seed" --threads 1 --no-progress --out "$work/out/$job" \
    --metrics-json "$work/json/$job.json" >"$work/log/$job" 2>&1
  echo $? >"$work/log/$job.rc"
}
export -f run_one
export tf root work

start=$(date +%s)
printf '%s\n' "${jobs_list[@]}" | xargs -P "$jobs" -I{} bash -c 'run_one {}'
elapsed=$(( $(date +%s) - start ))

failed=0
printf '%-26s %s\n' pipeline "seeds ($seeds)"
for p in "$root"/pipelines/*.yaml; do
  name=$(basename "$p" .yaml)
  [ -n "$only" ] && [ "$name" != "$only" ] && continue
  row=""
  notes=""
  for s in $seeds; do
    rc=$(cat "$work/log/$name.$s.rc")
    if [ "$rc" = 0 ]; then
      row+=" pass"
    else
      row+=" FAIL"
      failed=$((failed + 1))
      notes+="  seed $s (exit $rc): $(grep -E '^  FAIL  ' "$work/log/$name.$s" | awk '{print $2"="$4}' | paste -sd' ' -)"$'\n'
    fi
  done
  printf '%-26s%s\n' "$name" "$row"
  [ -n "$notes" ] && printf '%s' "$notes"
done
echo
echo "$failed failed runs; ${#jobs_list[@]} runs, $jobs in parallel, ${elapsed} s"
[ "$failed" -eq 0 ]
