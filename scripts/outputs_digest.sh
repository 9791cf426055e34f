#!/usr/bin/env bash
# Digest of everything imukit writes for the README's commands and every example: one line
# "sha256  name" per output file and per captured stdout/stderr. Used to show that a change which
# should not alter behaviour (a refactor) leaves every output byte-identical:
#   bash scripts/outputs_digest.sh > before.txt     # on the old commit
#   bash scripts/outputs_digest.sh > after.txt      # on the new one
#   diff before.txt after.txt
# Needs the release CLI (target/release/imukit) and the Python package in .venv (scripts/test.sh
# builds both). Writes nothing outside a temporary folder.
set -euo pipefail
cd "$(dirname "$0")/.."
bin="$PWD/target/release/imukit"
# shellcheck disable=SC1091
[ -x .venv/bin/python ] && . .venv/bin/activate
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
log="$work/_log"
mkdir -p "$log"

# Runs a command, keeping its stdout and stderr (with the temporary folder's name taken out) and
# its exit code under the name $1.
run() {
  local name=$1
  shift
  set +e
  "$@" >"$log/$name.out" 2>"$log/$name.err"
  echo $? >"$log/$name.code"
  set -e
  sed -i "s#$work#WORK#g" "$log/$name.out" "$log/$name.err"
}

cd "$work"
# The README's set-up command and its variants.
run demo "$bin" demo --out-dir demo
for s in $("$bin" scenario | awk '$1 != "" {print $1}'); do
  run "scenario_$s" "$bin" scenario "$s"
  run "demo_$s" "$bin" demo --scenario "$s" --out-dir "demo_$s"
done
run scenario_list "$bin" scenario
run presets "$bin" presets
for p in ideal mpu-6050 stim300 hg9900; do run "preset_$p" "$bin" presets "$p"; done
run convert "$bin" convert 0.15 "°/√h"

# Every example scenario: simulate, plot, animate.
for f in "$OLDPWD"/examples/*.toml; do
  n=$(basename "$f" .toml)
  run "sim_$n" "$bin" simulate "$f" --out "ex_${n}_imu.csv" --truth "ex_${n}_truth.csv"
  run "plot_${n}_truth" "$bin" plot "ex_${n}_truth.csv" --out "ex_${n}_truth.png"
  run "plot_${n}_imu" "$bin" plot "ex_${n}_imu.csv" --out "ex_${n}_imu.svg"
done
run mc "$bin" simulate "$OLDPWD/examples/preset_monte_carlo.toml" --out mc/imu.csv --runs 3
run animate_gif "$bin" animate ex_expression_truth.csv --out body.gif
run animate_html "$bin" animate ex_track_truth.csv --out body.html --body 0.3 0.2 0.1 --lever-arm -0.075 -0.075 0.025 --fps 10 --speed 0.5

# Navigation and comparison.
run integrate "$bin" integrate ex_expression_imu.csv --init ex_expression_truth.csv --out nav.csv
run integrate_rk4 "$bin" integrate ex_expression_imu.csv --init ex_expression_truth.csv --scheme rk4 --substeps 2 --out nav_rk4.csv
run compare "$bin" compare ex_expression_truth.csv nav.csv --out err.csv
run plot_err "$bin" plot err.csv --out err.png
run plot_overlay "$bin" plot ex_expression_truth.csv nav.csv --out overlay.svg
run exercise "$bin" exercise --out-dir exercise
run planar "$bin" integrate exercise/inertial_data.dat --planar --scheme exercise --out planar.csv
for filt in imufilter ahrsfilter ecompass madgwick mahony complementary; do
  run "orient_$filt" "$bin" orient ex_matlab_orientation_imu.csv --filter "$filt" --nav-frame NED --accel-sign matlab --out "orient_$filt.csv"
  run "compare_$filt" "$bin" compare ex_matlab_orientation_truth.csv "orient_$filt.csv" --out "orient_err_$filt.csv"
done
run orient_tuned "$bin" orient ex_matlab_orientation_imu.csv --nav-frame NED --accel-sign matlab --param GyroscopeNoise=7.6154e-7 --param InitialProcessNoiseScale=10 --out orient_tuned.csv
run allan "$bin" allan ex_matlab_stationary_imu.csv --column gyro_x_rad_s --column accel_z_m_s2 --out allan.csv --plot allan.png
run plot_allan "$bin" plot allan.csv --out allan2.svg

# Refusals: the messages a user reads.
printf 'rate_hz = 100.0\n[trajectory]\ntype = "expression"\nposition_m = ["sine(t)", "0", "0"]\n' >bad_formula.toml
run bad_formula "$bin" simulate bad_formula.toml --out x.csv
printf 't_s,pos_x_m,pos_y_m,pos_z_m\n0,0,0,0\n0.1,nan,0,0\n' >bad_samples.csv
printf '[trajectory]\ntype = "samples"\nfile = "bad_samples.csv"\nattitude = "tangent"\n' >bad_samples.toml
run bad_samples "$bin" simulate bad_samples.toml --out x.csv
printf '[imu.gyroscope]\nnoise_density_rad_s_per_rt_hz = -1\n[trajectory]\ntype = "builtin"\nname = "static"\n' >bad_param.toml
run bad_param "$bin" simulate bad_param.toml --out x.csv
run bad_integrate "$bin" integrate ex_expression_imu.csv --out y.csv
run bad_convert "$bin" convert 1 "furlongs"
run bad_orient "$bin" orient ex_matlab_orientation_imu.csv --filter nosuch --out z.csv

# The Python examples and their figures.
if command -v python >/dev/null && python -c 'import imukit' 2>/dev/null; then
  for f in differentiation_error_study matlab_imusensor matlab_orientation allan_study navigation_round_trip; do
    [ -f "$OLDPWD/examples/$f.py" ] || continue
    run "py_$f" python "$OLDPWD/examples/$f.py" --figures "py_$f"
  done
fi

find . -type f ! -name '*.imukit-partial' -print0 | sort -z | xargs -0 sha256sum
