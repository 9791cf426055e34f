#!/usr/bin/env bash
# Regenerates the README's figures in docs/img (commit them with the change that alters them):
#   bash scripts/figures.sh
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --quiet --release -p imu-cli
bin=target/release/imukit
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p docs/img

# 1. The demo's truth: the figure-8, exact kinematics.
"$bin" demo --out-dir "$work/demo" >/dev/null
"$bin" plot "$work/demo/truth.csv" --out docs/img/truth.png

# 2. Allan deviation of a STIM300 at rest for an hour, with the fitted lines.
cat > "$work/stim300.toml" <<'TOML'
rate_hz = 100.0
duration_s = 3600.0
[trajectory]
type = "builtin"
name = "static"
[imu]
preset = "stim300"
seed = 1
TOML
"$bin" simulate "$work/stim300.toml" --out "$work/stim300.csv"
"$bin" allan "$work/stim300.csv" --column gyro_x_rad_s --column gyro_y_rad_s --column gyro_z_rad_s \
  --out "$work/allan.csv" --plot docs/img/allan.png >/dev/null

# 3. The planar cart exercise: the cart's rail against dead reckoning of the erroneous data.
"$bin" exercise --out-dir "$work/exercise" >/dev/null
"$bin" plot "$work/exercise/truth.csv" "$work/exercise/inertial_data_errors_trapezoid.csv" \
  "$work/exercise/inertial_data_errors_exercise.csv" --out docs/img/exercise.png
# 4. Orientation: attitude errors of imufilter, default and tuned, on the rotating platform.
"$bin" simulate examples/matlab_orientation.toml --out "$work/or_imu.csv" --truth "$work/or_truth.csv" >/dev/null
"$bin" orient "$work/or_imu.csv" --nav-frame NED --accel-sign matlab --out "$work/default.csv" >/dev/null
"$bin" orient "$work/or_imu.csv" --nav-frame NED --accel-sign matlab --param GyroscopeNoise=7.6154e-7 \
  --param AccelerometerNoise=0.0015398 --param GyroscopeDriftNoise=3.0462e-12 \
  --param LinearAccelerationNoise=0.00096236 --param InitialProcessNoiseScale=10 --out "$work/tuned.csv" >/dev/null
"$bin" compare "$work/or_truth.csv" "$work/default.csv" --out "$work/imufilter_default.csv" >/dev/null
"$bin" compare "$work/or_truth.csv" "$work/tuned.csv" --out "$work/imufilter_tuned.csv" >/dev/null
"$bin" plot "$work/imufilter_default.csv" "$work/imufilter_tuned.csv" --out docs/img/orientation.png
ls -l docs/img
