#!/usr/bin/env bash
# BENCHMARKS.md's speed tables, every figure measured in one run: one step
# of each friction FMU through the C ABI, the LuGre stick-slip benchmark on
# the host against FMPy (scripts/bench_fmpy.py, the same FMUs, step and
# scheme) and against the monolithic Rust loop, Appels and Herder's
# Experiments 3 curve, the bristle law from 10 to 100 000 bristles,
# fricsim sweep on one core and on all, and fricsim diagnose on the EMPS
# data.
#
# Builds the FMUs (build-fmu.sh), the pinned Python venv with FMPy
# (scripts/setup-venv.sh) and the speed-table program
# (bench/src/bin/speed_table.rs), then runs it; the tables are written
# between the markers `<!-- speed: begin … -->` and `<!-- speed: end -->`
# of BENCHMARKS.md. Arguments go to the program: --quick (short runs, no
# fricsim diagnose: the tables appear, the numbers mean little),
# --repeats N, --update OTHER.md, --python PATH; --help lists them.
# The full run takes about a minute after the build, most of it FMPy and
# fricsim diagnose; run it on an
# otherwise idle machine, since it measures time.
set -euo pipefail
cd "$(dirname "$0")/.."
./build-fmu.sh >/dev/null
scripts/setup-venv.sh
cargo build --release -p fricsim-bench -p fricsim --bin speed-table --bin fricsim
args=("$@")
case " $* " in
    *" --update "*|*" --update="*) ;;
    *) args+=(--update BENCHMARKS.md) ;;
esac
SPEED_TABLE_COMMAND="scripts/bench.sh${*:+ $*}" \
    exec target/release/speed-table "${args[@]}"
