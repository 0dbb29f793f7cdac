#!/usr/bin/env bash
# Build the FMU libraries (friction laws, rigs) in release mode and package one .fmu per model into
# dist/: dist/<Name>.fmu holds modelDescription.xml (rendered from the code's
# variable table) and binaries/linux64/<modelIdentifier>.so. Then every
# example system examples/<name>.ssd (sources ../dist/*.fmu) is checked and
# packed into a self-contained dist/<name>.ssp (FMUs and .ssv under resources/).
set -euo pipefail
cd "$(dirname "$0")"
cargo build --release -p friction-fmu-c -p rig-fmu-c -p fmu-packager -p friction-fmu
target/release/fmu-package check modelDescription
target/release/fmu-package build --lib-dir target/release --out dist
cargo build --release -p fricsim
# (packed afresh: an example renamed or removed leaves no stale archive)
rm -f dist/*.ssp
for ssd in examples/*.ssd; do
    target/release/fricsim pack "$ssd" "dist/$(basename "$ssd" .ssd).ssp"
done
