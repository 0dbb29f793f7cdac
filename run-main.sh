#!/usr/bin/env bash
# Main job: build the FMUs and the host, then co-simulate the LuGre
# stick-slip benchmark (1995: m = 1 kg, k = 2 N/m, pulled at 0.1 m/s) as
# Rig1D.fmu + LuGre.fmu with the Jacobi master at a 1e-4 s macro step.
# Writes out/stick_slip.csv and the plot out/stick_slip.svg.
set -euo pipefail
cd "$(dirname "$0")"
./build-fmu.sh
cargo build --release -p fricsim
target/release/fricsim cosim \
    --fmu rig=dist/Rig1D.fmu --fmu friction=dist/LuGre.fmu \
    --connect "rig.v->friction.v" --connect "friction.F->rig.F" \
    --step 1e-4 --stop 20 \
    --out out/stick_slip.csv --plot out/stick_slip.svg \
    --plot-signal rig.x --plot-signal rig.v --plot-signal friction.F
