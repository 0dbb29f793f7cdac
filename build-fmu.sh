#!/usr/bin/env bash
# Build the FMU libraries in release mode and package one .fmu per model into
# dist/: dist/<Name>.fmu holds modelDescription.xml (rendered from the code's
# variable table) and binaries/linux64/<modelIdentifier>.so.
set -euo pipefail
cd "$(dirname "$0")"
cargo build --release -p friction-fmu -p fmu-packager
target/release/fmu-package check modelDescription
target/release/fmu-package build --lib target/release/libfriction_fmu.so --out dist
