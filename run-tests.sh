#!/usr/bin/env bash
# All tests, on a fresh machine: build the FMUs (build-fmu.sh installs
# MinGW-w64 and Wine through scripts/setup-windows.sh: the Windows DLLs are
# cross-built and tested under Wine), run the Rust tests, create the pinned
# Python venv (FMPy, fmutool, libcosimpy), install Chromium (the report
# tests render report.html in it), build the `fmi` crate's importer
# (libclang for its bindings), build and install the Python package
# fricsim (python/, maturin) and run the Python tests (pytest-xdist, two
# workers).
#
# The set-ups that mostly wait on the network (pip's downloads, apt's)
# run in the background while the Rust builds and tests keep the cores
# busy; their output is in target/set-up/ and shown when they end. apt
# runs one install at a time: MinGW and Wine first, then the browser and
# libclang in one background chain (apt refuses a second install while
# one holds its lock).
set -euo pipefail
cd "$(dirname "$0")"
mkdir -p target/set-up

declare -A pids
# start NAME COMMAND...: run COMMAND in the background, its output in
# target/set-up/NAME.log
start() {
    local name=$1
    shift
    "$@" > "target/set-up/$name.log" 2>&1 &
    pids[$name]=$!
}
# finish NAME: wait for NAME, show its output, stop here if it failed
finish() {
    local name=$1 status=0
    wait "${pids[$name]}" || status=$?
    unset "pids[$name]"
    cat "target/set-up/$name.log"
    if [ "$status" -ne 0 ]; then
        echo "run-tests.sh: the set-up '$name' failed (exit status $status), output above" >&2
        exit "$status"
    fi
}
# mark STEP: the elapsed time when STEP ended, so that a CI log shows
# where its minutes go
mark() {
    echo "run-tests.sh: $1 done, $((SECONDS / 60)) min $((SECONDS % 60)) s since the start" >&2
}
# a failure in the foreground stops the background set-ups too
trap 'for pid in "${pids[@]}"; do kill "$pid" 2> /dev/null || true; done' EXIT

start venv scripts/setup-venv.sh
scripts/setup-windows.sh
mark "MinGW-w64 and Wine set-up"
start browser-and-fmi-crate bash -c 'scripts/setup-browser.sh && scripts/setup-fmi-crate.sh'
./build-fmu.sh
mark "build-fmu.sh (FMUs, fricsim, examples)"
cargo test --workspace --profile release-test --no-run
mark "Rust test build"
cargo test --workspace --profile release-test
mark "Rust tests"
# the host's library crates document their public API without a broken link
RUSTDOCFLAGS="-D warnings" cargo doc --quiet --no-deps -p fricsim-fmi -p fricsim-core \
    -p fricsim-diagnose -p fricsim-hidden-effects -p fricsim
mark "API documentation"
finish venv
mark "pinned venv (waited for)"
finish browser-and-fmi-crate
mark "Chromium and the fmi crate (waited for)"
scripts/setup-python-package.sh
mark "Python package fricsim"
# on two workers, each test file whole on one of them (a file's module
# fixtures, such as its Dask cluster or the Wine prefix of
# test_windows_dll.py, stay in one process) but the long files whose tests
# share nothing, spread test by test and handed out first (tests/conftest.py,
# SPREAD_FILES); the slowest tests listed at the end. PYTHONFAULTHANDLER:
# a worker that dies of a signal, also while it tears its modules down
# after its last test, prints the Python stack of each of its threads
# (not once the interpreter has shut the handler down, at its very end)
PYTHONFAULTHANDLER=1 .venv/bin/python -m pytest tests -q -n 2 --dist loadfile --no-loadscope-reorder --durations=15
mark "Python tests"
