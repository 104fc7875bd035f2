#!/usr/bin/env bash
# Purpose: under a process limit that stops threads from starting, --threads 100 (run and sweep) goes on with the workers it got: same results, a warning, exit 0 (it once aborted: threads not joined on a throw).
set -u
source "$(dirname "$0")/lib.sh"
if [ -n "${TRACKFLOW_SANITIZE:-}" ]; then
  echo "SKIPPED: AddressSanitizer reserves terabytes of address space, so an address-space limit cannot be tested under it"
  exit 77
fi

base | sed 's/runs: 2/runs: 60/' > "$TMP/p.yaml"
"$TF" run "$TMP/p.yaml" --threads 1 --out "$TMP/o1" --metrics-json "$TMP/one.json" >/dev/null 2>&1 || fail "the reference run failed"
# Root ignores RLIMIT_NPROC, so the limit is on address space: 64 MiB thread stacks in 600 MB run
# out after a few threads and leave room for the heap (MALLOC_ARENA_MAX: per-thread malloc
# arenas would exhaust it before the stacks do).
limit="ulimit -s 65536 && ulimit -v 600000 && MALLOC_ARENA_MAX=1"
expect_run "--threads 100 under an address-space limit runs on fewer threads" 0 \
  "warning: engine: started [0-9]+ of 60 worker threads" \
  -- bash -c "$limit exec \"$TF\" run \"$TMP/p.yaml\" --threads 100 --out \"$TMP/o2\" --metrics-json \"$TMP/many.json\""
cmp -s "$TMP/one.json" "$TMP/many.json" || fail "the metrics differ from --threads 1"
echo "ok: and its metrics equal those of --threads 1"
checks=$((checks + 1))
grid=$(seq -s, 1 80)
"$TF" sweep "$TMP/p.yaml" --threads 1 --runs 1 --param "kf.q=$grid" --out "$TMP/o3" > "$TMP/sweep1.txt" 2>&1 || fail "reference sweep failed"
expect_run "sweep --threads 100 under the same limit" 0 "started [0-9]+ of 80 threads" \
  -- bash -c "$limit exec \"$TF\" sweep \"$TMP/p.yaml\" --threads 100 --runs 1 --param kf.q=$grid --out \"$TMP/o4\" > \"$TMP/sweep100.txt\""
cmp -s "$TMP/sweep1.txt" "$TMP/sweep100.txt" || fail "the sweep table differs from --threads 1"
echo "ok: and its table equals that of --threads 1"
checks=$((checks + 1))
finish
