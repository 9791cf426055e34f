#!/usr/bin/env bash
# Runs every test of imukit, Rust and Python, from a fresh clone: sets up what it needs
# (a Python virtual environment in .venv with maturin, numpy, pytest, sympy, mypy; the release CLI;
# the Python extension), checks formatting, lints and the heap-free core, runs the examples.
set -euo pipefail
cd "$(dirname "$0")/.."

echo "== Python environment (.venv)"
if [ ! -x .venv/bin/python ]; then
  "${PYTHON:-python3}" -m venv .venv
fi
# shellcheck disable=SC1091
. .venv/bin/activate
python -m pip install --quiet --disable-pip-version-check "maturin>=1.5,<2" "numpy>=1.21" "pytest>=7" "sympy>=1.9" "mypy>=1.8" "matplotlib>=3.5" "dask[distributed]>=2023.1" "scipy>=1.7" "pandas>=2" "polars>=0.20" "pyarrow>=14"

echo "== Format and lints"
cargo fmt --all -- --check
cargo clippy --workspace --all-targets --quiet -- -D warnings
RUSTDOCFLAGS="-D warnings" cargo doc --quiet --no-deps -p imu-core -p imukit -p imu-plot -p imu-cli   # doc links resolve

echo "== Heap-free core: builds without std, never names alloc or std, no std-only dependency"
cargo build --quiet -p imu-core --no-default-features --features libm
# A bare-metal target has no std and no allocator: the core must build there.
if rustup target add thumbv7em-none-eabihf >/dev/null 2>&1; then
  cargo build --quiet -p imu-core --no-default-features --features libm --target thumbv7em-none-eabihf
else
  echo "(rustup could not add thumbv7em-none-eabihf here; the host no_std build above stands in)"
fi
if cargo tree -p imu-core -e normal --prefix none | grep -E '^num-dual '; then
  echo "imu-core depends on a std-only crate" >&2
  exit 1
fi
if grep -rnE '(^|[^A-Za-z0-9_])alloc::|extern crate (alloc|std)|\bstd::' crates/imu-core/src; then
  echo "imu-core names alloc or std" >&2
  exit 1
fi

echo "== Rust tests"
cargo test --workspace --exclude imu-py

echo "== Python extension and CLI (release)"
cargo build --quiet --release -p imu-cli
maturin develop --quiet --release -m crates/imu-py/Cargo.toml

echo "== Python stubs match the built module"
python -m mypy.stubtest imukit._core

echo "== Python tests"
IMUKIT_BIN="$PWD/target/release/imukit" python -m pytest -q crates/imu-py/tests tests/python --doctest-glob=README.md README.md --doctest-modules crates/imu-py/python/imukit/plot.py crates/imu-py/python/imukit/_monte_carlo.py crates/imu-py/python/imukit/_orientation.py crates/imu-py/python/imukit/_sensor.py crates/imu-py/python/imukit/_truth.py

echo "== Hostile input (a short seeded run; see tests/fuzz/hostile.py for a long one)"
IMUKIT_BIN="$PWD/target/release/imukit" python tests/fuzz/hostile.py --cases 400 --seed 1

echo "== Examples"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for f in examples/*.toml; do
  name=$(basename "$f" .toml)
  target/release/imukit simulate "$f" --out "$out/${name}_imu.csv" --truth "$out/${name}_truth.csv"
  target/release/imukit plot "$out/${name}_truth.csv" --out "$out/${name}_truth.png"
  target/release/imukit plot "$out/${name}_imu.csv" --out "$out/${name}_imu.png"
done
for f in differentiation_error_study matlab_imusensor matlab_orientation allan_study navigation_round_trip; do
  python "examples/$f.py" --figures "$out/figures"
done
python examples/gyrocompass.py
target/release/imukit integrate "$out/schuler_imu.csv" --init "$out/schuler_truth.csv" --nav-frame NED \
  --earth wgs84 --vertical hold --out "$out/schuler_nav.csv"
target/release/imukit compare "$out/schuler_truth.csv" "$out/schuler_nav.csv" --out "$out/schuler_err.csv"
target/release/imukit plot "$out/schuler_err.csv" --out "$out/schuler.png"
for f in imufilter ahrsfilter ecompass madgwick mahony complementary; do
  target/release/imukit orient "$out/matlab_orientation_imu.csv" --filter "$f" --nav-frame NED --accel-sign matlab \
    --out "$out/orient_$f.csv"
  target/release/imukit compare "$out/matlab_orientation_truth.csv" "$out/orient_$f.csv" --out "$out/orient_err_$f.csv"
done
target/release/imukit plot "$out/orient_err_ahrsfilter.csv" --out "$out/orient_err.png"
target/release/imukit exercise --out-dir "$out/exercise"
target/release/imukit study examples/study/tunnel.toml --out "$out/tunnel.csv" --plot "$out/tunnel.png"
target/release/imukit study examples/study/tunnel_wheels.toml --out "$out/wheels.csv" --plot "$out/wheels.png"

echo "== NumPy comparison (agreement checked; the ratios at this small N are not the benchmark)"
IMUKIT_BIN="$PWD/target/release/imukit" python benches/compare_numpy.py --sizes 1e4
echo "== All tests passed"
