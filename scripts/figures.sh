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

# 1. The demo's truth: the seed's figure-8, exact kinematics.
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

# 3. Seed 001's exercise: the cart's rail against dead reckoning of the erroneous data.
"$bin" exercise --out-dir "$work/exercise" >/dev/null
"$bin" plot "$work/exercise/truth.csv" "$work/exercise/inertial_data_errors_trapezoid.csv" \
  "$work/exercise/inertial_data_errors_exercise.csv" --out docs/img/exercise.png
ls -l docs/img
