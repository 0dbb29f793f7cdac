#!/usr/bin/env bash
# All tests, on a fresh machine: build the FMUs (build-fmu.sh installs
# MinGW-w64 and Wine through scripts/setup-windows.sh: the Windows DLLs are
# cross-built and tested under Wine), run the Rust tests, create the pinned
# Python venv (FMPy, fmutool, libcosimpy), install Chromium (the report
# tests render report.html in it), build the `fmi` crate's importer
# (libclang for its bindings), build and install the Python package
# fricsim (python/, maturin) and run the Python tests (pytest-xdist, two
# workers).
set -euo pipefail
cd "$(dirname "$0")"
./build-fmu.sh
cargo test --workspace --profile release-test
scripts/setup-venv.sh
scripts/setup-browser.sh
scripts/setup-fmi-crate.sh
scripts/setup-python-package.sh
# on two workers, each test file whole on one of them (--dist loadfile:
# a file's module fixtures, such as its Dask cluster or the Wine prefix
# of test_windows_dll.py, stay in one process)
.venv/bin/python -m pytest tests -q -n 2 --dist loadfile
