#!/usr/bin/env bash
# Runs every test of imukit, Rust and Python, from a fresh clone: sets up what it needs, checks
# formatting, lints and the heap-free core, runs the Rust tests, builds the wheel (manylinux2014,
# abi3, the `imukit` command inside) and the source distribution, installs the wheel into a fresh
# virtual environment with no Rust on PATH, and runs the Python tests, the hostile-input run and
# the examples against what that wheel installed.
#   .venv        build tools (maturin, ziglang); kept between runs
#   .venv-wheel  made anew each run from dist/imukit-*.whl with its [test] extra
set -euo pipefail
cd "$(dirname "$0")/.."
section() { echo "== $1 (${SECONDS}s)"; }

section "Build environment (.venv)"
if [ ! -x .venv/bin/python ]; then
  "${PYTHON:-python3}" -m venv .venv
fi
# shellcheck disable=SC1091
. .venv/bin/activate   # maturin finds zig as `python -m ziglang` of the active environment
python -m pip install --quiet --disable-pip-version-check "maturin>=1.9,<2" "ziglang>=0.13" "check-jsonschema>=0.28"

section "Format and lints"
cargo fmt --all -- --check
python3 scripts/check_layers.py   # no room of the library imports a room above its own; no circle between rooms of imu-core or imu-io
cargo clippy --workspace --all-targets --quiet -- -D warnings
check-jsonschema --builtin-schema vendor.github-workflows .github/workflows/*.yml
RUSTDOCFLAGS="-D warnings" cargo doc --quiet --no-deps -p imu-core -p imu-io -p imukit -p imu-plot -p imu-cli   # doc links resolve

section "Files and formats without the heavy ones: imu-io builds, lints and refuses them by name"
cargo clippy --quiet -p imu-io --no-default-features --lib -- -D warnings
cargo test --quiet -p imu-io --no-default-features --lib

section "Heap-free core: builds without std, never names alloc or std, no std-only dependency"
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

section "Rust tests"
cargo test --workspace --exclude imu-py
# A clean clone (CI) needs the test build no more: the wheel builds into its own folder.
if [ -n "${IMUKIT_FREE_DISK:-}" ]; then
  rm -rf target/debug
fi

section "Wheel (manylinux2014, abi3, with the imukit command) and source distribution"
rm -rf dist
# --zig links against glibc 2.17 whatever this machine has, so the wheel is manylinux2014.
maturin build --quiet --release --zig --compatibility manylinux2014 -m crates/imu-py/Cargo.toml --out dist
maturin sdist -m crates/imu-py/Cargo.toml --out dist
python3 scripts/check_dist.py dist

section "A fresh environment from the wheel, no Rust on PATH"
deactivate
rm -rf .venv-wheel
"${PYTHON:-python3}" -m venv .venv-wheel
wheel=$(ls dist/imukit-*.whl)
.venv-wheel/bin/python -m pip install --quiet --disable-pip-version-check "${wheel}[test]"
# From here on only the wheel's environment and the system's programs are on PATH.
PATH="$PWD/.venv-wheel/bin:$(printf '%s' "$PATH" | tr ':' '\n' | grep -vE '(cargo|rustup|\.venv)(/|$)' | paste -sd: -)"
export PATH
unset VIRTUAL_ENV
if command -v cargo >/dev/null || command -v rustc >/dev/null; then
  echo "a Rust toolchain is still on PATH" >&2
  exit 1
fi
(cd "$(mktemp -d)" && imukit demo >/dev/null && test -s imukit-demo/imu.csv && test -s imukit-demo/truth.png \
  && python -c "import imukit; s = imukit.simulate({'trajectory': {'type': 'builtin', 'name': 'figure8'}}); assert s.imu.values.shape[0] == 2001" \
  && test "$(imukit --version)" = "imukit $(python -c 'import imukit; print(imukit.__version__)')")
export IMUKIT_BIN="$PWD/.venv-wheel/bin/imukit"

section "Python stubs match the installed module"
python -m mypy.stubtest imukit._core

section "Python tests (the installed wheel)"
python -m pytest -q crates/imu-py/tests tests/python --doctest-glob='*.md' README.md docs
python -m pytest -q --doctest-modules --pyargs imukit.plot imukit._monte_carlo imukit._orientation imukit._sensor imukit._truth imukit._table imukit._examples

section "Hostile input (a short seeded run; see tests/fuzz/hostile.py for a long one)"
python tests/fuzz/hostile.py --cases 400 --seed 1

section "Examples (written by the installed wheel into an empty folder: no checkout needed)"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
repo=$PWD
cd "$out"
imukit --quiet example all
diff -r "$repo/examples" examples
for f in examples/*.toml; do
  name=$(basename "$f" .toml)
  imukit simulate "$f" --out "$out/${name}_imu.csv" --truth "$out/${name}_truth.csv"
  imukit plot "$out/${name}_truth.csv" --out "$out/${name}_truth.png"
  imukit plot "$out/${name}_imu.csv" --out "$out/${name}_imu.png"
done
for f in differentiation_error_study matlab_imusensor matlab_orientation allan_study navigation_round_trip; do
  python "examples/$f.py" --figures "$out/figures"
done
python examples/gyrocompass.py
imukit integrate "$out/schuler_imu.csv" --init "$out/schuler_truth.csv" --nav-frame NED \
  --earth wgs84 --vertical hold --out "$out/schuler_nav.csv"
imukit compare "$out/schuler_truth.csv" "$out/schuler_nav.csv" --out "$out/schuler_err.csv"
imukit plot "$out/schuler_err.csv" --out "$out/schuler.png"
for f in imufilter ahrsfilter ecompass madgwick mahony complementary; do
  imukit orient "$out/matlab_orientation_imu.csv" --filter "$f" --nav-frame NED --accel-sign matlab \
    --out "$out/orient_$f.csv"
  imukit compare "$out/matlab_orientation_truth.csv" "$out/orient_$f.csv" --out "$out/orient_err_$f.csv"
done
imukit plot "$out/orient_err_ahrsfilter.csv" --out "$out/orient_err.png"
imukit exercise --out-dir "$out/exercise"
imukit study examples/study/tunnel.toml --out "$out/tunnel.csv" --plot "$out/tunnel.png"
imukit study examples/study/tunnel_wheels.toml --out "$out/wheels.csv" --plot "$out/wheels.png"
cd "$repo"

section "NumPy comparison (agreement checked; the ratios at this small N are not the benchmark)"
python benches/compare_numpy.py --sizes 1e4
section "All tests passed"
