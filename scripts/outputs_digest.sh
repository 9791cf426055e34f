#!/usr/bin/env bash
# Digest of everything imukit writes for the README's commands and every example: one line
# "sha256  name" per output file and per captured stdout/stderr. Used to show that a change which
# should not alter behaviour (a refactor) leaves every output byte-identical:
#   bash scripts/outputs_digest.sh > before.txt     # on the old commit
#   bash scripts/outputs_digest.sh > after.txt      # on the new one
#   diff before.txt after.txt
# With a folder as argument, the outputs are also kept there (to compare the numbers of a file
# whose digest differs).
# Needs the release CLI (target/release/imukit) and the Python package in .venv (scripts/test.sh
# builds both). Writes nothing outside a temporary folder.
set -euo pipefail
keep=${1:+$(realpath -m "$1")}
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

# Navigation and fusion on both Earths, in both frames: the tunnel road flat and on WGS-84
# (ENU as written, and NED), with every start and aid, and the outage study in a few runs.
# A navigation-grade part, and 70 s at rest before the car drives (the static alignment averages 60).
sed -e 's/^preset = "stim300".*/preset = "hg1700"/' -e 's/^start_s = 120.0/start_s = 170.0/' \
  -e 's/^time_s = .*/time_s = [70, 80, 90, 100, 110, 120, 130, 140, 150, 160, 170, 180, 190, 200, 210, 220]/' \
  "$OLDPWD/examples/car_tunnel.toml" >road.toml
printf '[baro]\nrate_hz = 10.0\nbias_m = 2.0\nnoise_m = 0.3\n' >>road.toml
sed 's/^nav_frame = "ENU"/nav_frame = "ENU"\nearth = "wgs84"\norigin = { latitude_deg = 46.5, longitude_deg = 8.0, height_m = 500.0 }/' road.toml >road_enu.toml
sed 's/^nav_frame = "ENU"/nav_frame = "NED"/' road_enu.toml >road_ned.toml
for r in road road_enu road_ned; do
  run "sim_$r" "$bin" simulate $r.toml --out $r.imu.csv --truth $r.truth.csv --gnss $r.gnss.csv --odometer $r.odo.csv --baro $r.baro.csv
  frame=ENU; [ $r = road_ned ] && frame=NED
  earth=flat; [ $r != road ] && earth=wgs84
  run "nav_$r" "$bin" integrate $r.imu.csv --init $r.truth.csv --nav-frame $frame --earth $earth --out $r.nav.csv
  run "nav_coning_$r" "$bin" integrate $r.imu.csv --init $r.truth.csv --nav-frame $frame --earth $earth --scheme coning --out $r.nav_coning.csv
  run "fuse_$r" "$bin" fuse $r.imu.csv $r.gnss.csv --init $r.truth.csv --scenario $r.toml --out $r.fuse.csv
  run "fuse_aids_$r" "$bin" fuse $r.imu.csv $r.gnss.csv --init $r.truth.csv --scenario $r.toml --odometer $r.odo.csv --nhc 0.05 --baro $r.baro.csv --out $r.fuse_aids.csv
  run "fuse_gnss_$r" "$bin" fuse $r.imu.csv $r.gnss.csv --align gnss --scenario $r.toml --out $r.fuse_gnss.csv
  run "fuse_static_$r" "$bin" fuse $r.imu.csv $r.gnss.csv --align static --scenario $r.toml --out $r.fuse_static.csv
  run "fuse_full_$r" "$bin" fuse $r.imu.csv $r.gnss.csv --init $r.truth.csv --scenario $r.toml --rest-s 20 --sensor-errors --out $r.fuse_full.csv
  run "compare_$r" "$bin" compare $r.truth.csv $r.fuse_full.csv --out $r.err.csv
done
run nav_baro "$bin" integrate road_ned.imu.csv --init road_ned.truth.csv --nav-frame NED --earth wgs84 --vertical baro --baro road_ned.baro.csv --out road_ned.nav_baro.csv
sed -e 's#^scenario = .*#scenario = "road_enu.toml"#' -e 's/^runs = .*/runs = 3/' "$OLDPWD/examples/study/tunnel.toml" >study.toml
run study "$bin" study study.toml --out study.csv

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
if [ -n "$keep" ]; then
  mkdir -p "$keep" && cp -r . "$keep"
fi
