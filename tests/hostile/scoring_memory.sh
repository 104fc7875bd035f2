#!/usr/bin/env bash
# Purpose: scoring a long recorded log through sink.metrics with its defaults (series: true) keeps memory flat: 10^6 rows at --threads 2 peak below 100 MB (issue 27; it was 773 MB, every estimate's record kept).
set -u
source "$(dirname "$0")/lib.sh"
if [ -n "${TRACKFLOW_SANITIZE:-}" ]; then
  echo "SKIPPED: AddressSanitizer's shadow memory and quarantine make a peak-RSS bound meaningless"
  exit 77
fi

# A spherical log: a target receding slowly at 10 Hz, with noise (bench/memory_long_log.sh's).
python3 - "$TMP/log.csv" <<'PY' || fail "could not write the log"
import random, sys
random.seed(1)
with open(sys.argv[1], "w") as f:
    f.write("time,range,azimuth,elevation\n")
    for k0 in range(0, 1000000, 100000):
        f.write("".join(f"{k * 0.1:.1f},{10000 + 0.01 * k + random.gauss(0, 10):.3f},"
                        f"{0.5 + random.gauss(0, 0.001):.6f},{0.1 + random.gauss(0, 0.001):.6f}\n"
                        for k in range(k0, k0 + 100000)))
PY
cat > "$TMP/p.yaml" <<YAML
pipeline: { name: long_log, seed: 1, runs: 2 }
nodes:
  - { id: radar, type: source.csv, params: { path: $TMP/log.csv, angle_unit: rad } }
  - { id: cm, type: convert.classical, input: radar }
  - { id: kf, type: filter.kalman, input: cm, params: { q: 0.01 m2/s3 } }
  - { id: score, type: sink.metrics, inputs: [kf] }
YAML
# The child's peak resident set from getrusage (no GNU time needed).
peak=$(python3 - "$TF" "$PLUGINS" "$TMP" <<'PY'
import resource, subprocess, sys
tf, plugins, tmp = sys.argv[1:4]
r = subprocess.run([tf, "run", f"{tmp}/p.yaml", "--threads", "2", "--no-progress", "--plugin-path", plugins,
                    "--out", f"{tmp}/o"], stdout=open(f"{tmp}/stdout.txt", "w"), stderr=subprocess.STDOUT)
print(r.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
PY
)
read -r rc kb <<< "$peak"
[ "$rc" = 0 ] || { cat "$TMP/stdout.txt" >&2; fail "the run exited $rc"; }
grep -Eq "series: [0-9]+ rows, each the mean over" "$TMP/stdout.txt" || fail "no note that the series rows are bin means"
echo "peak resident set: $kb kB"
[ "$kb" -lt 100000 ] || fail "10^6 rows through sink.metrics peaked at $kb kB (limit 100 MB)"
echo "ok: 10^6 rows through sink.metrics with series at --threads 2 peak below 100 MB"
checks=$((checks + 1))
finish
