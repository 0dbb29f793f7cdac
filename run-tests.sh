#!/usr/bin/env bash
# All tests, on a fresh machine: build the FMUs, run the Rust tests, create
# the pinned Python venv (FMPy), install Chromium (the report tests render
# report.html in it) and run the Python tests.
set -euo pipefail
cd "$(dirname "$0")"
./build-fmu.sh
cargo test --workspace --profile release-test
scripts/setup-venv.sh
scripts/setup-browser.sh
.venv/bin/python -m pytest tests -q
