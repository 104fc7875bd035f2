#!/usr/bin/env bash
# Purpose: the 2-D measurement frames end to end from recorded logs: a 2-D radar's polar log (range, azimuth) through filter.ekf and through tracker.multi, a planar sensor's x-y log through filter.kalman; the wiring refused where a frame cannot go (a polar log into filter.kalman or filter.ukf, a 3-value adapter on a 2-D filter), each at its own line.
set -u
TF=$1
source "$(dirname "$0")/lib.sh"

# One target at 10 km flying east at 100 m/s in the radar's plane, a plot every second (exact
# values: the filters' job here is to take them, not to smooth them).
python3 - "$TMP" <<'PY'
import math, sys
d = sys.argv[1]
with open(f"{d}/polar.csv", "w") as f, open(f"{d}/planar.csv", "w") as g, open(f"{d}/polar_plots.csv", "w") as h:
    f.write("time,range,azimuth\n"); g.write("time,x,y\n"); h.write("time,range,azimuth\n")
    for k in range(30):
        x, y = -1500 + 100 * k, 10000
        r, az = math.hypot(x, y), math.degrees(math.atan2(x, y))
        f.write(f"{k},{r:.3f},{az:.6f}\n"); g.write(f"{k},{x},{y}\n")
        h.write(f"{k},{r:.3f},{az:.6f}\n{k},{r + 3000:.3f},{az + 20:.6f}\n")  # two targets per look
PY

cat > "$TMP/polar_ekf.yaml" <<'YAML'
pipeline: { name: polar_ekf, runs: 1 }
nodes:
  - id: log
    type: source.csv
    params: { path: polar.csv, frame: polar, sigma_range: 20 m, sigma_azimuth: 1 mrad }
  - id: ekf
    type: filter.ekf
    input: log
    params: { q: 1 m2/s3 }
  - id: out
    type: sink.csv
    inputs: [ekf]
YAML
expect_run "filter.ekf takes a 2-D radar's polar log" 0 "ekf \(filter.ekf\)" -- "$TF" run "$TMP/polar_ekf.yaml" --out "$TMP/out1"
# The track lies in the radar's plane: z 0 on every initialised row.
python3 - "$TMP/out1/out.csv" <<'PY' || fail "filter.ekf on polar plots left the radar's plane"
import csv, sys
rows = [r for r in csv.DictReader(open(sys.argv[1])) if r.get("initialised", "1") in ("1", "true")]
assert rows and all(abs(float(r["z_m"])) < 1e-9 for r in rows if r["z_m"] != ""), "z not 0"
assert abs(float(rows[-1]["x_m"]) - 1400) < 60, rows[-1]["x_m"]
PY
checks=$((checks + 1))
echo "ok: the polar track stays in the radar's plane and follows the target"

sed 's/type: filter.ekf/type: filter.ukf/' "$TMP/polar_ekf.yaml" > "$TMP/polar_ukf.yaml"
expect_run "filter.ukf refuses a polar log at its input line" 2 \
  "polar_ukf.yaml:8:.*produces polar \\(range-azimuth\\) measurements, but filter.ukf takes spherical measurements; the filters that take them: .*filter.ekf" -- "$TF" validate "$TMP/polar_ukf.yaml"
sed 's/type: filter.ekf/type: filter.kalman/' "$TMP/polar_ekf.yaml" > "$TMP/polar_kf.yaml"
expect_run "filter.kalman refuses a polar log at its input line" 2 \
  "produces polar \(range-azimuth\) measurements, but filter.kalman takes cartesian/planar \(x-y\)" -- "$TF" validate "$TMP/polar_kf.yaml"
cat >> "$TMP/polar_ekf.yaml" <<'YAML'
  - id: grades
    type: adapt.quality_switch
    attach_to: ekf
YAML
expect_run "an adapter of three channels is refused on a polar filter, at its attach_to" 2 \
  "polar_ekf.yaml:15:.*cannot attach adapter 'grades'.*receives polar \(range-azimuth\) measurements and adapt.quality_switch takes spherical" -- \
  "$TF" validate "$TMP/polar_ekf.yaml"

cat > "$TMP/planar_kf.yaml" <<'YAML'
pipeline: { name: planar_kf, runs: 1 }
nodes:
  - id: log
    type: source.csv
    params: { path: planar.csv, frame: planar, sigma_position: 10 m }
  - id: kf
    type: filter.kalman
    input: log
    params: { q: 1 m2/s3 }
  - id: out
    type: sink.csv
    inputs: [kf]
YAML
expect_run "filter.kalman takes a planar x-y log" 0 "kf \(filter.kalman\)" -- "$TF" run "$TMP/planar_kf.yaml" --out "$TMP/out2"
python3 - "$TMP/out2/out.csv" <<'PY' || fail "filter.kalman on planar plots left z = 0"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert rows and all(r["z_m"] in ("", "0") or abs(float(r["z_m"])) == 0.0 for r in rows)
PY
checks=$((checks + 1))
echo "ok: the planar track stays in z = 0"

# Two targets per polar look into tracker.multi with filter.ekf per track: two confirmed tracks.
cat > "$TMP/polar_tracks.yaml" <<'YAML'
pipeline: { name: polar_tracks, runs: 1 }
nodes:
  - id: log
    type: source.csv
    params: { path: polar_plots.csv, frame: polar, content: detections, sigma_range: 20 m, sigma_azimuth: 1 mrad,
              detection_probability: 0.9, clutter_density: 1e-6 }
  - id: tracks
    type: tracker.multi
    input: log
    params:
      estimator: { type: filter.ekf, q: 1 m2/s3 }
      associator: { type: assoc.gnn }
      initiator: { type: init.m_of_n, m: 3, n: 4, max_speed: 300 m/s }
      deleter: { type: delete.misses, max_misses: 3 }
YAML
expect_run "tracker.multi tracks a polar detection log" 0 "tracks_confirmed_per_run +2$" -- "$TF" run "$TMP/polar_tracks.yaml"
# A per-track adapter of three channels on polar detections: refused when the first one reaches it.
sed 's/      deleter: { type: delete.misses, max_misses: 3 }/      deleter: { type: delete.misses, max_misses: 3 }\n      adapters: [{ type: adapt.range_r, alpha: 400 urad2, beta: 900 urad2, reference_range: 10 km }]/' \
  "$TMP/polar_tracks.yaml" > "$TMP/polar_adapted.yaml"
grep -q "adapt.range_r" "$TMP/polar_adapted.yaml" || fail "the adapter was not added to the test pipeline"
expect_run "a per-track adapter refuses a frame it does not take" 2 \
  "adapter adapt.range_r takes spherical measurements, but the detection at t=0.000000 s is polar" -- \
  "$TF" run "$TMP/polar_adapted.yaml"

finish
