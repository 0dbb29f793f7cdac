#!/usr/bin/env bash
# Build tests/fmi-crate/ (`fmi-crate-drive`: our FMUs loaded and stepped
# through the `fmi` crate's FMI 2.0 or FMI 3.0 Co-Simulation import API, by
# the FMU's version, for tests/test_fmi_crate.py)
# into target/fmi-crate/debug/ (the dev profile builds in half the CPU
# time of a release build). The crate's fmi-sys generates its bindings with
# bindgen at build time, which needs libclang: libclang-dev is installed
# from the distribution's packages when missing (without its recommends).
# Idempotent; needs root or sudo for apt-get on a fresh machine. The crate
# versions are pinned by tests/fmi-crate/Cargo.lock.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! dpkg -s libclang-dev > /dev/null 2>&1; then
    sudo=""
    if [ "$(id -u)" -ne 0 ]; then
        sudo="sudo"
    fi
    echo "setup-fmi-crate.sh: installing libclang-dev (Debian package) for the fmi crate's bindgen" >&2
    install="$sudo env DEBIAN_FRONTEND=noninteractive apt-get install -o DPkg::Lock::Timeout=600 -y -q --no-install-recommends libclang-dev"
    $install > /dev/null || { $sudo apt-get update -o DPkg::Lock::Timeout=600 -q > /dev/null && $install > /dev/null; }
fi
cargo build --locked --quiet --manifest-path tests/fmi-crate/Cargo.toml \
    --target-dir target/fmi-crate
test -x target/fmi-crate/debug/fmi-crate-drive
