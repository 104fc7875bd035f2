#!/usr/bin/env bash
# Purpose: text from a pipeline file cannot reach the terminal raw nor break the report page, free-text names and plugin type names follow the node-id rule, sweep refuses one parameter twice, an unclosed YAML quote is a syntax error at its line, and the processes of an MPI job refuse to merge different --set values or data files, naming the first difference (issue 27). The MPI part is skipped, saying so, without mpirun or an MPI build.
set -u
source "$(dirname "$0")/lib.sh"

# ---- Terminal text: description, sink paths, file names (printable(), as error messages) ------
ESC=$(printf '\033') BEL=$(printf '\007')
base | sed "s/name: hostile, /name: hostile, description: \"retitled \\\\e]0;PWNED\\\\a\\\\e[2J cleared\", /" > "$TMP/desc.yaml"
grep -q 'description: "retitled \\e\]0;PWNED\\a\\e\[2J' "$TMP/desc.yaml" || fail "the test pipeline has no escape in its description"
"$TF" run "$TMP/desc.yaml" --out "$TMP/o" > "$TMP/desc.out" 2>&1 || fail "the pipeline with an odd description did not run: $(cat "$TMP/desc.out")"
expect_no "a description's terminal escapes are not printed" "[$ESC$BEL]" "$TMP/desc.out"
grep -q "pipeline hostile: retitled ?]0;PWNED??\[2J cleared" "$TMP/desc.out" || fail "the description is not printed with '?' for its control characters: $(head -1 "$TMP/desc.out")"
checks=$((checks + 1)); echo "ok: ... each control character is printed as '?'"

{ base; printf '  - { id: log, type: sink.csv, inputs: [kf, truth], params: { path: "x\\n  measurements processed: 999 by 9 filters\\n  wrote \\e[2Jforged.csv" } }\n'; } > "$TMP/path.yaml"
"$TF" run "$TMP/path.yaml" --out "$TMP/o" > "$TMP/path.out" 2>&1
rc=$?
expect_no "a line break in a sink path cannot forge a summary line" "^  measurements processed: 999" "$TMP/path.out"
expect_no "... nor send a terminal escape" "[$ESC]" "$TMP/path.out"
[ "$rc" -eq 0 ] || [ "$rc" -eq 2 ] || fail "a sink path with control characters: exit $rc, not 0 or 2"

cp "$TMP/desc.yaml" "$TMP/$(printf 'p\033[2J.yaml')"
"$TF" validate "$TMP/$(printf 'p\033[2J.yaml')" > "$TMP/validate.out" 2>&1 || fail "validate failed: $(cat "$TMP/validate.out")"
expect_no "validate prints the file name without its escapes" "[$ESC]" "$TMP/validate.out"

# ---- The report page: a label "<!--<script>" --------------------------------------------------
# imm_pipeline NAME: two IMM modes, the first named NAME, scored against the truth.
imm_pipeline() {
  truth_radar imm_label 2 1 5
  cat <<YAML
    params: { sigma_range: 10 m, sigma_azimuth: 1 mrad, sigma_elevation: 1 mrad }
  - id: imm
    type: filter.imm
    input: radar
    params:
      modes:
        - { motion: constant_velocity, q: 1 m2/s3, name: "$1" }
        - { motion: constant_acceleration, q_jerk: 100 m2/s5 }
      transition: [0.99, 0.01, 0.01, 0.99]
  - { id: score, type: sink.metrics, inputs: [imm, truth] }
YAML
}
# The JSON data of a report (its tf-charts element) has no '<' left, so no label can switch the
# HTML tokenizer; the static page template itself is not looked at.
charts_have_no_lt() {
  python3 - "$1" <<'PY' || fail "$2"
import re, sys
page = open(sys.argv[1], encoding="utf-8").read()
m = re.search(r'<script id="tf-charts" type="application/json">(.*?)</script>', page, re.S)
sys.exit(0 if m and "<" not in m.group(1) else 1)
PY
  checks=$((checks + 1))
  echo "ok: $2"
}
imm_pipeline '<!--<script>' > "$TMP/imm_lt.yaml"
"$TF" run "$TMP/imm_lt.yaml" --out "$TMP/imm_lt" --report "$TMP/imm_lt/report.html" > "$TMP/imm_lt.out" 2>&1
rc=$?
if [ -e "$TMP/imm_lt/report.html" ]; then
  charts_have_no_lt "$TMP/imm_lt/report.html" "an IMM mode named <!--<script> leaves no raw '<' in the report's chart data"
fi
[ "$rc" -eq 2 ] || fail "an IMM mode named <!--<script>: exit $rc, expected 2 (a mode name follows the node-id rule): $(cat "$TMP/imm_lt.out")"
grep -q "imm_lt.yaml:[0-9]*:[0-9]*: node 'imm': parameter 'name': a mode name must be 1 to 100 ASCII letters, digits, '_' or '-'" "$TMP/imm_lt.out" ||
  fail "the refusal of the mode name does not name the parameter and its line: $(cat "$TMP/imm_lt.out")"
checks=$((checks + 1)); echo "ok: ... it is refused at its line, as a node id would be"
imm_pipeline 'two words' > "$TMP/imm_sp.yaml"
expect_run "an IMM mode name with a space is refused" 2 "parameter 'name': a mode name must be" -- "$TF" validate "$TMP/imm_sp.yaml"
imm_pipeline 'fast_mode' > "$TMP/imm_ok.yaml"
expect_run "a plain IMM mode name still runs" 0 "measurements processed" \
  -- "$TF" run "$TMP/imm_ok.yaml" --out "$TMP/imm_ok" --report "$TMP/imm_ok/report.html"
charts_have_no_lt "$TMP/imm_ok/report.html" "... and its report's chart data has no '<' either"
grep -q 'imm.p_fast_mode' "$TMP/imm_ok/report.html" || fail "the report does not label p_fast_mode"

# ---- Plugin type names are checked at registration ---------------------------------------------
BAD="$HOSTILE/bad_type_names"
expect_run "a type name '' is refused, naming the plugin file" 2 \
  "tfplugin_test_bad_type_names.so: register: type name '' refused: a type name is 1 to 100 ASCII letters" \
  -- "$TF" plugins --plugin-path "$BAD"
expect_run "... and one with a space" 2 "tfplugin_test_bad_type_names.so: register: type name 'test.bad name' refused" \
  -- "$TF" plugins --plugin-path "$BAD"
expect_run "... and one with a line break and an escape, quoted with '?'" 2 \
  "register: type name 'test.forged\?trackflow: all good\?\[2J' refused" -- "$TF" plugins --plugin-path "$BAD"
"$TF" plugins --plugin-path "$BAD" > "$TMP/types.out" 2>&1
expect_no "... none of them is listed" "^  (test.bad name|test.forged| )" "$TMP/types.out"
expect_no "... no raw line break forges a line" "^trackflow: all good" "$TMP/types.out"
grep -q "^  test.good_name " "$TMP/types.out" || fail "the plugin's good type is not listed: $(cat "$TMP/types.out")"
checks=$((checks + 1)); echo "ok: ... its good type is still listed"

# ---- sweep with one parameter twice ------------------------------------------------------------
base > "$TMP/p.yaml"
expect_run "sweep refuses one parameter given twice, naming it" 2 "--param kf.q is given twice" \
  -- "$TF" sweep "$TMP/p.yaml" --param kf.q=0,1 --param kf.q=2,3 --runs 1 --out "$TMP/o"
expect_run "... two parameters of one node are fine" 0 "grid points" \
  -- "$TF" sweep "$TMP/p.yaml" --param kf.q=0,1 --param radar.sigma_range=5,10 --runs 1 --out "$TMP/o"

# ---- An unclosed quote in YAML ------------------------------------------------------------------
sed 's/type: filter.kalman/type: "filter.kalman/' "$TMP/p.yaml" > "$TMP/quote.yaml"
expect_run "an unclosed double quote is a YAML syntax error at its line" 2 \
  "quote.yaml:18:11: YAML syntax error: the quote \" opened here is never closed" -- "$TF" validate "$TMP/quote.yaml"
sed "s/type: filter.kalman/type: 'filter.kalman/" "$TMP/p.yaml" > "$TMP/quote1.yaml"
expect_run "... and an unclosed single quote" 2 "quote1.yaml:18:11: YAML syntax error: the quote ' opened here is never closed" \
  -- "$TF" validate "$TMP/quote1.yaml"
sed "s/type: filter.kalman/type: 'filter.kalman' # it''s \"quoted/" "$TMP/p.yaml" > "$TMP/quote2.yaml"
expect_run "... closed quotes (and quotes in a comment) are fine" 0 ": ok" -- "$TF" validate "$TMP/quote2.yaml"
expect_run "... --set values are a syntax error too" 2 "--set radar.sigma_range:1:[0-9]+: YAML syntax error" \
  -- "$TF" validate "$TMP/p.yaml" --set 'radar.sigma_range="10 m'

# ---- MPI: the ranks must run the same parameters and data files ---------------------------------
if ! "$TF" --version | grep -q "MPI"; then
  echo "skipped: the MPI part (trackflow built without MPI)"
  finish
  exit 0
fi
if ! command -v mpirun > /dev/null; then
  echo "skipped: the MPI part (mpirun not found: openmpi-bin)"
  finish
  exit 0
fi
MPIRUN=(mpirun --oversubscribe)
[ "$(id -u)" -eq 0 ] && MPIRUN+=(--allow-run-as-root)
if [ -n "${TRACKFLOW_SANITIZE:-}" ]; then export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"; fi  # as tests/cli/mpi.sh
expect_run "mpirun with a different --set on one rank exits 2 naming the parameter and both values" 2 \
  "rank 1 differs from rank 0 in radar.sigma_range: '500 m' vs '10 m'" \
  -- "${MPIRUN[@]}" -np 1 "$TF" run "$TMP/p.yaml" --runs 20 --out "$TMP/m0" : -np 1 "$TF" run "$TMP/p.yaml" --runs 20 \
  --out "$TMP/m0" --set radar.sigma_range="500 m"
expect_run "... a default against a given value too" 2 "rank 1 differs from rank 0 in kf.q: '7' vs '[0-9.e-]+ \(its default\)'" \
  -- "${MPIRUN[@]}" -np 1 "$TF" run "$TMP/p.yaml" --runs 4 --out "$TMP/m0" : -np 1 "$TF" run "$TMP/p.yaml" --runs 4 \
  --out "$TMP/m0" --set kf.q=7
expect_run "... the same value in other units is the same pipeline" 0 "runs shared by 2 MPI processes" \
  -- "${MPIRUN[@]}" -np 1 "$TF" run "$TMP/p.yaml" --runs 4 --out "$TMP/m1" --set radar.sigma_range="0.01 km" : \
  -np 1 "$TF" run "$TMP/p.yaml" --runs 4 --out "$TMP/m1" --set radar.sigma_range="10 m"

# Two copies of a folder with one pipeline and a log of the same name; one rank works in each.
for d in a b; do
  mkdir -p "$TMP/$d"
  cp "$INPUTS/range_zero.csv" "$TMP/$d/log.csv"
  cat > "$TMP/$d/pipeline.yaml" <<'YAML'
pipeline: { name: ranks, seed: 1, runs: 4 }
nodes:
  - { id: radar, type: source.csv, params: { path: log.csv, range_unit: m, angle_unit: rad } }
  - { id: cm, type: convert.classical, input: radar }
  - { id: kf, type: filter.kalman, input: cm }
  - { id: out, type: sink.csv, inputs: [kf] }
YAML
done
expect_run "mpirun with identical folders in two working directories runs" 0 "runs shared by 2 MPI processes" \
  -- "${MPIRUN[@]}" -np 1 -wdir "$TMP/a" "$TF" run pipeline.yaml --out "$TMP/ma" : -np 1 -wdir "$TMP/b" "$TF" run pipeline.yaml --out "$TMP/ma"
sed -i '3s/^0.1,1001,/0.1,1002,/' "$TMP/b/log.csv"
cmp -s "$TMP/a/log.csv" "$TMP/b/log.csv" && fail "the two logs did not become different"
expect_run "mpirun with a different log at the same path on one rank exits 2 naming the file" 2 \
  "rank 1 differs from rank 0 in data file 'log.csv': '[0-9]+ bytes, FNV-1a [0-9a-f]{16}' vs '[0-9]+ bytes, FNV-1a [0-9a-f]{16}'" \
  -- "${MPIRUN[@]}" -np 1 -wdir "$TMP/a" "$TF" run pipeline.yaml --out "$TMP/mb" : -np 1 -wdir "$TMP/b" "$TF" run pipeline.yaml --out "$TMP/mb"
finish
