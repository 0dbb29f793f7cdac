#!/usr/bin/env bash
# What the instance guard costs a single-threaded importer: the FMUs as
# shipped (a call from a second thread is refused instead of corrupting
# the instance; from the thread the guard is biased to, a call enters and
# leaves by plain stores: fmu-src/fmi-export/src/guard.rs) against the same
# FMUs built with the guard
# compiled out (fmi-export feature `unguarded-instances`, for this script
# only), on the LuGre stick-slip benchmark (examples/stick_slip.ssd, 20 s
# at 1e-4 s, Jacobi), measured in turns A B A B in one run:
#   - the host's stepping, in process (`speed-table --only host`: its
#     best of 3 runs per turn);
#   - the whole `fricsim run` command, a fresh process writing its CSV;
#   - with valgrind present, instructions per macro step (callgrind,
#     `--stop 1` minus `--stop 0.0001`), which do not vary run to run.
# Writes the table between the `instance-guard` markers of BENCHMARKS.md
# (or of the file given with --update FILE); TURNS=N sets the turns
# (default 10). Run it on an otherwise idle machine.
set -euo pipefail
cd "$(dirname "$0")/.."
update=BENCHMARKS.md
if [ "${1:-}" = "--update" ]; then update=$2; fi
turns=${TURNS:-10}

./build-fmu.sh > /dev/null
cargo build --release -q -p fricsim-bench --bin speed-table
# The unguarded libraries, in a target directory of their own, packed into
# a root of their own (the examples refer to ../dist/).
CARGO_TARGET_DIR=target/unguarded cargo build --release -q -p friction-fmu-c -p rig-fmu-c \
    --features fmi-export/unguarded-instances
unguarded=target/bench-guard/unguarded
rm -rf "$unguarded" && mkdir -p "$unguarded"
cp -r examples "$unguarded/"
target/release/fmu-package build --out "$unguarded/dist" --platform linux64=target/unguarded/release > /dev/null

out=target/bench-guard/times.csv
echo "turn,build,in_process_ms,command_ns,final_force" > "$out"
for turn in $(seq 1 "$turns"); do
    for build in guarded unguarded; do
        root=.
        [ "$build" = unguarded ] && root=$unguarded
        line=$(target/release/speed-table --only host --repeats 3 --root "$root")
        ms=$(sed -E 's/.*: ([0-9.]+) ms,.*/\1/' <<< "$line")
        force=$(sed -E 's/.*final friction.F ([-0-9.e]+).*/\1/' <<< "$line")
        start=$(date +%s%N)
        target/release/fricsim run -q "$root/examples/stick_slip.ssd" \
            --out "target/bench-guard/$build.csv" > /dev/null
        end=$(date +%s%N)
        echo "$turn,$build,$ms,$((end - start)),$force" >> "$out"
    done
done

instructions=""
if command -v valgrind > /dev/null; then
    for build in guarded unguarded; do
        root=.
        [ "$build" = unguarded ] && root=$unguarded
        for stop in 1 0.0001; do
            valgrind --tool=callgrind --callgrind-out-file=/dev/null \
                target/release/speed-table --only host --stop "$stop" --root "$root" \
                2> "target/bench-guard/callgrind-$build-$stop.txt" > /dev/null
        done
        instructions+="$build,$(grep -o 'Collected : [0-9]*' "target/bench-guard/callgrind-$build-1.txt" | grep -o '[0-9]*'),$(grep -o 'Collected : [0-9]*' "target/bench-guard/callgrind-$build-0.0001.txt" | grep -o '[0-9]*');"
    done
fi

python3 scripts/bench-instance-guard-report.py "$out" "$update" "$turns" "$instructions" \
    "$(cmp -s target/bench-guard/guarded.csv target/bench-guard/unguarded.csv && echo same || echo different)"
