#!/usr/bin/env bash
# Main job: build the FMUs and the host, then co-simulate the LuGre
# stick-slip benchmark (1995: m = 1 kg, k = 2 N/m, pulled at 0.1 m/s) from
# its system file: dist/stick_slip.ssp, packed by build-fmu.sh from
# examples/stick_slip.ssd (Rig1D.fmu + LuGre.fmu, Jacobi master, macro step
# 1e-4 s, 20 s). Writes out/stick_slip.csv and the plot out/stick_slip.png.
set -euo pipefail
cd "$(dirname "$0")"
./build-fmu.sh
target/release/fricsim run dist/stick_slip.ssp \
    --out out/stick_slip.csv --plot out/stick_slip.png
