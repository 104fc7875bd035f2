#!/usr/bin/env bash
# Purpose: numbers on the command line are checked, never wrapped: --runs, --threads, --seed (full 64 bits), --track-run, in run and sweep.
set -u
source "$(dirname "$0")/lib.sh"

base > "$TMP/p.yaml"
for bad in -1 0 abc 1e3 12abc 18446744073709551616 ""; do
  expect_run "--runs '$bad' is refused" 2 "--runs must be a whole number from 1 to 18446744073709551615" \
    -- "$TF" run "$TMP/p.yaml" --runs "$bad" --out "$TMP/out"
done
for bad in -1 1025 4294967297 x; do
  expect_run "--threads '$bad' is refused" 2 "--threads must be a whole number from 0 to 1024" \
    -- "$TF" run "$TMP/p.yaml" --threads "$bad" --out "$TMP/out"
done
expect_run "--seed 2^64 is refused" 2 "--seed must be a whole number from 0 to 18446744073709551615" \
  -- "$TF" run "$TMP/p.yaml" --seed 18446744073709551616 --out "$TMP/out"
expect_run "--seed -1 is refused" 2 "--seed must be" -- "$TF" run "$TMP/p.yaml" --seed -1 --out "$TMP/out"
# Seeds above 2^63 work, and the command line and the file give the same numbers.
expect_run "--seed 2^64-1 runs" 0 "seed 18446744073709551615" \
  -- "$TF" run "$TMP/p.yaml" --seed 18446744073709551615 --out "$TMP/out" --metrics-json "$TMP/cli.json"
sed 's/seed: 1/seed: 18446744073709551615/' "$TMP/p.yaml" > "$TMP/seed.yaml"
expect_run "seed: 2^64-1 in the file runs" 0 "seed 18446744073709551615" \
  -- "$TF" run "$TMP/seed.yaml" --out "$TMP/out" --metrics-json "$TMP/file.json"
cmp -s "$TMP/cli.json" "$TMP/file.json" || fail "--seed 2^64-1 and seed: 2^64-1 give different metrics"
echo "ok: the same metrics either way"
expect_run "--track-run -1 is refused" 2 "--track-run must be" -- "$TF" report "$TMP/p.yaml" --track-run -1 --out "$TMP/out"
expect_run "sweep --runs -1 is refused" 2 "--runs must be" -- "$TF" sweep "$TMP/p.yaml" --param kf.q=0,1 --runs -1
expect_run "sweep --threads 99999 is refused" 2 "--threads must be" -- "$TF" sweep "$TMP/p.yaml" --param kf.q=0,1 --threads 99999
finish
