#!/usr/bin/env bash
# BENCHMARKS.md's accuracy table: relative RMS error of the friction force
# against the monolithic reference (fricsim reference) for the stick-slip
# benchmark at sigma0 = 1e5 and 1e7 N/m and Appels and Herder's piezo push, at
# macro steps 1e-5 ... 1e-2 s, for jacobi, gauss-seidel, newton,
# newton-interpolated and adaptive, with the wall time of every run.
#
# Builds the FMUs and the examples' archives (build-fmu.sh) and the
# accuracy-table program (bench/src/bin/accuracy_table.rs), then runs it;
# the tables are written between the markers of BENCHMARKS.md. Arguments
# go to the program: --quick (1e-3 s only, 2 s per case), --steps,
# --stop, --masters, --cases, --update OTHER.md; --help lists them.
# --check BENCHMARKS.md --steps 1e-2,1e-3 writes nothing: it recomputes
# those rows at their published duration and fails naming every error
# entry that differs from the published one (a second or two).
# The full table takes a few minutes; run it on an otherwise idle machine,
# since the wall times are part of it.
set -euo pipefail
cd "$(dirname "$0")/.."
./build-fmu.sh >/dev/null
cargo build --release -p fricsim-bench --bin accuracy-table
args=("$@")
case " $* " in
    *" --update "*|*" --update="*|*" --check "*|*" --check="*) ;;
    *) args+=(--update BENCHMARKS.md) ;;
esac
ACCURACY_TABLE_COMMAND="scripts/accuracy-table.sh${*:+ $*}" \
    exec target/release/accuracy-table "${args[@]}"
