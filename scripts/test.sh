#!/usr/bin/env bash
# Runs every test: Rust (workspace) now; Python joins when the bindings land.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --workspace --exclude imu-py
