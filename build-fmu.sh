#!/usr/bin/env bash
# Build the FMU libraries (friction laws, rigs) in release mode, for Linux
# and, cross-built with MinGW-w64, for Windows, and package two .fmu per
# model: dist/<Name>.fmu (FMI 2.0) holds modelDescription.xml (rendered
# from the code's variable table), binaries/linux64/<modelIdentifier>.so and
# binaries/win64/<modelIdentifier>.dll; dist/fmi3/<Name>.fmu (FMI 3.0) holds
# the FMI 3.0 description of the same table and the same two libraries
# (each exports both interfaces) under binaries/x86_64-linux/ and
# binaries/x86_64-windows/. Then every example system
# examples/<name>.ssd (sources ../dist/*.fmu) is checked and packed into a
# self-contained dist/<name>.ssp (FMUs and .ssv under resources/).
set -euo pipefail
cd "$(dirname "$0")"
# the MinGW-w64 linker, Wine for the tests, the Rust target (idempotent)
scripts/setup-windows.sh
# the host too, in the same cargo call: the link-time optimisation of each
# library and of fricsim (one thread each) run side by side
cargo build --release -p friction-fmu-c -p rig-fmu-c -p fmu-packager -p friction-fmu -p fricsim
# the linker and flags of this target are in .cargo/config.toml
cargo build --release --target x86_64-pc-windows-gnu -p friction-fmu-c -p rig-fmu-c
target/release/fmu-package check modelDescription
target/release/fmu-package build --out dist \
    --platform linux64=target/release \
    --platform win64=target/x86_64-pc-windows-gnu/release
# (packed afresh: an example renamed or removed leaves no stale archive)
rm -f dist/*.ssp
for ssd in examples/*.ssd; do
    target/release/fricsim pack "$ssd" "dist/$(basename "$ssd" .ssd).ssp"
done
