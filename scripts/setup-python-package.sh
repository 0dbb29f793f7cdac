#!/usr/bin/env bash
# Build the Python package `fricsim` (python/: the extension module of
# python/src/lib.rs by maturin, and the Python part) and install it into
# the repository's .venv (scripts/setup-venv.sh first). Run again after a
# change of the Rust or Python sources: cargo rebuilds what changed (a few
# seconds when nothing did), pip replaces the installed package.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup-venv.sh
# in the workspace's target/, whose release-test build (run-tests.sh's
# cargo test) has compiled the host and its dependencies already
export CARGO_TARGET_DIR="$PWD/target"
# maturin, the build backend, from the venv (pinned in tests/requirements.txt)
export PATH="$PWD/.venv/bin:$PATH"
.venv/bin/pip install --quiet --disable-pip-version-check --no-deps \
    --no-build-isolation --force-reinstall .
