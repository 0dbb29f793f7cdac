#!/usr/bin/env bash
# All tests, on a fresh machine: build the FMUs, run the Rust tests, create
# the pinned Python venv (FMPy) and run the FMPy conformance tests.
set -euo pipefail
cd "$(dirname "$0")"
./build-fmu.sh
cargo test --workspace --profile release-test
scripts/setup-venv.sh
.venv/bin/python -m pytest tests -q
