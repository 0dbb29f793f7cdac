#!/usr/bin/env bash
# Leak check of every shipped FMU: CYCLES (default 10000) instantiate /
# set up / initialize / step / FMU state round trip / refused call /
# terminate / free cycles of each dist/*.fmu binary, driven by
# scripts/leak_cycles.c, under valgrind --leak-check=full. Fails unless
# valgrind reports no error and 0 bytes definitely, indirectly and possibly
# lost. Without valgrind (or with NO_VALGRIND=1) the cycles run natively.
#
#   scripts/leak-check.sh [CYCLES]
set -euo pipefail
cd "$(dirname "$0")/.."
cycles=${1:-10000}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cc -O1 -g -Wall -Wextra -o "$work/leak_cycles" scripts/leak_cycles.c -ldl -lm
use_valgrind=1
if [ "${NO_VALGRIND:-0}" = 1 ] || ! command -v valgrind > /dev/null; then
    use_valgrind=0
    echo "valgrind not used: native cycles only"
fi
status=0
# every shipped FMU, from the one list (modelDescription/shipped.txt)
for name in $(grep -v '^#' modelDescription/shipped.txt | cut -d' ' -f1); do
    fmu="dist/$name.fmu"
    [ -f "$fmu" ] || { echo "$fmu missing: run ./build-fmu.sh"; exit 2; }
    mkdir -p "$work/$name"
    if command -v unzip > /dev/null; then
        unzip -q -o "$fmu" -d "$work/$name"
    else
        python3 -m zipfile -e "$fmu" "$work/$name"
    fi
    guid=$(grep -o 'guid="[^"]*"' "$work/$name/modelDescription.xml" | head -1 | cut -d'"' -f2)
    id=$(grep -o 'modelIdentifier="[^"]*"' "$work/$name/modelDescription.xml" | head -1 | cut -d'"' -f2)
    so="$work/$name/binaries/linux64/$id.so"
    start=$(date +%s%N)
    if [ $use_valgrind = 1 ]; then
        # One cycle first: what stays allocated at exit after any number of
        # cycles must be exactly what stays after one (no growth per cycle).
        in_use() { grep -o "in use at exit: [0-9,]* bytes" "$1" | tr -dc '0-9'; }
        run() {
            valgrind --leak-check=full --show-leak-kinds=definite,indirect,possible \
                --errors-for-leak-kinds=definite,indirect,possible --error-exitcode=99 \
                --log-file="$2" "$work/leak_cycles" "$so" "$guid" "$1" > "$work/$name.out"
        }
        if ! run 1 "$work/$name.1.valgrind" || ! run "$cycles" "$work/$name.valgrind"; then
            echo "$name: FAILED"; cat "$work/$name".*valgrind; cat "$work/$name.out"; status=1; continue
        fi
        log="$work/$name.valgrind"
        base=$(in_use "$work/$name.1.valgrind")
        after=$(in_use "$log")
        lost=$(grep -E "(definitely|indirectly|possibly) lost:" "$log" | sed -E 's/.*(definitely|indirectly|possibly) lost: ([0-9,]+) bytes.*/\1 \2 B/' | paste -sd, -)
        [ -n "$lost" ] || lost="no leak record"
        errors=$(grep -o "ERROR SUMMARY: [0-9]* errors" "$log")
        if [ "$base" != "$after" ]; then
            echo "$name: $after bytes in use at exit after $cycles cycles, $base after 1"; status=1
        fi
        summary="$lost; $errors; in use at exit $after B (1 cycle: $base B)"
    else
        "$work/leak_cycles" "$so" "$guid" "$cycles" > "$work/$name.out" || { echo "$name: FAILED"; status=1; continue; }
        summary="(no valgrind)"
    fi
    end=$(date +%s%N)
    ms=$(( (end - start) / 1000000 ))
    printf '%-16s %d cycles %3d.%d s  %s\n' "$name" "$cycles" $((ms / 1000)) $((ms % 1000 / 100)) "$summary"
done
exit $status
