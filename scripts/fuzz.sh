#!/usr/bin/env bash
# Coverage-guided fuzzing with libFuzzer (libfuzzer-sys) on the stable
# toolchain, without cargo-fuzz: the fuzz/ crate (outside the workspace) is
# built with the sanitizer-coverage flags cargo-fuzz would pass, and each
# target runs for SECONDS (default 300) from a seed corpus in fuzz/corpus/
# (not committed). Findings land in fuzz/artifacts/<target>/.
#
#   scripts/fuzz.sh [SECONDS] [TARGET...]
#
# Targets: fmi_calls deserialize_state model_description ssd.
# With ASAN=1 the targets are also built with AddressSanitizer (needs
# RUSTC_BOOTSTRAP=1 for -Zsanitizer on a stable compiler).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-300}
shift || true
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(fmi_calls deserialize_state model_description ssd)

flags="--cfg fuzzing -Cpasses=sancov-module -Cllvm-args=-sanitizer-coverage-level=4"
flags+=" -Cllvm-args=-sanitizer-coverage-inline-8bit-counters"
flags+=" -Cllvm-args=-sanitizer-coverage-pc-table"
flags+=" -Cllvm-args=-sanitizer-coverage-trace-compares"
flags+=" -Cdebug-assertions -Coverflow-checks -Cforce-frame-pointers"
target_dir=fuzz/target
if [ "${ASAN:-0}" = 1 ]; then
    flags+=" -Zsanitizer=address"
    export RUSTC_BOOTSTRAP=1
    target_dir=fuzz/target-asan
fi
host=$(rustc -vV | sed -n 's/^host: //p')
(cd fuzz && RUSTFLAGS="$flags" CARGO_TARGET_DIR="../$target_dir" \
    cargo build --release --target "$host" --bins)
bin="$target_dir/$host/release"

# Seed corpora: the checked-in model descriptions and example systems.
mkdir -p fuzz/corpus/{fmi_calls,deserialize_state,model_description,ssd}
cp -n modelDescription/*.xml host/tests/c/belt_oscillator/modelDescription.xml \
    fuzz/corpus/model_description/ 2>/dev/null || true
cp -n examples/*.ssd fuzz/corpus/ssd/ 2>/dev/null || true

for t in "${targets[@]}"; do
    mkdir -p "fuzz/artifacts/$t"
    echo "== $t: $seconds s"
    "$bin/$t" "fuzz/corpus/$t" -max_total_time="$seconds" -timeout=10 \
        -rss_limit_mb=2048 -max_len=4096 -print_final_stats=1 \
        -artifact_prefix="fuzz/artifacts/$t/" 2>&1 | tee "fuzz/artifacts/$t.log" |
        grep -E "^(#[0-9]+ +DONE|Done|stat::number_of_executed_units|stat::average_exec_per_sec|==[0-9]+== ERROR|SUMMARY|artifact_prefix|Test unit written)" || true
done
