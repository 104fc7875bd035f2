# Purpose: shared helpers of the CLI test scripts: expect an exit code and text in the output.
# Usage in a script: source "$(dirname "$0")/lib.sh"; then call expect_run.
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
checks=0

fail() {
  echo "FAIL: $*" >&2
  exit 1
}

# expect_run <what> <expected exit code> <regex that stdout+stderr must match> -- command...
expect_run() {
  local what=$1 code=$2 pattern=$3
  shift 4
  local out rc
  out=$("$@" 2>&1)
  rc=$?
  if [ "$rc" -ne "$code" ]; then
    printf '%s\n' "$out" >&2
    fail "$what: exit code $rc, expected $code"
  fi
  if ! printf '%s\n' "$out" | grep -Eq -- "$pattern"; then
    printf '%s\n' "$out" >&2
    fail "$what: output does not match /$pattern/"
  fi
  checks=$((checks + 1))
  echo "ok: $what"
}

finish() {
  echo "$checks passed, 0 failed"
}

# truth_radar NAME RUNS SEED SECONDS: the head of a pipeline, a constant-velocity truth at 10 Hz for
# SECONDS into sim.radar (its last line is the radar's `input:`, so a caller may add its params);
# a test appends the nodes it is about.
truth_radar() {
  cat <<YAML
pipeline: { name: $1, seed: $3, runs: $2 }
nodes:
  - id: truth
    type: sim.trajectory
    params:
      rate: 10 Hz
      initial_position: [6000, 8000, 1000]
      initial_velocity: [-150, 50, 0]
      segments: [ { type: constant_velocity, duration: $4 s } ]
  - id: radar
    type: sim.radar
    input: truth
YAML
}

# classical_kalman: the radar's measurements through convert.classical (node cm) into filter.kalman
# (node kf), to append after truth_radar; its last line is kf's `input:`, so a caller may add kf's params.
classical_kalman() {
  cat <<YAML
  - id: cm
    type: convert.classical
    input: radar
  - id: kf
    type: filter.kalman
    input: cm
YAML
}

# base_pipeline NAME RUNS: a valid pipeline (5 s at 10 Hz through sim.radar, convert.classical,
# filter.kalman and sink.metrics) that a test copies and breaks one thing in.
base_pipeline() {
  truth_radar "$1" "$2" 1 5
  echo "    params: { sigma_range: 10 m }"
  classical_kalman
  cat <<YAML
  - id: score
    type: sink.metrics
    inputs: [kf, truth]
YAML
}
