#!/usr/bin/env bash
# Purpose: the mutation suite: every breakage in cases.tsv must make `trackflow run` fail an expect check (exit 1).
#
# usage: run.sh TRACKFLOW PROJECT_DIR [WORK_DIR]
#   MUTATION_JOBS=2        breakages run in parallel (each run single-threaded)
#   MUTATION_ONLY=name     only the rows of this pipeline (for working on one pipeline)
#
# A breakage is caught only by exit 1 (an `expect:` check failed). Exit 0 is a miss; exit 2
# (configuration) or 3 (internal error) means the row itself is wrong and fails the suite too.
# Prints the table pipeline x breakage -> caught / MISSED / ERROR with the checks that failed.
set -u
tf=$1
root=$2
work=${3:-$(mktemp -d)}
jobs=${MUTATION_JOBS:-2}
only=${MUTATION_ONLY:-}
cases=$root/tests/mutation/cases.tsv
rm -rf "$work/rows" "$work/out" "$work/log"
mkdir -p "$work/rows" "$work/out" "$work/log"

# Rows: pipeline <TAB> breakage <TAB> node.param=value [<TAB> node.param=value ...]; # comments.
n=0
bad=0
declare -A rows_of
while IFS= read -r line || [ -n "$line" ]; do
  [[ -z "${line//[[:space:]]/}" || "$line" == \#* ]] && continue
  IFS=$'\t' read -r -a f <<<"$line"
  if [ "${#f[@]}" -lt 3 ]; then
    echo "cases.tsv: row needs pipeline, breakage and at least one override (tab-separated): $line"
    bad=1
    continue
  fi
  if [ ! -f "$root/pipelines/${f[0]}.yaml" ]; then
    echo "cases.tsv: no pipeline pipelines/${f[0]}.yaml (row '${f[1]}')"
    bad=1
    continue
  fi
  rows_of[${f[0]}]=$(( ${rows_of[${f[0]}]:-0} + 1 ))
  [ -n "$only" ] && [ "${f[0]}" != "$only" ] && continue
  printf '%s\n' "$line" >"$work/rows/$(printf '%04d' $n)"
  n=$((n + 1))
done <"$cases"

# Every pipeline is an integration test, so every pipeline has breakages it must catch.
for p in "$root"/pipelines/*.yaml; do
  name=$(basename "$p" .yaml)
  if [ "${rows_of[$name]:-0}" -lt 3 ]; then
    echo "cases.tsv: pipeline $name has ${rows_of[$name]:-0} breakages; every pipeline needs at least 3"
    bad=1
  fi
done

run_one() {
  local id=$1 line args=() f
  line=$(cat "$work/rows/$id")
  IFS=$'\t' read -r -a f <<<"$line"
  for s in "${f[@]:2}"; do args+=(--set "$s"); done
  "$tf" run "$root/pipelines/${f[0]}.yaml" --threads 1 --no-progress --out "$work/out/$id" "${args[@]}" \
    >"$work/log/$id" 2>&1
  echo $? >"$work/log/$id.rc"
}
export -f run_one
export tf root work

start=$(date +%s)
ls "$work/rows" | xargs -P "$jobs" -I{} bash -c 'run_one {}'
elapsed=$(( $(date +%s) - start ))

printf '%-24s %-50s %-7s %s\n' pipeline breakage result "failed checks (first 3)"
printf '%-24s %-50s %-7s %s\n' -------- -------- ------ -----------------------
caught=0
missed=0
for r in $(ls "$work/rows"); do
  IFS=$'\t' read -r -a f <"$work/rows/$r"
  rc=$(cat "$work/log/$r.rc")
  checks=$(grep -E '^  FAIL  ' "$work/log/$r" | awk '{print $2}' | sort -u | head -3 | paste -sd, -)
  case $rc in
    1) result=caught; caught=$((caught + 1)) ;;
    0) result=MISSED; missed=$((missed + 1)); checks="(every check passed)" ;;
    *) result="ERROR"; missed=$((missed + 1)); checks="exit $rc: $(grep -m1 -iE 'error|refused' "$work/log/$r" | cut -c1-100)" ;;
  esac
  printf '%-24s %-50s %-7s %s\n' "${f[0]}" "${f[1]}" "$result" "$checks"
done
echo
echo "$caught of $n breakages caught, $missed not; $jobs in parallel, ${elapsed} s"
[ "$bad" -eq 0 ] && [ "$missed" -eq 0 ]
